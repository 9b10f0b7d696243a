"""The Alart–Curnier Newton method (masonrycli.engine.newton) against hand-built solutions, dense references
and finite differences, on the small problems of tests/test_engine_nlgs.py."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.engine import newton, nlgs
from tests.test_engine_nlgs import _random_problem, _stack_problem

G, DT = 9.81, 1e-3


def _one_block(vx=0.0, gap=0.0):
    """A unit block (1 kg, inertia 1/6 kg·m²) on the support by its two bottom corners (bodies 0 = block,
    1 = support; n = (0, −1) from the block to the support, t = (−1, 0)), falling at g·dt, pushed at vx."""
    q = np.array([[0.0, 0.5, 0.0], [0.0, -0.5, 0.0]])
    body = np.array([(0, 1), (0, 1)], dtype=np.int32)
    point = np.array([(-0.5, 0.0), (0.5, 0.0)])
    normal = np.array([(0.0, -1.0), (0.0, -1.0)])
    pack = np.zeros((2, nlgs.PACK_WIDTH))
    inv_mass, inv_inertia = np.array([1.0, 0.0]), np.array([6.0, 0.0])
    nlgs._prepare(body, point, normal, np.full(2, gap), 2, q, inv_mass, inv_inertia, 0.5, DT, pack)
    v_free = np.array([[vx, -G * DT, 0.0], [0.0, 0.0, 0.0]])
    return body, pack, v_free


def test_phi_vanishes_on_a_resting_block_and_only_there():
    body, pack, v_free = _one_block()
    rn = G * DT / 2  # each corner carries half the weight: the block stops, no friction needed
    f, _, merit = newton.phi(body, pack, 2, 0.5, v_free, np.array([[0.0, rn], [0.0, rn]]))
    assert np.abs(f).max() < 1e-15 and merit < 1e-30
    f, _, _ = newton.phi(body, pack, 2, 0.5, v_free, np.array([[0.0, 1.1 * rn], [0.0, 0.9 * rn]]))
    assert np.abs(f).max() > 1e-4  # it would spin: not a solution
    f, _, _ = newton.phi(body, pack, 2, 0.5, v_free, np.array([[0.2 * rn, rn], [-0.2 * rn, rn]]))
    assert np.abs(f).max() < 1e-15  # an inner stress inside the cone: still a solution


def test_phi_vanishes_on_an_open_contact_with_no_impulse():
    body, pack, v_free = _one_block(vx=0.3, gap=0.01)  # 1 cm above the support, falling at g·dt: stays open
    f, _, _ = newton.phi(body, pack, 2, 0.5, v_free, np.zeros((2, 2)))
    assert np.abs(f).max() == 0.0


def test_phi_vanishes_on_a_sliding_block():
    # Pushed at 1 m/s, μ = 0.5: one step of friction (μ g dt) cannot stop it. By hand: the block neither rotates
    # nor sinks, so both corners slide at the same u_t = (v_support − v_block)·t = v_x > 0 (t = (−1, 0)), with
    # r_t = −μ r_n; the block gets (−r_t, r_n) at corners (∓0.5, −0.5) from its centroid, whose moments cancel:
    #   Σ r_n = g dt,  0.5 (r_n1 − r_n0) − 0.5 μ Σ r_n = 0
    body, pack, v_free = _one_block(vx=1.0)
    mu = 0.5
    total = G * DT
    diff = mu * total
    r = np.array([[0.0, (total - diff) / 2], [0.0, (total + diff) / 2]])
    r[:, 0] = -mu * r[:, 1]
    v = v_free.copy()
    newton._velocity(body, pack, 2, v_free, r, v)
    assert abs(v[0, 1]) < 1e-15 and abs(v[0, 2]) < 1e-15 and v[0, 0] > 0  # hand solution: slides, no spin
    f, _, _ = newton.phi(body, pack, 2, mu, v_free, r)
    assert np.abs(f).max() < 1e-15


@pytest.mark.parametrize("seed", [3, 17, 23])
def test_phi_vanishes_at_the_gauss_seidel_solution(seed):
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _random_problem(seed)
    count = body.shape[0]
    v, r, status = v0.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    _, res = nlgs._nlgs(body, pack, count, mu, 1e-14, 200000, v, r, status)
    assert res <= 1e-14
    f, _, _ = newton.phi(body, pack, count, mu, v0, r)
    assert np.abs(f).max() < 1e-11


def _dense_jacobian(jac, pack, h, m_inv):
    """F'(r) = A Wfull + B densely, W = hᵀ M⁻¹ h (the module doc's formula)."""
    count = jac.shape[0]
    a, b = np.zeros((2 * count, 2 * count)), np.zeros((2 * count, 2 * count))
    for c in range(count):
        a[2 * c : 2 * c + 2, 2 * c : 2 * c + 2] = [[jac[c, 0], jac[c, 2]], [0.0, jac[c, 1]]]
        b[2 * c : 2 * c + 2, 2 * c : 2 * c + 2] = [[jac[c, 3], jac[c, 5]], [0.0, jac[c, 4]]]
    return a @ (h.T @ m_inv @ h) + b


@pytest.mark.parametrize("seed", [5, 41])
def test_the_jacobian_matches_finite_differences_of_phi(seed):
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _random_problem(seed)
    count = body.shape[0]
    rng = np.random.default_rng(seed)
    r = np.abs(rng.normal(scale=0.05, size=(count, 2)))  # a generic point, away from the kinks
    f, jac, _ = newton.phi(body, pack, count, mu, v0, r)
    J = _dense_jacobian(jac, pack, h, m_inv)
    for _ in range(5):
        d = rng.normal(size=(count, 2))
        eps = 1e-8
        f2, _, _ = newton.phi(body, pack, count, mu, v0, r + eps * d)
        np.testing.assert_allclose((f2 - f).ravel() / eps, J @ d.ravel(), rtol=1e-5, atol=1e-7)


@pytest.mark.parametrize("seed", [5, 41])
def test_the_velocity_system_gives_the_dense_newton_step(seed):
    # dr from the sparse velocity system against (F' + λ D) dr = −F solved densely.
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _random_problem(seed)
    count = body.shape[0]
    rng = np.random.default_rng(seed)
    r = np.abs(rng.normal(scale=0.05, size=(count, 2)))
    f, jac, _ = newton.phi(body, pack, count, mu, v0, r)
    d = np.column_stack([pack[:, nlgs.P_WTT], pack[:, nlgs.P_WNN]]).ravel()
    ref = np.linalg.solve(_dense_jacobian(jac, pack, h, m_inv) + newton.LAMBDA * np.diag(d), -f.ravel())
    dr = newton.newton_direction(body, pack, count, v0, f, jac)
    np.testing.assert_allclose(dr.ravel(), ref, rtol=1e-8, atol=1e-12 * np.abs(ref).max())


def test_newton_steps_decrease_the_merit_and_a_resume_converges_with_consistent_velocities():
    # The stack of 10 blocks sheared at random (load through every bed joint: Gauss–Seidel's slow case).
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _stack_problem(10)
    count = body.shape[0]
    v_gs, r_gs, status = v0.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    nlgs._nlgs(body, pack, count, mu, 1e-13, 200000, v_gs, r_gs, status)
    # Newton steps alone (a budget of 2 steps, the sweeps after them left out): Armijo makes the merit fall
    iterate, r, v, shift = r0.copy(), np.empty_like(r0), np.empty_like(v0), [newton.LAMBDA]
    merits = [newton.phi(body, pack, count, mu, v0, iterate)[2]]
    for _ in range(4):
        newton.newton_steps(body, pack, count, mu, 1e-12, 2, 10**6, v0, iterate, r, v, status, shift)
        merits.append(newton.phi(body, pack, count, mu, v0, iterate)[2])
    assert all(b < a for a, b in zip(merits, merits[1:])) and merits[-1] < 0.5 * merits[0]
    # one resume of 20 000 units from the start: Newton steps, then sweeps to the tolerance
    iterate, shift = r0.copy(), [newton.LAMBDA]
    done, res = newton.newton_steps(body, pack, count, mu, 1e-10, 20000, 10**6, v0, iterate, r, v, status, shift)
    assert res <= 1e-10 and done < 20000
    np.testing.assert_allclose(v.ravel(), v0.ravel() + m_inv @ h @ r.ravel(), atol=1e-12)
    np.testing.assert_allclose(v, v_gs, atol=1e-8)  # velocities are unique
    assert (r[:, 1] >= 0).all() and (np.abs(r[:, 0]) <= mu * r[:, 1] + 1e-15).all()
    f, _, _ = newton.phi(body, pack, count, mu, v0, r)
    assert np.abs(f).max() < 1e-8


def test_a_resume_never_passes_its_limit():
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _stack_problem(10)
    count = body.shape[0]
    iterate, r, v, status = r0.copy(), np.empty_like(r0), np.empty_like(v0), np.zeros(count, dtype=np.int8)
    for limit in (1, 50, newton.NEWTON_UNITS + newton.WATCHDOG + 1, 500):
        done, _ = newton.newton_steps(body, pack, count, mu, 1e-14, 10**6, limit, v0, iterate, r, v, status, [1e-3])
        assert done <= limit
