"""Solid and fixed abutments (`--abutments solid|fixed`): each pier and its skewback one block, or that block
the rigid foundation. A fixed abutment is the four-hinge reference's rigid springer, so the LP must find the
reference's λ and hinges, at the ordinary μ = 0.6, with no joint sliding."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.ops import unary_union
from test_limit_ring_mechanisms import _joint, _unordered, reference, segmental_reference_ring

from geometry_library.blocks import GeometryError
from geometry_library.builders import build_aqueduct, build_arch
from masonrycli.limit import LiveLoad, analyse
from masonrycli.scenario.builtin import builtin

BRIDGE = dict(span=8.0, rise=2.0, ring_thickness=0.5, pier_width=3.0, pier_courses=5)


def test_a_solid_abutment_is_its_pier_and_skewback_in_one_block():
    courses, solid = build_arch(**BRIDGE), build_arch(**BRIDGE, abutments="solid")
    names = [b.name for b in solid.blocks]
    assert names[0] == "left-abutment" and names[-1] == "right-abutment" and len(names) == 32
    for side in ("left", "right"):
        parts = [b for b in courses.blocks if b.name.startswith(f"{side}-pier") or b.name == f"{side}-skewback"]
        block = solid.blocks[names.index(f"{side}-abutment")]
        assert block.polygon.area == pytest.approx(sum(b.polygon.area for b in parts), rel=1e-12)
        union = unary_union([b.polygon for b in parts])
        assert block.polygon.symmetric_difference(union).area < 1e-9  # exactly the stones it replaces


@pytest.mark.parametrize("voussoirs", [20, 31])
def test_fixed_abutments_are_the_references_rigid_springers(voussoirs):
    """μ = 0.6: the ring on fixed abutments turns on four hinges, as the reference, which knows no sliding."""
    sc = builtin("arch", **BRIDGE, voussoirs=voussoirs, abutments="fixed")
    i, e = segmental_reference_ring(voussoirs)
    i, e = i + (0, 1.0), e + (0, 1.0)  # the springing line: 5 courses of 0.20 m
    expected, (hinged, _) = reference(i, e, "horizontal")
    r = analyse(sc, LiveLoad("horizontal"))
    assert r.load_factor == pytest.approx(expected, rel=1e-6)
    vw = max(2, len(str(voussoirs)))
    want = {_joint(k, voussoirs, "left-foundation", "right-foundation", lambda k: f"v{k + 1:0{vw}d}") for k in hinged}
    assert _unordered(r.hinges) == want and r.sliding_joints == []
    assert r.model.block_count == voussoirs


def test_a_solid_abutment_stands_under_its_arch_and_fill_in_the_engine():
    """The engine at rest for 0.3 s: the bridge on solid abutments, filled, does not move (λ > 0 under the
    dead load: it has an equilibrium)."""
    from masonrycli.run import Simulation

    sc = builtin("arch", **BRIDGE, abutments="solid", fill_cover=0.3, settlement=0.0, duration=0.3)
    sim = Simulation(sc)
    for _ in range(sim.model.n_steps):
        sim.step()
    moved = np.abs(sim.state.body_q[: sim.model.block_count, :2] - sim.model.body_q0[: sim.model.block_count, :2])
    assert moved.max() < 1e-5


def test_bad_abutments_are_one_line():
    with pytest.raises(GeometryError, match="abutments must be one of courses, solid, fixed, got 'hollow'"):
        build_arch(abutments="hollow")
    with pytest.raises(GeometryError, match="the aqueduct's piers are courses"):
        build_aqueduct(abutments="solid")


@pytest.mark.parametrize("level", [2.6, 1.5])
def test_the_filled_rings_least_thickness_is_the_four_hinge_references(level):
    """`--min-thickness` with a fill to a fixed level on fixed abutments: the thickness at which the
    enumeration's least λ under a vanishing horizontal load reaches 0, the fill's weight and inertia on each
    voussoir from its chord up to the level (tests/test_limit_fill.py's reference_fill, clipped at the level).
    2.6 m over the springing line is over the crown of any ring tried (least ring 0.0399 m, 0.0720 bare); 1.5 m
    fills the haunches only, its level crossing the chords near the crown (0.1236 m: a haunch fill with none
    over the crown bends the thrust line away from the ring's shape; unchecked before, the reference's
    quadrilateral of a crossing chord being a bow tie)."""
    import json
    import math

    from four_hinge_reference import least_load_factor
    from scipy.optimize import brentq
    from test_limit_fill import reference_fill
    from test_limit_ring_mechanisms import ring, voussoir_loads

    from cli_helpers import invoke

    radius, alpha = 5.0, math.asin(0.8)  # the springing line at y = 0 here

    def lam(t, filled=True):
        i, e = ring(radius, t, alpha, 30, centre_y=-3.0)
        centroid, area = voussoir_loads(i, e)
        at, fill = reference_fill(e, level)
        fill = fill * (2000.0 / 2500.0) * filled  # per the blocks' ρ g: dead and live are in areas × ρ_stone
        extra = (
            ("dead", np.stack([0 * fill, -fill], axis=1), at),
            ("live", np.stack([fill, 0 * fill], axis=1), at),
        )
        dead, live = np.stack([0 * area, -area], axis=1), np.stack([area, 0 * area], axis=1)
        return least_load_factor(i, e, centroid, dead, live, extra=extra)[0]

    expected = brentq(lam, 0.02, 0.3, xtol=1e-8)
    assert abs(expected / brentq(lambda t: lam(t, False), 0.02, 0.3, xtol=1e-8) - 1) > 0.05  # the fill matters
    shape = ["--span", "8", "--rise", "2", "--ring-thickness", "0.5", "--pier-width", "3", "--pier-courses", "5"]
    result = invoke(
        "limit",
        "arch",
        *shape,
        "--abutments",
        "fixed",
        "--fill-to",
        str(level),
        "--friction",
        "10",
        "--min-thickness",
        "--json",
    )
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["least_ring_thickness_m"] == pytest.approx(expected, rel=2e-4)


def test_the_references_fill_over_a_chord_crossing_the_level_is_shapelys_region_under_it():
    """reference_fill against shapely: over each extrados chord, the part of its vertical strip above the chord
    and below the level (the 0.1236 m ring under fill to 1.5 m: chords under, across and over the level)."""
    import math

    from shapely.geometry import Polygon, box
    from test_limit_fill import reference_fill
    from test_limit_ring_mechanisms import ring

    _, e = ring(5.0, 0.1236, math.asin(0.8), 30, centre_y=-3.0)
    level = 1.5
    centroid, area = reference_fill(e, level)
    below, above = e[:, 1] < level, e[:, 1] > level
    crossing = below[:-1] != below[1:]
    assert crossing.sum() == 2 and (above[:-1] & above[1:]).any() and (below[:-1] & below[1:]).any()
    for k in range(len(e) - 1):
        strip = Polygon([e[k], e[k + 1], (e[k + 1, 0], 10.0), (e[k, 0], 10.0)])
        region = strip.intersection(box(e[:, 0].min() - 1, -10.0, e[:, 0].max() + 1, level))
        assert area[k] == pytest.approx(region.area, abs=1e-12)
        if region.area > 0:
            np.testing.assert_allclose(centroid[k], region.centroid.coords[0], atol=1e-9)
