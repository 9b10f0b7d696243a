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
