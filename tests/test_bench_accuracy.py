"""The accuracy-reference benchmark's bookkeeping (benchmarks/bench_accuracy.py): run specs, which run is
compared with which reference, and the table (the runs themselves: test_solver_reference.py)."""

import pytest

from benchmarks import bench_accuracy, solver_reference


def test_the_first_reference_is_bench_solvers_tight_solve():
    assert solver_reference.parse_spec(bench_accuracy.BENCH_REFERENCE) == {
        "solver": "nlgs",
        "tolerance": 1e-7,
        "max_iterations": 20000,
    }


def test_references_meet_the_ones_before_them_and_runs_meet_every_reference():
    runs = {
        "a": {"samples": {"100": (2.0, 4.0), "200": (1.0, 1.0)}},
        "b": {"samples": {"100": (2.02, 4.0), "200": (0.99, 1.0)}},
        "t": {"samples": {"100": (1.9, 3.0)}},
    }
    bench_accuracy.compare(runs, ["a", "b"])
    assert runs["a"]["error_pct"] == {}
    assert runs["b"]["error_pct"] == {"a": {"100": pytest.approx((1.0, 0.0)), "200": pytest.approx((-1.0, 0.0))}}
    assert runs["t"]["error_pct"]["a"] == {"100": pytest.approx((-5.0, -25.0))}
    assert runs["t"]["error_pct"]["b"]["100"][0] == pytest.approx(100 * (1.9 - 2.02) / 2.02)
    assert "| t |" in bench_accuracy.table("case", runs | {k: r | _figures() for k, r in runs.items()}, ["a", "b"])


def _figures() -> dict:
    return {
        "cpu_s": 1.0,
        "sweeps_mean": 3.0,
        "sweeps_max": 5,
        "unconverged": 0,
        "residual_median": 1e-6,
        "residual_max": 2e-6,
    }


def test_an_unknown_reference_solver_is_refused():
    with pytest.raises(SystemExit) as exit_info:
        bench_accuracy.main(["--cases", "wall-51", "--references", "sor:1e-7"])
    assert exit_info.value.code == 2
