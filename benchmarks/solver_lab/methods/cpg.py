"""Conjugate projected gradient (CPG, Renouf & Alart 2005, CMAME 194; LMGC90's other solver) on the step.

Impulse space. With the De Saxcé shift s_α = μ|u_t,α| frozen, the step is the convex quadratic programme

    min f(r) = ½ rᵀ W r + qᵀ r   over   K = Π_α {r_α : |r_t| ≤ μ r_n},
    W = H M⁻¹ Hᵀ (never formed: W p = H (M⁻¹ (Hᵀ p)), one "matvec"),  q_α = (H v_free)_α + (0, bias_α + s_α),

whose gradient is the shifted contact velocity g = ∇f = (u_t, u_n + bias + s); −g ∈ N_K(r) (g ∈ K*, g ⊥ r)
with s = μ|u_t| is exactly the contact law of DESIGN.md §2 (no dilatancy). W is singular on hyperstatic
walls (impulses are not unique, velocities are); CG needs only W p.

Metric P: the identity (LMGC90's CPG) or P = blockdiag(W_αα) (the diagonal-block preconditioner: the
gradient step is P⁻¹ g and both projections are taken in the W_αα norm, contact by contact):

    Π_K(x)      projection onto the wedge K (interior: x; else the nearer of the two edge rays, apex included)
    Π_T(r)(y)   projection onto K's tangent cone at r: everything where r is inside; K itself at the apex;
                the half-plane a·d ≤ 0, a = (±1, −μ), on a sliding edge r_t = ±μ r_n

One CPG iteration (LMGC90 / Renouf–Alart, in the form of Siconos' fc2d_cpg; g, w, p per contact):

    start   r ← Π_K(r_warm); u ← H v(r); s ← μ|u_t|; g ← (u_t, u_n + bias + s); w ← Π_T(r)(−P⁻¹ g); p ← w
    loop    if −g·p ≤ 0: p ← w                          (restart: not a descent direction)
            Wp ← W p ;  α ← (−g·p) / (p·Wp)             (exact line minimum of f along p)
            r ← Π_K(r + α p)
            u ← H v(r);  s ← μ|u_t| (each iteration, as LMGC90) or kept (frozen);  g ← (u_t, u_n + bias + s)
            stop when the lab's RMS law residual of (v(r), r) ≤ target
            w ← Π_T(r)(−P⁻¹ g);  z ← Π_T(r)(p)          (the previous direction, made feasible)
            β ← −(w·Wp) / (p·Wp);  p ← w + β z          (W-conjugate to the last direction)

Two matvecs an iteration (W p, and v(r) = v_free + M⁻¹ Hᵀ r with u = H v, which the projection forces to
recompute), one at the start. The projected step is not a descent step (on wall-8-typical f rose from −1.2 to
+2.1 J in one iteration that clipped 150 contacts); the monotone restart rule keeps f at the iteration's shift
from rising:

    if f(r⁺) > f(r):  p ← w (restart, its own line minimum); then α ← α/2, at most BACKTRACK trials (1 matvec each)

Variants:

    cpg                    identity metric, s ← μ|u_t| every iteration (LMGC90's CPG), no monotone rule
    cpg-pre                P = blockdiag(W_αα), s every iteration
    cpg-mono, cpg-pre-mono the same with the monotone restart rule
    cpg-pre-mono-frozen    De Saxcé rounds: s frozen for one CPG run on the convex QP until its natural residual
                           (RMS |W_αα (r − Π_K^{W_αα}(r − W_αα⁻¹ g))|) ≤ INNER_FRACTION × target, then
                           s ← μ|u_t| and the directions restarted
    cpg-pre-mono-oracle-s  one CPG run with s frozen at the reference's μ|u_t| (reads the answer: the cost of the
                           convex part alone)

All stopped on the lab's RMS law residual ≤ target of (v(r), r), checked every iteration; cap ITER_CAP.
``iterations``: CPG iterations; ``Outcome.detail``: matvecs, restarts (and rounds). Sweep units: the harness's
rule (CPU time over one engine sweep), numpy throughout, the check included; a compiled matvec costs about
what a sweep does (both visit each contact's two bodies once each way), so matvecs are the compiled floor.
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.solver_lab.outcome import Clock, Outcome
from masonrycli.engine import nlgs as N

ITER_CAP = 10_000
"""CPG iterations a solve (2 matvecs each: 20 000 matvecs, 5–50× what momentum's sweeps need on these steps)."""
INNER_FRACTION = 0.1
"""cpg-frozen: a round ends when the frozen QP's RMS natural residual ≤ this × target (m/s)."""
BACKTRACK = 30
"""Monotone variants: at most this many restarts / halvings of the step before a rise of f is accepted."""
EDGE = 1e-12
"""Relative tolerance for "on a cone edge" (Π_K puts points on an edge exactly up to rounding)."""


class Operators:
    """W applied matrix-free through the lab's H and M⁻¹; the per-contact blocks W_αα; the metric."""

    def __init__(self, ctx, precondition: bool):
        p, pack = ctx.p, ctx.pack
        self.H = ctx.H
        self.HT = ctx.H.T.tocsr()
        self.minv = ctx.minv
        self.v_free = p.v_free.ravel().copy()
        self.mu = p.mu
        self.bias = pack[:, N.P_BIAS].copy()
        self.wtt, self.wtn, self.wnn = pack[:, N.P_WTT].copy(), pack[:, N.P_WTN].copy(), pack[:, N.P_WNN].copy()
        self.pre = precondition
        det = self.wtt * self.wnn - self.wtn**2
        self.itt, self.itn, self.inn = self.wnn / det, -self.wtn / det, self.wtt / det
        self.u_free = (self.H @ self.v_free).reshape(-1, 2)
        self.matvecs = 0

    def velocity(self, r):
        """v(r) = v_free + M⁻¹ Hᵀ r (3B,) and u = H v (C, 2): one matvec."""
        self.matvecs += 1
        v = self.v_free + self.minv * (self.HT @ r.ravel())
        return v, (self.H @ v).reshape(-1, 2)

    def apply_w(self, p):
        self.matvecs += 1
        return (self.H @ (self.minv * (self.HT @ p.ravel()))).reshape(-1, 2)

    def energy(self, r, u, s):
        """f(r) = ½ rᵀ W r + qᵀ r at the shift s, from u = H v(r) (W r = u − u_free): no matvec."""
        return float((r * (0.5 * (u - self.u_free) + self.u_free)).sum() + ((self.bias + s) * r[:, 1]).sum())

    def gradient(self, u, s):
        g = u.copy()
        g[:, 1] += self.bias + s
        return g

    # the metric P (identity, or W_αα per contact)
    def P(self, x):
        if not self.pre:
            return x
        return np.stack([self.wtt * x[:, 0] + self.wtn * x[:, 1], self.wtn * x[:, 0] + self.wnn * x[:, 1]], axis=1)

    def P_inv(self, y):
        if not self.pre:
            return y
        return np.stack([self.itt * y[:, 0] + self.itn * y[:, 1], self.itn * y[:, 0] + self.inn * y[:, 1]], axis=1)

    def project_cone(self, x):
        """Π_K(x) in the metric P: x where inside; else the nearer of the two edge rays t e±, e± = (±μ, 1),
        t = max(0, e·Px / e·Pe) (t = 0: the apex)."""
        mu = self.mu
        inside = (x[:, 1] >= 0) & (np.abs(x[:, 0]) <= mu * x[:, 1])
        px = self.P(x)
        best = None
        best_d = None
        for sign in (1.0, -1.0):
            e = np.broadcast_to(np.array([sign * mu, 1.0]), x.shape)
            pe = self.P(e)
            t = np.maximum(0.0, (px * e).sum(1) / (pe * e).sum(1))
            cand = t[:, None] * e
            d = x - cand
            dist = (self.P(d) * d).sum(1)
            if best is None:
                best, best_d = cand, dist
            else:
                nearer = dist < best_d
                best = np.where(nearer[:, None], cand, best)
                best_d = np.where(nearer, dist, best_d)
        return np.where(inside[:, None], x, best)

    def faces(self, r):
        """(apex, edge sign) per contact: apex where r = 0, sign ±1 on the edge r_t = ±μ r_n, 0 inside."""
        mu = self.mu
        apex = r[:, 1] <= 0.0
        lim = mu * r[:, 1] * (1.0 - EDGE)
        sign = np.where(r[:, 0] >= lim, 1.0, np.where(r[:, 0] <= -lim, -1.0, 0.0))
        return apex, np.where(apex, 0.0, sign)

    def project_tangent(self, faces, y):
        """Π_T(r)(y) in the metric P: y inside; Π_K(y) at the apex; on the edge r_t = σ μ r_n the half-plane
        a·d ≤ 0, a = (σ, −μ): d = y − max(0, a·y) / (aᵀP⁻¹a) P⁻¹a."""
        apex, sign = faces
        out = y.copy()
        if apex.any():
            out[apex] = self.project_cone(y)[apex]
        edge = sign != 0.0
        if edge.any():
            a = np.stack([sign, -self.mu * np.ones_like(sign)], axis=1)
            pa = self.P_inv(a)
            ay = (a * y).sum(1)
            t = np.where(edge & (ay > 0.0), ay / (a * pa).sum(1), 0.0)
            out -= t[:, None] * pa
        return out

    def natural_residual(self, r, g):
        """m/s: RMS over contacts of |W_αα (r − Π_K^{W_αα}(r − W_αα⁻¹ g))|, zero exactly at the frozen QP's
        solution (whatever the metric P)."""
        pre, self.pre = self.pre, True
        try:
            d = r - self.project_cone(r - self.P_inv(g))
            e = self.P(d)
        finally:
            self.pre = pre
        return float(np.sqrt((e * e).sum(1).mean())) if e.size else 0.0


def shift(ops, u):
    return ops.mu * np.abs(u[:, 0])


def run_cpg(ctx, target, clock, precondition=False, mode="each", monotone=False, cap=None, s_fixed=None):
    """CPG on the step (module doc). ``mode``: "each" (s ← μ|u_t| every iteration), "frozen" (De Saxcé
    rounds) or "oracle" (s frozen at the reference's); ``monotone``: the restart rule that keeps f(r) at the
    iteration's shift from growing. ``s_fixed``: the convex QP at this shift, stopped on its natural residual
    (for tests). Returns (v (B, 3), r, iterations, rounds, restarts, matvecs, residual)."""
    p = ctx.p
    cap = ITER_CAP if cap is None else cap
    with clock("setup"):
        ops = Operators(ctx, precondition)
    with clock("cpg"):
        r = ops.project_cone(p.r_warm.astype(float))
        v, u = ops.velocity(r)
        s = shift(ops, (ops.H @ p.v_ref.ravel()).reshape(-1, 2) if mode == "oracle" else u)
        if s_fixed is not None:
            mode, s = "fixed", s_fixed
        g = ops.gradient(u, s)
        w = d = ops.project_tangent(ops.faces(r), -ops.P_inv(g))
        steepest = True
    its = restarts = 0
    rounds = 1

    def measure():
        return ops.natural_residual(r, g) if mode == "fixed" else ctx.residual(v.reshape(-1, 3), r)

    with clock("check"):
        residual = measure()
    while residual > target and its < cap:
        with clock("cpg"):
            gd = -float((g * d).sum())
            if gd <= 0.0 and not steepest:  # the conjugate direction does not descend: restart
                d, steepest = w, True
                gd = -float((g * d).sum())
                restarts += 1
            dwd = 0.0
            if gd > 0.0:
                wd = ops.apply_w(d)
                dwd = float((d * wd).sum())
            solved = gd <= 0.0 or dwd <= 0.0  # the frozen QP is solved, or W d = 0 (a self-stress direction)
            if not solved:
                alpha = gd / dwd
                r1 = ops.project_cone(r + alpha * d)
                v1, u1 = ops.velocity(r1)
                if monotone:
                    f0 = ops.energy(r, u, s)
                    for _ in range(BACKTRACK):
                        if ops.energy(r1, u1, s) <= f0:
                            break
                        if not steepest:  # restart on the projected gradient, its own line minimum
                            d, steepest = w, True
                            gd = -float((g * d).sum())
                            wd = ops.apply_w(d)
                            dwd = float((d * wd).sum())
                            alpha = gd / dwd
                            restarts += 1
                        else:  # projected backtracking along it
                            alpha *= 0.5
                        r1 = ops.project_cone(r + alpha * d)
                        v1, u1 = ops.velocity(r1)
                r, v, u = r1, v1, u1
                if mode == "each":
                    s = shift(ops, u)
                g = ops.gradient(u, s)
        its += 1  # a round that cannot move is counted too, so that it still ends at the cap
        if solved:
            if mode != "frozen":
                break
            with clock("cpg"):  # next De Saxcé round
                rounds += 1
                s = shift(ops, u)
                g = ops.gradient(u, s)
                w = d = ops.project_tangent(ops.faces(r), -ops.P_inv(g))
                steepest = True
            continue
        with clock("check"):
            residual = measure()
            if residual <= target:
                break
            new_round = mode == "frozen" and ops.natural_residual(r, g) <= INNER_FRACTION * target
        with clock("cpg"):
            if new_round:  # the shift of this iterate, directions restarted
                rounds += 1
                s = shift(ops, u)
                g = ops.gradient(u, s)
            faces = ops.faces(r)
            w = ops.project_tangent(faces, -ops.P_inv(g))
            if new_round:
                d, steepest = w, True
            else:
                z = ops.project_tangent(faces, d)
                d = w - float((w * wd).sum()) / dwd * z
                steepest = False
    return v.reshape(-1, 3), r, its, rounds, restarts, ops.matvecs, residual


def _method(precondition: bool, mode: str, monotone: bool = False):
    def solve(ctx, target) -> Outcome:
        clock = Clock()
        t0 = time.process_time()
        v, r, its, rounds, restarts, matvecs, res = run_cpg(ctx, target, clock, precondition, mode, monotone)
        cpu = time.process_time() - t0 - clock.phases.get("setup", 0.0)  # W's operators exist in the engine
        detail = f"{matvecs} matvecs, {restarts} restarts" + (f", {rounds} rounds" if mode == "frozen" else "")
        return Outcome(v, r, its, 0.0, clock.phases, converged=res <= target, cpu_s=cpu, detail=detail)

    return solve


METHODS = {
    "cpg": _method(False, "each"),
    "cpg-pre": _method(True, "each"),
    "cpg-mono": _method(False, "each", monotone=True),
    "cpg-pre-mono": _method(True, "each", monotone=True),
    "cpg-pre-mono-frozen": _method(True, "frozen", monotone=True),
    "cpg-pre-mono-oracle-s": _method(True, "oracle", monotone=True),
}
