"""Augmented Lagrangian in velocity space with a semismooth Newton inner solve (convex, line-searched).

Outer iteration k holds impulse estimates r̂ and Tresca thresholds s = μ r̂_n. Per contact, with
u = H_α v + (0, bias_α) and ρ_α = κ / W_nn,α,

    r_n(v) = max(0, r̂_n − ρ u_n),   r_t(v) = clip(r̂_t − ρ u_t, −s, s)

is minus the gradient of a convex, piecewise-quadratic Ψ_α(u). The inner problem

    min_v  E(v) = ½ |v − v_free|²_M + Σ_α Ψ_α(H_α v + b_α)      (∇E = M (v − v_free) − Hᵀ r(v))

is solved by Newton on ∇E = 0 with K = M + Hᵀ diag(ρ·active) H (symmetric positive definite; sparse
Cholesky-like factor per step, scipy's splu here) and a backtracking line search on E — global and
finite for a piecewise quadratic. Then r̂ ← r(v), s ← μ r̂_n (multiplier update + Coulomb fixed point on
the thresholds). At a fixed point r = proj(r − ρ u) with |r_t| ≤ μ r_n: exactly Signorini–Coulomb, no
penalty left (ρ only sets the speed). Stopped on the contact-law residual.

The multiplier update never moves self-equilibrated impulses (the null space of H M⁻¹, large on a
hyperstatic wall), yet the Coulomb thresholds depend on how r_n is shared between redundant contacts:
alone it stalls (measured: residual stuck at 5e-4 m/s on wall-8-typical). ``SWEEPS_BETWEEN`` engine NLGS
sweeps after each outer update redistribute the impulses; κ = 1000 was the best of 100 / 1000 tried.
The inner solve must converge: capped at 10 Newton steps instead of 30 the outer iteration diverged
(wall-8-cold: velocity error 4e18 m/s after 30 outer iterations, against 3e-4 m/s with 30).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from benchmarks.solver_lab import law
from benchmarks.solver_lab.outcome import Clock, Outcome
from masonrycli.engine import nlgs as N

KAPPA = 1000.0
SWEEPS_BETWEEN = 5
OUTER_CAP = 30
INNER_CAP = 30


def _impulse(x_t, x_n, s):
    return np.clip(x_t, -s, s), np.maximum(x_n, 0.0)


def _energy(dv_m, x_t, x_n, s, rho):
    pn = np.maximum(x_n, 0.0)
    ax = np.abs(x_t)
    ht = np.where(ax <= s, 0.5 * x_t * x_t, s * ax - 0.5 * s * s)
    return dv_m + float(((0.5 * pn * pn + ht) / rho).sum())


class _Inner:
    """The inner problem of one outer iteration: fixed r̂, thresholds s; x = the dynamic velocities."""

    def __init__(self, ops, r_hat, s):
        self.ops, self.r_hat, self.s = ops, r_hat, s

    def parts(self, x):
        o = self.ops
        ut = o.Ht @ x + o.u0[:, 0]
        un = o.Hn @ x + o.u0[:, 1]
        return self.r_hat[:, 0] - o.rho * ut, self.r_hat[:, 1] - o.rho * un

    def energy(self, x, xt, xn):
        d = x - self.ops.vf
        return _energy(0.5 * float(d @ (self.ops.m * d)), xt, xn, self.s, self.ops.rho)

    def solve(self, x, clock) -> tuple[np.ndarray, int]:
        """Newton with backtracking from x; returns (x, Newton steps)."""
        o, s = self.ops, self.s
        steps = 0
        for _ in range(INNER_CAP):
            with clock("assemble"):
                xt, xn = self.parts(x)
                rt, rn = _impulse(xt, xn, s)
                grad = o.m * (x - o.vf) - (o.Ht.T @ rt + o.Hn.T @ rn)
                if np.abs(grad).max() <= 1e-12 * max(1.0, float(np.abs(o.m * x).max())):
                    break
                at = o.rho * (np.abs(xt) < s)
                an = o.rho * (xn > 0)
                K = (sp.diags(o.m) + o.Ht.T @ sp.diags(at) @ o.Ht + o.Hn.T @ sp.diags(an) @ o.Hn).tocsc()
            with clock("factor"):
                d = spla.splu(K).solve(-grad)
            steps += 1
            with clock("line search"):
                e0 = self.energy(x, xt, xn)
                slope = float(grad @ d)
                t = 1.0
                while t > 1e-8:
                    trial = x + t * d
                    if self.energy(trial, *self.parts(trial)) <= e0 + 1e-4 * t * slope:
                        break
                    t *= 0.5
                x = x + t * d
        return x, steps


def alm_newton(ctx, target, kappa: float = KAPPA, sweeps: int = SWEEPS_BETWEEN) -> Outcome:
    p, H, pack = ctx.p, ctx.H, ctx.pack
    clock = Clock()
    with clock("setup"):
        dyn = np.flatnonzero(ctx.minv > 0)
        Hd = H[:, dyn].tocsr()
        vf = p.v_free.ravel()
        u0 = (H @ vf - Hd @ vf[dyn]).reshape(-1, 2)  # fixed support velocities enter u as a constant
        u0[:, 1] += pack[:, N.P_BIAS]
        ops = SimpleNamespace(
            Ht=Hd[0::2], Hn=Hd[1::2], m=1.0 / ctx.minv[dyn], vf=vf[dyn], u0=u0, rho=kappa / pack[:, N.P_WNN]
        )
        r = p.r_warm.copy()
        v = law.velocity_from_impulse(p, H, r)
        x = v.ravel()[dyn]
    outer = steps = 0
    ok = False
    while outer < OUTER_CAP:
        outer += 1
        inner = _Inner(ops, r, p.mu * np.maximum(r[:, 1], 0.0))
        x, k = inner.solve(x, clock)
        steps += k
        with clock("update"):
            rt, rn = _impulse(*inner.parts(x), inner.s)
            r = np.stack([rt, rn], axis=1)
        if sweeps:
            with clock("sweeps"):
                ctx.sweep(r, sweeps)
        with clock("check"):
            v = law.velocity_from_impulse(p, H, r)
            x = v.ravel()[dyn]
            if ctx.residual(v, r) <= target:
                ok = True
                break
    return Outcome(v, r, steps, float("nan"), clock.phases, converged=ok)


METHODS = {"alm-newton": alm_newton}
