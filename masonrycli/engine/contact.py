"""Conventions shared by the engine and its readers: the contact frame and the contact status.

Contact frame (the one place it is stated; every kernel and reader refers here). A contact between
bodies a and b (a < b in the broad phase's order) has a unit normal n pointing from a to b and the
tangent

    t = (n_y, −n_x)

(n turned clockwise by 90°). Local vectors are written (t, n): the relative velocity
u = (u_t, u_n) = H_αᵀ v is the velocity of b's material point at the contact minus a's, projected on
(t, n); the impulse r = (r_t, r_n) acts on b and −r on a. A point of body k at lever arm ρ from its
centroid moves at (v_x − ω ρ_y, v_y + ω ρ_x).

This module imports nothing heavy (no numba), so that readers of frames and histories can use it.
"""

from __future__ import annotations

from enum import IntEnum


class ContactStatus(IntEnum):
    """State of a contact after a step's solve (stored as int8 in ``contact_status`` arrays)."""

    OPEN = 0
    """No impulse: the contact is separating or stays open within the step."""
    STICK = 1
    """Closed, u_t = 0, |r_t| < μ r_n (or at the limit without sliding)."""
    SLIP = 2
    """Closed, |r_t| = μ r_n, friction opposed to the sliding velocity."""
