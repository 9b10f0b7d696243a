"""The lab's conjugate projected gradient (benchmarks/solver_lab/methods/cpg.py) on a tiny wall's cold step (7
blocks on a ground moving at 1.3 cm/s: the lower course slides on the ground, r_t = μ r_n there).

References built here independently of the module: the cone projections checked by their optimality conditions,
the frozen-shift problem solved by scipy's SLSQP in velocity space from dense matrices of the lab's H
(law.h_matrix), and the lab's tight reference (the engine's NLGS to 1e-9 m/s).
"""

import numpy as np
import pytest

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import cpg as G
from benchmarks.solver_lab.outcome import Clock, Context
from masonrycli.engine import nlgs as N
from tests.solver_lab_helpers import frozen_shift_qp, tiny_cold_problem


@pytest.fixture(scope="module")
def cold():
    return tiny_cold_problem()


def _metric(ops, i):
    return np.array([[ops.wtt[i], ops.wtn[i]], [ops.wtn[i], ops.wnn[i]]]) if ops.pre else np.eye(2)


@pytest.mark.parametrize("precondition", [False, True])
def test_cone_and_tangent_projections_satisfy_their_optimality_conditions(cold, precondition):
    # x̂ = Π_K(x) in the metric P iff x̂ ∈ K, x̂ᵀP(x − x̂) = 0 and eᵀP(x − x̂) ≤ 0 for both edge rays e± = (±μ, 1).
    ops = G.Operators(Context(cold), precondition)
    mu = cold.mu
    rng = np.random.default_rng(2)
    x = rng.normal(size=(cold.count, 2))
    xh = ops.project_cone(x)
    assert (xh[:, 1] >= 0).all() and (np.abs(xh[:, 0]) <= mu * xh[:, 1] + 1e-12).all()
    for i in range(cold.count):
        P, d = _metric(ops, i), x[i] - xh[i]
        assert abs(xh[i] @ P @ d) <= 1e-10 * (1 + np.linalg.norm(x[i]) ** 2)
        for e in (np.array([mu, 1.0]), np.array([-mu, 1.0])):
            assert e @ P @ d <= 1e-10
    # tangent cone on an edge r = t e₊: the half-plane d_t − μ d_n ≤ 0; its projection is P-orthogonal there
    r = np.tile([mu, 1.0], (cold.count, 1))
    y = rng.normal(size=(cold.count, 2))
    yh = ops.project_tangent(ops.faces(r), y)
    assert (yh[:, 0] - mu * yh[:, 1] <= 1e-12).all()
    inside = y[:, 0] - mu * y[:, 1] <= 0
    np.testing.assert_allclose(yh[inside], y[inside])
    for i in np.flatnonzero(~inside):
        assert abs((y[i] - yh[i]) @ _metric(ops, i) @ np.array([mu, 1.0])) <= 1e-12  # along the edge


@pytest.mark.parametrize("precondition", [False, True])
def test_frozen_shift_qp_matches_scipy(cold, precondition):
    # With s frozen the step is min ½ rᵀWr + qᵀr over the cone; in velocity space min ½ (v − v_free)ᵀM(v − v_free)
    # s.t. u_n + bias + s ± μ u_t ≥ 0, whose solution (unique: strictly convex) SLSQP finds.
    ctx = Context(cold)
    p = cold
    H = law.h_matrix(p, ctx.pack).toarray()
    dyn = np.flatnonzero(ctx.minv > 0)
    sup = np.flatnonzero(ctx.minv == 0)
    ht, hn = H[0::2][:, dyn], H[1::2][:, dyn]
    u_sup = (H[:, sup] @ p.v_free.ravel()[sup]).reshape(-1, 2)
    m = 1.0 / ctx.minv[dyn]
    mu = p.mu
    s = np.random.default_rng(5).uniform(0.0, 2e-3, p.count)
    x_ref = frozen_shift_qp(ht, hn, u_sup, m, p.v_free.ravel()[dyn], ctx.pack[:, N.P_BIAS], mu, s)
    v, r, its, _, _, _, natural = G.run_cpg(ctx, 1e-10, Clock(), precondition, monotone=True, cap=5000, s_fixed=s)
    assert natural <= 1e-10 and its < 5000
    np.testing.assert_allclose(v.ravel()[dyn], x_ref, atol=1e-7)
    assert (r[:, 1] >= 0).all() and (np.abs(r[:, 0]) <= mu * r[:, 1] + 1e-12).all()


@pytest.mark.parametrize("method", ["cpg-mono", "cpg-pre-mono", "cpg-pre"])
def test_full_coulomb_law_holds_and_matches_the_reference(cold, method):
    ctx = Context(cold)
    ctx.sweep_s = ctx.accel_cost = 1.0
    out = G.METHODS[method](ctx, 1e-5)
    assert out.converged and "matvecs" in out.detail
    v = law.velocity_from_impulse(cold, ctx.H, out.r)
    np.testing.assert_allclose(out.v, v, atol=1e-12)  # v = v(r): CPG works on the impulses
    assert ctx.residual(v, out.r) <= 1e-5
    assert law.velocity_error(cold, v) <= 2e-4  # against the engine's NLGS to 1e-9 m/s
    assert (out.r[:, 1] >= 0).all() and (np.abs(out.r[:, 0]) <= cold.mu * out.r[:, 1] + 1e-12).all()
    np.testing.assert_allclose(v[:7, 0], cold.v_ref[:7, 0], atol=2e-4)  # the lower course slides


def test_stops_at_the_cap_without_claiming_convergence(cold):
    ctx = Context(cold)
    v, r, its, rounds, restarts, matvecs, res = G.run_cpg(ctx, 1e-14, Clock(), True, monotone=True, cap=3)
    assert its == 3 and res > 1e-14
    assert matvecs >= 1 + 2 * 3  # the start's v(r), then W p and v(r) each iteration (more on restarts)
