"""Gauss–Seidel with Nesterov momentum: the engine's default solver "nlgs-accel" (engine/momentum.py) in the lab.

nlgs-accel      the engine's accelerated solve (``dispatch.solve`` with ``solver = "nlgs-accel"``) from r_warm,
                stopped when the lab's RMS contact-law residual ≤ target, like nlgs-law: the count is found
                at sweep counts ≤ 10 % apart, then re-run in one kernel call and timed. The momentum cannot
                be resumed between kernel calls, so every count tried is a fresh solve from r_warm.
nlgs-accel-G    the same with restart growth G instead of the engine's (``Tuning.lane_growth``, 1.1): the
                lane sweeps that run these sweeps take it as a kernel argument, so the variant runs in this
                process with ``dataclasses.replace(TUNING, lane_growth=G)`` handed to ``dispatch.solve``, the
                same compiled kernel (until 29 Nov it ran in a worker process with an empty numba cache that
                set the compile-time constant momentum.RESTART_GROWTH before anything compiled).

Sweep units: accelerated sweeps × ``ctx.accel_cost``, the CPU time of one accelerated sweep over one plain
sweep on the same problem (the harness measures both in the same run; the variants run the same kernel).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from benchmarks.solver_lab.methods.gauss_seidel import CAP
from benchmarks.solver_lab.outcome import Clock, Outcome
from masonrycli.engine.tuning import TUNING

GROWTHS = (1.05, 1.2)
"""Restart growths measured beside the engine's (1.3 diverged on the 248-block wall, see momentum.py)."""


def accelerated_sweeps(ctx, r0: np.ndarray, n: int, tuning=TUNING) -> tuple[np.ndarray, np.ndarray]:
    """``n`` sweeps of the engine's accelerated solve from impulses ``r0`` with ``tuning``; returns (v, r)."""
    r = r0.copy()
    v, _ = ctx.sweep(r, n, "nlgs-accel", tuning)
    return v, r


_found: dict = {}  # (problem, target, growth) → (sweeps, converged): the search is not timed, do it once


def accelerated(ctx, target, tuning=TUNING) -> Outcome:
    p = ctx.p
    key = (p.name, target, tuning.lane_growth)
    if key not in _found:
        n = 0
        ok = False
        while n < CAP and not ok:
            n += max(1, n // 10)
            v, r = accelerated_sweeps(ctx, p.r_warm, n, tuning)
            ok = ctx.residual(v, r) <= target
        _found[key] = n, ok
    n, ok = _found[key]
    clock = Clock()
    with clock("sweeps"):
        v, r = accelerated_sweeps(ctx, p.r_warm, n, tuning)
    return Outcome(v, r, n, n * ctx.accel_cost, clock.phases, converged=ok)


def variant(growth: float):
    """nlgs-accel with restart growth ``growth`` (module doc)."""
    tuning = dataclasses.replace(TUNING, lane_growth=growth)

    def solve(ctx, target) -> Outcome:
        return accelerated(ctx, target, tuning)

    return solve


METHODS = {"nlgs-accel": accelerated} | {f"nlgs-accel-{g:g}": variant(g) for g in GROWTHS}
