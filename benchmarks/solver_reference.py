"""The accuracy reference of the solver benchmarks (bench_solver.py, bench_accuracy.py): the slips sampled,
the tight solves they are measured against, how far those solves are from converged, and how far two of
them lie apart.

A solver's accuracy is its top-course and mean slip (benchmarks.solver_cases.slips; for the arch and the
aqueduct, the highest block's and the mean displacement) at 0.1 and 0.2 s in % of a tight solve's. On tall
walls a tight solve stops at its sweep cap short of its tolerance (plain ``nlgs`` at 1e-7 m/s, cap 20 000:
195 of 200 steps of the 32-course wall, all 200 of the 64-course wall), and two equally tight solves of a
hyperstatic wall take different trajectories (benchmarks/JOURNAL.md, "Is the tight solve a reference on tall
walls?"). So a reference run keeps its unconverged and capped steps and its largest residual, and a second
reference from another solver gives the *spread* (its slips in % of the first's): an error no larger than
the spread, at the same sample and measure, is not resolved by the reference.
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.solver_cases import course_of, is_wall, make_scenario, slips
from masonrycli.run import Simulation, simulate
from masonrycli.scenario.scenario import SOLVERS

SAMPLES = (100, 200)
"""Steps (dt = 1e-3) at which the accuracy is read: 0.1 and 0.2 s."""
TIGHT = {"tolerance": 1e-7, "max_iterations": 20000, "solver": "nlgs"}
"""The reference of every accuracy figure: plain Gauss–Seidel far below the default tolerance."""
SECOND = {"tolerance": 1e-7, "max_iterations": 20000, "solver": "nlgs-accel"}
"""The second reference: the same tolerance and cap, the other solver — the cheapest independent tight solve
bench_accuracy measured (wall-248 6.9 s of CPU against the first's 15.5 s; h32 106 s against 75 s; in
bench_solver's run at 99802b3, 16 s against 17 s and 121 s against 84 s)."""


class Sampler:
    """A sink keeping the displacement measures (top, mean) at the steps ``steps``."""

    def __init__(self, sim: Simulation, case: str, steps=SAMPLES):
        m = sim.model
        self.n = m.block_count
        self.q0 = m.body_q0[: self.n].copy()
        self.ground0 = m.body_q0[self.n :].copy()
        self.course = course_of(m.block_name) if is_wall(case) else None
        self.steps = steps
        self.values: dict[int, tuple[float, float]] = {}

    def close(self, status: str = "completed", note: str = "") -> None:
        """Nothing to write (the sink protocol of masonrycli.run.simulate)."""

    def on_frame(self, frame) -> None:
        if frame.step not in self.steps:
            return
        if self.course is not None:
            ground_dx = frame.support_q[0, 0] - self.ground0[0, 0]
            self.values[frame.step] = slips(self.q0[:, 0], frame.block_q[:, 0], ground_dx, self.course)
        else:
            d = np.hypot(*(frame.block_q[:, :2] - self.q0[:, :2]).T)
            self.values[frame.step] = (float(d[np.argmax(self.q0[:, 1])]), float(d.mean()))


class Residuals:
    """A sink keeping every step's final residual and whether it converged."""

    def __init__(self):
        self.residual: list[float] = []
        self.unconverged = 0

    def on_frame(self, frame) -> None:
        """Frames are the sampler's business."""

    def log_step(self, step, time, stats) -> None:
        self.residual.append(stats.residual)
        self.unconverged += not stats.converged


def errors_pct(samples: dict, reference: dict) -> dict:
    """Relative error (%) of each (top, mean) sample against the reference's."""
    out = {}
    for step, (top, mean) in samples.items():
        if step in reference:
            rt, rm = reference[step]
            out[step] = (100.0 * (top - rt) / abs(rt), 100.0 * (mean - rm) / abs(rm))
    return out


def parse_spec(spec: str) -> dict:
    """``SOLVER:TOLERANCE[:CAP]`` → run options {solver, tolerance[, max_iterations]}."""
    parts = spec.split(":")
    if len(parts) not in (2, 3) or parts[0] not in SOLVERS:
        raise ValueError(f"{spec!r}: expected SOLVER:TOLERANCE[:CAP], SOLVER one of {', '.join(SOLVERS)}")
    options = {"solver": parts[0], "tolerance": float(parts[1])}
    if len(parts) == 3:
        options["max_iterations"] = int(parts[2])
    return options


def spec_of(options: dict) -> str:
    """Run options {solver, tolerance[, max_iterations]} → ``SOLVER:TOLERANCE[:CAP]`` (parse_spec's inverse)."""
    spec = f"{options['solver']}:{options['tolerance']:.0e}".replace("e-0", "e-")
    return spec + (f":{options['max_iterations']}" if "max_iterations" in options else "")


def run(case: str, duration: float, steps=SAMPLES, **options) -> dict:
    """One run of ``case`` with run ``options`` (no recording): CPU s, sweeps, unconverged steps (residual
    above the tolerance or at the cap), capped steps (the whole cap used), residuals (m/s), and the slips at
    ``steps``."""
    sc = make_scenario(case, duration, **options)
    sim = Simulation(sc)
    sampler, residuals = Sampler(sim, case, steps), Residuals()
    t = time.process_time()
    result = simulate(sc, [sampler, residuals], sim=sim)
    cpu = time.process_time() - t
    res = np.array(residuals.residual)
    return {
        "options": options,
        "cpu_s": cpu,
        "steps": result.steps,
        "sweeps_mean": result.tally.sweeps_mean,
        "sweeps_max": result.tally.sweeps_max,
        "unconverged": residuals.unconverged,
        "capped": result.tally.capped,
        "residual_median": float(np.median(res)),
        "residual_max": float(res.max()),
        "samples": {str(k): v for k, v in sampler.values.items()},
        "status": result.status,
    }


def spread_pct(first: dict, second: dict) -> dict:
    """The second reference's slips in % of the first's, per sample: step → (top, mean)."""
    return errors_pct(second["samples"], first["samples"])


def unresolved(error: dict, spread: dict) -> dict:
    """Per sample and measure of ``error`` (errors_pct), whether it is no larger than the references'
    spread there (then the reference cannot tell it from zero); samples without a spread are left out."""
    return {
        step: tuple(abs(e) <= abs(s) for e, s in zip(pair, spread[step], strict=True))
        for step, pair in error.items()
        if step in spread
    }
