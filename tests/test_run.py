"""The time loop's own bookkeeping (masonrycli.run): the solver's per-step statistics kept as running
aggregates — equal, bit for bit, to the same figures taken over per-step arrays, and in memory that does
not grow with the number of steps."""

from __future__ import annotations

import math
import tracemalloc
from types import SimpleNamespace

import numpy as np
import pytest
from test_analysis_collapse import block_scenario

from masonrycli.run import SolverTally, simulate
from masonrycli.scenario.motion import Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

from cli_helpers import invoke, words
from engine_helpers import PerStep


def test_tally_equals_the_figures_over_per_step_arrays():
    run = RunConfig(duration=0.03, max_iterations=60)  # a cap some steps of the shaken wall reach, others not
    sc = scenario_from_builder("wall", {"blocks": 51}, run, Material(), {"ground": Sine(amplitude=1.0, frequency=2.0)})
    steps = PerStep()
    tally = simulate(sc, [steps]).tally
    its = np.array([r[0] for r in steps.rows], dtype=np.int64)
    res = np.array([r[1] for r in steps.rows])
    nc = np.array([r[2] for r in steps.rows], dtype=np.int64)
    assert tally.steps == len(its) == 30 and 0 < tally.capped < 30
    assert tally.capped == int((its >= 60).sum()) and tally.sweeps_max == its.max()
    assert tally.sweeps_mean == float(its.mean()) and tally.contacts_mean == float(nc.mean())  # bit for bit
    assert tally.contacts_max == nc.max() and tally.residual_max == res.max() and tally.residual_last == res[-1]
    assert tally.residual_max_step == int(np.argmax(res)) + 1  # numpy's first maximum, steps counted from 1


def test_a_nan_residual_makes_the_maximum_nan_as_numpy_does():
    tally = SolverTally(cap=10)
    for residual in (1e-6, math.nan, 1e-3, 2e-7):
        tally.add(SimpleNamespace(iterations=3, residual=residual, contact_count=2))
    assert math.isnan(tally.residual_max) and math.isnan(np.max([1e-6, math.nan, 1e-3, 2e-7]))
    assert tally.residual_last == 2e-7 and tally.sweeps_mean == 3.0 and tally.capped == 0
    assert tally.residual_max_step == 2 == int(np.argmax([1e-6, math.nan, 1e-3, 2e-7])) + 1
    assert SolverTally(cap=10).sweeps_mean == 0.0  # no step


def test_memory_of_a_run_does_not_grow_with_its_steps():
    """The run kept three 8-byte numbers per step (24 B/step: 2.4 GB for 10⁸ steps) for its summary."""
    sc = block_scenario(0.8, 0.4, 0.6, 0.05, duration=10.0)

    def peak(steps: int) -> int:
        tracemalloc.start()
        result = simulate(sc, steps=steps)
        size = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert result.steps == steps
        return size

    peak(100)  # numba's first call allocates for itself
    small, large = peak(1_000), peak(8_000)
    assert large - small < 24 * 7_000 / 10, (small, large)  # a tenth of what the arrays took (+190 kB before)


def test_outcome_shows_round_off_as_zero():
    from masonrycli.run import describe_outcome

    rest = {"state": "intact", "residual_drift": 2.16e-19, "hinges": 0, "max_opening": 1.67e-35}
    assert describe_outcome(rest) == "intact (residual drift 0 % of the height, 0 hinges, largest opening 0 mm)"
    moved = {"state": "damaged", "residual_drift": 0.0031, "hinges": 2, "max_opening": 5.41e-6}
    assert (
        describe_outcome(moved) == "damaged (residual drift 0.31 % of the height, 2 hinges, largest opening 0.00541 mm)"
    )


