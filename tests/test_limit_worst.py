"""`masonry limit --load point --worst --point-force F`: an axle of F newtons at the worst place on the top.

Against the four-hinge reference (tests/four_hinge_reference.py): the filled segmental ring on rigid
skewbacks with F down at every point of every voussoir's extrados chord — its ends and points between them,
so the reference checks the scan's claim that λ is least at an end of a stretch, not only its value.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from four_hinge_reference import least_load_factor
from test_limit_fill import COVER, filled_ring_reference, filled_ring_scenario

from masonrycli.errors import InputError
from masonrycli.limit import LiveLoad, analyse
from masonrycli.limit.problem import parse_force

from cli_helpers import invoke

AXLE = 100e3  # N


def test_the_worst_place_of_an_axle_matches_the_reference_over_every_point_of_the_extrados():
    voussoirs = 20
    i, e, _, centroid, _, fill_at, fill, dead = filled_ring_reference(voussoirs)
    extra = (("dead", np.stack([0 * fill, -fill], axis=1), fill_at),)
    tried = []  # (λ, x, voussoir)
    for k in range(voussoirs):
        for w in (0.0, 0.3, 0.7, 1.0):  # the chord's ends, and two points between them
            point = (1 - w) * e[k] + w * e[k + 1]
            live = np.zeros_like(dead)
            live[k] = (0.0, -AXLE)
            at = centroid.copy()
            at[k] = point
            lam, _ = least_load_factor(i, e, centroid, dead, live, live_at=at, extra=extra)
            tried.append((lam, point[0], k, w))
    least = min(tried)
    assert least[3] in (0.0, 1.0)  # at an end of a chord, as the scan assumes
    ends = [t for t in tried if t[3] in (0.0, 1.0)]
    assert min(t[0] for t in tried) == min(t[0] for t in ends)

    r = analyse(filled_ring_scenario(voussoirs), LiveLoad("point", worst=True, force=AXLE))
    assert r.load_factor == pytest.approx(least[0], rel=1e-6)
    # the place: one where the reference's λ is the least (the symmetric ring has two, mirror images)
    at_least = {round(x, 9) for lam, x, k, w in tried if lam <= least[0] * (1 + 1e-9)}
    assert round(r.load.at, 9) in at_least and abs(r.load.at) == pytest.approx(abs(least[1]), abs=1e-9)
    assert r.summary()["collapse_load_N"] == pytest.approx(least[0] * AXLE, rel=1e-6)
    assert len(r.places) == 2 * voussoirs  # both ends of each voussoir's top
    # every place's λ is the reference's at that place
    by_place = {(round(x, 9), k): lam for lam, x, k, w in ends}
    for p in r.places:  # where no admissible mechanism moves the load (a springing's end), neither has a λ
        expected = by_place[(round(p.at, 9), int(p.block[1:]) - 1)]
        assert p.load_factor is None if np.isinf(expected) else p.load_factor == pytest.approx(expected, rel=1e-6)


@pytest.mark.parametrize("force", [1e-3, AXLE, 1e12, 1e15, 1e21])
def test_a_force_scales_lambda_and_leaves_the_collapse_load(force):
    """λ × F is the collapse load whatever F: the same place, F or the block's own weight. The LP took F as
    given: at 1e15 N a collapse load of a fifth, at 1e21 N a negative one, at 1 mN 'unbounded'."""
    sc = filled_ring_scenario(20)
    own = analyse(sc, LiveLoad("point", at=-2.0))
    axle = analyse(sc, LiveLoad("point", at=-2.0, force=force))
    assert axle.reference_force == force
    assert axle.load_factor * force == pytest.approx(own.load_factor * own.reference_force, rel=1e-9)


@pytest.mark.parametrize(
    "text, newtons", [("100kN", 1e5), ("100 kN", 1e5), ("2.5e5N", 2.5e5), ("1MN", 1e6), ("850 n", 850.0)]
)
def test_a_force_is_read_with_its_unit(text, newtons):
    assert parse_force(text) == newtons


@pytest.mark.parametrize(
    "text, said",
    [
        ("100", "--point-force 100: give its unit, e.g. 100kN or 100N"),
        ("10t", "--point-force 10t: t is not a unit of force (N, kN or MN): a mass; 10t weighs 98.1 kN"),
        ("100psi", "psi is not a unit of force"),
        ("kN", "expected a force with its unit"),
    ],
)
def test_a_force_without_its_unit_or_with_another_is_refused(text, said):
    with pytest.raises(InputError, match=None) as err:
        parse_force(text)
    assert said in str(err.value)


@pytest.mark.parametrize(
    "args, said",
    [
        (["--load", "point", "--point-force", "100"], "--point-force 100: give its unit"),
        (["--load", "point", "--at", "-2", "--point-force", "-5kN"], "--point-force -5000 N: must be a force > 0"),
        (["--point-force", "100kN"], "only a point load has a size (use --load point)"),
        (["--worst"], "--worst: the worst place of a point load (use --load point)"),
        (["--load", "point", "--worst", "--at", "-2"], "--worst and --at -2: --worst finds the place itself"),
        (["--load", "point", "--at", "40"], "--at 40: no block over x = 40 m"),
        (["--load", "point", "--at", "-2", "--spread", "30"], "--spread 30: no fill to spread through"),
        (["--load", "point", "--at", "-2", "--spread", "95", "--fill-cover", "0.3"], "0 to 90 degrees"),
        (["--spread", "30", "--fill-cover", "0.3"], "--spread 30: a point load down on the fill's surface spreads"),
    ],
)
def test_bad_point_load_options_are_one_line_exit_2(args, said):
    result = invoke("limit", "arch", "--span", "8", "--rise", "2", *args)
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and said in lines[0], result.output


@pytest.mark.parametrize("x, angle", [(-2.0, 30.0), (0.4, 26.6)])
def test_an_axle_spread_through_the_fill_matches_the_reference(x, angle):
    """`--spread DEG`: the axle on the fill's surface at x bears uniformly on the extrados over x ± d tan(DEG),
    d the fill's depth over the extrados at x; on each voussoir its part acts at the middle of the part of
    its chord (the resultant of a uniform load on a straight edge). The reference builds the same from the
    ring's chords and the level, and enumerates the four-hinge mechanisms."""
    import dataclasses

    voussoirs = 20
    sc = filled_ring_scenario(voussoirs)
    options = dict(span=8.0, rise=2.0, ring_thickness=0.5, voussoirs=voussoirs, pier_width=1.0, fill_cover=COVER)
    sc = dataclasses.replace(sc, structure={"builder": "arch", **options})  # where the fill's level comes from
    i, e, level, centroid, _, fill_at, fill, dead = filled_ring_reference(voussoirs)
    k = int(np.searchsorted(e[:, 0], x)) - 1
    chord = lambda k, u: e[k, 1] + (u - e[k, 0]) * (e[k + 1, 1] - e[k, 1]) / (e[k + 1, 0] - e[k, 0])  # noqa: E731
    half = (level - chord(k, x)) * np.tan(np.radians(angle))
    live, at = np.zeros_like(dead), centroid.copy()
    for j in range(voussoirs):
        lo, hi = max(e[j, 0], x - half), min(e[j + 1, 0], x + half)
        if hi > lo:
            live[j] = (0.0, -AXLE * (hi - lo) / (2 * half))
            at[j] = (0.5 * (lo + hi), chord(j, 0.5 * (lo + hi)))
    assert np.count_nonzero(live[:, 1]) >= 2  # spread over more than one voussoir
    extra = (("dead", np.stack([0 * fill, -fill], axis=1), fill_at),)
    expected, _ = least_load_factor(i, e, centroid, dead, live, live_at=at, extra=extra)
    r = analyse(sc, LiveLoad("point", at=x, force=AXLE, spread=angle))
    assert r.load_factor == pytest.approx(expected, rel=1e-6)
    point, _ = least_load_factor(
        i,
        e,
        centroid,
        dead,
        np.where(np.arange(voussoirs)[:, None] == k, [0, -AXLE], 0.0),
        live_at=np.where(np.arange(voussoirs)[:, None] == k, [x, chord(k, x)], centroid),
        extra=extra,
    )
    assert abs(expected / point - 1) > 0.01  # the spread matters
    # --verify gives the engine the same strip: each part a weight on its voussoir, f·λ·F in all
    from masonrycli.limit.verify import tilted_scenario

    weighted = tilted_scenario(sc, r, 1.05, duration=0.5)
    added = [a.carried_mass - b.carried_mass for a, b in zip(weighted.assembly.blocks, sc.assembly.blocks)]
    assert np.count_nonzero(added) == np.count_nonzero(live[:, 1])
    assert sum(added) == pytest.approx(1.05 * r.load_factor * AXLE / 9.81, rel=1e-12)


