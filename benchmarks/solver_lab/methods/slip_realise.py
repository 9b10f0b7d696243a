"""Turning the course-slip coarse step (slip.py) into impulses: three realisations, measured against each other.

The coarse step of slip.py gives each course c a horizontal velocity change δu_c and each bed joint k a new
friction total per class. The fine solver (the engine's Gauss–Seidel) continues from impulses r, with
v = v_free + M⁻¹ Hᵀ r, so the step must be handed over as Δr with (v, r) kept consistent:

    tangential  the joints' friction totals spread over their contacts (spread: each group's change shared in
                proportion to each contact's room in its direction, so every contact stays in its cone).
                Each course's x-momentum changes by m_c δu_c; every block also spins, as a bed friction acts
                off its centroid.
    balance     tangential, then bed-joint normal impulses of least norm that cancel the vertical force and
                the moment the spread puts on every block: Δn = G λ, (Gᵀ G + reg) λ = −(Hᵀ Δr_t)_(y, ω), G the
                closed joint contacts' normal rows on the blocks' (y, ω); r_n clipped at 0 and the spread
                redone on the new normals, BALANCE_PASSES times.
    min-norm    Δr of least norm with M⁻¹ Hᵀ Δr = P δu (every block of course c: (δu_c, 0, 0)) over the touching
                contacts (r_n > 0 or no gap): Δr = A λ, (A Aᵀ + reg) λ = M P δu, A the free directions' columns
                of Hᵀ; a contact sliding in a bed joint moves along its cone's edge (Δr_t = σ μ Δr_n). Up to
                MIN_NORM_ROUNDS solves: a contact pulled into tension is fixed at r = 0, one pushed out of its
                cone is tied to the edge it crossed (Δr_t = σ μ (r_n + Δr_n) − r_t), and the rest solved again
                (an active-set approximation of the least-norm problem with the cones); then r + Δr clipped
                back into the cones.

The regularisation reg (BALANCE_REG relative to each diagonal entry) matters for min-norm: measured on
wall-16-cold and wall-32-cold after 20 and 200 sweeps (JOURNAL, "nlgs-slip"), 1e-9 leaves blocks whose free
contacts were all fixed nearly singular (Δr up to 167 N·s, the step's velocity error 1e-1 m/s), 1e-2 damps the
step to nothing, 1e-4 realises the translation within 10–40 % of its own error.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from masonrycli.engine import nlgs as N

BALANCE_REG = 1e-4
"""Tikhonov weight, relative to each diagonal entry, of the realisations' normal equations."""
MIN_NORM_ROUNDS = 6
"""Least-norm solves a coarse step of the "min-norm" realisation."""
BALANCE_PASSES = 2
"""Balance solves a coarse step of the "balance" realisation (each after the spread on the last normals)."""


def _factor_solve(K, rhs) -> np.ndarray:
    d = K.diagonal()
    K = K + sp.diags(np.maximum(BALANCE_REG * d, BALANCE_REG * 1e-6 * float(d.max(initial=1.0))))
    return spla.splu(K.tocsc(), permc_spec="COLAMD").solve(rhs)


def spread(lam_c, x, idx, target) -> np.ndarray:
    """x moved so that each group's sum (groups ``idx``) is ``target``: each group's change shared in proportion
    to each contact's room in its direction (λ_α − x_α or λ_α + x_α), so every |x_α| ≤ λ_α stays."""
    cur = np.bincount(idx, x, target.size)
    delta = target - cur
    d = delta[idx]
    room = np.maximum(np.where(d > 0, lam_c - x, lam_c + x), 0.0)
    total = np.bincount(idx, room, target.size)
    frac = np.minimum(np.abs(delta) / np.where(total > 0, total, np.inf), 1.0)
    return x + np.sign(d) * frac[idx] * room


def spread_joints(ctx, joint, tau, r, lam_c, x, idx, target, balance: bool) -> np.ndarray:
    """Δr (C, 2) of the "tangential" (``balance`` False) or "balance" realisation (module doc). ``joint``, ``tau``:
    slip.Chain's; ``lam_c``, ``x``: each contact's friction bound and x-impulse (slip.State); ``idx``: each joint
    contact's group (joint × class), ``target``: each group's new x-impulse total."""
    inj = joint >= 0
    rows = np.flatnonzero(inj)
    x_new = spread(lam_c[inj], x[inj], idx, target)
    dr = np.zeros_like(r)
    dr[inj, 0] = (x_new - x[inj]) / tau[inj]
    for _ in range(BALANCE_PASSES if balance else 0):
        dn = balance_normals(ctx, joint, r, dr)
        rn = np.maximum(r[inj, 1] + dn[inj], 0.0)
        lam = ctx.p.mu * rn * np.abs(tau[inj])
        lam_grp = np.bincount(idx, lam, target.size)
        x_new = spread(lam, np.clip(x[inj], -lam, lam), idx, np.clip(target, -lam_grp, lam_grp))
        dr[rows, 0] = (x_new - x[inj]) / tau[inj]
        dr[rows, 1] = rn - r[inj, 1]
    return dr


