"""The lab's normal sub-solve alternated with the course-slip step (benchmarks/solver_lab/methods/normal_slip.py).

The normal sub-problem (tangential impulses held) against an independent small QP on a 7-block, 2-course wall's
cold step: scipy's SLSQP on the velocity-space QP built from dense matrices of the lab's H (unique velocities:
strictly convex), and the impulse-space KKT conditions checked directly, with and without the cone bound; then
the alternation on a 7-block, 3-course wall shaken at 1 m/s (bed joints slide) against the target and the
lab's tight reference.
"""

import numpy as np
import pytest
from scipy.optimize import minimize

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import ipm as I
from benchmarks.solver_lab.methods import normal_slip as NS
from benchmarks.solver_lab.outcome import Context
from masonrycli.engine import nlgs as N
from tests.solver_lab_helpers import tiny_cold_problem


@pytest.fixture(scope="module")
def stack():
    return tiny_cold_problem()


@pytest.fixture(scope="module")
def sliding():
    return tiny_cold_problem(courses=3, name="tiny-normal-slip")


def _held(ctx, sweeps=3):
    """Impulses after a few sweeps from zero: tangentials to hold, normals to start from."""
    r = np.zeros((ctx.p.count, 2))
    ctx.sweep(r, sweeps)
    return r


@pytest.mark.parametrize("cones", [False, True])
def test_normal_solve_matches_an_independent_qp(stack, cones):
    p = stack
    ctx = Context(p)
    ops = I.Operators(ctx)
    r = _held(ctx)
    assert np.abs(r[:, 0]).max() > 0  # something is held
    rn, its = NS.normal_solve(ops, r, cones=cones)
    assert its < NS.NORMAL_CAP
    # dense pieces from the lab's H, all dofs; supports keep v_free
    H = law.h_matrix(p, ctx.pack).toarray()
    minv = law.inv_mass_diag(p)
    dyn = np.flatnonzero(minv > 0)
    sup = np.flatnonzero(minv == 0)
    ht, hn = H[0::2], H[1::2]
    low = np.abs(r[:, 0]) / p.mu if cones else np.zeros(p.count)
    # velocity space: x* = v_free + M⁻¹ (H_tᵀ r_t + H_nᵀ low); min ½ |x − x*|²_M s.t. u_n + bias ≥ 0
    star = p.v_free.ravel() + minv * (ht.T @ r[:, 0] + hn.T @ low)
    m = 1.0 / minv[dyn]
    c = hn[:, sup] @ p.v_free.ravel()[sup] + ctx.pack[:, N.P_BIAS]
    A = hn[:, dyn]
    res = minimize(
        lambda x: 0.5 * (x - star[dyn]) @ (m * (x - star[dyn])),
        star[dyn],
        jac=lambda x: m * (x - star[dyn]),
        constraints=[{"type": "ineq", "fun": lambda x: A @ x + c, "jac": lambda x: A}],
        method="SLSQP",
        options={"ftol": 1e-15, "maxiter": 500},
    )
    assert res.success
    v = law.velocity_from_impulse(p, ctx.H, np.stack([r[:, 0], rn], 1))
    scale = np.abs(res.x).max()
    np.testing.assert_allclose(v.ravel()[dyn], res.x, atol=1e-6 * scale)
    # impulse space: r_n ≥ low, w = u_n + bias ≥ 0, (r_n − low) w = 0 (W = H_n M⁻¹ H_nᵀ never formed here)
    w = hn @ v.ravel() + ctx.pack[:, N.P_BIAS]
    assert (rn >= low - 1e-9 * rn.max()).all()
    assert w.min() >= -1e-7
    assert np.abs((rn - low) * w).max() <= 1e-7 * rn.max()


def test_tangential_solve_matches_an_independent_qp(sliding):
    # Tresca with g = μ r_n held, in impulse space: min ½ r_tᵀ W_tt r_t + r_tᵀ H_t v° subject to |r_t| ≤ g
    # (W_tt = H_t M⁻¹ H_tᵀ dense from the lab's H, v° = v_free + M⁻¹ H_nᵀ r_n), by L-BFGS-B; the velocities
    # v° + M⁻¹ H_tᵀ r_t are unique (W_tt is singular: r_t is not), so they are compared
    p = sliding
    ctx = Context(p)
    ops = I.Operators(ctx)
    r = _held(ctx, 5)
    g = p.mu * r[:, 1]
    assert (g > 0).sum() > 4
    rt, its = NS.tangential_solve(ops, r)
    assert its < NS.NORMAL_CAP
    assert (np.abs(rt) <= g * (1 + 1e-12) + 1e-15).all()
    H = law.h_matrix(p, ctx.pack).toarray()
    minv = law.inv_mass_diag(p)
    ht, hn = H[0::2], H[1::2]
    v0 = p.v_free.ravel() + minv * (hn.T @ r[:, 1])
    W = ht @ (minv[:, None] * ht.T)
    q = ht @ v0
    res = minimize(
        lambda y: 0.5 * y @ W @ y + q @ y,
        np.zeros(p.count),
        jac=lambda y: W @ y + q,
        bounds=list(zip(-g, g, strict=True)),
        method="L-BFGS-B",
        options={"ftol": 1e-16, "gtol": 1e-13, "maxiter": 20000},
    )
    want = v0 + minv * (ht.T @ res.x)
    v = law.velocity_from_impulse(p, ctx.H, np.stack([rt, r[:, 1]], 1)).ravel()
    np.testing.assert_allclose(v, want, atol=1e-6 * np.abs(want).max())


def test_normal_solve_is_a_fixed_point_at_the_reference(sliding):
    # with the reference's tangentials held (cone bound on), the reference's velocities solve the normal problem
    p = sliding
    ctx = Context(p)
    rn, _ = NS.normal_solve(I.Operators(ctx), p.r_ref)
    r, v = NS.with_normals(ctx, p.r_ref, rn)
    assert law.velocity_error(p, v) < 1e-6
    np.testing.assert_array_equal(r[:, 0], p.r_ref[:, 0])  # no tangential clipped


@pytest.mark.parametrize("k, slip", [(5, "guard"), (20, "guard"), (20, "tresca")])
def test_alternation_reaches_the_target_and_the_reference(sliding, k, slip):
    p = sliding
    ctx = Context(p)
    ctx.sweep_s = 1e-6
    trace = []
    out = NS.alternate(ctx, 1e-8, k, trace, slip=slip)
    v = law.velocity_from_impulse(p, ctx.H, out.r)
    np.testing.assert_allclose(out.v, v, atol=1e-9)
    assert out.converged and ctx.residual(v, out.r) <= 1e-8
    assert law.velocity_error(p, v) < 1e-5
    assert out.iterations == len(trace) and trace[-1][0] == k * out.iterations


def test_stops_at_the_round_cap_without_claiming_convergence(sliding):
    ctx = Context(sliding)
    ctx.sweep_s = 1e-6
    out = NS.alternate(ctx, 1e-14, 0, rounds_cap=3, slip="guard")
    assert out.iterations == 3 and not out.converged