def test_spread_needs_a_fill_to_spread_through():
    """Carried masses that are not one fill's (one voussoir's 1 % heavier) have no level to spread through; the
    same ring's masses as built are one fill's, found again from them (geometry_library.fill.level_from_carried)."""
    import dataclasses

    sc = filled_ring_scenario(20)
    blocks = list(sc.assembly.blocks)
    blocks[5] = dataclasses.replace(blocks[5], carried_mass=1.01 * blocks[5].carried_mass)
    uneven = dataclasses.replace(sc, assembly=dataclasses.replace(sc.assembly, blocks=tuple(blocks)))
    with pytest.raises(InputError, match="no fill to spread through"):
        analyse(uneven, LiveLoad("point", at=-2.0, spread=30.0))
    assert analyse(sc, LiveLoad("point", at=-2.0, spread=30.0)).load.patches


def test_a_files_fill_is_spread_through_as_the_built_ins(tmp_path):
    """'masonry build arch … --fill-cover 0.3 --out b.geojson' keeps each block's carried mass, not the level:
    the fill was drawn from them (3b41e9b) but '--spread' said 'no fill to spread through'. The built-in's λ,
    its strip's blocks and shares are the reference (the built-in's against the four-hinge enumeration above)."""
    bridge = ("--span", 8, "--rise", 2, "--ring-thickness", 0.5, "--pier-width", 3, "--pier-courses", 5)
    assert invoke("build", "arch", *bridge, "--fill-cover", 0.3, "--out", tmp_path / "b.geojson").exit_code == 0
    load = ("--load", "point", "--at", -2, "--spread", 26.6, "--point-force", "100kN", "--json")
    ours = invoke("limit", tmp_path / "b.geojson", *load)
    theirs = invoke("limit", "arch", *bridge, "--fill-cover", 0.3, *load)
    assert ours.exit_code == 0 and theirs.exit_code == 0, ours.output
    ours, theirs = json.loads(ours.stdout), json.loads(theirs.stdout)
    assert ours["load_factor"] == pytest.approx(theirs["load_factor"], rel=1e-9)
    strip = [(p["block"], p["share"]) for p in theirs["load"]["spread_onto"]]
    assert [p["block"] for p in ours["load"]["spread_onto"]] == [b for b, _ in strip]
    np.testing.assert_allclose([p["share"] for p in ours["load"]["spread_onto"]], [s for _, s in strip], atol=1e-12)


def test_the_table_says_whether_the_axle_is_carried():
    """λ ≥ 1 carries the given force, λ < 1 does not: an axle of half and of twice the bridge's collapse load
    over its quarter span."""
    from masonrycli.scenario.builtin import builtin

    from cli_helpers import words

    shape = dict(span=8.0, rise=2.0, ring_thickness=0.5, pier_width=3.0, pier_courses=5)
    collapse = analyse(builtin("arch", **shape), LiveLoad("point", at=-2.0, force=AXLE)).load_factor * AXLE
    options = [f"--{k.replace('_', '-')}={v:g}" for k, v in shape.items()]
    for factor, verdict in ((0.5, "carries it"), (2.0, "does not carry it")):
        force = factor * collapse
        result = invoke("limit", "arch", *options, "--load", "point", "--at", "-2", "--point-force", f"{force:.17g}N")
        assert result.exit_code == 0, result.output
        size = f"{force / 1e3:.4g} kN"
        assert f"({verdict}: collapse at {1 / factor:.3g} × {size})" in words(result.output.replace("│", " "))
