"""Sweep variants for stalled steps (benchmarks.solver_lab.sweep_variants: lab kernels), against dense numpy references."""

import numpy as np
import pytest
from test_engine_bodies import _problem as _bodies_problem
from test_engine_faces import _faces_problem
from test_engine_nlgs import _packed_row, _slow_sweeps

from benchmarks.solver_lab import sweep_variants as sv
from masonrycli.engine import nlgs
from masonrycli.engine.momentum import RESTART_GROWTH


def _problem(seed=17):
    """The body-order tests' random problem (three bodies and a support)."""
    return _bodies_problem(seed)


def _reference(body, h, m_inv, v_free, r, mu, bias, sweeps, omega, accelerate, alternate, adaptive, status):
    """The variant written out with dense H, W and M⁻¹, one contact at a time (module doc's pseudo-code,
    tolerance 0: no finishing switch). Returns (v, r, residual of the last sweep)."""
    count = body.shape[0]
    w_full = h.T @ m_inv @ h
    v = v_free.ravel() + m_inv @ h @ r.ravel()
    r_prev, v_prev = r.copy(), v.copy()
    w = np.full(count, 1.0 if adaptive else omega)
    beta, j, last = 0.0, 1, np.inf
    for s in range(sweeps):
        if accelerate:
            v, v_prev = v + beta * (v - v_prev), v.copy()
        order = range(count - 1, -1, -1) if alternate and s % 2 == 1 else range(count)
        e2 = 0.0
        for c in order:
            wb = w_full[2 * c : 2 * c + 2, 2 * c : 2 * c + 2]
            y = r[c] + beta * (r[c] - r_prev[c]) if accelerate else r[c].copy()
            if accelerate:
                r_prev[c] = r[c]
            u_free = h[:, 2 * c : 2 * c + 2].T @ v - wb @ y
            lt, ln, st = nlgs._local_solve(
                u_free[0], u_free[1], _packed_row((wb[0, 0], wb[0, 1], wb[1, 1]), bias[c], mu), 0, mu
            )
            loc = np.array([lt, ln])
            if adaptive:
                w[c] = max(0.5 * w[c], omega) if st != status[c] else min(1.0, w[c] * sv.ADAPT_RAISE)
            status[c] = st
            new = y + w[c] * (loc - y)
            if accelerate and w[c] < 1.0:
                new[1] = max(new[1], 0.0)
                new[0] = np.clip(new[0], -mu * new[1], mu * new[1])
            v += m_inv @ h[:, 2 * c : 2 * c + 2] @ (new - y)
            r[c] = new
            e = wb @ (loc - y)
            e2 += float(e @ e)
        residual = np.sqrt(e2 / count)
        if accelerate:
            if residual > RESTART_GROWTH * last:
                j = 1
            last = residual
            beta = (j - 1.0) / (j + 2.0)
            j += 1
    return v.reshape(-1, 3), r, residual


@pytest.mark.parametrize(
    "omega, accelerate, order, adaptive",
    [
        (0.7, False, sv.ORDER_FORWARD, False),
        (0.5, False, sv.ORDER_ALTERNATE, False),
        (0.8, True, sv.ORDER_FORWARD, False),
        (1.0, True, sv.ORDER_FORWARD, False),
        (0.25, False, sv.ORDER_FORWARD, True),
        (0.25, True, sv.ORDER_FORWARD, True),
    ],
)
def test_variant_sweeps_match_dense_reference(omega, accelerate, order, adaptive):
    body, pack, h, m_inv, v_free, r0, mu, bias = _problem()
    count = body.shape[0]
    status0 = np.full(count, nlgs.STATUS_STICK, dtype=np.int8)
    for sweeps in (1, 3, 12):
        v, r, status = v_free.copy(), r0.copy(), status0.copy()
        units, res = sv.variant_sweeps(
            body, pack, count, mu, 0.0, sweeps, v, r, status, omega, accelerate, order, 0, adaptive, 10**9
        )
        alternate = order == sv.ORDER_ALTERNATE
        v_ref, r_ref, res_ref = _reference(
            body, h, m_inv, v_free, r0.copy(), mu, bias, sweeps, omega, accelerate, alternate, adaptive, status0.copy()
        )
        assert units == sweeps
        assert res == pytest.approx(res_ref, rel=1e-9, abs=1e-15)
        np.testing.assert_allclose(r, r_ref, rtol=1e-9, atol=1e-14)
        np.testing.assert_allclose(v, v_ref, rtol=1e-9, atol=1e-12)


