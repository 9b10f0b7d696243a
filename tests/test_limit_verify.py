"""--verify: the NSCD engine near the LP's λ stands below it and collapses above it, the same way."""

from __future__ import annotations

import math

import numpy as np
import pytest

from masonrycli.limit import LiveLoad, analyse
from masonrycli.limit.command import resolve_structure
from masonrycli.limit.verify import tilted_scenario, verify

from limit_helpers import column


@pytest.mark.parametrize("direction", ["+x", "-x"])
def test_tilted_scenario_rotates_gravity_and_fixes_the_supports(direction):
    sc = column(1, 0.4, 0.8, 0.9)
    result = analyse(sc, LiveLoad("tilt", direction))
    tilted = tilted_scenario(sc, result, 1.05, duration=0.5)
    gx, gy = tilted.run.gravity
    assert math.hypot(gx, gy) == pytest.approx(9.81, rel=1e-12)
    assert gx / -gy == pytest.approx((1 if direction == "+x" else -1) * 1.05 * 0.5, rel=5e-3)
    assert tilted.run.duration == 0.5 and all(m.role == "fixed" for m in tilted.motions)


@pytest.mark.parametrize(
    ("mu", "mode"),
    [(0.9, "overturns"), (0.3, "slides")],
)
def test_block_on_a_tilting_table_stands_below_and_falls_above_lambda(mu, mode):
    sc = column(1, 0.4, 0.8, mu)
    result = analyse(sc, LiveLoad("tilt"))
    low, high = verify(sc, result, duration=2.0)
    assert not low.collapsed and low.max_displacement < 1e-3 and low.max_speed < 1e-3
    assert high.collapsed and high.as_predicted and low.as_predicted
    if mode == "overturns":  # it falls the way the LP's mechanism says
        assert high.similarity > 0.99
        assert high.hinges == ("b0|ground",) == high.shared_hinges
    else:
        # The LP's slide dilates (associative flow: velocity along (1, μ)); the engine's slides flat along
        # (1, 0). The two fields are then exactly the dilatancy angle apart: cos = 1/√(1 + μ²).
        assert high.similarity == pytest.approx(1 / math.sqrt(1 + mu**2), abs=2e-3)


@pytest.mark.slow
def test_default_arch_stands_at_095_and_collapses_at_105_lambda_like_the_lp():
    sc = resolve_structure("arch", None)
    result = analyse(sc, LiveLoad("horizontal"))
    low, high = verify(sc, result)
    assert not low.collapsed and high.collapsed
    assert high.similarity > 0.95
    # The engine's hinges at collapse are hinges of the LP's mechanism.
    assert high.hinges and set(high.shared_hinges) == set(high.hinges)
    assert np.isfinite(high.max_displacement)


def test_a_point_load_is_verified_as_a_weight_where_it_acts():
    """--verify of an axle on the filled ring (rigid skewbacks, no sliding): the load becomes a mass f·λ·F/g the
    loaded voussoir carries at (X, its extrados) under plain gravity; the engine stands at 0.95 λ and
    collapses at 1.05 λ on the LP's hinges (λ itself checked against the four-hinge reference in
    tests/test_limit_fill.py and test_limit_worst.py)."""
    from test_limit_fill import filled_ring_scenario

    sc = filled_ring_scenario(20)
    result = analyse(sc, LiveLoad("point", at=-2.0, force=100e3))
    weighted = tilted_scenario(sc, result, 1.05, duration=0.5)
    assert tuple(weighted.run.gravity) == tuple(sc.run.gravity)
    i = [b.name for b in sc.assembly.blocks].index(result.load.block)
    before, after = sc.assembly.blocks[i], weighted.assembly.blocks[i]
    added = 1.05 * result.load_factor * 100e3 / 9.81
    assert after.carried_mass == pytest.approx(before.carried_mass + added, rel=1e-12)
    moment = after.carried_mass * after.carried_at[0] - before.carried_mass * before.carried_at[0]
    assert moment / added == pytest.approx(-2.0, abs=1e-9)  # the added mass sits on x = −2
    low, high = verify(sc, result)
    assert not low.collapsed and high.collapsed
    assert low.tilt_deg is None and set(high.hinges) <= set(result.hinges) and len(high.shared_hinges) >= 3


G = 9.81


def _threshold(sc, high):
    """m: the collapse threshold d, 0.1 × the block's radius; it is crossed at d = ½ a t² under a net
    acceleration a (a rigid block lifting or sliding from rest)."""
    from masonrycli.model import build_model

    m = build_model(sc)
    threshold = 0.1 * float(np.median(m.body_radius[: m.block_count]))
    assert high.threshold == pytest.approx(threshold, rel=1e-12)
    return threshold


def test_a_point_load_up_is_an_applied_force_the_block_rises_under_past_its_weight():
    """A 0.4 × 0.8 m block pulled up at its centroid: the LP lifts it at λ = 1 (× its weight); the engine, given
    the load as a force (no weight can pull up; it was refused, exit 2), holds it at 0.95 and lifts it at 1.05
    with a net 0.05 g: the threshold d reached at t = √(2 d / 0.05 g)."""
    sc = column(1, 0.4, 0.8, 0.6)
    result = analyse(sc, LiveLoad("point", "+y", block="b0"))
    assert result.load_factor == pytest.approx(1.0, rel=1e-9)
    low, high = verify(sc, result, duration=1.5)
    assert not low.collapsed and low.max_displacement < 1e-6
    assert high.collapsed and high.applied == "force" and high.tilt_deg is None
    d = _threshold(sc, high)
    assert high.time == pytest.approx(math.sqrt(2 * d / (0.05 * G)), rel=0.02)
    # (no similarity: at λ = 1 the load cancels the weight, so every lifting motion is a mechanism of the LP's,
    # a toe's rotation as well as a straight lift)


@pytest.mark.parametrize(("mu", "mode"), [(0.9, "overturns"), (0.3, "slides")])
def test_a_point_load_along_x_is_an_applied_force_at_its_point(mu, mode):
    """The same block pushed along +x at its centroid: the LP's λ = min(μ, B / H = 0.5); the engine stands at
    0.95 λ and overturns about its toe, or slides with a net (1.05 − 1) μ g: t = √(2 d / (0.05 μ g))."""
    sc = column(1, 0.4, 0.8, mu)
    result = analyse(sc, LiveLoad("point", "+x", block="b0"))
    assert result.load_factor == pytest.approx(min(mu, 0.5), rel=1e-9)
    low, high = verify(sc, result, duration=2.0)
    assert not low.collapsed and low.max_displacement < 1e-3 and low.max_speed < 1e-3
    assert high.collapsed and high.applied == "force"
    if mode == "overturns":
        assert high.similarity > 0.99 and high.hinges == ("b0|ground",) == high.shared_hinges
    else:
        d = _threshold(sc, high)
        assert high.time == pytest.approx(math.sqrt(2 * d / (0.05 * mu * G)), rel=0.02)
