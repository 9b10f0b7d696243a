"""`masonry limit --load point --worst --point-force F`: an axle of F newtons at the worst place on the top.

Against the four-hinge reference (tests/four_hinge_reference.py): the filled segmental ring on rigid
skewbacks with F down at every point of every voussoir's extrados chord — its ends and points between them,
so the reference checks the scan's claim that λ is least at an end of a stretch, not only its value.
"""

from __future__ import annotations

import numpy as np
import pytest
from four_hinge_reference import least_load_factor
from test_limit_fill import COVER, FILL_DENSITY, SPRINGING, STONE, G, filled_ring_scenario, reference_fill
from test_limit_ring_mechanisms import segmental_reference_ring, voussoir_loads

from masonrycli.errors import InputError
from masonrycli.limit import LiveLoad, analyse
from masonrycli.limit.problem import parse_force

from cli_helpers import invoke

AXLE = 100e3  # N


def test_the_worst_place_of_an_axle_matches_the_reference_over_every_point_of_the_extrados():
    voussoirs = 20
    i, e = segmental_reference_ring(voussoirs)
    i, e = i + (0, SPRINGING), e + (0, SPRINGING)
    centroid, area = voussoir_loads(i, e)
    weight = STONE * G * area
    fill_at, fill_area = reference_fill(e, e[:, 1].max() + COVER)
    fill = FILL_DENSITY * G * fill_area
    dead = np.stack([0 * weight, -weight], axis=1)
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
    ],
)
def test_bad_point_load_options_are_one_line_exit_2(args, said):
    result = invoke("limit", "arch", "--span", "8", "--rise", "2", *args)
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and said in lines[0], result.output
