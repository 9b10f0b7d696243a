"""The lab's hand-over recordings (benchmarks/solver_lab/handover.py): the offline units of a rule are the
engine's, on a captured step written from a small problem whose momentum is made to stall."""

import json
from dataclasses import replace

import numpy as np
import pytest

from benchmarks.solver_lab import handover, hard_steps
from masonrycli.engine.tuning import TUNING
from tests.test_engine_nlgs import _stack_problem

STALL_AT_ONCE = replace(TUNING, first_stall=1)


@pytest.fixture
def captured(tmp_path, monkeypatch):
    # A 12-block column on its support (slow for Gauss–Seidel: load travels the height), saved as
    # hard_steps.capture saves a step; momentum stalls after one sweep (STALL_AT_ONCE) so that the step goes to
    # stalled.py.
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _stack_problem(12)
    np.savez(
        tmp_path / "col-1.npz",
        body=body,
        pack=pack,
        v_free=v0,
        r_warm=r0,
        status=np.zeros(body.shape[0], dtype=np.int8),
        mu=mu,
        tolerance=1e-9,
        cap=100_000,
    )
    (tmp_path / "index-col-c0.json").write_text(json.dumps({"col-1": {"case": "col", "units": 5000}}))
    monkeypatch.setattr(hard_steps, "HARD", tmp_path)
    monkeypatch.setattr(handover, "HARD", tmp_path)
    monkeypatch.setattr(handover, "RECORD_UNITS", 3000)
    return tmp_path


@pytest.mark.parametrize(
    "units, rule, path",
    [(3000, (0, 1.8, 0), "converges"), (3000, (5, 1.0, 2), "hands over"), (4, (0, 1.8, 0), "budget")],
)
def test_a_rule_replayed_offline_costs_what_the_engine_spends(captured, monkeypatch, units, rule, path):
    # (3000, off): the stage converges the step; (3000, level 1.0 over 2 windows of 5): it hands over early;
    # (4 units): it runs out of its budget. Each time the offline sum is the engine's own count.
    handover.record(["col"], 0, None, captured / "rec.npz", tuning=STALL_AT_ONCE)
    steps = handover.load(captured / "rec.npz")
    window, level, cycling = rule
    offline = handover.evaluate(steps, handover.level_rule(window, level, cycling), budget=units)["col-1"]
    assert offline["finished"] == (path == "converges")
    assert (offline["stage"] < units) == (path != "budget")
    rule_tuning = replace(
        STALL_AT_ONCE,
        bodies_units=units,
        bodies_window=max(window, 1),
        bodies_level=level,
        bodies_cycling=cycling,
        bodies_reenter=0,  # the offline sum is that of a stage that never re-enters
    )
    engine = hard_steps.replay_step("col-1", tuning=rule_tuning)
    assert offline["units"] == engine["units"] and offline["converged"] == engine["converged"]
    assert offline["finished"] == (not engine["methods"])  # the round-robin never ran
