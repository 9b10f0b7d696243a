"""The solver benchmarks' accuracy reference (benchmarks/solver_reference.py): run specs, a reference run's
unconverged and capped steps against a run starved of sweeps, and the spread between two references that
decides which errors are resolved — through bench_solver's summary, as the benchmark uses it."""

import pytest

from benchmarks import bench_solver, solver_cases, solver_reference
from benchmarks.solver_cases import make_scenario
from masonrycli.run import simulate

TINY = ("wall", {"blocks": None, "courses": 3, "length": 0.9}, 0.02, {"ground": solver_cases.SINE})
"""A wall of a few blocks (3 courses, 0.9 m), shaken as the benchmark's walls."""
STEPS = 20
"""0.02 s at dt = 1e-3."""
SAMPLES = (10, 20)


@pytest.fixture
def tiny(monkeypatch):
    monkeypatch.setitem(solver_cases.CASES, "tiny", TINY)
    return "tiny"


def test_a_spec_names_solver_tolerance_and_an_optional_cap():
    assert solver_reference.parse_spec("nlgs:1e-7:20000") == solver_reference.TIGHT
    assert solver_reference.parse_spec("nlgs-accel:3e-6") == {"solver": "nlgs-accel", "tolerance": 3e-6}
    for bad in ("sor:1e-7", "nlgs", "nlgs:1e-7:2:3"):
        with pytest.raises(ValueError):
            solver_reference.parse_spec(bad)
    for options in (solver_reference.TIGHT, solver_reference.SECOND, {"solver": "nlgs", "tolerance": 3e-5}):
        assert solver_reference.parse_spec(solver_reference.spec_of(options)) == options


def test_a_run_keeps_every_steps_residual_and_the_slips_at_the_samples():
    r = solver_reference.run("wall-51", 0.1, solver="nlgs", tolerance=1e-6)
    direct = simulate(make_scenario("wall-51", 0.1, solver="nlgs", tolerance=1e-6)).tally
    assert r["sweeps_mean"] == direct.sweeps_mean and r["residual_max"] == direct.residual_max
    assert 0.0 < r["residual_median"] <= r["residual_max"] <= 1e-6 and r["unconverged"] == r["capped"] == 0
    assert list(r["samples"]) == ["100"]


def test_a_run_starved_of_sweeps_counts_every_step_capped(tiny):
    tight = solver_reference.run(tiny, 0.02, SAMPLES, **solver_reference.TIGHT)
    starved = solver_reference.run(tiny, 0.02, SAMPLES, solver="nlgs", tolerance=1e-7, max_iterations=1)
    # one sweep a step cannot bring a shaken wall to 1e-7 m/s: every step ends at the cap, unconverged
    assert starved["steps"] == STEPS and starved["capped"] == starved["unconverged"] == STEPS
    assert starved["residual_max"] > 1e-7
    # the tight solve of a few blocks converges on every step, below its tolerance
    assert tight["capped"] == tight["unconverged"] == 0 and tight["residual_max"] <= 1e-7
    assert list(tight["samples"]) == list(starved["samples"]) == ["10", "20"]


def test_errors_within_the_references_spread_are_marked_unresolved(tiny):
    tight = solver_reference.run(tiny, 0.02, SAMPLES, **solver_reference.TIGHT)
    starved = solver_reference.run(tiny, 0.02, SAMPLES, solver="nlgs", tolerance=1e-7, max_iterations=1)
    ref, other = tight["samples"], starved["samples"]
    # a solver halfway between the two references, and one twice as far from the first as the second is
    half = {k: tuple((a + b) / 2 for a, b in zip(ref[k], other[k], strict=True)) for k in ref}
    far = {k: tuple(2 * b - a for a, b in zip(ref[k], other[k], strict=True)) for k in ref}
    run = {"sim_s": 0.02, "blocks": 9, "sweeps_mean": 1.0}
    runs = {"half": [run | {"cpu_s": 1.0, "samples": half}], "far": [run | {"cpu_s": 1.0, "samples": far}]}
    row = bench_solver.summarise(runs, tight, [], starved)
    assert row["tight"]["capped"] == 0 and row["second"]["capped"] == STEPS
    assert row["second"]["settings"] == {"solver": "nlgs", "tolerance": 1e-7, "max_iterations": 1}
    for k in ("10", "20"):
        spread = tuple(100 * (b - a) / abs(a) for a, b in zip(ref[k], other[k], strict=True))
        assert row["spread_pct"][k] == pytest.approx(spread)
        assert row["solvers"]["half"]["error_pct"][k] == pytest.approx(tuple(s / 2 for s in spread))
        assert row["solvers"]["far"]["error_pct"][k] == pytest.approx(tuple(2 * s for s in spread))
        assert row["solvers"]["half"]["unresolved"][k] == (True, True)
        assert row["solvers"]["far"]["unresolved"][k] == (False, False)
    half_cell = bench_solver._err(
        row["solvers"]["half"]["error_pct"], row["solvers"]["half"]["unresolved"], ("10", "20")
    )
    far_cell = bench_solver._err(row["solvers"]["far"]["error_pct"], row["solvers"]["far"]["unresolved"], ("10", "20"))
    assert half_cell.count("≈") == 4 and "≈" not in far_cell


def test_without_a_second_reference_nothing_is_marked():
    tight = {"samples": {"100": (2.0, 4.0)}, "unconverged": 3, "capped": 2, "residual_max": 1e-5}
    runs = {"nlgs": [{"cpu_s": 1.0, "sim_s": 1.0, "blocks": 7, "sweeps_mean": 1.0, "samples": {"100": (2.0, 4.0)}}]}
    row = bench_solver.summarise(runs, tight, [])
    assert row["solvers"]["nlgs"]["unresolved"] == {} and "second" not in row and "spread_pct" not in row
    assert row["tight"]["unconverged"] == 3 and row["tight"]["capped"] == 2 and row["tight"]["residual_max"] == 1e-5
