"""Two ways of finding the friction shift s = μ|u_t| for the interior-point method of methods/ipm.py.

(a) Statuses.
methods/ipm.py found that with s = μ|u_t| known the IPM solves the step in a number of iterations that
hardly grows with height, and that finding s is what grows. At the answer s is simple once each contact's
status is known: a sticking contact has u_t = 0, so s = 0 (a constant: no kink), and a contact sliding in
the direction sg = ±1 has s = μ sg u_t (linear in the velocities: its linearisation in the Newton matrix is
exact, LU as ipm-newton). Here each contact carries a status c ∈ {0, +1, −1} and the shift is

    s_α = 0            where c_α = 0         (stick: the rows u_n + bias ± μ u_t ≥ 0 are the cone itself)
    s_α = μ c_α u_t,α  where c_α = ±1        (slide: linearised, ∂s = μ c ∂u_t — exact, not a kink)

so for fixed statuses the step is the frozen-s problem at the right shift if the statuses are right. The
statuses are the only combinatorial guess, and they settle: each iteration a candidate status is read from
the iterate (ipm.slip_sign: ±1 where 2μ|u_t| exceeds SLIP_RATIO × the contact's smaller slack, else 0), and
a contact takes its candidate only after the candidate has been the same for SETTLE consecutive iterations
(a contact's status is kept while it is undecided; no restart: the changed shift only enters the primal
residual, which the infeasible IPM absorbs).

    start: λ from the starting impulses; c from the starting velocities (±1 where |u_t| > SLIDE_SPEED)
    loop:  u = H x ; s, sg from c (above) ; (x, λ, z) ← ipm.iterate(x, λ, z, s, sg)
           stop when the lab's law residual of (v(r), r) ≤ target
           cand = slip_sign(u, z) ; age = age + 1 where cand = previous cand, else 1
           c ← cand where age ≥ SETTLE

    ipm-status          impulses and statuses from the warm start (its velocities: the previous step's sliding)
    ipm-status-oracle   statuses from the reference's velocities, never changed (reads the answer: the cost
                        of the IPM once the statuses are known), impulses from the warm start

(b) A predictor. PREDICT_SWEEPS of the engine's accelerated sweeps ("nlgs-accel" kernel) from the warm
start; s frozen at μ|u_t| of their velocities; one IPM on that convex QP (ipm.run_ipm "frozen", stopped
when its own primal and complementarity residuals are ≤ 0.1 × target); then the engine's accelerated
sweeps from its impulses to the target (ipm.closing; the De Saxcé rounds after it are ipm.py's, which
oscillate):

    ipm-pred            predictor, frozen-s IPM, closing sweeps
    ipm-pred-close4     predictor, then ipm-newton (s linearised, updated) to 1e-4 m/s, closing sweeps

``iterations``: IPM iterations; ``Outcome.detail``: status changes ("rounds" slot of ipm._outcome) and
closing sweeps; the predictor's sweeps are in the CPU time (sweep units), not in the counts.
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.solver_lab.methods import ipm
from benchmarks.solver_lab.outcome import Clock

SETTLE = 3
"""Consecutive iterations a contact's candidate status must hold before the contact takes it."""
SLIDE_SPEED = 1e-5
"""m/s: a contact slides at the start where its starting |u_t| exceeds this (the lab's law-residual target)."""
PREDICT_SWEEPS = 100
"""(b): engine accelerated sweeps before the IPM."""


def rays(r, mu):
    """λ (C, 2) ≥ 0 on the cone's rays from impulses r (clipped at 0 outside the cone)."""
    return np.maximum(np.stack([(r[:, 1] + r[:, 0] / mu) / 2, (r[:, 1] - r[:, 0] / mu) / 2], axis=1), 0.0)


def predict(ctx, clock):
    """(b): λ of PREDICT_SWEEPS engine accelerated sweeps from the warm start (timed)."""
    with clock("predict"):
        r = ctx.p.r_warm.copy()
        ctx.sweep(r, PREDICT_SWEEPS, "nlgs-accel")
    return rays(r, ctx.p.mu)


def shift(ops, u, status):
    """(s, sg): s = μ c u_t (0 where c = 0), linearised where c ≠ 0 (None: no sliding contact, Cholesky)."""
    s = ops.mu * status * u[:, 0]
    return s, (status if status.any() else None)


def run_status(ctx, target, stop_at, clock, start="warm", settle=SETTLE):
    """The status-shift IPM (module doc). ``start``: "warm" or "oracle" (statuses fixed).
    Returns (v, r, iterations, status changes, residual) like ipm.run_ipm."""
    p = ctx.p
    ops = ipm.operators(ctx, clock)
    mu = p.mu
    with clock("ipm"):
        lam0 = rays(p.r_warm, mu)
        if start == "oracle":
            x0 = p.v_ref.ravel()[ipm.Operators._dofs(ops.bodies)]
            settle = ipm.ITER_CAP + 1
        else:
            x0 = ops.velocity(lam0)
        ut = ops.contact_velocity(x0)[:, 0]
        status = np.where(np.abs(ut) > SLIDE_SPEED, np.sign(ut), 0.0)
        s0 = shift(ops, ops.contact_velocity(ops.velocity(lam0)), status)[0]
        lam, x, z = ipm._start(ops, lam0, ops.bias + s0)
        cand = status.copy()
        age = np.zeros(p.count, dtype=np.int64)
    its = changes = 0
    residual = np.inf
    while its < ipm.ITER_CAP:
        with clock("ipm"):
            s, sg = shift(ops, ops.contact_velocity(x), status)
            try:
                x, lam, z = ipm.guarded_iterate(ops, x, lam, z, s, sg)  # as ipm-newton
            except np.linalg.LinAlgError:
                break
        its += 1
        with clock("check"):
            residual = ctx.residual(ops.full_velocity(p, x), ops.impulse(lam))
        if residual <= stop_at:
            break
        with clock("ipm"):
            new = ipm.slip_sign(ops, ops.contact_velocity(x), z)
            age = np.where(new == cand, age + 1, 1)
            cand = new
            move = (age >= settle) & (cand != status)
            changes += int(move.sum())
            status = np.where(move, cand, status)
    v = ops.full_velocity(p, x)
    return v, ops.impulse(lam), its, changes, residual


def _plain(start: str, settle: int = SETTLE):
    def solve(ctx, target):
        clock = Clock()
        t0 = time.process_time()
        v, r, its, changes, res = run_status(ctx, target, target, clock, start, settle)
        out = ipm._outcome(clock, v, r, its, changes, res, target, time.process_time() - t0)
        out.detail = out.detail.replace("rounds", "status changes")
        return out

    return solve


METHODS = {
    "ipm-status": _plain("warm"),
    "ipm-status-oracle": _plain("oracle"),
    "ipm-pred": ipm.closing(1e-5, "frozen", predict),
    "ipm-pred-close4": ipm.closing(1e-4, "newton", predict),
}
