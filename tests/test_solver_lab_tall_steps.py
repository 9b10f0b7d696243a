"""The lab's comparison of the engine's chain with the IPM and CPG methods on kept steps
(benchmarks/solver_lab/tall_steps.py), on the first two steps of an 8-course wall captured by hard_steps.py."""

import json

import numpy as np

from benchmarks.solver_lab import hard_steps, law, tall_steps
from benchmarks.solver_lab.methods import ipm
from benchmarks.solver_lab.outcome import Context
from benchmarks.solver_lab.stalled_steps import as_problem


def test_run_counts_each_method_and_its_answers_meet_the_law(tmp_path, monkeypatch, capsys):
    data = tmp_path / "set"
    hard_steps.capture(["h8"], 0, 1, motions=[(1.0, 2.0, 0.0)], duration=0.002, directory=data)
    index = json.loads((data / "index-h8-c0.json").read_text())
    monkeypatch.setattr(tall_steps, "SETS", {"t": data})
    monkeypatch.setattr(tall_steps, "CASES", ("h8",))
    factor = ipm.Operators.factor
    out = tmp_path / "run.json"
    tall_steps.run(list(tall_steps.METHODS), out)
    assert ipm.Operators.factor is factor  # the counting wrapper is undone
    steps = json.loads(out.read_text())["steps"]
    assert sorted(steps) == sorted(f"t/{n}" for n in index)
    units = tall_steps.FACTOR_UNITS
    for name, entry in steps.items():
        # the engine as it runs today spends on each step what the capture run spent on it
        assert entry["engine"]["units"] == index[name.split("/")[1]]["units"]
        for m in ("ipm-pred", "ipm-pred-close4", "ipm-pred-bodies"):
            e = entry[m]
            expect = 100 + e["iterations"] * tall_steps.MATVEC_UNITS + e["closing"]
            expect += e["factors"]["chol"] * units["chol"]["h32"] + e["factors"]["lu"] * units["lu"]["h32"]
            assert e["units"] == round(expect)
            assert e["factors"]["chol"] + e["factors"]["lu"] >= e["iterations"] > 0
        for m in tall_steps.METHODS[1:]:
            e = entry[m]
            assert e["converged"], (name, m)
            # the answer's velocities and impulses meet the contact law (law.py's numpy residual, RMS), and
            # are the engine's to within what that tolerance leaves on a cold start (the lab's wall-8-cold: 1.1e-3 m/s)
            assert e["law"] <= 2e-5, (name, m, e["law"])
            assert e["dv"] <= 3e-3, (name, m, e["dv"])
    tall_steps.table([out])
    lines = capsys.readouterr().out.splitlines()
    total = [line for line in lines if line.startswith("| all h8")]
    assert len(total) == 1 and "0 missed" in total[0].split("|")[3]


def test_closing_sweeps_meet_the_engines_tolerance_from_any_impulses(tmp_path):
    hard_steps.capture(["h8"], 0, 1, motions=[(1.0, 2.0, 0.0)], duration=0.002, directory=tmp_path)
    path = sorted(tmp_path.glob("h8-*.npz"))[-1]
    ctx = Context(as_problem(path))
    for body_order in (False, True):
        r = np.zeros_like(ctx.p.r_warm)  # a cold start
        n, res, v = tall_steps._closing(ctx, r, 20_000, body_order)
        assert 0 < n < 20_000 and res <= tall_steps.TOLERANCE
        np.testing.assert_allclose(law.velocity_from_impulse(ctx.p, ctx.H, r), v, atol=1e-12)
        assert ctx.residual(v, r) <= 2e-5
