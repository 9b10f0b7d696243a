"""The interior-point method (methods/ipm.py) on the ordinary steps of a trajectory sample.

    python -m benchmarks.solver_lab ipm-ordinary --sample nwt-wall-248 [--every 4] [--loose 1e-4 3e-5]

On each ordinary step (momentum converged it without stalling) of a trajectory sample (``trajectory.py``),
from the step's warm start: ``ipm-newton`` (methods/ipm.py) until the lab's RMS law residual ≤ LOOSE, then
the engine's accelerated sweeps (``dispatch.first_stage``, stall window 500, cap 20 000 — as
newton_ordinary.py) to the engine's test (in-sweep RMS ≤ 1e-5 m/s). Against momentum alone from the same
warm start (the engine; its sweeps equal the run's on ordinary steps). Reported per LOOSE: IPM iterations
and closing sweeps (sum, mean, median, largest), steps whose closing sweeps stalled, and the CPU time of the
IPM part and of the closing sweeps over momentum's (one timed pass after an untimed one; the operators'
one-off numpy setup is left out as in ipm.py).

A trajectory step stores the contacts as the engine's ``dispatch.solve`` got them (``pack``), not the geometry,
so the lab's Problem is rebuilt from the pack: masses and inertias from its per-contact inverse masses
(P_IMA…); no reference velocity (v_ref = v_free, unused: the table reports counts and CPU only).
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import ipm
from benchmarks.solver_lab.newton_ordinary import Step
from benchmarks.solver_lab.outcome import Clock, Context
from benchmarks.solver_lab.trajectory import TRAJECTORY
from masonrycli.engine.nlgs import P_IIA, P_IIB, P_IMA, P_IMB

LOOSE = (1e-4, 3e-5)


class _StepProblem:
    """The fields of problems.Problem that ipm.py, law.py and Context read, from a trajectory step."""

    def __init__(self, s: Step, name: str):
        self.name = name
        self.body = s.body
        self.mu = s.mu
        self.v_free = s.v_free
        self.r_warm = s.r_warm
        nb = s.v_free.shape[0]
        self.q_m = np.zeros((nb, 3))
        self.inv_mass, self.inv_inertia = np.zeros(nb), np.zeros(nb)
        for side, (cm, ci) in enumerate(((P_IMA, P_IIA), (P_IMB, P_IIB))):
            self.inv_mass[s.body[:, side]] = s.pack[:, cm]
            self.inv_inertia[s.body[:, side]] = s.pack[:, ci]
        self.v_ref = s.v_free
        self.radius = np.ones(nb)

    @property
    def count(self) -> int:
        return int(self.body.shape[0])


def context(s: Step, name: str) -> Context:
    ctx = Context.__new__(Context)
    ctx.p = _StepProblem(s, name)
    ctx.pack = s.pack
    ctx.H = law.h_matrix(ctx.p, s.pack)
    ctx.minv = law.inv_mass_diag(ctx.p)
    return ctx


def table(sample: str, every: int, loose: tuple[float, ...] = LOOSE) -> None:
    paths = sorted((TRAJECTORY / sample).glob("step-*.npz"))
    steps = [s for s in (Step(p) for p in paths) if not s.stalled][::every]
    print(f"{sample}: {len(steps)} ordinary steps (every {every}-th of {len(paths)} kept)", flush=True)
    engine = {"units": [], "cpu": 0.0}
    rows = {lo: {"its": [], "closing": [], "stalled": 0, "ipm_cpu": 0.0, "close_cpu": 0.0} for lo in loose}
    for s in steps:
        ctx = context(s, f"{sample}/{s.step}")
        ipm.operators(ctx, Clock())  # one-off setup, untimed
        its, res, *_ = s.sweeps(s.r_warm)
        t = time.process_time()
        s.sweeps(s.r_warm)
        engine["cpu"] += time.process_time() - t
        engine["units"].append(its)
        for lo in loose:
            row = rows[lo]
            ipm.run_ipm(ctx, 1e-5, lo, Clock(), "newton")  # untimed pass
            t = time.process_time()
            v, r, n_ipm, _, _ = ipm.run_ipm(ctx, 1e-5, lo, Clock(), "newton")
            row["ipm_cpu"] += time.process_time() - t
            t = time.process_time()
            n_close, res, *_ = s.sweeps(r)
            row["close_cpu"] += time.process_time() - t
            row["its"].append(n_ipm)
            row["closing"].append(n_close)
            row["stalled"] += res > 1e-5
    e = np.array(engine["units"])
    print(
        f"momentum: sweeps Σ {e.sum()}, mean {e.mean():.0f}, median {np.median(e):.0f}, max {e.max()};"
        f" CPU {1e3 * engine['cpu'] / len(steps):.2f} ms a step"
    )
    print(
        "| LOOSE m/s | IPM iterations mean / median / max | closing sweeps Σ / mean / median / max | stalled |"
        " CPU ms a step (IPM + sweeps) | CPU ÷ momentum |"
    )
    print("|---|---|---|---|---|---|")
    for lo in loose:
        row = rows[lo]
        it, cl = np.array(row["its"]), np.array(row["closing"])
        cpu = row["ipm_cpu"] + row["close_cpu"]
        print(
            f"| {lo:g} | {it.mean():.1f} / {np.median(it):.0f} / {it.max()} | {cl.sum()} / {cl.mean():.0f} /"
            f" {np.median(cl):.0f} / {cl.max()} | {row['stalled']} | {1e3 * row['ipm_cpu'] / len(steps):.1f} +"
            f" {1e3 * row['close_cpu'] / len(steps):.2f} | {cpu / engine['cpu']:.1f} |",
            flush=True,
        )
