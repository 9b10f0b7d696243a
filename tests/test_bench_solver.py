"""The solver benchmark's bookkeeping (benchmarks/bench_solver.py): both solvers run, each row summarised
against the same tight solve, the ratio taken between the fastest repeats."""

import pytest

from benchmarks import bench_solver
from benchmarks.solver_cases import make_scenario
from masonrycli.run import simulate
from masonrycli.scenario.scenario import SOLVERS


def _run(cpu: float, top: float, mean: float, sweeps: float = 10.0) -> dict:
    return {"cpu_s": cpu, "sim_s": 0.5, "blocks": 7, "sweeps_mean": sweeps, "samples": {"100": (top, mean)}}


def test_summary_takes_each_solvers_fastest_repeat_and_the_ratio_between_them():
    tight = {"sweeps_mean": 999.0, "unconverged": 0, "samples": {"100": (2.0, 4.0), "200": (1.0, 1.0)}}
    runs = {
        SOLVERS[0]: [_run(0.3, 2.02, 4.0), _run(0.2, 2.02, 4.0), _run(0.25, 2.02, 4.0)],
        "nlgs": [_run(0.9, 1.9, 3.0), _run(0.8, 1.9, 3.0), _run(1.1, 1.9, 3.0)],
    }
    pymunk = [{"cpu_s": 0.1, "sim_s": 0.5, "slips": {100: (1.0, 2.0)}}, {"cpu_s": 0.05, "sim_s": 0.5, "slips": {}}]
    row = bench_solver.summarise(runs, tight, pymunk)
    accel, plain = row["solvers"][SOLVERS[0]], row["solvers"]["nlgs"]
    assert accel["cpu_per_sim_s"] == pytest.approx(0.4) and plain["cpu_per_sim_s"] == pytest.approx(1.6)
    assert accel["cpu_runs"] == [0.3, 0.2, 0.25]
    assert row["ratio_nlgs_over_default"] == pytest.approx(4.0) and accel["over_default"] == pytest.approx(1.0)
    # errors in % of the tight solve's top and mean slips; the step missing in the runs is left out
    assert accel["error_pct"] == {"100": pytest.approx((1.0, 0.0))}
    assert plain["error_pct"] == {"100": pytest.approx((-5.0, -25.0))}
    assert row["tight"]["settings"]["solver"] == "nlgs" and row["tight"]["settings"]["tolerance"] == 1e-7
    assert row["pymunk"]["cpu_per_sim_s"] == pytest.approx(0.1)  # the faster repeat, with no sample
    assert row["pymunk"]["ratio_over_pymunk"] == {SOLVERS[0]: pytest.approx(4.0), "nlgs": pytest.approx(16.0)}
    assert row["pymunk"]["error_pct"] == {}


def test_a_single_solver_has_no_ratio():
    tight = {"sweeps_mean": 1.0, "unconverged": 0, "samples": {}}
    row = bench_solver.summarise({"nlgs": [_run(0.5, 1.0, 1.0)]}, tight, [])
    assert "ratio_nlgs_over_default" not in row and "over_default" not in row["solvers"]["nlgs"]
    assert "pymunk" not in row


@pytest.mark.parametrize("solver", SOLVERS)
def test_each_benchmark_run_uses_the_solver_asked_for(solver):
    bench = bench_solver.run_masonry("wall-51", 0.03, record=False, solver=solver)
    direct = simulate(make_scenario("wall-51", 0.03, solver=solver)).tally
    assert bench["sweeps_mean"] == direct.sweeps_mean and bench["sweeps_max"] == direct.sweeps_max
    assert bench["ns_per_contact_sweep"] > 0.0


def test_the_two_solvers_take_different_paths():
    runs = [bench_solver.run_masonry("wall-51", 0.03, record=False, solver=s) for s in SOLVERS]
    assert runs[0]["sweeps_mean"] != runs[1]["sweeps_mean"]


@pytest.mark.parametrize("argv", [["--solvers", "sor"], ["--second-reference", "sor:1e-7"]])
def test_an_unknown_solver_is_refused(argv):
    with pytest.raises(SystemExit) as exit_info:
        bench_solver.main(argv)
    assert exit_info.value.code == 2
