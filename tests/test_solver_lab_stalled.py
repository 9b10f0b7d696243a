"""The lab's stalled-step tools (benchmarks/solver_lab/stalled_steps.py) on the 51-block wall, with
momentum's stall window shrunk to one sweep so that its steps go to stalled.py."""

from dataclasses import replace

import numpy as np

from benchmarks.solver_lab import law, stalled_steps
from benchmarks.solver_lab.outcome import Context
from masonrycli.engine import dispatch, stalled
from masonrycli.engine.tuning import TUNING


def test_capture_keeps_the_stalled_steps_and_the_table_solves_them(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(stalled_steps, "STALLED", tmp_path)
    solve, finish = dispatch.solve, stalled.continue_stalled
    steps, kept = stalled_steps._capture_case("wall-51", 0.005, replace(TUNING, first_stall=1))
    assert (dispatch.solve, stalled.continue_stalled) == (solve, finish)  # the run's wrappers are undone
    assert steps == 5 and kept and all((tmp_path / name).exists() for name in kept)
    stalled_steps.table(sorted(tmp_path.glob("*.npz")), repeat=1)
    out = capsys.readouterr().out
    rows = [line for line in out.splitlines() if line.startswith("| wall-51-")]
    assert len(rows) == len(kept)
    totals = out.splitlines()[-1].split("|")[3:-1]  # one cell per method, engine first
    assert len(totals) == len(stalled_steps.METHODS) and "0 missed" in totals[0]
    # each kept step is also a lab problem: the inverse masses read back from the packed rows give the
    # engine's velocities for the engine's impulses (v = v_free + M⁻¹ Hᵀ r in the lab's numpy H)
    for name in kept:
        p = stalled_steps.as_problem(tmp_path / name)
        ctx = Context(p)
        r = p.r_warm.copy()
        v, _ = ctx.sweep(r, 200)
        assert np.abs(r).max() > 0
        np.testing.assert_allclose(law.velocity_from_impulse(p, ctx.H, r), v, atol=1e-12)
        assert ctx.residual(v, r) < 1e-3
