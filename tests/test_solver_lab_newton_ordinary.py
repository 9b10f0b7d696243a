"""The lab's Newton-type first stages (benchmarks/solver_lab/newton_ordinary.py) on the small problems of
tests/test_engine_nlgs.py: its H against the dense one, its smallest impulse change against a dense
pseudo-inverse, and the status piece's F vanishing at a Gauss–Seidel solution and after its own Newton step."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks.solver_lab import newton_ordinary as no
from masonrycli.engine import newton, nlgs
from tests.test_engine_nlgs import _random_problem, _stack_problem


def _step(tmp_path, problem):
    body, pack, h, m_inv, _, v0, r0, mu, _ = problem
    path = tmp_path / "step-0001.npz"
    np.savez(path, step=1, sweeps=0, stalled=False, body=body, pack=pack, v_free=v0, r_warm=r0, mu=mu)
    return no.Step(path), h, m_inv


@pytest.mark.parametrize("problem", [_random_problem(5), _stack_problem(6)], ids=["random", "stack"])
def test_rows_are_the_dense_h_and_inverse_masses(tmp_path, problem):
    s, h, m_inv = _step(tmp_path, problem)
    hs, minv = s.rows()
    np.testing.assert_allclose(hs.toarray(), h, atol=1e-15)
    np.testing.assert_allclose(minv, np.diag(m_inv))


def test_min_norm_change_is_the_weighted_pseudo_inverse_solution(tmp_path):
    # A column of 6 blocks: 12 contacts, 24 impulse rows on 18 dofs (hyperstatic, like the walls).
    s, h, m_inv = _step(tmp_path, _stack_problem(6))
    rng = np.random.default_rng(0)
    dv = rng.normal(scale=0.01, size=s.v_free.shape)
    dv[-1] = 0.0  # the support
    dr = no.min_norm_change(s, dv).ravel()
    dyn = np.diag(m_inv) > 0
    target = dv.ravel()[dyn] / np.diag(m_inv)[dyn]
    np.testing.assert_allclose(h[dyn] @ dr, target, atol=1e-12)
    # argmin |W^{1/2}⁻¹ dr| subject to h dr = M dv: dr = W^{1/2} pinv(h W^{1/2}) M dv (W: diagonal blocks' W)
    root = np.sqrt(np.stack([1 / s.pack[:, nlgs.P_WTT], 1 / s.pack[:, nlgs.P_WNN]], 1).ravel())
    ref = root * (np.linalg.pinv(h[dyn] * root) @ target)
    np.testing.assert_allclose(dr, ref, atol=1e-12 * np.abs(ref).max())


def test_status_piece_vanishes_at_the_solution_and_its_newton_step_solves_the_piece(tmp_path):
    s, _, _ = _step(tmp_path, _stack_problem(6))
    v, r, status = s.v_free.copy(), s.r_warm.copy(), np.zeros(s.count, np.int8)
    _, res = nlgs._nlgs(s.body, s.pack, s.count, s.mu, 1e-14, 200_000, v, r, status)
    assert res <= 1e-14
    jac = no._piece(s, status, r)
    assert np.abs(no._piece_value(s, jac, r)).max() < 1e-12
    # the piece is linear: one Newton step with a small shift lands on it from anywhere, to O(λ) (the piece is
    # singular, 24 rows on 18 dofs: a shift of 1e-12 already loses digits to 1/λ, as on the walls)
    rng = np.random.default_rng(1)
    r1 = r + rng.normal(scale=1e-3, size=r.shape)
    dr = newton.newton_direction(s.body, s.pack, s.count, s.v_free, no._piece_value(s, jac, r1), jac, 1e-8)
    assert np.abs(no._piece_value(s, jac, r1 + dr)).max() < 1e-5 * np.abs(no._piece_value(s, jac, r1)).max()
