"""Momentum sweeps in body order (masonrycli.engine.bodies), against a dense numpy reference."""

import numpy as np
import pytest
from test_engine_faces import _faces_problem
from test_engine_nlgs import _dense_h, _packed_row, _random_contacts, _slow_sweeps

from masonrycli.engine import bodies, nlgs
from masonrycli.engine.momentum import RESTART_GROWTH


def _problem(seed):
    q, inv_mass, inv_inertia, body, point, normal, gap = _random_contacts(seed=seed)
    mu, dt, count = 0.5, 1e-3, body.shape[0]
    pack = np.zeros((count, nlgs.PACK_WIDTH))
    nlgs._prepare(body, point, normal, gap, count, q, inv_mass, inv_inertia, mu, dt, pack)
    h = _dense_h(q, body, point, normal)
    m_inv = np.diag(np.column_stack([inv_mass, inv_mass, inv_inertia]).ravel())
    rng = np.random.default_rng(seed + 2)
    v_free = rng.normal(scale=0.1, size=(4, 3))
    v_free[3] = 0.0
    r0 = np.abs(rng.normal(scale=0.01, size=(count, 2)))
    return body, pack, h, m_inv, v_free, r0, mu, np.maximum(gap, 0.0) / dt


def _reference(body, h, m_inv, v_free, r, mu, bias, sweeps):
    """The module doc's sweeps written out with dense H, W and M⁻¹: bodies 0, 1, 2 (3 is the support) in
    turn, each visiting its contacts in index order; extrapolation of all r and v at each sweep's start.
    Returns (v, r, the last sweep's residual)."""
    count = body.shape[0]
    order = [c for k in range(3) for c in range(count) if k in body[c]]
    w_full = h.T @ m_inv @ h
    v = v_free.ravel() + m_inv @ h @ r.ravel()
    r_prev, v_prev = r.copy(), v.copy()
    beta, j, last = 0.0, 1, np.inf
    for _ in range(sweeps):
        v, v_prev = v + beta * (v - v_prev), v.copy()
        r, r_prev = r + beta * (r - r_prev), r.copy()
        e2, seen = 0.0, set()
        for c in order:
            wb = w_full[2 * c : 2 * c + 2, 2 * c : 2 * c + 2]
            u_free = h[:, 2 * c : 2 * c + 2].T @ v - wb @ r[c]
            row = _packed_row((wb[0, 0], wb[0, 1], wb[1, 1]), bias[c], mu)
            rt, rn, _ = nlgs._local_solve(u_free[0], u_free[1], row, 0, mu)
            dr = np.array([rt, rn]) - r[c]
            v += m_inv @ h[:, 2 * c : 2 * c + 2] @ dr
            r[c] = (rt, rn)
            if c not in seen:
                seen.add(c)
                e2 += float((wb @ dr) @ (wb @ dr))
        residual = np.sqrt(e2 / count)
        if residual > RESTART_GROWTH * last:
            j = 1
        last = residual
        beta = (j - 1.0) / (j + 2.0)
        j += 1
    return v.reshape(-1, 3), r, residual, len(order)


@pytest.mark.parametrize("seed", [5, 17])
def test_body_order_sweeps_match_dense_reference(seed):
    body, pack, h, m_inv, v_free, r0, mu, bias = _problem(seed)
    count = body.shape[0]
    for sweeps in (1, 3, 12):
        v_ref, r_ref, res_ref, visits = _reference(body, h, m_inv, v_free, r0.copy(), mu, bias, sweeps)
        v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
        cap = (sweeps * visits - 0.5) / count  # sweep units: exactly `sweeps` sweeps
        units, res = bodies.body_order_sweeps(body, pack, count, mu, 0.0, cap, v, r, status, 10**9)
        assert units == -(-sweeps * visits // count)  # visits / C, rounded up
        assert res == pytest.approx(res_ref, rel=1e-9, abs=1e-15)
        np.testing.assert_allclose(r, r_ref, rtol=1e-9, atol=1e-14)
        np.testing.assert_allclose(v, v_ref, rtol=1e-9, atol=1e-12)


def test_body_order_sweeps_end_on_the_contact_law():
    for seed in (1, 4, 6, 9, 10):  # geometries on which Gauss–Seidel converges (faces test)
        body, pack, h, m_inv, v_free, r0, mu, bias = _faces_problem(seed)
        count = body.shape[0]
        v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
        units, res = bodies.body_order_sweeps(body, pack, count, mu, 1e-13, 10**5, v, r, status, 10**4)
        assert res <= 1e-13 and units >= 1
        # v is v_free + M⁻¹ H r, and one more dense point sweep from r moves nothing
        np.testing.assert_allclose(v, v_free + (m_inv @ h @ r.ravel()).reshape(-1, 3), atol=1e-12)
        w = h.T @ m_inv @ h
        blocks = [w[2 * c : 2 * c + 2, 2 * c : 2 * c + 2] for c in range(count)]
        _, r2, res2 = _slow_sweeps(body, blocks, h, m_inv, v_free, r.copy(), mu, bias, 1)
        assert res2 < 1e-11
        np.testing.assert_allclose(r2, r, atol=1e-11)


def test_body_order_sweeps_stop_at_the_cap():
    body, pack, h, m_inv, v_free, r0, mu, bias = _problem(5)
    count = body.shape[0]
    v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    units, res = bodies.body_order_sweeps(body, pack, count, mu, 1e-300, 7, v, r, status, 10**9)
    assert 7 <= units <= 7 + 2 and res > 0.0  # the sweep that crosses the cap ends (≤ 2 units a sweep)
