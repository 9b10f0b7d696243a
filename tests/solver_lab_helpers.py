"""A small captured problem for the solver lab's tests."""

from __future__ import annotations

from benchmarks.solver_lab.capture import SINE, capture_run, reference
from masonrycli.run import Simulation
from masonrycli.scenario import Material, RunConfig, scenario_from_builder


def tiny_cold_problem():
    """The cold start (step 1, every impulse 0) of a 7-block, 2-course shaken wall, with its tight
    reference (contact-law residual ≤ 1e-9 m/s): small enough for dense references."""
    sc = scenario_from_builder(
        "wall", {"blocks": 7, "courses": 2}, RunConfig(duration=0.002), Material(), {"ground": SINE}
    )
    p = capture_run(Simulation(sc), typical_step=1)[0]["cold"]
    p.name = "tiny-cold"
    reference(p)
    assert p.ref_residual <= 1e-9
    return p
