"""The contact law and the accuracy measures of the lab, in numpy (independent of the engine's kernels).

Notation (DESIGN.md §2): u = Hᵀ v per contact in its frame (t, n), v = v_free + M⁻¹ H r. H is built
here as a sparse (2C × 3B) matrix whose row 2α is the tangential and row 2α+1 the normal relative
velocity of contact α (body b minus body a at the contact point).

Contact-law residual, m/s. For each contact take the velocity it would have without its own impulse,
u_free = u − W_αα r_α, solve the 2×2 local problem exactly (open / stick / slide ±, as the engine does),
and measure how far the velocity would move: |W_αα (r*_α − r_α)|. It is zero exactly when every contact
satisfies Signorini + Coulomb with the given velocities — no regularisation, no dilatancy — and it is
what one more Gauss–Seidel visit of that contact would change. The harness reports its root mean square
over the contacts (the quantity of the engine's stopping test, there taken during the sweep) and its
largest value.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from masonrycli.engine import nlgs as N


def h_matrix(problem, pack) -> sp.csr_matrix:
    """H (2C × 3B): u = H v."""
    c, b = problem.count, problem.q_m.shape[0]
    a_, b_ = problem.body[:, 0].astype(np.int64), problem.body[:, 1].astype(np.int64)
    nx, ny = pack[:, N.P_NX], pack[:, N.P_NY]
    rows, cols, vals = [], [], []
    for row_off, cx, cy, ca, cb in (
        (0, ny, -nx, pack[:, N.P_TA], pack[:, N.P_TB]),
        (1, nx, ny, pack[:, N.P_NA], pack[:, N.P_NB]),
    ):
        r = 2 * np.arange(c) + row_off
        for body, sign, arm in ((b_, 1.0, cb), (a_, -1.0, ca)):
            rows += [r, r, r]
            cols += [3 * body, 3 * body + 1, 3 * body + 2]
            vals += [sign * cx, sign * cy, sign * arm]
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(2 * c, 3 * b))


def inv_mass_diag(problem) -> np.ndarray:
    """(3B,) diagonal of M⁻¹ (0 for supports)."""
    return np.stack([problem.inv_mass, problem.inv_mass, problem.inv_inertia], axis=1).ravel()


def velocity_from_impulse(problem, H, r) -> np.ndarray:
    """v = v_free + M⁻¹ Hᵀ r, (B, 3)."""
    return problem.v_free + (inv_mass_diag(problem) * (H.T @ r.ravel())).reshape(-1, 3)


def local_solve(ut, un, pack, mu):
    """Vectorised exact 2×2 solve (same enumeration as the engine's ``_local_solve``): (r_t, r_n)."""
    bias = pack[:, N.P_BIAS]
    target = -bias - un
    rt = np.zeros_like(ut)
    rn = np.zeros_like(un)
    done = un + bias >= 0.0  # open
    st_t = -pack[:, N.P_ITT] * ut + pack[:, N.P_ITN] * target
    st_n = -pack[:, N.P_ITN] * ut + pack[:, N.P_INN] * target
    stick = ~done & (pack[:, N.P_INN] > 0) & (st_n >= 0) & (np.abs(st_t) <= mu * st_n)
    rt[stick], rn[stick] = st_t[stick], st_n[stick]
    done |= stick
    s0 = np.where(ut >= 0.0, 1.0, -1.0)
    for s in (s0, -s0):
        inv = np.where(s > 0, pack[:, N.P_ISP], pack[:, N.P_ISM])
        cn = target * inv
        ct = -s * mu * cn
        slip = ut + pack[:, N.P_WTT] * ct + pack[:, N.P_WTN] * cn
        ok = ~done & (inv > 0) & (s * slip >= 0)
        rt[ok], rn[ok] = ct[ok], cn[ok]
        done |= ok
    rest = ~done  # unreachable for a positive definite W (as in the engine)
    rn[rest] = target[rest] / pack[rest, N.P_WNN]
    rt[rest] = np.clip(-ut[rest] / pack[rest, N.P_WTT], -mu * rn[rest], mu * rn[rest])
    return rt, rn


def law_residual(problem, pack, H, v, r) -> np.ndarray:
    """(C,) m/s: |W_αα (r*_α − r_α)| for the pair (v, r); see the module docstring."""
    u = (H @ v.ravel()).reshape(-1, 2)
    wtt, wtn, wnn = pack[:, N.P_WTT], pack[:, N.P_WTN], pack[:, N.P_WNN]
    ut = u[:, 0] - (wtt * r[:, 0] + wtn * r[:, 1])
    un = u[:, 1] - (wtn * r[:, 0] + wnn * r[:, 1])
    rt, rn = local_solve(ut, un, pack, problem.mu)
    dt_, dn = rt - r[:, 0], rn - r[:, 1]
    return np.hypot(wtt * dt_ + wtn * dn, wtn * dt_ + wnn * dn)


def velocity_error(problem, v) -> float:
    """m/s: largest difference from the reference of any block point (|Δv| + |Δω|·radius)."""
    d = v - problem.v_ref
    n = problem.inv_mass > 0
    return float((np.hypot(d[n, 0], d[n, 1]) + np.abs(d[n, 2]) * problem.radius[n]).max(initial=0.0))


def velocity_scale(problem) -> float:
    """m/s: the largest block point speed of the reference (to read velocity errors against)."""
    v = problem.v_ref
    n = problem.inv_mass > 0
    return float((np.hypot(v[n, 0], v[n, 1]) + np.abs(v[n, 2]) * problem.radius[n]).max(initial=0.0))