def test_a_block_displaced_without_drift_or_opening_says_why_it_is_damaged():
    # A block falling freely 1e6 m from the rest (the far block of a scenario) made the summary read
    # "damaged (residual drift 0 % of the height, 0 hinges, largest opening 0 mm)": damaged by the block's
    # displacement (> 5 mm, docs/collapse.md), which the line did not show.
    from masonrycli.run import describe_outcome
    from masonrycli.scenario.toml_file import loads_scenario

    sc = loads_scenario(
        """
[run]
duration = 0.05
[[support]]
name = "ground"
polygon = [[-5, -1], [5, -1], [5, 0], [-5, 0]]
[[block]]
polygon = [[0, 0], [1, 0], [1, 1], [0, 1]]
[[block]]
polygon = [[999990, 0], [999991, 0], [999991, 1], [999990, 1]]
"""
    )
    outcome = simulate(sc).outcome
    # θ = 0.5 integrates a constant acceleration exactly: the free block has fallen g t² / 2
    assert outcome["max_displacement"] == pytest.approx(0.5 * 9.81 * 0.05**2, rel=1e-9)
    said = describe_outcome(outcome)
    assert said.startswith("damaged (") and "largest block displacement 12.3 mm" in said, said


def test_solver_option_runs_either_solver_to_the_same_motion(tmp_path):
    """--solver nlgs (plain Gauss–Seidel, the reference) and the default accelerated solver both converge
    every step, and their motions agree to within what the tolerance allows (velocities are unique)."""
    q = {}
    for solver in ("nlgs", "nlgs-accel32", "nlgs-accel", None):
        npz = tmp_path / f"h_{solver}.npz"
        extra = ("--solver", solver) if solver else ()
        r = invoke("simulate", "wall", "--duration", "0.1", "--no-recording", "--history", npz, *extra)
        assert r.exit_code == 0, r.output
        h = np.load(npz)
        assert h["nlgs_unconverged"][-1] == 0 and np.all(h["nlgs_residual"] <= 1e-5)
        q[solver] = h["block_q"]
    np.testing.assert_array_equal(q[None], q["nlgs-accel32"])  # the default
    for solver in ("nlgs-accel32", "nlgs-accel"):
        assert np.abs(q["nlgs"][..., :2] - q[solver][..., :2]).max() < 5e-4  # m, after 0.1 s of shaking


def test_the_summary_gives_the_peak_drift_a_history_of_every_step_shows(tmp_path):
    # an intact wall's state line gave its residual drift (~0) and no word of how far it swung meanwhile
    npz = tmp_path / "h.npz"
    args = (
        "--courses",
        4,
        "--length",
        1.2,
        "--amp",
        1,
        "--duration",
        0.3,
        "--record-every",
        1,
        "--no-recording",
        "--history",
        npz,
    )
    result = invoke("simulate", "wall", *args)
    assert result.exit_code == 0, result.output
    h = np.load(npz)
    # the top course (centroids within half a block height of the highest) relative to the ground, over the
    # blocks' vertical extent, at every step: a plain loop over the history
    q0, ext = h["block_q"][0], h["block_extent"]
    height = ext[:, 3].max() - ext[:, 1].min()
    top = [i for i in range(len(q0)) if q0[i, 1] >= q0[:, 1].max() - 0.5 * 0.2]
    peak = 0.0
    for k in range(len(h["time"])):
        top_dx = sum(h["block_q"][k, i, 0] - q0[i, 0] for i in top) / len(top)
        peak = max(peak, abs(top_dx - (h["support_q"][k, 0, 0] - h["support_q"][0, 0, 0])) / height)
    assert peak > 1e-4
    said = words(result.output.replace("│", " "))  # a row's wrapped lines joined
    assert f"peak drift {100 * peak:.3g} % of the height ({1000 * peak * height:.3g} mm over {height:.3g} m)" in said


def test_a_run_ended_early_measures_the_loading_over_the_steps_it_ran(monkeypatch):
    """'simulate wall --duration 1e5' diverged at t = 243 s (step 243 406 of 10⁸), and its summary then measured
    the intensity over all 10⁸ steps (eqsig's Nigam–Jennings, a Python loop a sample: over 10 minutes, during
    which a SIGTERM said "already stopping" and changed nothing). A run that diverged, failed or was stopped
    measures the steps it ran; a completed one (at collapse too) its whole loading."""
    import masonrycli.run as run
    from masonrycli.scenario.builtin import builtin

    asked = []
    measure = run.applied_intensity
    monkeypatch.setattr(run, "applied_intensity", lambda sc, m, steps=None: asked.append(steps) or measure(sc, m, 50))
    monkeypatch.setattr(run.Simulation, "diverged", lambda sim: "a test" if sim.state.step == 40 else "")
    result = simulate(builtin("wall", duration=1000.0))
    assert result.status == "diverged" and result.steps == 40
    assert asked == [40]
