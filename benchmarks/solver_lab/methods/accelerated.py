"""Gauss–Seidel with Nesterov momentum: the engine's default solver "nlgs-accel" (engine/momentum.py) in the lab.

nlgs-accel      the engine's accelerated solve (``dispatch.solve`` with ``solver = "nlgs-accel"``) from r_warm,
                stopped when the lab's RMS contact-law residual ≤ target, like nlgs-law: the count is found
                at sweep counts ≤ 10 % apart, then re-run in one kernel call and timed. The momentum cannot
                be resumed between kernel calls, so every count tried is a fresh solve from r_warm.
nlgs-accel-G    the same with restart growth G instead of the engine's RESTART_GROWTH. numba freezes a
                global at compile time and the engine's kernels are cached on disk, so a variant runs in a
                worker process with its own empty numba cache directory, which sets RESTART_GROWTH before
                anything compiles; the worker times the solve in its own CPU time.

Sweep units: accelerated sweeps × ``ctx.accel_cost``, the CPU time of one accelerated sweep over one plain
sweep on the same problem (the harness measures both in the same run; the variants run the same kernel).
"""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.solver_lab.methods.gauss_seidel import CAP
from benchmarks.solver_lab.outcome import Clock, Context, Outcome

GROWTHS = (1.05, 1.2)
"""Restart growths measured beside the engine's (1.3 diverged on the 248-block wall, see momentum.py)."""


def accelerated_sweeps(ctx, r0: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` sweeps of the engine's accelerated solve from impulses ``r0``; returns (v, r)."""
    r = r0.copy()
    v, _ = ctx.sweep(r, n, "nlgs-accel")
    return v, r


_found: dict = {}  # (problem, target) → (sweeps, converged): the search is not timed, do it once


def accelerated(ctx, target) -> Outcome:
    p = ctx.p
    key = (p.name, target)
    if key not in _found:
        n = 0
        ok = False
        while n < CAP and not ok:
            n += max(1, n // 10)
            v, r = accelerated_sweeps(ctx, p.r_warm, n)
            ok = ctx.residual(v, r) <= target
        _found[key] = n, ok
    n, ok = _found[key]
    clock = Clock()
    with clock("sweeps"):
        v, r = accelerated_sweeps(ctx, p.r_warm, n)
    return Outcome(v, r, n, n * ctx.accel_cost, clock.phases, converged=ok)


class _Worker:
    """A child process whose engine runs with RESTART_GROWTH = ``growth`` (module doc)."""

    def __init__(self, growth: float):
        self.cache = tempfile.TemporaryDirectory(prefix="lab-numba-")
        env = dict(os.environ, NUMBA_CACHE_DIR=self.cache.name, RERUN_ANALYTICS="0")
        cmd = [sys.executable, "-m", "benchmarks.solver_lab.methods.accelerated", repr(growth)]
        root = Path(__file__).resolve().parents[3]
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env, cwd=root)

    def solve(self, problem, target: float, cost: float) -> Outcome:
        pickle.dump((problem, target, cost), self.proc.stdin)
        self.proc.stdin.flush()
        return pickle.load(self.proc.stdout)


_workers: dict[float, _Worker] = {}


def variant(growth: float):
    def solve(ctx, target) -> Outcome:
        if growth not in _workers:
            _workers[growth] = _Worker(growth)
        return _workers[growth].solve(ctx.p, target, ctx.accel_cost)

    return solve


def _serve(growth: float) -> None:
    """Worker loop: (problem, target, cost) in on stdin, the Outcome (with its CPU seconds) out on stdout."""
    from masonrycli.engine import momentum

    momentum.RESTART_GROWTH = growth  # before the first call compiles the kernels (empty cache directory)
    contexts: dict[str, Context] = {}
    while True:
        try:
            problem, target, cost = pickle.load(sys.stdin.buffer)
        except EOFError:
            return
        if problem.name not in contexts:
            contexts[problem.name] = Context(problem)
        ctx = contexts[problem.name]
        ctx.accel_cost = cost
        t = time.process_time()
        out = accelerated(ctx, target)
        out.cpu_s = time.process_time() - t
        pickle.dump(out, sys.stdout.buffer)
        sys.stdout.buffer.flush()


METHODS = {"nlgs-accel": accelerated} | {f"nlgs-accel-{g:g}": variant(g) for g in GROWTHS}

if __name__ == "__main__":
    _serve(float(sys.argv[1]))
