"""The stalled-step methods (masonrycli.engine.stalled), forced on small problems whose answer is known:
plain Gauss–Seidel's velocities (unique) and the contact law."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from masonrycli.engine import momentum, nlgs, stalled
from tests.test_engine_nlgs import _stack_problem


def _solve(problem, solver, tolerance, cap=100000):
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = problem
    count = body.shape[0]
    model = SimpleNamespace(friction=mu, tolerance=tolerance, max_iterations=cap, solver=solver)
    v, r, status = v0.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    its, res = nlgs.solve(body, pack, count, model, v, r, status)
    return v, r, its, res


def test_a_stalled_accelerated_solve_ends_converged_on_gauss_seidel_velocities(monkeypatch):
    # A momentum window of 1 sweep sends the step to stalled.py at once, and first budgets of 1 unit make it
    # go round the three methods many times (budgets 1, 2, 4, …): every resume must carry its method's
    # iterate on, and the step must end converged with v the velocity of its impulses.
    problem = _stack_problem(6)
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = problem
    v_gs, _, _, _ = _solve(problem, "nlgs", 1e-10)
    monkeypatch.setattr(momentum, "STALL_SWEEPS", 1)
    monkeypatch.setattr(stalled, "FIRST_BUDGET", 1)
    v, r, its, res = _solve(problem, "nlgs-accel", 1e-10)
    assert res <= 1e-10
    np.testing.assert_allclose(v, v_gs, atol=1e-8)
    np.testing.assert_allclose(v.ravel(), v0.ravel() + m_inv @ h @ r.ravel(), atol=1e-12)
    assert its > 1


def test_each_method_alone_finishes_the_step(monkeypatch):
    # The round-robin with one method at a time: each converges to the same velocities from its own start.
    problem = _stack_problem(6)
    v_gs, _, _, _ = _solve(problem, "nlgs", 1e-10)
    monkeypatch.setattr(momentum, "STALL_SWEEPS", 1)
    monkeypatch.setattr(stalled, "FIRST_BUDGET", 3)
    for method in stalled.METHODS:
        monkeypatch.setattr(stalled, "METHODS", (method,))
        v, r, its, res = _solve(problem, "nlgs-accel", 1e-10)
        assert res <= 1e-10, method
        np.testing.assert_allclose(v, v_gs, atol=1e-8, err_msg=method)


def test_at_the_cap_the_lowest_residual_is_kept_and_the_step_counts_unconverged(monkeypatch):
    problem = _stack_problem(10)
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = problem
    monkeypatch.setattr(momentum, "STALL_SWEEPS", 1)
    monkeypatch.setattr(stalled, "FIRST_BUDGET", 2)
    cap = 40
    v, r, its, res = _solve(problem, "nlgs-accel", 1e-14, cap=cap)
    assert its == cap and res > 1e-14
    np.testing.assert_allclose(v.ravel(), v0.ravel() + m_inv @ h @ r.ravel(), atol=1e-12)
    # the state kept is one of the methods' iterates after a sweep: impulses inside the Coulomb cone
    assert (r[:, 1] >= 0).all() and (np.abs(r[:, 0]) <= mu * r[:, 1] + 1e-15).all()
