"""The friction-shift variants of the lab's interior-point method (benchmarks/solver_lab/methods/ipm_shift.py)
on a tiny wall's cold step (7 blocks on a ground moving at 1.3 cm/s: the lower course slides on the ground).

Reference: the lab's tight solve of the step (the engine's NLGS to a contact-law residual ≤ 1e-9 m/s,
built independently of the IPM), and the law itself (law.law_residual, the cone).
"""

import numpy as np
import pytest

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import ipm_shift as S
from benchmarks.solver_lab.outcome import Clock, Context
from tests.solver_lab_helpers import tiny_cold_problem


@pytest.fixture(scope="module")
def cold():
    return tiny_cold_problem()


def _context(problem):
    ctx = Context(problem)
    ctx.sweep_s = ctx.accel_cost = 1.0
    return ctx


def _check_against_reference(p, ctx, out, target, tolerance):
    assert out.converged
    v = law.velocity_from_impulse(p, ctx.H, out.r)
    np.testing.assert_allclose(out.v, v, atol=1e-12)  # v = v(r)
    assert ctx.residual(v, out.r) <= target
    assert law.velocity_error(p, v) <= tolerance
    assert (out.r[:, 1] >= 0).all() and (np.abs(out.r[:, 0]) <= p.mu * out.r[:, 1] + 1e-12).all()
    np.testing.assert_allclose(v[:7, 0], p.v_ref[:7, 0], atol=tolerance)  # the lower course's sliding


@pytest.mark.parametrize("method", ["ipm-status", "ipm-status-oracle"])
def test_status_shift_solves_the_step(cold, method):
    ctx = _context(cold)
    _check_against_reference(cold, ctx, S.METHODS[method](ctx, 1e-5), 1e-5, 2e-4)


@pytest.mark.parametrize("method", ["ipm-pred", "ipm-pred-close4"])
def test_predicted_shift_then_closing_sweeps_reach_a_tight_target(cold, method, monkeypatch):
    monkeypatch.setattr(S, "PREDICT_SWEEPS", 2)  # 100 sweeps solve this small step alone
    ctx = _context(cold)
    out = S.METHODS[method](ctx, 1e-7)  # tighter than the IPM stops at: the sweeps must finish it
    assert "closing sweeps" in out.detail
    _check_against_reference(cold, ctx, out, 1e-7, 1e-5)


def test_status_shift_is_zero_when_sticking_and_mu_ut_when_sliding_the_right_way(cold):
    ops = S.ipm.Operators(_context(cold))
    u = np.zeros((cold.count, 2))
    u[:, 0] = np.linspace(-1e-3, 1e-3, cold.count)
    status = np.sign(u[:, 0])
    status[::3] = 0.0
    s, sg = S.shift(ops, u, status)
    np.testing.assert_allclose(s, np.where(status != 0, cold.mu * np.abs(u[:, 0]), 0.0))
    assert sg is status
    assert S.shift(ops, u, np.zeros(cold.count))[1] is None  # no sliding contact: the symmetric (Cholesky) K


def test_frozen_mode_is_one_ipm_at_the_starting_shift(cold):
    ctx = _context(cold)
    lam = S.predict(ctx, Clock())
    v, r, its, rounds, res = S.ipm.run_ipm(ctx, 1e-5, 1e-12, Clock(), "frozen", lam_start=lam)
    assert rounds == 1 and its < S.ipm.ITER_CAP
