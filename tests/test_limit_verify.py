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
