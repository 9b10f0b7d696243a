"""The lab's interior-point method (benchmarks/solver_lab/methods/ipm.py) on a tiny wall's cold step (7 blocks
on a ground moving at 1.3 cm/s: the lower course slides on the ground, r_t = μ r_n there).

References built here independently of the module: dense matrices from the lab's H (law.h_matrix), the
frozen-shift QP solved by scipy's SLSQP, and the lab's tight reference (the engine's NLGS to 1e-9 m/s).
"""

import numpy as np
import pytest

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import ipm as I
from benchmarks.solver_lab.outcome import Clock, Context
from masonrycli.engine import nlgs as N
from tests.solver_lab_helpers import frozen_shift_qp, tiny_cold_problem


@pytest.fixture(scope="module")
def cold():
    return tiny_cold_problem()


def _dense(ctx, ops):
    """(H_t, H_n on the dynamic dofs in the band order, supports' part of u (C, 2), M diagonal) from law.h_matrix."""
    p = ctx.p
    H = law.h_matrix(p, ctx.pack).toarray()
    dofs = (3 * ops.bodies[:, None] + np.arange(3)).ravel()
    sup = np.setdiff1d(np.arange(H.shape[1]), dofs)
    u_sup = (H[:, sup] @ p.v_free.ravel()[sup]).reshape(-1, 2)
    return H[0::2][:, dofs], H[1::2][:, dofs], u_sup, 1.0 / ctx.minv[dofs]


@pytest.mark.parametrize("linearised", [False, True])
def test_banded_newton_matrix_matches_the_dense_one(cold, linearised):
    # K = M + Aᵀ diag(d) Ã; A's rows u_n ± μ u_t; Ã adds ∂(μ|u_t|)/∂x = μ sg H_t to both rows.
    ctx = Context(cold)
    ops = I.Operators(ctx)
    ht, hn, _, m = _dense(ctx, ops)
    mu = cold.mu
    rng = np.random.default_rng(3)
    d = rng.uniform(0.1, 10.0, (cold.count, 2))
    sg = rng.integers(-1, 2, cold.count).astype(float) if linearised else None
    a_plus, a_minus = hn + mu * ht, hn - mu * ht
    slope = (mu * (sg if linearised else np.zeros(cold.count)))[:, None] * ht
    K = np.diag(m) + a_plus.T @ (d[:, :1] * (a_plus + slope)) + a_minus.T @ (d[:, 1:] * (a_minus + slope))
    rhs = rng.normal(size=ops.n)
    np.testing.assert_allclose(ops.solve(ops.factor(d, sg), rhs), np.linalg.solve(K, rhs), rtol=1e-9, atol=1e-12)


def test_frozen_shift_qp_matches_scipy(cold):
    # With s frozen the step is min ½ (x − x_free)ᵀ M (x − x_free) s.t. u_n + bias + s ± μ u_t ≥ 0: the IPM's
    # velocities must be SLSQP's (unique: strictly convex), and its impulses the QP's multipliers.
    ctx = Context(cold)
    ops = I.Operators(ctx)
    ht, hn, u_sup, m = _dense(ctx, ops)
    mu = cold.mu
    rng = np.random.default_rng(5)
    s = rng.uniform(0.0, 2e-3, cold.count)
    x_ref = frozen_shift_qp(ht, hn, u_sup, m, ops.x_free, ctx.pack[:, N.P_BIAS], mu, s)
    lam, x, z = I._start(ops, np.zeros((cold.count, 2)), ops.bias + s)
    for _ in range(60):  # to convergence; past it the barrier weights' ill-conditioning only adds noise
        x, lam, z, _ = I.iterate(ops, x, lam, z, s)
        if float((z * lam).mean()) < 1e-11:
            break
    assert float((z * lam).mean()) < 1e-11
    np.testing.assert_allclose(x, x_ref, atol=1e-7)
    # KKT of the QP: M (x − x_free) = Aᵀ λ with λ ≥ 0 — the impulses r = Eᵀλ reproduce the velocities
    A = np.vstack([hn + mu * ht, hn - mu * ht])
    np.testing.assert_allclose(m * (x - ops.x_free), A.T @ np.concatenate([lam[:, 0], lam[:, 1]]), atol=1e-9)
    assert lam.min() > 0.0


@pytest.mark.parametrize("method", ["ipm-newton", "ipm-each", "ipm-damped"])
def test_full_coulomb_law_holds_and_matches_the_reference(cold, method):
    ctx = Context(cold)
    ctx.sweep_s = ctx.accel_cost = 1.0
    out = I.METHODS[method](ctx, 1e-5)
    assert out.converged
    v = law.velocity_from_impulse(cold, ctx.H, out.r)
    np.testing.assert_allclose(out.v, v, atol=1e-12)  # v = v(r): the IPM keeps the dual residual at 0
    assert ctx.residual(v, out.r) <= 1e-5
    assert law.velocity_error(cold, v) <= 2e-4  # against the engine's NLGS to 1e-9 m/s
    # inside the cone, and the lower course slides on the ground at the reference's speed
    assert (out.r[:, 1] >= 0).all() and (np.abs(out.r[:, 0]) <= cold.mu * out.r[:, 1] + 1e-12).all()
    np.testing.assert_allclose(v[:7, 0], cold.v_ref[:7, 0], atol=2e-4)


def test_closing_sweeps_reach_the_target_from_the_loose_ipm(cold):
    ctx = Context(cold)
    ctx.sweep_s = ctx.accel_cost = 1.0
    out = I.METHODS["ipm-close"](ctx, 1e-7)  # tighter than the IPM's 1e-3: the sweeps must run
    assert out.converged and "closing sweeps" in out.detail
    v = law.velocity_from_impulse(cold, ctx.H, out.r)
    assert ctx.residual(v, out.r) <= 1e-7
    assert law.velocity_error(cold, v) <= 1e-5


def test_stops_at_the_cap_without_claiming_convergence(cold, monkeypatch):
    ctx = Context(cold)
    monkeypatch.setattr(I, "ITER_CAP", 2)
    v, r, its, rounds, res = I.run_ipm(ctx, 1e-12, 1e-12, Clock(), "newton")
    assert its == 2 and res > 1e-12