def _law_holds(body, h, m_inv, v_free, v, r, mu, bias):
    # v is v_free + M⁻¹ H r, and one more dense point sweep from r moves nothing.
    np.testing.assert_allclose(v, v_free + (m_inv @ h @ r.ravel()).reshape(-1, 3), atol=1e-12)
    w = h.T @ m_inv @ h
    blocks = [w[2 * c : 2 * c + 2, 2 * c : 2 * c + 2] for c in range(body.shape[0])]
    _, r2, res2 = _slow_sweeps(body, blocks, h, m_inv, v_free, r.copy(), mu, bias, 1)
    assert res2 < 1e-11
    np.testing.assert_allclose(r2, r, atol=1e-11)


@pytest.mark.parametrize(
    "omega, accelerate, order",
    [(0.7, False, sv.ORDER_RANDOM), (1.0, True, sv.ORDER_RANDOM_FACES), (0.7, True, sv.ORDER_TURN), (0.6, False, 0)],
)
def test_variant_sweeps_end_on_the_contact_law(omega, accelerate, order):
    for seed in (1, 4, 6, 9, 10):  # geometries on which Gauss–Seidel converges (faces test)
        body, pack, h, m_inv, v_free, r0, mu, bias = _faces_problem(seed)
        count = body.shape[0]
        v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
        units, res = sv.variant_sweeps(body, pack, count, mu, 1e-13, 10**5, v, r, status, omega, accelerate, order)
        assert res <= 1e-13 and units >= 1
        _law_holds(body, h, m_inv, v_free, v, r, mu, bias)


def test_shuffle_is_a_seeded_permutation():
    a = np.arange(50)
    sv._shuffle(a, 50, np.array([np.uint64(12345)], dtype=np.uint64))
    b = np.arange(50)
    sv._shuffle(b, 50, np.array([np.uint64(12345)], dtype=np.uint64))
    c = np.arange(50)
    sv._shuffle(c, 50, np.array([np.uint64(999)], dtype=np.uint64))
    assert sorted(a) == list(range(50)) and np.array_equal(a, b) and not np.array_equal(a, c)


def test_body_sweeps_with_one_round_are_point_sweeps_in_body_order():
    # One inner round per body visits each contact once from each body with mass: a point sweep in the
    # order of the bodies' contact lists (body 3 is the support: its contacts are visited from the other side).
    body, pack, h, m_inv, v_free, r0, mu, bias = _problem(seed=5)
    count = body.shape[0]
    order = [c for k in range(3) for c in range(count) if k in body[c]]
    w = h.T @ m_inv @ h
    blocks = [w[2 * c : 2 * c + 2, 2 * c : 2 * c + 2] for c in range(count)]
    for sweeps in (1, 4):
        v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
        cap = (sweeps * len(order) - 0.5) / count  # sweep units: exactly `sweeps` sweeps of len(order) visits
        units, _ = sv.body_sweeps(body, pack, count, mu, 0.0, cap, v, r, status, rounds=1)
        vr = v_free.ravel() + m_inv @ h @ r0.ravel()
        rr = r0.copy()
        from test_engine_nlgs import _slow_sweep

        for _ in range(sweeps):
            _slow_sweep(body, blocks, h, m_inv, vr, rr, mu, bias, order)
        np.testing.assert_allclose(r, rr, rtol=1e-9, atol=1e-14)
        np.testing.assert_allclose(v.ravel(), vr, rtol=1e-9, atol=1e-12)


def test_body_sweeps_end_on_the_contact_law():
    for seed in (1, 4, 6, 9, 10):
        body, pack, h, m_inv, v_free, r0, mu, bias = _faces_problem(seed)
        count = body.shape[0]
        v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
        units, res = sv.body_sweeps(body, pack, count, mu, 1e-13, 10**5, v, r, status, alternate=seed % 2 == 0)
        assert res <= 1e-13 and units >= 1
        _law_holds(body, h, m_inv, v_free, v, r, mu, bias)
