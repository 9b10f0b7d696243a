"""A bridge's fill (dead load only) over the segmental ring: `masonry limit` against the four-hinge reference
(tests/four_hinge_reference.py, the fill's weight computed here from its definition: the quadrilateral
between each voussoir's extrados chord and the fill level, by the shoelace formula), and the closed forms a
fill has: its total weight, and a symmetric fill's symmetric thrust.

Both sides solve the same discrete ring with the fill's weight on each voussoir at its column's centroid
(no sliding: μ = 10), so they agree to rounding, hinge for hinge, as the bare ring does.
"""

from __future__ import annotations

import numpy as np
import pytest
from four_hinge_reference import least_load_factor
from test_limit_ring_mechanisms import (
    MU,
    RING,
    _joint,
    _unordered,
    segmental_reference_ring,
    voussoir_loads,
)

from geometry_library.blocks import Assembly
from geometry_library.builders import build_arch
from masonrycli.limit import LiveLoad, analyse
from masonrycli.limit.analysis import support_thrusts
from masonrycli.scenario.motion import Fixed
from masonrycli.scenario.scenario import Material, RunConfig, Scenario

G = 9.81
SPRINGING = 3.4  # the builder's default piers: 17 courses of 0.20 m
COVER = 0.3  # m of fill over the crown
FILL_DENSITY = 1900.0
STONE = 2500.0  # the builder's block density


def filled_ring_scenario(voussoirs: int) -> Scenario:
    """The builder's segmental ring under COVER of fill, its voussoirs (carrying their fill) on its two
    skewbacks held fixed (rigid abutments, which carry the fill over them)."""
    assembly = build_arch(
        span=8.0,
        rise=2.0,
        ring_thickness=RING,
        voussoirs=voussoirs,
        pier_width=1.0,
        fill_cover=COVER,
        fill_density=FILL_DENSITY,
    )
    from geometry_library.blocks import Support

    ring = tuple(b for b in assembly.blocks if b.name.startswith("v"))
    springers = tuple(Support(b.polygon, b.name) for b in assembly.blocks if b.name.endswith("skewback"))
    return Scenario(
        name="filled",
        run=RunConfig(),
        material=Material(density=STONE, friction=MU),
        assembly=Assembly(blocks=ring, supports=springers),
        motions=tuple(Fixed() for _ in springers),
    )


def reference_fill(extrados: np.ndarray, level: float) -> tuple[np.ndarray, np.ndarray]:
    """Centroids and areas of the fill over each extrados chord E_k E_k+1 up to ``level``: the quadrilateral
    E_k, E_k+1, (x_k+1, level), (x_k, level) clipped to y ≤ level (Sutherland–Hodgman on one half-plane), so a
    chord crossing the level carries the triangle under it and a chord above the level nothing. Unclipped,
    the quadrilateral of a crossing chord is a bow tie whose shoelace subtracts the part above the level (a
    haunch fill below the crown)."""
    centroids, areas = [], []
    for k in range(len(extrados) - 1):
        quad = [extrados[k], extrados[k + 1], (extrados[k + 1, 0], level), (extrados[k, 0], level)]
        clipped = []
        for p, q in zip(quad, quad[1:] + quad[:1]):
            (px, py), (qx, qy) = p, q
            if py <= level:
                clipped.append((px, py))
            if (py - level) * (qy - level) < 0:  # the edge crosses the level: keep where it does
                clipped.append((px + (level - py) / (qy - py) * (qx - px), level))
        x, y = np.array(clipped).T
        xn, yn = np.roll(x, -1), np.roll(y, -1)
        cr = x * yn - xn * y
        area = 0.5 * cr.sum()
        if abs(area) < 1e-15:  # a chord above the level: no fill
            centroids.append(extrados[k])
            areas.append(0.0)
            continue
        centroids.append((((x + xn) * cr).sum() / (6 * area), ((y + yn) * cr).sum() / (6 * area)))
        areas.append(abs(area))
    return np.array(centroids), np.array(areas)


def filled_ring_reference(voussoirs: int):
    """The reference's filled ring, built apart from the builder: intrados and extrados chains on the springing
    line, the fill level, each voussoir's centroid and own weight (N), its fill's point and weight (N), and the
    own weights as dead loads (x, y)."""
    i, e = segmental_reference_ring(voussoirs)
    i, e = i + (0, SPRINGING), e + (0, SPRINGING)
    level = e[:, 1].max() + COVER
    centroid, area = voussoir_loads(i, e)
    weight = STONE * G * area
    fill_at, fill_area = reference_fill(e, level)
    fill = FILL_DENSITY * G * fill_area
    dead = np.stack([0 * weight, -weight], axis=1)
    return i, e, level, centroid, weight, fill_at, fill, dead


