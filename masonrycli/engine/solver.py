"""One Moreau–Jean time step: launchers only, every loop lives in a kernel.

1. q_m = q_n + (1 − θ) dt v_n                          integrate.intermediate_q
2. contacts at q_m within alert + 2·dt·(top speed)     collision.detect_contacts
3. warm start: r_α ← r of the previous step with the same key
4. v_free = v_n + dt g ; supports get v(t_n+1)         integrate.free_velocity
5. lever arms, W_αα, Signorini bias                    nlgs.prepare_contacts
6. NLGS → r, v_n+1                                     nlgs.solve
7. contact forces, dissipation, support work           nlgs.contact_power
8. q_n+1 = q_n + dt (θ v_n+1 + (1 − θ) v_n)            integrate.update_q
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from masonrycli.engine import integrate, nlgs
from masonrycli.engine.collision import ContactBuffers, detect_contacts


@dataclass(frozen=True)
class StepStats:
    contact_count: int
    iterations: int
    residual: float
    dissipated: float
    """Energy dissipated at the contacts during the step, J."""
    support_work: float
    """Work of the supports on the blocks during the step, J."""
    max_penetration: float
    """Largest penetration among the step's contacts at detection, m (0 if none)."""


class Solver:
    """Owns the per-step work buffers of one model. ``step(state)`` advances ``state`` in place.

    After a step, the ``contact_*`` properties hold the step's contacts (views of length C).
    """

    def __init__(self, model):
        self.model = model
        b = model.body_count
        self.buffers = ContactBuffers(model.body_vert_start)
        self.body_q_m = np.empty((b, 3))
        """(B, 3) configuration at which the last step detected its contacts."""
        self._v_old = np.empty((b, 3))
        self._prev_key = np.empty(0, dtype=np.int64)
        self._prev_r = np.empty((0, 2))
        self._count = 0
        self._alloc(self.buffers.contact_capacity)

    def _alloc(self, capacity: int) -> None:
        self._ra = np.zeros((capacity, 2))
        self._rb = np.zeros((capacity, 2))
        self._pack = np.zeros((capacity, nlgs.PACK_WIDTH))
        self._r = np.zeros((capacity, 2))
        self._status = np.zeros(capacity, dtype=np.int8)
        self._force = np.zeros((capacity, 2))
        self.support_force = np.zeros((self.model.support_count, 2))
        """(S, 2) N: total force the blocks exert on each support during the last step."""

    # Views of the last step's contacts -------------------------------------------------------
    @property
    def contact_body(self) -> np.ndarray:
        return self.buffers.contact_body[: self._count]

    @property
    def contact_point(self) -> np.ndarray:
        return self.buffers.contact_point[: self._count]

    @property
    def contact_normal(self) -> np.ndarray:
        return self.buffers.contact_normal[: self._count]

    @property
    def contact_gap(self) -> np.ndarray:
        return self.buffers.contact_gap[: self._count]

    @property
    def contact_r(self) -> np.ndarray:
        """(C, 2) local impulses (r_t, r_n), N·s, on body b."""
        return self._r[: self._count]

    @property
    def contact_force(self) -> np.ndarray:
        """(C, 2) world force on body b, N."""
        return self._force[: self._count]

    @property
    def contact_status(self) -> np.ndarray:
        """(C,) int8: 0 open, 1 stick, 2 slip."""
        return self._status[: self._count]

    def contact_tangential_velocity(self, body_v: np.ndarray) -> np.ndarray:
        """(C,) m/s: u_t = (v_b(I) − v_a(I))·t of the last step's contacts for velocities ``body_v``
        (B, 3), with the step's lever arms (numpy; called for recorded frames only)."""
        c = self._count
        body = self.buffers.contact_body[:c]
        n = self.buffers.contact_normal[:c]
        ra, rb = self._ra[:c], self._rb[:c]
        va, vb = body_v[body[:, 0]], body_v[body[:, 1]]
        # point velocity v + ω ẑ × r = (vx − ω r_y, vy + ω r_x), projected on t = (n_y, −n_x)
        dx = (vb[:, 0] - vb[:, 2] * rb[:, 1]) - (va[:, 0] - va[:, 2] * ra[:, 1])
        dy = (vb[:, 1] + vb[:, 2] * rb[:, 0]) - (va[:, 1] + va[:, 2] * ra[:, 0])
        return dx * n[:, 1] - dy * n[:, 0]

    def detect(self, body_q: np.ndarray, alert: float | None = None) -> int:
        """Contacts of configuration ``body_q`` within ``alert`` (default: the model's alert distance)
        into the buffers (no solve); returns the count."""
        m = self.model
        alert = m.alert_distance if alert is None else alert
        count = detect_contacts(body_q, m.body_vert_start, m.vert_local, m.body_dynamic, alert, self.buffers)
        if self.buffers.contact_capacity > self._r.shape[0]:
            self._alloc(self.buffers.contact_capacity)
        self._count = count
        return count

    def detection_distance(self, body_v: np.ndarray) -> float:
        """m: the alert distance plus how far two bodies can approach each other within a step.

        A pair farther apart than the alert distance but closing fast (a falling block, a collapsing
        arch) would otherwise be found only once it has penetrated, and a penetration is never pushed
        out. Found in time, its Signorini condition u_n + g/dt ≥ 0 stops it at contact instead.
        Points move at most |v| + |ω|·radius; two bodies approach at most twice the fastest.
        """
        speed = np.hypot(body_v[:, 0], body_v[:, 1]) + np.abs(body_v[:, 2]) * self.model.body_radius
        return self.model.alert_distance + 2.0 * self.model.dt * float(speed.max(initial=0.0))

    def _warm_start(self, count: int) -> None:
        # Impulses of contacts that existed last step (same key) start from their last value.
        key = self.buffers.contact_key[:count]
        r = self._r[:count]
        r[:] = 0.0
        if self._prev_key.size and count:
            pos = np.searchsorted(self._prev_key, key)
            pos = np.minimum(pos, self._prev_key.size - 1)
            hit = self._prev_key[pos] == key
            r[hit] = self._prev_r[pos[hit]]

    def _remember(self, count: int) -> None:
        key = self.buffers.contact_key[:count]
        order = np.argsort(key, kind="stable")
        self._prev_key = key[order]
        self._prev_r = self._r[:count][order]

    def step(self, state) -> StepStats:
        m = self.model
        k = state.step
        integrate.intermediate_q(state.body_q, state.body_v, m.dt, m.theta, self.body_q_m)
        count = self.detect(self.body_q_m, self.detection_distance(state.body_v))
        self._warm_start(count)
        self._v_old[:] = state.body_v
        integrate.free_velocity(m, self._v_old, m.support_velocity[k + 1], state.body_v)
        bf = self.buffers
        body, normal = bf.contact_body, bf.contact_normal
        nlgs.prepare_contacts(
            body, bf.contact_point, normal, bf.contact_gap, count, self.body_q_m, m, self._ra, self._rb, self._pack
        )
        iterations, residual = nlgs.solve(body, self._pack, count, m, state.body_v, self._r, self._status)
        dissipated, work = nlgs.contact_power(
            body,
            normal,
            self._ra,
            self._rb,
            self._r,
            count,
            self._v_old,
            state.body_v,
            m,
            self._force,
            self.support_force,
        )
        integrate.update_q(state.body_q, self._v_old, state.body_v, m.dt, m.theta)
        state.step = k + 1
        state.time = state.step * m.dt
        self._remember(count)
        gap = self.buffers.contact_gap[:count]
        penetration = float(max(0.0, -gap.min())) if count else 0.0
        return StepStats(count, int(iterations), float(residual), float(dissipated), float(work), penetration)
