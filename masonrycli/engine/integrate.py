"""Moreau–Jean θ-method: free velocity, intermediate configuration, position update, energies.

    v_free = v_n + dt · g                     (blocks; gravity is the only external force)
    q_m    = q_n + (1 − θ) · dt · v_n         (contacts are detected here)
    q_n+1  = q_n + dt · (θ · v_n+1 + (1 − θ) · v_n)

Supports carry their imposed velocity in the same arrays, so one update moves every body.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import njit


@njit
def _intermediate_q(body_q, body_v, dt, theta, out_q):
    # q_m = q_n + (1 − θ)·dt·v_n, all bodies (supports translate with their imposed velocity).
    h = (1.0 - theta) * dt
    for b in range(body_q.shape[0]):
        for k in range(3):
            out_q[b, k] = body_q[b, k] + h * body_v[b, k]


@njit
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


@njit
def _update_q(body_q, body_v_old, body_v_new, dt, theta):
    # q_n+1 = q_n + dt·(θ v_n+1 + (1 − θ) v_n), in place.
    for b in range(body_q.shape[0]):
        for k in range(3):
            body_q[b, k] += dt * (theta * body_v_new[b, k] + (1.0 - theta) * body_v_old[b, k])


@njit
def _energies(body_q, body_v, body_mass, body_inertia, gravity, block_count):
    # Kinetic ½ m|v|² + ½ I ω² and potential −m g·x, summed over blocks only.
    kinetic = 0.0
    potential = 0.0
    for b in range(block_count):
        m = body_mass[b]
        kinetic += 0.5 * m * (body_v[b, 0] ** 2 + body_v[b, 1] ** 2) + 0.5 * body_inertia[b] * body_v[b, 2] ** 2
        potential -= m * (gravity[0] * body_q[b, 0] + gravity[1] * body_q[b, 1])
    return kinetic, potential


def intermediate_q(body_q: np.ndarray, body_v: np.ndarray, dt: float, theta: float, out: np.ndarray) -> None:
    """Write q_m = q_n + (1 − θ)·dt·v_n into ``out`` (B, 3)."""
    _intermediate_q(body_q, body_v, dt, theta, out)


def free_velocity(model, body_v: np.ndarray, support_v_next: np.ndarray, out: np.ndarray) -> None:
    """Write v_free (B, 3): blocks get gravity over dt, supports their imposed velocity at t_n+1."""
    _free_velocity(body_v, model.body_dynamic, model.gravity, model.dt, support_v_next, model.block_count, out)


def update_q(body_q: np.ndarray, v_old: np.ndarray, v_new: np.ndarray, dt: float, theta: float) -> None:
    """Advance ``body_q`` (B, 3) in place with the θ-rule."""
    _update_q(body_q, v_old, v_new, dt, theta)


def energies(model, body_q: np.ndarray, body_v: np.ndarray) -> tuple[float, float]:
    """(kinetic, potential) energy of the blocks, J per block thickness; potential is −Σ m g·x."""
    return _energies(body_q, body_v, model.body_mass, model.body_inertia, model.gravity, model.block_count)
