"""The lab's truncated nonsmooth Newton method (benchmarks/solver_lab/methods/tnnmg.py), on a tiny wall's
cold step (every impulse 0: Gauss–Seidel needs hundreds of sweeps, so the Newton path runs).

Checked against quantities built here independently: the dense Delassus matrix W = H M⁻¹ Hᵀ for the
energy, its gradient and the Newton step (pseudo-inverse of W_FF), and the lab's tight reference for the
solve.
"""

import numpy as np
import pytest

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import tnnmg as T
from benchmarks.solver_lab.outcome import Clock, Context
from masonrycli.engine import nlgs as N
from tests.solver_lab_helpers import tiny_cold_problem


@pytest.fixture(scope="module")
def cold():
    return tiny_cold_problem()


def _dense(ctx):
    H = ctx.H.toarray()
    W = H @ np.diag(ctx.minv) @ H.T
    ops = T.Operators(ctx)
    return H, W, ops


def test_energy_and_gradient_match_the_dense_delassus(cold):
    ctx = Context(cold)
    p = ctx.p
    rng = np.random.default_rng(1)
    ctx.pack[:, N.P_BIAS] = rng.uniform(0.0, 1e-3, p.count)  # gaps: this step has none, give it some
    H, W, ops = _dense(ctx)
    q = H @ p.v_free.ravel()
    q[1::2] += ctx.pack[:, N.P_BIAS]  # Signorini bias on the normal rows
    r = rng.normal(size=2 * p.count) * 1e-2
    assert abs(ops.energy(r) - (0.5 * r @ W @ r + q @ r)) < 1e-9 * max(1.0, abs(ops.energy(r)))
    np.testing.assert_allclose(ops.gradient(ops.velocity(r)), W @ r + q, atol=1e-12)


def test_newton_step_matches_a_dense_pseudo_inverse_solve(cold):
    # At the reference's statuses the equalities of the free rows are consistent: the step's velocity
    # change must be the dense minimiser's, M⁻¹ H_Fᵀ pinv(W_FF)(−∇E_F) (unique, although dr is not).
    ctx = Context(cold)
    p = ctx.p
    H, W, ops = _dense(ctx)
    r0, s, rows = T.oracle_start(p, p.r_warm.ravel())
    g = ops.gradient(ops.velocity(r0))
    dr, _ = T.newton_direction(ops, rows, g, Clock(), eps=1e-6, al_cap=200, al_tol=1e-12)
    dr_dense = np.zeros_like(dr)
    dr_dense[rows] = -np.linalg.pinv(W[np.ix_(rows, rows)], rcond=1e-10) @ g[rows]
    dv, dv_dense = ctx.minv * (H.T @ dr), ctx.minv * (H.T @ dr_dense)
    assert np.abs(dv_dense).max() > 1e-2  # the step does something
    np.testing.assert_allclose(dv, dv_dense, atol=1e-7 * np.abs(dv_dense).max())


def test_oracle_step_lands_on_the_reference_velocities(cold):
    ctx = Context(cold)
    o = T.oracle_step(ctx)
    assert o["iterate"][0] > 1e-3  # the warm start is off
    assert o["step"][0] < 1e-9  # one step with the right statuses gives the reference's velocities


def test_line_search_never_raises_the_energy(cold):
    ctx = Context(cold)
    ops = T.Operators(ctx)
    r = ctx.p.r_warm.ravel().copy()
    s = ctx.p.mu * r[1::2]
    g = ops.gradient(ops.velocity(r))
    same, alpha = T.line_search(ops, r, g, s, g, Clock())  # uphill: rejected
    assert alpha == 0.0 and np.array_equal(same, r)
    down, alpha = T.line_search(ops, r, -g, s, g, Clock())  # downhill: taken, inside the box
    assert alpha > 0.0 and ops.energy(down) < ops.energy(r)
    assert (down[1::2] >= 0).all() and (np.abs(down[0::2]) <= s).all()


def test_tnnmg_reaches_the_target_with_newton_steps_and_agrees_with_the_reference(cold):
    ctx = Context(cold)
    p = ctx.p
    for name in ("tnnmg", "tnnmg-s20"):
        out = T.METHODS[name](ctx, 1e-7)
        assert out.converged, name
        assert out.iterations >= 1, name  # the Newton path ran (5 sweeps alone do not reach 1e-7 here)
        v = law.velocity_from_impulse(p, ctx.H, out.r)
        np.testing.assert_allclose(out.v, v, atol=1e-9)
        assert ctx.residual(v, out.r) <= 1e-7, name
        assert law.velocity_error(p, v) < 1e-5, name
