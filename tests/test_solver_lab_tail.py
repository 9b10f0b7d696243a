"""The lab's tail analysis (benchmarks/solver_lab/tail.py): its sweep counts at each level are those at which
the engine's own stopping test would stop, and its "own" count is where an independent numpy law residual
(benchmarks/solver_lab/law.py) of the iterate first meets the tolerance."""

from dataclasses import replace
from types import SimpleNamespace

import numpy as np

from benchmarks.solver_lab import law, ordinary, tail, trajectory
from masonrycli.engine import momentum
from masonrycli.engine.tuning import TUNING


def _steps(tmp_path, monkeypatch):
    monkeypatch.setattr(trajectory, "TRAJECTORY", tmp_path)
    monkeypatch.setattr(ordinary, "TRAJECTORY", tmp_path)
    monkeypatch.setattr(tail, "TRAJECTORY", tmp_path)
    trajectory.capture("wall-51", every=4, duration=0.03, tuning=replace(TUNING, lanes=False))
    steps = [ordinary.Step(p) for p in sorted((tmp_path / "wall-51").glob("step-*.npz"))]
    ordinary.references("wall-51", steps)
    return steps


def _law_rms(step, v, r):
    d = step.arrays("engine")
    problem = SimpleNamespace(count=step.count, q_m=np.zeros(step.v_free.shape[0]), body=d["body"], mu=step.mu)
    return np.sqrt((law.law_residual(problem, d["pack"], law.h_matrix(problem, d["pack"]), v, r) ** 2).mean())


def test_first_at():
    h = np.array([5.0, 3.0, 4.0, 1.0])
    assert tail.first_at(h, 3.5) == 2 and tail.first_at(h, 1.0) == 4 and tail.first_at(h, 0.5) == 4


def test_levels_are_where_the_stopping_test_stops_and_own_is_the_law_residual(tmp_path, monkeypatch):
    checked = 0
    for s in _steps(tmp_path, monkeypatch):
        row = tail.step_tail(s, levels=(3e-5, 1.5e-5))
        assert row["at"] == sorted(row["at"]) and row["at"][-1] <= row["sweeps"] == s.solve({})[0]
        for level, k in zip((3e-5, 1.5e-5), row["at"]):
            its, _, v, _ = s.solve({}, tolerance=level)
            assert its == k or (its > k and k == row["sweeps"])
            assert np.isclose(tail.block_error(s, v), row["errors"][(3e-5, 1.5e-5).index(level)])
        history = np.zeros(ordinary.CAP)
        n = s.solve({}, history=history)[0]
        grew = sum(history[i] > momentum.RESTART_GROWTH * history[i - 1] for i in range(1, n))
        assert row["restarts"] == grew
        own = row["own"]
        assert own >= 1
        _, _, v, r = s.solve({}, cap=own)
        assert _law_rms(s, v, r) <= ordinary.TOLERANCE * (1 + 1e-9)
        if own > 1:
            _, _, v, r = s.solve({}, cap=own - 1)
            assert _law_rms(s, v, r) > ordinary.TOLERANCE
            checked += 1
    assert checked > 0
