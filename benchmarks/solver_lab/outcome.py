"""What a method hands back to the harness, and the context it gets (problem + prebuilt operators)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from benchmarks.solver_lab import law
from masonrycli.engine import dispatch
from masonrycli.engine.tuning import TUNING


@dataclass
class Outcome:
    v: np.ndarray
    """(B, 3) end-of-step velocities."""
    r: np.ndarray
    """(C, 2) impulses; the harness re-derives v from them to check consistency."""
    iterations: int
    """The method's own iteration count (sweeps for Gauss–Seidel variants)."""
    sweeps: float
    """Work in Gauss–Seidel sweeps: sweeps run, plus any other work converted at the problem's
    measured time per sweep (see ``Context.sweep_s``)."""
    phases: dict = field(default_factory=dict)
    """phase name → CPU seconds."""
    converged: bool = True
    cpu_s: float | None = None
    """CPU seconds of the solve when it ran in another process (the harness's clock would miss them), or
    when part of the call is not the method's work (an untimed search)."""
    detail: str = ""
    """Counts beside ``iterations`` (e.g. outer rounds, closing sweeps), printed with them."""


class Clock:
    """Accumulates CPU seconds per phase: ``with clock("sweeps"): ...``."""

    def __init__(self):
        self.phases: dict[str, float] = {}
        self._name = ""

    def __call__(self, name: str) -> Clock:
        self._name = name
        return self

    def __enter__(self):
        self._t = time.process_time()

    def __exit__(self, *exc):
        self.phases[self._name] = self.phases.get(self._name, 0.0) + time.process_time() - self._t


class Context:
    """One problem with what every method needs prebuilt (not timed: the engine builds ``pack`` anyway;
    methods that need H or M⁻¹ must count building them in their own phases if the engine would have to)."""

    def __init__(self, problem):
        self.p = problem
        self.pack = problem.pack()
        self.H = law.h_matrix(problem, self.pack)
        self.minv = law.inv_mass_diag(problem)
        self.sweep_s = np.nan
        """CPU seconds of one engine NLGS sweep on this problem (measured by the harness)."""
        self.accel_cost = np.nan
        """CPU time of one accelerated sweep (solver "nlgs-accel") over one plain sweep (measured by the harness)."""

    def sweep(self, r: np.ndarray, n: int, solver: str = "nlgs", tuning=TUNING) -> tuple[np.ndarray, np.ndarray]:
        """``n`` engine NLGS sweeps (``solver``: plain or "nlgs-accel"; ``tuning``: the engine's Tuning, the
        shipped one by default) from impulses ``r`` (updated in place); returns (v, status)."""
        p = self.p
        v = p.v_free.copy()
        status = np.zeros(p.count, dtype=np.int8)
        dispatch.solve(p.body, self.pack, p.count, p.shim(0.0, n, solver=solver), v, r, status, tuning)
        return v, status

    def residual(self, v: np.ndarray, r: np.ndarray) -> float:
        """m/s: root mean square of the contact-law residual over the contacts (law.law_residual) — the
        quantity the engine's stopping test compares with its tolerance, here taken after the sweep."""
        e = law.law_residual(self.p, self.pack, self.H, v, r)
        return float(np.sqrt((e * e).mean())) if e.size else 0.0

    def residual_max(self, v: np.ndarray, r: np.ndarray) -> float:
        """m/s: the largest contact-law residual."""
        return float(law.law_residual(self.p, self.pack, self.H, v, r).max(initial=0.0))


def project_cone(r: np.ndarray, mu: float) -> np.ndarray:
    """r with r_n ≥ 0 and |r_t| ≤ μ r_n (componentwise clip; a valid start for Gauss–Seidel)."""
    out = r.copy()
    out[:, 1] = np.maximum(out[:, 1], 0.0)
    lim = mu * out[:, 1]
    out[:, 0] = np.clip(out[:, 0], -lim, lim)
    return out


def sweeps_with_corrections(ctx, target: float, sweeps: int, cap: int, clock: Clock, correct):
    """Engine sweeps from r_warm in chunks of ``sweeps`` until the law residual ≤ ``target`` or ``cap``
    sweeps; after each chunk that misses it, ``correct(v, r, residual)`` returns a new (r, v) to continue
    from, or None to keep the iterate. The residual checks are timed as "check" (the engine would do them
    in the sweep). Returns (v, r, sweeps done, corrections tried, corrections kept, converged)."""
    r = ctx.p.r_warm.copy()
    v = None
    done = tried = kept = 0
    while done < cap:
        with clock("sweeps"):
            v, _ = ctx.sweep(r, sweeps)
        done += sweeps
        with clock("check"):
            residual = ctx.residual(v, r)
        if residual <= target:
            return v, r, done, tried, kept, True
        tried += 1
        new = correct(v, r, residual)
        if new is not None:
            r, v = new
            kept += 1
    return v, r, done, tried, kept, False