def balance_normals(ctx, joint, r, dr) -> np.ndarray:
    """(C,) Δn on the closed joint contacts cancelling the vertical force and the moment that the tangential part
    of dr puts on every block (module doc, "balance")."""
    p = ctx.p
    rows = np.flatnonzero((joint >= 0) & (r[:, 1] > 0.0))
    dyn = np.flatnonzero(p.inv_mass > 0)
    cols = np.stack([3 * dyn + 1, 3 * dyn + 2], axis=1).ravel()
    G = ctx.H[2 * rows + 1][:, cols].tocsc()
    drt = np.zeros(2 * p.count)
    drt[0::2] = dr[:, 0]
    lam = _factor_solve((G.T @ G).tocsc(), -(ctx.H.T @ drt)[cols])
    out = np.zeros(p.count)
    out[rows] = G @ lam
    return out


def min_norm(ctx, course, joint, r, sliding, du, raw: list | None = None, dv=None) -> np.ndarray:
    """Δr (C, 2) of the "min-norm" realisation of the courses' translation ``du`` (module doc). ``course`` (B,),
    ``joint`` (C,): slip.Chain's; ``sliding`` (C,): the joint contacts at their friction limit (slip.State's
    classes 0 and 2). ``raw`` (a list): gets the least-norm Δr before the final clip, for the diagnostic.
    ``dv`` (B, 3): realise this velocity change instead (the oracle diagnostic of slip.oracle_rounds)."""
    p = ctx.p
    touching = (r[:, 1] > 0.0) | (ctx.pack[:, N.P_BIAS] <= 0.0)
    edge = touching & sliding & (joint >= 0)  # moved along the cone's edge: Δr_t = σ μ (r_n + Δr_n) − r_t
    sigma = np.sign(r[:, 0])
    Ht = ctx.H.T.tocsc()
    dyn = np.flatnonzero(p.inv_mass > 0)
    keep = np.stack([3 * dyn, 3 * dyn + 1, 3 * dyn + 2], axis=1).ravel()
    f = np.zeros((p.inv_mass.size, 3))
    if dv is None:
        s = course >= 0
        f[s, 0] = du[course[s]] / p.inv_mass[s]
    else:
        f[dyn] = dv[dyn] / np.stack([p.inv_mass, p.inv_mass, p.inv_inertia], axis=1)[dyn]
    f = f.ravel()
    fixed = np.zeros(p.count, bool)
    dr = np.zeros_like(r)
    for _ in range(MIN_NORM_ROUNDS):
        free = np.flatnonzero(touching & ~edge & ~fixed)
        tied = np.flatnonzero(edge & ~fixed)
        dr = np.zeros_like(r)
        dr[fixed] = -r[fixed]
        dr[tied, 0] = sigma[tied] * p.mu * r[tied, 1] - r[tied, 0]
        tied_col = Ht[:, 2 * tied + 1] + Ht[:, 2 * tied] @ sp.diags(sigma[tied] * p.mu)
        A = sp.hstack([Ht[:, 2 * free], Ht[:, 2 * free + 1], tied_col]).tocsr()[keep]
        x = A.T @ _factor_solve((A @ A.T).tocsc(), (f - Ht @ dr.ravel())[keep])
        nf = free.size
        dr[free, 0] = x[:nf]
        dr[free, 1] = x[nf : 2 * nf]
        dr[tied, 1] = x[2 * nf :]
        dr[tied, 0] += sigma[tied] * p.mu * x[2 * nf :]
        new = r + dr
        pulled = touching & ~fixed & (new[:, 1] < 0.0)
        over = touching & ~fixed & ~edge & ~pulled & (np.abs(new[:, 0]) > p.mu * new[:, 1])
        if not (pulled.any() or over.any()):
            break
        fixed |= pulled
        sigma = np.where(over, np.sign(new[:, 0]), sigma)
        edge |= over
    if raw is not None:
        raw.append(dr.copy())
    new = r + dr
    rn = np.maximum(new[:, 1], 0.0)
    lim = p.mu * rn
    rt = np.where(edge, sigma * lim, np.clip(new[:, 0], -lim, lim))
    return np.stack([rt, rn], axis=1) - r
