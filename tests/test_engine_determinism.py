"""Same scenario, same bits: two runs of the 248-block shaken wall give identical block_q."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.outputs.history import History
from masonrycli.run import simulate
from masonrycli.scenario.motion import Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder


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


def test_a_step_gives_the_same_bits_fused_or_through_the_launchers(monkeypatch):
    """The fused before/after-solve calls (engine.fused) against the launchers one by one: a wall shaken
    until joints open and close, every step's state and contacts compared bit for bit."""
    from masonrycli.engine import fused
    from masonrycli.run import Simulation

    sc = scenario_from_builder(
        "wall", {"blocks": 51}, RunConfig(duration=0.15), Material(), {"ground": Sine(amplitude=1.0, frequency=2.0)}
    )
    fast, slow = Simulation(sc), Simulation(sc)
    before_solve, fused_calls = fused.before_solve, 0
    for _ in range(fast.model.n_steps):
        s = fast.solver
        support_v_next = fast.model.support_velocity[fast.state.step + 1]
        begun = before_solve(s.model, s.buffers, s._warm, fast.state, support_v_next, s.body_q_m, s.body_v_n, s._r)
        fused_calls += begun is not None
        fast.state.body_v[:] = slow.state.body_v  # undo its v_free: step() begins the step again
        fast.step()
        with monkeypatch.context() as m:
            m.setattr(fused, "before_solve", lambda *args: None)  # always the launchers
            slow.step()
        for a, b in ((fast.state.body_q, slow.state.body_q), (fast.state.body_v, slow.state.body_v)):
            assert a.tobytes() == b.tobytes()
        assert fast.solver.contact_r.tobytes() == slow.solver.contact_r.tobytes()
        assert fast.last == slow.last
    assert fused_calls == fast.model.n_steps  # Simulation() detected once already: every step fused
    assert np.abs(fast.state.body_q[:51, 2]).max() > 1e-4  # blocks rocked: contacts changed on the way
