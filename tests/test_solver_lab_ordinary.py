"""The lab's trajectory sample and first-stage variants (benchmarks/solver_lab/trajectory.py, ordinary.py,
ordinary_runs.py): with the engine's parameters the lab kernel must be the engine's accelerated solve, or
none of the variants' figures compare with the engine. The lab kernel is the scalar first stage in 4 runs
(momentum.py), the engine's until the lane sweeps replaced it: the engine runs here with Tuning.lanes off
(SCALAR)."""

from dataclasses import replace
from types import SimpleNamespace

import numpy as np

from benchmarks.bench_solver import run_masonry
from benchmarks.solver_lab import ordinary, ordinary_runs, sweep_orders, trajectory
from masonrycli.engine import dispatch
from masonrycli.engine.tuning import TUNING

SCALAR = replace(TUNING, lanes=False)


def _sample(tmp_path, monkeypatch):
    monkeypatch.setattr(trajectory, "TRAJECTORY", tmp_path)
    trajectory.capture("wall-51", every=4, duration=0.03, tuning=SCALAR)
    return [ordinary.Step(p) for p in sorted((tmp_path / "wall-51").glob("step-*.npz"))]


def test_lab_kernel_with_engine_parameters_is_the_engine(tmp_path, monkeypatch):
    steps = _sample(tmp_path, monkeypatch)
    assert [s.step for s in steps] == [1, 4, 8, 12, 16, 20, 24, 28]
    for s in steps:
        its, res, v, r = s.solve({})
        assert its == s.engine_sweeps and res <= ordinary.TOLERANCE
        # the same solve by the engine's launcher, from the kept (detection-order) arrays
        d = s.raw
        v_e, r_e = s.v_free.copy(), d["r_warm"].copy()
        model = SimpleNamespace(
            friction=s.mu, tolerance=ordinary.TOLERANCE, max_iterations=ordinary.CAP, solver="nlgs-accel"
        )
        its_e, _ = dispatch.solve(d["body"], d["pack"], s.count, model, v_e, r_e, np.zeros(s.count, np.int8), SCALAR)
        assert its_e == its
        np.testing.assert_array_equal(v, v_e)
        o = sweep_orders.sweep_order("engine", d["point"], d["body"])
        np.testing.assert_array_equal(r, r_e[o])


def test_gamma_start_is_in_the_cone_and_zero_gamma_is_the_warm_start(tmp_path, monkeypatch):
    s = _sample(tmp_path, monkeypatch)[-1]
    d = s.arrays("engine")
    np.testing.assert_array_equal(s.start(d, 0.0), d["r_warm"])
    r = s.start(d, 1.0)
    assert (r[:, 1] >= 0).all() and (np.abs(r[:, 0]) <= s.mu * r[:, 1] + 1e-15).all()


def test_check_stops_on_the_iterate_residual(tmp_path, monkeypatch):
    # a check is one more pass, counted in the units (the kernel leaves their number in history[-1]);
    # the sweeps are the engine's until the check stops the step, so never more
    for s in _sample(tmp_path, monkeypatch):
        plain = s.solve({})[0]
        history = np.zeros(10_000)
        its, res, _, _ = s.solve({"check": 1.2}, history=history)
        assert its - history[-1] <= plain and res <= ordinary.TOLERANCE


def test_engine_variant_in_a_whole_run_is_the_engine_run():
    engine = run_masonry("wall-51", 0.05, record=False, tuning=SCALAR)
    lab = ordinary_runs.run_variant("wall-51", {}, 0.05)
    assert lab["sweeps_mean"] == engine["sweeps_mean"] and lab["sweeps_max"] == engine["sweeps_max"]
    assert lab["unconverged"] == engine["unconverged"] == 0
