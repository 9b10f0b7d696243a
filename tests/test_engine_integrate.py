"""The θ-method kernels (engine/integrate.py) and power.tangential_velocity against naive numpy references
written from their definitions (integrate.py's module doc, contact.py's frame), on random bodies."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from masonrycli.engine import integrate, nlgs, power

BLOCKS, SUPPORTS = 7, 2
BODIES = BLOCKS + SUPPORTS


def _model(rng, theta):
    mass = rng.uniform(0.5, 3.0, BODIES)
    inertia = rng.uniform(0.05, 0.4, BODIES)
    dynamic = np.arange(BODIES) < BLOCKS
    return SimpleNamespace(
        dt=1e-3,
        theta=theta,
        gravity=np.array([0.3, -9.81]),
        block_count=BLOCKS,
        body_dynamic=dynamic,
        body_radius=rng.uniform(0.1, 0.6, BODIES),
        body_mass=mass,
        body_inertia=inertia,
        body_inv_mass=np.where(dynamic, 1.0 / mass, 0.0),
        body_inv_inertia=np.where(dynamic, 1.0 / inertia, 0.0),
        friction=0.6,
        block_applied=np.zeros((0, 6)),  # no applied force, as a built Model
    )


def _close(a, b):
    np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("theta", [0.5, 1.0])
def test_a_step_of_the_theta_method_is_its_definition(theta):
    rng = np.random.default_rng(20261129)
    m = _model(rng, theta)
    q, v = rng.normal(size=(BODIES, 3)), rng.normal(size=(BODIES, 3))
    q_m, v_old = np.empty((BODIES, 3)), np.empty((BODIES, 3))
    top = integrate.begin_step(m, q, v, q_m, v_old)
    _close(q_m, q + (1.0 - theta) * m.dt * v)
    assert np.array_equal(v_old, v)
    # every body's fastest point, supports included (the detection distance must see them coming)
    _close(top, np.max(np.hypot(v[:, 0], v[:, 1]) + np.abs(v[:, 2]) * m.body_radius))

    support_v = rng.normal(size=(SUPPORTS, 2))
    v_free = np.full((BODIES, 3), np.nan)
    integrate.free_velocity(m, v, support_v, v_free, q)
    _close(v_free[:BLOCKS, :2], v[:BLOCKS, :2] + m.dt * m.gravity)
    assert np.array_equal(v_free[:BLOCKS, 2], v[:BLOCKS, 2])
    assert np.array_equal(v_free[BLOCKS:, :2], support_v) and not v_free[BLOCKS:, 2].any()

    v_new = rng.normal(size=(BODIES, 3))
    q1 = q.copy()
    speed = integrate.update_q(m, q1, v, v_new)
    _close(q1, q + m.dt * (theta * v_new + (1.0 - theta) * v))
    _close(speed, np.max(np.hypot(v_new[:BLOCKS, 0], v_new[:BLOCKS, 1])))  # blocks only, no ω

    kinetic, potential = integrate.energies(m, q, v)
    b = slice(0, BLOCKS)
    _close(
        kinetic, np.sum(0.5 * m.body_mass[b] * (v[b, 0] ** 2 + v[b, 1] ** 2) + 0.5 * m.body_inertia[b] * v[b, 2] ** 2)
    )
    _close(potential, -np.sum(m.body_mass[b] * (q[b, :2] @ m.gravity)))


def test_update_q_reports_a_block_not_finite_and_ignores_a_support():
    rng = np.random.default_rng(7)
    m = _model(rng, 0.5)
    q, v = rng.normal(size=(BODIES, 3)), rng.normal(size=(BODIES, 3))
    v_support_nan = v.copy()
    v_support_nan[BLOCKS, 0] = np.nan  # a support's velocity: not the divergence test's business
    assert np.isfinite(integrate.update_q(m, q.copy(), v, v_support_nan))
    v_block_nan = v.copy()
    v_block_nan[2, 2] = np.inf
    assert np.isnan(integrate.update_q(m, q.copy(), v, v_block_nan))


def test_tangential_velocity_is_the_relative_velocity_of_the_material_points_on_t():
    rng = np.random.default_rng(11)
    m = _model(rng, 0.5)
    q = rng.normal(size=(BODIES, 3))
    count = 12
    body = np.sort(np.array([rng.choice(BODIES, 2, replace=False) for _ in range(count)]), axis=1).astype(np.int32)
    point = rng.normal(size=(count, 2))
    angle = rng.uniform(0, 2 * np.pi, count)
    normal = np.column_stack([np.cos(angle), np.sin(angle)])
    pack = np.empty((count, nlgs.PACK_WIDTH))
    nlgs.prepare_contacts(body, point, normal, np.zeros(count), count, q, m, pack)
    v = rng.normal(size=(BODIES, 3))

    def material_velocity(k):  # v_k + ω_k × (p − x_k), per contact
        arm = point - q[k, :2]
        return v[k, :2] + v[k, 2:3] * np.column_stack([-arm[:, 1], arm[:, 0]])

    du = material_velocity(body[:, 1]) - material_velocity(body[:, 0])
    tangent = np.column_stack([normal[:, 1], -normal[:, 0]])  # contact.py: t = (n_y, −n_x)
    _close(power.tangential_velocity(body, pack, count, v), np.sum(du * tangent, axis=1))


def test_an_applied_force_adds_its_impulse_and_its_moment_about_the_turned_point():
    """v_free = v_n + dt (g + F/m), ω_free = ω_n + dt (R(θ) r0 × F) / I, on blocks with a force (limit
    --verify's point load along ±x or up); the others as before, bit for bit."""
    rng = np.random.default_rng(7)
    m = _model(rng, 0.5)
    force = np.zeros((BLOCKS, 2))
    force[2] = (40.0, -15.0)
    r0 = rng.normal(size=(BLOCKS, 2))
    applied = np.zeros((BLOCKS, 6))
    applied[:, 0:2] = force / m.body_mass[:BLOCKS, None]
    applied[:, 2:4] = r0
    applied[:, 4:6] = force / m.body_inertia[:BLOCKS, None]
    q, v = rng.normal(size=(BODIES, 3)), rng.normal(size=(BODIES, 3))
    support_v = rng.normal(size=(SUPPORTS, 2))
    plain, pushed = np.full((BODIES, 3), np.nan), np.full((BODIES, 3), np.nan)
    integrate.free_velocity(m, v, support_v, plain, q)
    integrate.free_velocity(SimpleNamespace(**(vars(m) | {"block_applied": applied})), v, support_v, pushed, q)
    c, s = np.cos(q[2, 2]), np.sin(q[2, 2])
    r = (c * r0[2, 0] - s * r0[2, 1], s * r0[2, 0] + c * r0[2, 1])
    _close(pushed[2, :2], v[2, :2] + m.dt * (m.gravity + force[2] / m.body_mass[2]))
    _close(pushed[2, 2], v[2, 2] + m.dt * (r[0] * force[2, 1] - r[1] * force[2, 0]) / m.body_inertia[2])
    others = np.arange(BODIES) != 2
    assert np.array_equal(pushed[others], plain[others])
