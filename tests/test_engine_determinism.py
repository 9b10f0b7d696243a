"""Same scenario, same bits: two runs of the 248-block shaken wall give identical block_q."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.history import History
from masonrycli.motion import Sine
from masonrycli.run import simulate
from masonrycli.scenario import Material, RunConfig, scenario_from_builder


def _wall_history(duration: float) -> np.ndarray:
    sc = scenario_from_builder(
        "wall",
        {"blocks": 248},
        RunConfig(duration=duration, record_every=25),
        Material(),
        {"ground": Sine(amplitude=1.0, frequency=2.0)},
    )
    hist = History([b.name for b in sc.assembly.blocks], [s.name for s in sc.assembly.supports])
    result = simulate(sc, sinks=[hist])
    assert result.status == "completed"
    return hist.arrays()["block_q"]


@pytest.mark.slow
def test_248_block_wall_is_bit_identical_run_after_run():
    a = _wall_history(0.3)
    b = _wall_history(0.3)
    assert a.shape == (13, 248, 3)
    # The wall moved (the test is not comparing two resting states).
    assert np.abs(a[-1, :, 0] - a[0, :, 0]).max() > 1e-3
    assert a.tobytes() == b.tobytes()
