"""Joint-block Gauss–Seidel (methods/joint.py) on the ordinary steps of a trajectory sample.

    python -m benchmarks.solver_lab trajectory --case wall-248 --every 5 --name nwt-wall-248
    python -m benchmarks.solver_lab joint-ordinary --sample nwt-wall-248 [--every 1] [--repeat 2]

Every ordinary step of ``data/trajectory/SAMPLE`` (the engine's momentum converged it without stalling) is
solved from its warm start by

    engine           the engine's accelerated solve (``dispatch.first_stage``, momentum alone, its in-sweep
                     test at 1e-5 m/s): the run's sweep counts
    pointwise-accel  methods/joint.py's kernel, one point per joint: momentum on point sweeps in detection
                     order, stopped when the lab's law residual of the iterate (law.py) ≤ 1e-5 m/s
    joint-accel      the same kernel with each joint solved exactly (inner rounds to 1e-12 m/s)
    joint-accel-r2   two rounds per joint
    joint-gs         exact joints, no momentum (reported with --plain)

The kernel's rows share one stopping rule, so their sweeps compare directly; the engine's row is the
run's own rule (in-sweep residual) and sweep order, given for scale. Reported per variant: sweeps over the
steps (sum, ÷ pointwise-accel's, geometric mean of the per-step ratio), point visits per contact and
sweep, CPU s of the whole sample (kernel calls only, counts found beforehand, minimum of ``repeat``
interleaved rounds) and its ratio to the engine's, and the velocity error against a tight solve (momentum
to 1e-9 m/s, cap 20 000; largest |Δv| over the bodies, mean over the steps).
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.solver_lab.methods import joint
from benchmarks.solver_lab.newton_ordinary import Step
from benchmarks.solver_lab.trajectory import TRAJECTORY
from masonrycli.engine import dispatch

TOLERANCE = 1e-5
CAP = 20_000
KERNEL = {  # name → (rounds, accelerate, pointwise)
    "pointwise-accel": (1, True, True),
    "joint-accel": (joint.ROUNDS_EXACT, True, False),
    "joint-accel-r2": (2, True, False),
    "joint-gs": (joint.ROUNDS_EXACT, False, False),
}


def _engine(s: Step, n: int | None = None):
    """The engine's momentum from the warm start (n: exactly n sweeps, else to its own test): (sweeps, v)."""
    v, r, status = s.v_free.copy(), s.r_warm.copy(), np.zeros(s.count, np.int8)
    tol = 0.0 if n is not None else TOLERANCE
    its, _ = dispatch.first_stage(s.body, s.pack, s.count, s.mu, tol, n or CAP, v, r, status, CAP)
    return int(its), v


def _kernel(s: Step, name: str, n: int | None = None):
    """The joint kernel's variant ``name`` (n: exactly n sweeps, else until the law residual ≤ TOLERANCE):
    (sweeps, v, visits per contact·sweep, converged)."""
    rounds, accelerate, pointwise = KERNEL[name]
    starts = np.arange(s.count + 1, dtype=np.int64) if pointwise else joint.joint_starts(s.body)
    v, _, sweeps, law, stats = joint.joint_solve(
        s.body, s.pack, s.mu, s.v_free, s.r_warm, TOLERANCE, n or CAP, rounds, accelerate, n is None, starts
    )
    return sweeps, v, stats[0] / max(sweeps * s.count, 1), n is not None or law <= TOLERANCE


def table(sample: str, every: int, repeat: int, plain: bool = False) -> None:
    paths = sorted((TRAJECTORY / sample).glob("step-*.npz"))
    steps = [s for s in (Step(p) for p in paths) if not s.stalled][::every]
    names = ["engine", *[k for k in KERNEL if plain or k != "joint-gs"]]
    print(f"{sample}: {len(steps)} ordinary steps (every {every}-th of {len(paths)} kept)", flush=True)
    rows = {m: {"its": [], "visits": [], "err": [], "ok": [], "cpu": np.inf} for m in names}
    for s in steps:
        v_ref = s.tight[0]
        for m in names:
            if m == "engine":
                n, v = _engine(s)
                visits, ok = 1.0, True
            else:
                n, v, visits, ok = _kernel(s, m)
            row = rows[m]
            row["its"].append(n)
            row["visits"].append(visits)
            row["ok"].append(ok)
            row["err"].append(float(np.abs(v - v_ref).max()))
    for _ in range(repeat):
        for m in names:
            t = time.process_time()
            for s, n in zip(steps, rows[m]["its"]):
                _engine(s, n) if m == "engine" else _kernel(s, m, n)
            rows[m]["cpu"] = min(rows[m]["cpu"], time.process_time() - t)
    base = np.array(rows["pointwise-accel"]["its"], dtype=float)
    print(
        "| variant | sweeps Σ | ÷ pointwise-accel | per step (geo. mean) | visits / contact·sweep |"
        " not converged | CPU s | CPU ÷ engine | velocity error m/s (mean of max) |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for m in names:
        row = rows[m]
        its = np.array(row["its"], dtype=float)
        geo = np.exp(np.log(its / base).mean())
        print(
            f"| {m} | {its.sum():.0f} | {its.sum() / base.sum():.3f} | {geo:.3f} | {np.mean(row['visits']):.2f} |"
            f" {len(steps) - sum(row['ok'])} | {row['cpu']:.3f} | {row['cpu'] / rows['engine']['cpu']:.2f} |"
            f" {np.mean(row['err']):.2e} |",
            flush=True,
        )