@pytest.mark.parametrize("voussoirs", [20, 31])
def test_filled_ring_matches_the_four_hinge_reference(voussoirs):
    """Horizontal acceleration (the fill's mass accelerated with the ring: its inertia at its centroid) and a
    point load over the quarter span (λ × the voussoir's own weight, the fill's weight dead)."""
    sc = filled_ring_scenario(voussoirs)
    i, e, _, centroid, weight, fill_at, fill, dead = filled_ring_reference(voussoirs)
    fill_dead = np.stack([0 * fill, -fill], axis=1)
    vw = max(2, len(str(voussoirs)))
    name = lambda k: f"v{k + 1:0{vw}d}"  # noqa: E731
    hinge_names = lambda ks: {_joint(k, voussoirs, "left-skewback", "right-skewback", name) for k in ks}  # noqa: E731

    # the builder's fill on each voussoir is the reference's, to rounding
    carried = np.array([b.carried_mass for b in sc.assembly.blocks])
    np.testing.assert_allclose(carried * G, fill, rtol=1e-9)
    np.testing.assert_allclose([b.carried_at for b in sc.assembly.blocks], fill_at, atol=1e-9)

    live = np.stack([weight, 0 * weight], axis=1)
    extra = (("dead", fill_dead, fill_at), ("live", np.stack([fill, 0 * fill], axis=1), fill_at))
    expected, (hinged, _) = least_load_factor(i, e, centroid, dead, live, extra=extra)
    r = analyse(sc, LiveLoad("horizontal"))
    assert r.load_factor == pytest.approx(expected, rel=1e-6)
    assert _unordered(r.hinges) == hinge_names(hinged)
    bare, _ = least_load_factor(i, e, centroid, dead, live)
    assert abs(expected / bare - 1) > 0.05  # the fill changes the answer: the test would see it missing

    quarter = int(np.searchsorted(i[:, 0], -2.0)) - 1
    live = np.zeros_like(dead)
    live[quarter] = (0.0, -weight[quarter])
    expected, (hinged, _) = least_load_factor(i, e, centroid, dead, live, extra=(("dead", fill_dead, fill_at),))
    r = analyse(sc, LiveLoad("point", "-y", block=name(quarter)))
    assert r.load_factor == pytest.approx(expected, rel=1e-6)
    assert _unordered(r.hinges) == hinge_names(hinged)
    assert r.reference_force == pytest.approx(weight[quarter], rel=1e-9)  # its own weight, not its fill's


def test_a_symmetric_fill_gives_a_symmetric_thrust_and_more_of_it():
    """The filled bridge's least and greatest abutment thrust, left equal to right; the fill adds to both."""
    options = dict(span=8.0, rise=2.0, ring_thickness=0.5, pier_width=3.0, pier_courses=5)
    from masonrycli.scenario.builtin import builtin

    def thrusts(**fill):
        r = analyse(builtin("arch", **options, **fill), LiveLoad(), thrust=True)
        return {name: (lo, hi) for name, _, lo, hi in support_thrusts(r.model, r.joints)}

    bare, filled = thrusts(), thrusts(fill_cover=0.5)
    left, right = filled["left-foundation"], filled["right-foundation"]
    np.testing.assert_allclose(left, right, rtol=1e-6)
    assert left[0] > 1.5 * bare["left-foundation"][0]


def test_the_recording_of_a_filled_bridge_says_its_fill_and_puts_a_block_load_where_it_acts():
    """The mechanism recording draws the blocks, not the fill: its panel said nothing of the 421.6 kN/m a
    filled bridge carries. And its arrow of a point load on a block stood at the body's centre of mass, which
    the fill moves up: the load acts at the block's own centroid (the shoelace of its polygon)."""
    from geometry_library.mass import mass_properties
    from masonrycli.limit.drawing import load_arrow, mechanism_document

    scenario = filled_ring_scenario(20)
    fill = sum(b.carried_mass for b in scenario.assembly.blocks) * G
    result = analyse(scenario, LiveLoad("point", block="v05"))
    said = mechanism_document(result)
    assert f"{fill:.4g} N of fill" in said, said
    point, _ = load_arrow(result)
    block = next(b for b in scenario.assembly.blocks if b.name == "v05")
    assert point == pytest.approx(mass_properties(block.vertices).centroid, abs=1e-9)
    import dataclasses

    blocks = tuple(dataclasses.replace(b, carried_mass=0.0, carried_at=None) for b in scenario.assembly.blocks)
    bare_ring = dataclasses.replace(scenario, assembly=dataclasses.replace(scenario.assembly, blocks=blocks))
    bare = analyse(bare_ring, LiveLoad("point", block="v05"))
    assert "of fill" not in mechanism_document(bare)
