"""Moreau–Jean θ-method: free velocity, intermediate configuration, position update, energies.

    v_free = v_n + dt · (g + F_b / m_b)       (blocks; F_b: a force applied at a point of block b, which
                                               only limit --verify gives, a point load along ±x or up)
    q_m    = q_n + (1 − θ) · dt · v_n         (contacts are detected here)
    q_n+1  = q_n + dt · (θ · v_n+1 + (1 − θ) · v_n)

Supports carry their imposed velocity in the same arrays, so one update moves every body.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import njit


@njit(inline="always")
def _begin_step(body_q, body_v, body_radius, dt, theta, out_q, out_v_old):
    # One pass over the bodies at the start of a step:
    #   q_m = q_n + (1 − θ)·dt·v_n  (supports translate with their imposed velocity), v_old = v_n,
    #   top point speed max_k |v_k| + |ω_k|·radius_k  (for the detection distance).
    h = (1.0 - theta) * dt
    top = 0.0
    for b in range(body_q.shape[0]):
        for k in range(3):
            out_q[b, k] = body_q[b, k] + h * body_v[b, k]
            out_v_old[b, k] = body_v[b, k]
        speed = np.sqrt(body_v[b, 0] * body_v[b, 0] + body_v[b, 1] * body_v[b, 1]) + abs(body_v[b, 2]) * body_radius[b]
        if speed > top:
            top = speed
    return top


@njit(inline="always")
def _free_velocity(body_v, body_dynamic, gravity, dt, support_v_next, block_count, out_v, body_q, applied):
    # Blocks: v_free = v_n + dt·g. Supports: their imposed velocity at t_n+1 (no rotation).
    # Applied forces (rows of ``applied``, block b: Fx/m, Fy/m, r0x, r0y, Fx/I, Fy/I; none when it has no
    # rows): v_free += dt·F/m, ω_free += dt·(r × F)/I with r = R(θ_n)·r0 the point of application as the
    # block has turned (a fixed direction, as a weight's).
    for b in range(body_v.shape[0]):
        if body_dynamic[b]:
            out_v[b, 0] = body_v[b, 0] + dt * gravity[0]
            out_v[b, 1] = body_v[b, 1] + dt * gravity[1]
            out_v[b, 2] = body_v[b, 2]
            if b < applied.shape[0]:
                cos, sin = np.cos(body_q[b, 2]), np.sin(body_q[b, 2])
                rx = cos * applied[b, 2] - sin * applied[b, 3]
                ry = sin * applied[b, 2] + cos * applied[b, 3]
                out_v[b, 0] += dt * applied[b, 0]
                out_v[b, 1] += dt * applied[b, 1]
                out_v[b, 2] += dt * (rx * applied[b, 5] - ry * applied[b, 4])
        else:
            s = b - block_count
            out_v[b, 0] = support_v_next[s, 0]
            out_v[b, 1] = support_v_next[s, 1]
            out_v[b, 2] = 0.0


@njit(inline="always")
def _update_q(body_q, body_v_old, body_v_new, dt, theta, block_count):
    # q_n+1 = q_n + dt·(θ v_n+1 + (1 − θ) v_n), in place; in the same pass, for the divergence check,
    # whether every block's q and v are finite and the top block speed |v| (NaN if not finite).
    finite = True
    top = 0.0
    for b in range(body_q.shape[0]):
        for k in range(3):
            body_q[b, k] += dt * (theta * body_v_new[b, k] + (1.0 - theta) * body_v_old[b, k])
            if b < block_count and not (np.isfinite(body_q[b, k]) and np.isfinite(body_v_new[b, k])):
                finite = False
        if b < block_count:
            speed = np.sqrt(body_v_new[b, 0] * body_v_new[b, 0] + body_v_new[b, 1] * body_v_new[b, 1])
            if speed > top:
                top = speed
    return top if finite else np.nan


@njit
def _energies(body_q, body_v, body_mass, body_inertia, gravity, block_count):
    # Kinetic ½ m|v|² + ½ I ω² and potential −m g·x, summed over blocks only.
    kinetic = 0.0
    potential = 0.0
    for b in range(block_count):
        m = body_mass[b]
        vx, vy, w = body_v[b, 0], body_v[b, 1], body_v[b, 2]
        kinetic += 0.5 * m * (vx * vx + vy * vy) + 0.5 * body_inertia[b] * (w * w)
        potential -= m * (gravity[0] * body_q[b, 0] + gravity[1] * body_q[b, 1])
    return kinetic, potential


def begin_step(model, body_q: np.ndarray, body_v: np.ndarray, out_q: np.ndarray, out_v_old: np.ndarray) -> float:
    """Write q_m = q_n + (1 − θ)·dt·v_n into ``out_q`` and v_n into ``out_v_old`` (B, 3); return the top
    speed of any body point, m/s (|v| + |ω|·radius)."""
    return _begin_step(body_q, body_v, model.body_radius, model.dt, model.theta, out_q, out_v_old)


def free_velocity(model, body_v: np.ndarray, support_v_next: np.ndarray, out: np.ndarray, body_q: np.ndarray) -> None:
    """Write v_free (B, 3): blocks get gravity (and their applied force, ``model.block_applied``, its point
    turned by ``body_q``'s θ) over dt, supports their imposed velocity at t_n+1."""
    _free_velocity(
        body_v,
        model.body_dynamic,
        model.gravity,
        model.dt,
        support_v_next,
        model.block_count,
        out,
        body_q,
        model.block_applied,
    )


def update_q(model, body_q: np.ndarray, v_old: np.ndarray, v_new: np.ndarray) -> float:
    """Advance ``body_q`` (B, 3) in place with the θ-rule; return the top block speed |v| (m/s), NaN
    when a block's position or velocity is not finite."""
    return _update_q(body_q, v_old, v_new, model.dt, model.theta, model.block_count)


def energies(model, body_q: np.ndarray, body_v: np.ndarray) -> tuple[float, float]:
    """(kinetic, potential) energy of the blocks, J per block thickness; potential is −Σ m g·x."""
    return _energies(body_q, body_v, model.body_mass, model.body_inertia, model.gravity, model.block_count)
