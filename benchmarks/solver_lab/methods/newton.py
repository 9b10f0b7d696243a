"""Active-set (semismooth) Newton in velocity space, and the same linear solve as a reference polish.

Given a status per contact — open, stick, or slip in direction s — the contact law is linear:

    stick α:  H_α v = (0, −bias_α)                 impulse (r_t, r_n) free
    slip α:   H_nα v = −bias_α                      impulse r_n (−sμ, 1) in (t, n)
    open α:   nothing                               impulse 0
    M (v − v_free) = Dᵀ λ,  G v = g                 (G: constraint rows, D: impulse directions)

The walls are hyperstatic (more rows than velocity unknowns, G rank-deficient), so the impulses are not
unique but v is. In velocity space this is well posed: the augmented-Lagrangian (method of multipliers)
iteration

    (M + Dᵀ G / ε) v = M v_free + Dᵀ (λ + g/ε),   λ ← λ + (g − G v)/ε

with one sparse LU of K = M + DᵀG/ε per status set converges to the exact constrained v (no
regularisation left: the multipliers absorb it) and to the λ nearest the start, i.e. the warm impulses.
Non-symmetric only through the sliding rows (D ≠ G there).

Newton: statuses ← what the exact local solve picks at the current (v, r); linear solve; repeat until the
contact-law residual ≤ target. Between Newton steps ``SWEEPS_BETWEEN`` NLGS sweeps fix statuses locally
(a wrong guess gives r_n < 0 or a friction-cone violation that Gauss–Seidel repairs in a few sweeps).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from benchmarks.solver_lab import law
from benchmarks.solver_lab.outcome import Clock, Outcome, project_cone
from masonrycli.engine import nlgs as N

EPS_REL = 1e-4
"""ε = EPS_REL · median W_nn: the penalty only conditions K; the multiplier updates remove it."""
AL_TOL = 1e-13
"""m/s: constraint violation at which the multiplier iteration stops."""
AL_CAP = 60
SWEEPS_BETWEEN = 5
NEWTON_CAP = 30


def statuses(ctx, v, r):
    """(status (C,) 0/1/2, slip sign s (C,)) that the exact local solve picks at (v, r)."""
    p, pack = ctx.p, ctx.pack
    u = (ctx.H @ v.ravel()).reshape(-1, 2)
    ut = u[:, 0] - (pack[:, N.P_WTT] * r[:, 0] + pack[:, N.P_WTN] * r[:, 1])
    un = u[:, 1] - (pack[:, N.P_WTN] * r[:, 0] + pack[:, N.P_WNN] * r[:, 1])
    rt, rn = law.local_solve(ut, un, pack, p.mu)
    st = np.zeros(p.count, dtype=np.int8)
    closed = rn > 0.0
    st[closed] = 1
    slip = closed & (np.abs(rt) >= p.mu * rn * (1.0 - 1e-12))
    st[slip] = 2
    s = np.where(rt < 0.0, 1.0, -1.0)  # r_t = −s μ r_n
    return st, s, np.stack([rt, rn], axis=1)


def linear_solve(ctx, st, s, r0, clock):
    """Exact v and impulses for the status set (st, s), impulses nearest r0. Returns (v, r, al_iterations)."""
    p, H = ctx.p, ctx.H
    minv = ctx.minv
    dyn = np.flatnonzero(minv > 0)
    sup = np.flatnonzero(minv == 0)
    bias = ctx.pack[:, N.P_BIAS]
    with clock("assemble"):
        stick = np.flatnonzero(st == 1)
        slip = np.flatnonzero(st == 2)
        rows_g = np.concatenate([2 * stick, 2 * stick + 1, 2 * slip + 1])
        G = H[rows_g]
        Ht_slip = H[2 * slip]
        D = sp.vstack([H[2 * stick], H[2 * stick + 1], G[2 * stick.size :] - sp.diags(s[slip] * p.mu) @ Ht_slip])
        D = D.tocsc()
        G = G.tocsc()
        g = np.concatenate([np.zeros(stick.size), -bias[stick], -bias[slip]])
        vf = p.v_free.ravel()
        g = g - G[:, sup] @ vf[sup]
        Gd, Dd = G[:, dyn], D[:, dyn]
        md = 1.0 / minv[dyn]
        wnn = ctx.pack[:, N.P_WNN]
        eps = EPS_REL * float(np.median(wnn)) if wnn.size else 1.0
        K = (sp.diags(md) + (Dd.T @ Gd) / eps).tocsc()
        lam = np.concatenate([r0[stick, 0], r0[stick, 1], r0[slip, 1]])
        base = md * vf[dyn]
    with clock("factor"):
        lu = spla.splu(K)
    its = 0
    with clock("solve"):
        while its < AL_CAP:
            its += 1
            vd = lu.solve(base + Dd.T @ (lam + g / eps))
            viol = g - Gd @ vd
            lam = lam + viol / eps
            if np.abs(viol).max(initial=0.0) <= AL_TOL:
                break
    r = np.zeros_like(r0)
    ns = stick.size
    r[stick, 0], r[stick, 1] = lam[:ns], lam[ns : 2 * ns]
    r[slip, 1] = lam[2 * ns :]
    r[slip, 0] = -s[slip] * p.mu * lam[2 * ns :]
    v = law.velocity_from_impulse(p, H, r)
    return v, r, its


def polish(ctx, v, r, rounds: int = 5):
    """Reference polish: statuses of (v, r), exact linear solve, repeated while the residual drops."""
    clock = Clock()
    best = (ctx.residual(v, r), v, r)
    for _ in range(rounds):
        st, s, _ = statuses(ctx, best[1], best[2])
        v2, r2, _ = linear_solve(ctx, st, s, best[2], clock)
        res = ctx.residual(v2, r2)
        if res >= best[0]:
            break
        best = (res, v2, r2)
    return best


def ssn(ctx, target) -> Outcome:
    p = ctx.p
    clock = Clock()
    r = p.r_warm.copy()
    with clock("sweeps"):
        v, _ = ctx.sweep(r, SWEEPS_BETWEEN)
    sweeps, newton = SWEEPS_BETWEEN, 0
    ok = False
    while newton < NEWTON_CAP:
        with clock("check"):
            if ctx.residual(v, r) <= target:
                ok = True
                break
            st, s, _ = statuses(ctx, v, r)
        v, r, _ = linear_solve(ctx, st, s, r, clock)
        newton += 1
        with clock("check"):
            if ctx.residual(v, r) <= target:
                ok = True
                break
        r = project_cone(r, p.mu)
        with clock("sweeps"):
            v, _ = ctx.sweep(r, SWEEPS_BETWEEN)
        sweeps += SWEEPS_BETWEEN
    return Outcome(v, r, newton, float(sweeps), clock.phases, converged=ok)


METHODS = {"ssn-v": ssn}
