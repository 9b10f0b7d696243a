"""Moreau–Jean θ-method: free velocity, intermediate configuration, position update, energies.

    v_free = v_n + dt · g                     (blocks; gravity is the only external force)
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
def _free_velocity(body_v, body_dynamic, gravity, dt, support_v_next, block_count, out_v):
    # Blocks: v_free = v_n + dt·g. Supports: their imposed velocity at t_n+1 (no rotation).
    for b in range(body_v.shape[0]):
        if body_dynamic[b]:
            out_v[b, 0] = body_v[b, 0] + dt * gravity[0]
            out_v[b, 1] = body_v[b, 1] + dt * gravity[1]
            out_v[b, 2] = body_v[b, 2]
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


def free_velocity(model, body_v: np.ndarray, support_v_next: np.ndarray, out: np.ndarray) -> None:
    """Write v_free (B, 3): blocks get gravity over dt, supports their imposed velocity at t_n+1."""
    _free_velocity(body_v, model.body_dynamic, model.gravity, model.dt, support_v_next, model.block_count, out)


def update_q(model, body_q: np.ndarray, v_old: np.ndarray, v_new: np.ndarray) -> float:
    """Advance ``body_q`` (B, 3) in place with the θ-rule; return the top block speed |v| (m/s), NaN
    when a block's position or velocity is not finite."""
    return _update_q(body_q, v_old, v_new, model.dt, model.theta, model.block_count)


def energies(model, body_q: np.ndarray, body_v: np.ndarray) -> tuple[float, float]:
    """(kinetic, potential) energy of the blocks, J per block thickness; potential is −Σ m g·x."""
    return _energies(body_q, body_v, model.body_mass, model.body_inertia, model.gravity, model.block_count)
