"""NLGS with a safeguarded linear correction in velocity space (``nlgs-linear``).

Gauss–Seidel removes local errors in a few sweeps and global ones (load carried through many courses)
slowly. A Newton-like correction solves the *linearised* problem at once, with the statuses the exact
local solves pick at the current iterate:

    stick α:  H_α (v + Δv) = (0, −bias_α)          impulse increment Δr_α free (2 rows)
    slip α:   H_nα (v + Δv) = −bias_α               Δr_α = (−sμ, 1) Δλ_α (friction on the cone edge)
    open α:   Δr_α = −r_α
    M Δv = Hᵀ Δr

The walls are hyperstatic (impulses not unique), so each constraint row gets a compliance proportional
to its contact's own flexibility, ε_α = DELTA · (W_tt + W_nn)/2, and regularises the *increment* only:
Δλ = −(G(v + Δv) − g)/ε. One sparse LU of K = M + Dᵀ ε⁻¹ G (D = G except on slip rows: non-symmetric)
gives Δv; impulses r + Δr are projected into the cone and v re-derived from them. The correction is kept
only if it lowers the contact-law residual below DROP times what it was (else the iterate is unchanged);
then SMOOTH more engine sweeps, and so on until the target.

Iterations: corrections kept (of one tried every SMOOTH sweeps). Work in sweep units: the sweeps run plus
the corrections' CPU time (kept or not) over one sweep's.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from benchmarks.solver_lab import law
from benchmarks.solver_lab.outcome import Clock, Outcome, project_cone, sweeps_with_corrections
from masonrycli.engine import nlgs as N

DELTA = 1e-2
"""Compliance of a constraint row relative to its contact's W_αα (1e-4 and 1e-6: worse, see benchmarks/JOURNAL.md, "Two more methods")."""
SMOOTH = 10
"""Engine sweeps between corrections."""
DROP = 0.5
"""A correction is kept when it at least halves the RMS contact-law residual."""
CAP = 50_000


def _statuses(ctx, v, r):
    pack = ctx.pack
    u = (ctx.H @ v.ravel()).reshape(-1, 2)
    ut = u[:, 0] - (pack[:, N.P_WTT] * r[:, 0] + pack[:, N.P_WTN] * r[:, 1])
    un = u[:, 1] - (pack[:, N.P_WTN] * r[:, 0] + pack[:, N.P_WNN] * r[:, 1])
    rt, rn = law.local_solve(ut, un, pack, ctx.p.mu)
    closed = rn > 0.0
    slip = closed & (np.abs(rt) >= ctx.p.mu * rn * (1.0 - 1e-12))
    s = np.where(rt < 0.0, 1.0, -1.0)  # r_t = −s μ r_n
    return np.flatnonzero(closed & ~slip), np.flatnonzero(slip), np.flatnonzero(~closed), s


def correction(ctx, v, r):
    """Impulses after one linearised solve at the statuses of (v, r), projected into the cone."""
    p, pack, mu = ctx.p, ctx.pack, ctx.p.mu
    stick, slip, opened, s = _statuses(ctx, v, r)
    dyn = np.flatnonzero(ctx.minv > 0)
    hd = ctx.H[:, dyn].tocsr()
    bias = pack[:, N.P_BIAS]
    eps = DELTA * 0.5 * (pack[:, N.P_WTT] + pack[:, N.P_WNN])
    rows = np.concatenate([2 * stick, 2 * stick + 1, 2 * slip + 1])
    g = np.concatenate([np.zeros(stick.size), -bias[stick], -bias[slip]])
    w = 1.0 / np.concatenate([eps[stick], eps[stick], eps[slip]])
    gm = hd[rows]
    dm = sp.vstack([hd[2 * stick], hd[2 * stick + 1], hd[2 * slip + 1] - sp.diags(s[slip] * mu) @ hd[2 * slip]])
    k = sp.diags(1.0 / ctx.minv[dyn]) + dm.T @ sp.diags(w) @ gm
    violation = (ctx.H @ v.ravel())[rows] - g
    r_open = np.zeros(2 * p.count)
    r_open[2 * opened] = -r[opened, 0]
    r_open[2 * opened + 1] = -r[opened, 1]
    dv = spla.splu(k.tocsc()).solve(-(dm.T @ (w * violation)) + hd.T @ r_open)
    dl = -w * (violation + gm @ dv)
    out = r.copy()
    n = stick.size
    out[stick, 0] += dl[:n]
    out[stick, 1] += dl[n : 2 * n]
    out[slip, 1] += dl[2 * n :]
    out[slip, 0] -= s[slip] * mu * dl[2 * n :]
    out[opened] = 0.0
    return project_cone(out, mu)


def solve(ctx, target) -> Outcome:
    clock = Clock()

    def correct(v, r, before):
        with clock("correction"):
            trial = correction(ctx, v, r)
            v_trial = law.velocity_from_impulse(ctx.p, ctx.H, trial)
            return (trial, v_trial) if ctx.residual(v_trial, trial) < DROP * before else None

    v, r, sweeps, _, kept, converged = sweeps_with_corrections(ctx, target, SMOOTH, CAP, clock, correct)
    # The engine would check the residual in the sweep (free); the correction is extra work.
    extra = clock.phases.get("correction", 0.0) / ctx.sweep_s
    return Outcome(v, r, kept, sweeps + extra, clock.phases, converged=converged)


METHODS = {"nlgs-linear": solve}
