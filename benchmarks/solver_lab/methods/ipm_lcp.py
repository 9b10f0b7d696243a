"""An interior-point method on the LCP form of the 2-D Coulomb law (no De Saxcé shift, no sign of u_t).

methods/ipm.py found that the IPM resolves the self-stress in a flat number of iterations once the shift
s = μ|u_t| is known, and that finding s (a kink at u_t = 0) is what grows. Here |u_t| is a variable: per
contact the multipliers y = (r_n, β₊, β₋, γ) ≥ 0 (β±: friction impulse along ±t, γ: the sliding speed) and
slacks w ≥ 0 with w ∘ y = 0 (Stewart–Trinkle's form, exact in 2-D where the cone has two rays):

    w₁ = u_n + bias          ⊥ r_n      Signorini on the normal velocity itself: no dilatancy
    w₂ = γ + u_t             ⊥ β₊       sliding along −t: γ = −u_t, friction along +t
    w₃ = γ − u_t             ⊥ β₋
    w₄ = μ r_n − β₊ − β₋     ⊥ γ        sliding: β₊ + β₋ = μ r_n
    M (v − v_free) = Hᵀ r,   r = (β₊ − β₋, r_n)

w is linear in (v, y) but the LCP is not monotone (the μ r_n in w₄), so this is a heuristic IPM (no
convergence guarantee). One Mehrotra iteration, v = v(y) kept exactly (dv = M⁻¹ Hᵀ E dy):

    rp = F(v, y) − w ;  D = Y W⁻¹ (4 per contact) ; J_y = ∂w/∂y, G = ∂w/∂u (4 × 2: rows n, t, −t, 0)
    dw = (I + J_y D)⁻¹ (G H dv + q),  q = rp − J_y W⁻¹ r_c       (4 × 4 per contact, batched)
    dy = −W⁻¹ r_c − D dw
    (M + Hᵀ E D (I + J_y D)⁻¹ G H) dv = −Hᵀ E (W⁻¹ r_c + D (I + J_y D)⁻¹ q)   (2 × 2 per contact, banded LU)
    predictor r_c = w ∘ y ; corrector r_c = w ∘ y + dw_a ∘ dy_a − σ μ_c, σ = (μ_aff / μ_c)³
    α = min(1, 0.995 × the largest step keeping w, y > 0)

Methods (stopped on the lab's RMS law residual ≤ target, like ipm.py; the shared Operators of ipm.py):

    ipm-lcp          the IPM alone
    ipm-lcp-close4   to 1e-4 m/s, then the engine's accelerated sweeps (as ipm-close4)
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.solver_lab.methods import ipm
from benchmarks.solver_lab.outcome import Clock, Outcome

STEP_FRACTION = 0.995


def _impulse(y):
    """r (C, 2) = (β₊ − β₋, r_n)."""
    return np.stack([y[:, 1] - y[:, 2], y[:, 0]], axis=1)


def _velocity(ops, y):
    return ops.x_free + ops.minv * (ops.HdT @ _impulse(y).ravel())


def _rows(ops, u, y):
    """F(v, y) (C, 4)."""
    mu = ops.mu
    return np.stack(
        [u[:, 1] + ops.bias, y[:, 3] + u[:, 0], y[:, 3] - u[:, 0], mu * y[:, 0] - y[:, 1] - y[:, 2]], axis=1
    )


def _jy(mu, c):
    """∂w/∂y (4 × 4), the same for every contact; returned broadcast to (C, 4, 4)."""
    j = np.zeros((4, 4))
    j[1, 3] = j[2, 3] = 1.0
    j[3] = (mu, -1.0, -1.0, 0.0)
    return np.broadcast_to(j, (c, 4, 4))


# G = ∂w/∂u (4 × 2, columns t, n) and E: r = E y (2 × 4, rows t, n)
_G = np.array([[0.0, 1.0], [1.0, 0.0], [-1.0, 0.0], [0.0, 0.0]])
_E = np.array([[0.0, 1.0, -1.0, 0.0], [1.0, 0.0, 0.0, 0.0]])


def _start(ops, r0):
    c = r0.shape[0]
    y = np.zeros((c, 4))
    y[:, 0] = np.maximum(r0[:, 1], 0.0)
    y[:, 1] = np.maximum(r0[:, 0], 0.0)
    y[:, 2] = np.maximum(-r0[:, 0], 0.0)
    x = _velocity(ops, y)
    u = ops.contact_velocity(x)
    y[:, 3] = np.abs(u[:, 0])
    w, y = ipm.interior(_rows(ops, u, y), y)
    return _velocity(ops, y), y, w


def iterate(ops, x, y, w, jy):
    m = w.size
    u = ops.contact_velocity(x)
    rp = _rows(ops, u, y) - w
    mu_c = float((w * y).sum()) / m
    d = np.minimum(y / w, ipm.D_CAP * ops.m.max(initial=1.0))
    # B = (I + J_y D)⁻¹ per contact; K's blocks E D B G
    a = np.eye(4) + jy * d[:, None, :]
    b = np.linalg.inv(a)
    dbg = np.einsum("ij,cj,cjk,kl->cil", _E, d, b, _G)  # (C, 2, 2): E D B G
    fac = ops.factor_blocks(np.concatenate([dbg[:, 0, 0], dbg[:, 0, 1], dbg[:, 1, 0], dbg[:, 1, 1]]))

    def direction(rc):
        q = rp - np.einsum("cij,cj->ci", jy, rc / w)
        bq = np.einsum("cij,cj->ci", b, q)
        rhs = -(ops.HdT @ np.einsum("ij,cj->ci", _E, rc / w + d * bq).ravel())
        dx = ops.solve(fac, rhs)
        du = ops.contact_velocity(dx) - ops.u_const
        dw = np.einsum("cij,cj->ci", b, du @ _G.T + q)
        dy = -rc / w - d * dw
        return dx, dw, dy

    _, dw_a, dy_a = direction(w * y)
    a_aff = min(1.0, ipm._max_step(w, dw_a), ipm._max_step(y, dy_a))
    mu_aff = float(((w + a_aff * dw_a) * (y + a_aff * dy_a)).sum()) / m
    sigma = (mu_aff / mu_c) ** 3 if mu_c > 0 else 0.0
    _, dw, dy = direction(w * y + dw_a * dy_a - sigma * mu_c)
    alpha = min(1.0, STEP_FRACTION * min(ipm._max_step(w, dw), ipm._max_step(y, dy)))
    y = y + alpha * dy
    w = w + alpha * dw
    return _velocity(ops, y), y, w, alpha


def run(ctx, stop_at, clock):
    """Returns (v, r, iterations, residual)."""
    p = ctx.p
    ops = ipm.operators(ctx, clock)
    jy = _jy(p.mu, p.count)
    with clock("ipm"):
        x, y, w = _start(ops, p.r_warm)
    residual = np.inf
    its = 0
    v = ops.full_velocity(p, x)
    while its < ipm.ITER_CAP:
        with clock("ipm"):
            try:
                x, y, w, _ = iterate(ops, x, y, w, jy)
            except np.linalg.LinAlgError:
                break
        its += 1
        with clock("check"):
            v = ops.full_velocity(p, x)
            residual = ctx.residual(v, _impulse(y))
            if residual <= stop_at:
                break
    return v, _impulse(y), its, residual


def plain(ctx, target) -> Outcome:
    clock = Clock()
    t0 = time.process_time()
    v, r, its, res = run(ctx, target, clock)
    cpu = time.process_time() - t0 - clock.phases.get("setup", 0.0)
    return Outcome(v, r, its, 0.0, clock.phases, converged=res <= target, cpu_s=cpu)


def closing(loose):
    def solve(ctx, target) -> Outcome:
        clock = Clock()
        t0 = time.process_time()
        v, r, its, res = run(ctx, loose, clock)
        ipm_s = time.process_time() - t0 - clock.phases.get("setup", 0.0)
        n, ok, v, sweeps_s = ipm.close(ctx, v, r, res, target, ("ipm-lcp", loose), clock)
        return Outcome(v, r, its, 0.0, clock.phases, converged=ok, cpu_s=ipm_s + sweeps_s, detail=f"{n} closing sweeps")

    return solve


METHODS = {"ipm-lcp": plain, "ipm-lcp-close4": closing(1e-4)}
