"""engine/dispatch.py, engine/tuning.py and interleaved.sweeps' modes: the contact solve's choices are explicit.
The tuning is one frozen value handed down (no engine module keeps a switch to patch), a Solver hands its own to
every step's solve, and each named sweep mode is the kernel it names."""

from __future__ import annotations

import dataclasses
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from masonrycli.engine import dispatch, interleaved, momentum, nlgs, stalled
from masonrycli.engine.tuning import TUNING
from tests.test_engine_nlgs import _stack_problem


def test_the_tuning_is_frozen_and_no_engine_module_keeps_a_switch():
    with pytest.raises(dataclasses.FrozenInstanceError):
        TUNING.lanes = False
    gone = [(nlgs, "LANES"), (nlgs, "solve"), (nlgs, "_nlgs_interleaved"), (momentum, "STALL_SWEEPS")]
    gone += [(stalled, name) for name in ("BODIES_UNITS", "BODIES_CYCLING", "FIRST_BUDGET", "METHODS", "NEWTON_AHEAD")]
    assert [f"{m.__name__}.{name}" for m, name in gone if hasattr(m, name)] == []


def test_a_solver_hands_its_tuning_to_every_solve(monkeypatch):
    seen = []
    solve = dispatch.solve

    def spy(*args):
        seen.append(args[7])
        return solve(*args)

    monkeypatch.setattr(dispatch, "solve", spy)
    from masonrycli.run import Simulation
    from tests.engine_helpers import scenario

    mine = replace(TUNING, first_stall=150)
    sim = Simulation(scenario("column5.toml"), tuning=mine)
    for _ in range(3):
        sim.step()
    assert sim.solver.tuning is mine and len(seen) == 3 and all(t is mine for t in seen)


@pytest.mark.parametrize(
    "mode, kernel, extra",
    [
        (interleaved.MOMENTUM, "_accelerated", (False,)),
        (interleaved.TURNING, "_accelerated", (True,)),
        (interleaved.PLAIN, "_plain", (False,)),
        (interleaved.ALTERNATING, "_plain", (True,)),
    ],
)
def test_each_sweep_mode_is_the_kernel_it_names(mode, kernel, extra):
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _stack_problem(6)
    count = body.shape[0]
    v, r, st = v0.copy(), r0.copy(), np.zeros(count, np.int8)
    out = interleaved.sweeps(body, pack, count, mu, 1e-9, 300, v, r, st, mode, 50)
    v2, r2, st2 = v0.copy(), r0.copy(), np.zeros(count, np.int8)
    if kernel == "_accelerated":
        ref = interleaved._accelerated(body, pack, count, mu, 1e-9, 300, v2, v2.reshape(-1), r2, st2, 50, *extra)
    else:
        ref = interleaved._plain(body, pack, count, mu, 1e-9, 300, v2, r2, st2, *extra)
    assert out == ref and np.array_equal(v, v2) and np.array_equal(r, r2)


def test_an_unknown_sweep_mode_is_refused():
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _stack_problem(2)
    with pytest.raises(ValueError, match="no sweep mode 'forward'"):
        interleaved.sweeps(
            body, pack, body.shape[0], mu, 1e-9, 10, v0.copy(), r0.copy(), np.zeros(4, np.int8), "forward"
        )


def test_the_plain_solver_sweeps_plainly_and_the_accelerated_one_starts_with_its_first_stage():
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _stack_problem(6)
    count = body.shape[0]
    for solver, mode in (("nlgs", interleaved.PLAIN), ("nlgs-accel", None)):
        model = SimpleNamespace(friction=mu, tolerance=1e-8, max_iterations=5000, solver=solver)
        v, r, st = v0.copy(), r0.copy(), np.zeros(count, np.int8)
        out = dispatch.solve(body, pack, count, model, v, r, st)
        v2, r2, st2 = v0.copy(), r0.copy(), np.zeros(count, np.int8)
        if mode is None:
            ref = dispatch.first_stage(body, pack, count, mu, 1e-8, 5000, v2, r2, st2, TUNING.first_stall)
        else:
            ref = interleaved.sweeps(body, pack, count, mu, 1e-8, 5000, v2, r2, st2, mode)
        assert ref[1] <= 1e-8 and out == ref and np.array_equal(v, v2), solver
