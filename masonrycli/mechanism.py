"""Joint states: how far each joint has opened, how much of a block's load slides, which joints hinge.

*Joint ends* are the contact points of the initial configuration (blocks against blocks or supports).
Each end is followed with the two bodies: its material point on a and on b and the normal, which turns
with body a. The **opening** of an end is the normal separation of its two material points,

    opening = (X_b − X_a) · n(θ_a) + g₀        (m; > 0 open, 0 closed as built, < 0 penetrating)

so it keeps growing when the joint opens beyond the alert distance (where contact detection stops
seeing it). A *joint* is a body pair with two initial ends (the two ends of a face-to-face contact).

Per block (the paper's "load level" indicators):

* ``block_max_opening`` — the largest opening, ≥ 0, over the ends of the block's joints (m; single
  corner-to-corner contacts are not joints);
* ``block_sliding_ratio`` — the share of the block's normal contact load carried by sliding contacts:
  Σ_slip r_n / Σ_closed r_n over its current contacts (0 with none), "slip" meaning at the friction
  limit *and* sliding faster than ``SLIP_SPEED`` (``reported_status``). Weighting by r_n keeps lightly
  loaded contacts (vertical joints) from dominating the ratio.

Per contact, ``mobilised_friction`` is the share of the available friction in use, |r_t| / (μ r_n): 1 at
the friction limit, 0 on open contacts (and where μ r_n ≤ 0, where no friction is available).

A joint is **hinged** when exactly one of its current contact points carries normal force (r_n > 0),
its other end has opened by more than ``OPENING``, and it carries at least ``LOAD_FRACTION`` × the
mean block weight (nearly unloaded joints are not reported).

All vectorised with numpy (no Python loop over joints, ends or contacts).
"""

from __future__ import annotations

import numpy as np

from masonrycli.frame import CONTACT_OPEN, CONTACT_SLIP, CONTACT_STICK

SLIP_SPEED = 1e-3
"""m/s: a contact at the friction limit is reported as slipping only when its faces slide faster than
this; slower, it is reported as sticking (the solver's "slide" branch also covers contacts that are
merely at the limit, creeping by a few µm per step)."""
OPENING = 1e-4
"""m: opening above which the unloaded end of a joint counts as open (0.1 mm)."""
LOAD_FRACTION = 1e-3
"""Joints carrying less than this fraction of the mean block weight are never hinges."""
JOINT_FIELDS = {
    "block_sliding_ratio": ((), "1", "share of the block's normal contact load carried by sliding contacts"),
    "block_max_opening": ((), "m", "largest opening of the block's joints (followed kinematically), ≥ 0"),
}
"""Per-block fields of :meth:`JointTracker.block_fields`: name → (shape after N, unit, description)."""


def reported_status(status: np.ndarray, tangential_velocity: np.ndarray) -> np.ndarray:
    """(C,) int8: the solver's contact status with slip kept only where |u_t| > ``SLIP_SPEED``."""
    out = np.array(status, dtype=np.int8, copy=True)
    out[(out == CONTACT_SLIP) & (np.abs(tangential_velocity) <= SLIP_SPEED)] = CONTACT_STICK
    return out


def mobilised_friction(contact_r: np.ndarray, status: np.ndarray, friction: float) -> np.ndarray:
    """(C,) |r_t| / (μ r_n) of the closed contacts (status not open), 0 for open ones or where μ r_n ≤ 0.

    ``contact_r`` (C, 2) holds the local impulses (r_t, r_n); ``friction`` is the Coulomb coefficient μ.
    """
    closed = status != CONTACT_OPEN
    out = np.zeros(status.shape[0])
    denom = friction * contact_r[closed, 1]
    out[closed] = np.divide(np.abs(contact_r[closed, 0]), denom, out=np.zeros(denom.size), where=denom > 0)
    return out


def _rotate(theta: np.ndarray, xy: np.ndarray) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * xy[:, 0] - s * xy[:, 1], s * xy[:, 0] + c * xy[:, 1]], axis=1)


class JointTracker:
    """Joint ends of the initial configuration, followed with the bodies.

    Args:
        contact_body, contact_point, contact_normal, contact_gap: the initial contacts (C0 rows).
        body_q0: (B, 3) initial poses. block_count: N. mean_block_weight: N (per thickness).
    """

    def __init__(
        self,
        contact_body,
        contact_point,
        contact_normal,
        contact_gap,
        body_q0,
        block_count: int,
        mean_block_weight: float,
    ):
        body = np.asarray(contact_body, dtype=np.int64).reshape(-1, 2)
        self.block_count = int(block_count)
        self.body_count = int(body_q0.shape[0])
        self.end_body = body
        """(E, 2) bodies a, b of each joint end."""
        q0 = np.asarray(body_q0)
        # Material points and normal in the bodies' frames (θ = 0 initially, so only a translation).
        self._local_a = np.asarray(contact_point) - q0[body[:, 0], :2]
        self._local_b = np.asarray(contact_point) - q0[body[:, 1], :2]
        self._normal0 = np.asarray(contact_normal, dtype=np.float64).copy()
        self._gap0 = np.asarray(contact_gap, dtype=np.float64).copy()
        key = body[:, 0] * self.body_count + body[:, 1]
        unique, inverse, counts = np.unique(key, return_inverse=True, return_counts=True)
        is_joint = counts >= 2
        self.key = unique[is_joint]
        """(J,) int64 a·B + b of each joint, sorted."""
        self.joint_body = np.stack([self.key // self.body_count, self.key % self.body_count], axis=1)
        """(J, 2) bodies a < b of each joint."""
        joint_of_pair = np.cumsum(is_joint) - 1
        self._end_joint = np.where(is_joint[inverse], joint_of_pair[inverse], -1)
        self.min_force = LOAD_FRACTION * mean_block_weight

    def opening(self, body_q: np.ndarray) -> np.ndarray:
        """(E,) m: opening of every joint end in configuration ``body_q`` (B, 3)."""
        a, b = self.end_body[:, 0], self.end_body[:, 1]
        xa = body_q[a, :2] + _rotate(body_q[a, 2], self._local_a)
        xb = body_q[b, :2] + _rotate(body_q[b, 2], self._local_b)
        n = _rotate(body_q[a, 2], self._normal0)
        return np.einsum("ij,ij->i", xb - xa, n) + self._gap0

    def block_fields(self, body_q, contact_body, contact_r, contact_status) -> dict[str, np.ndarray]:
        """``JOINT_FIELDS`` for configuration ``body_q`` and the current contacts (impulses r = (r_t, r_n))."""
        n = self.block_count
        # Only the ends of joints: a corner-to-corner contact has no face whose opening could be read,
        # and its normal may lie along a face that slides (the slip would be counted as opening).
        opening = np.maximum(self.opening(body_q), 0.0)
        max_opening = np.zeros(n)
        in_joint = self._end_joint >= 0
        for side in range(2):
            owner = self.end_body[:, side]
            blocks = (owner < n) & in_joint
            np.maximum.at(max_opening, owner[blocks], opening[blocks])
        rn = np.asarray(contact_r)[:, 1]
        closed = np.where(contact_status != CONTACT_OPEN, rn, 0.0)
        sliding = np.where(contact_status == CONTACT_SLIP, rn, 0.0)
        load = np.zeros(n)
        slide = np.zeros(n)
        for side in range(2):
            owner = np.asarray(contact_body)[:, side]
            blocks = owner < n
            load += np.bincount(owner[blocks], weights=closed[blocks], minlength=n)
            slide += np.bincount(owner[blocks], weights=sliding[blocks], minlength=n)
        ratio = np.divide(slide, load, out=np.zeros(n), where=load > 0)
        return {"block_sliding_ratio": ratio, "block_max_opening": max_opening}

    def hinged(self, body_q, contact_body, contact_rn, dt: float) -> np.ndarray:
        """(J,) bool: which joints are hinged (one end carries all the normal force, the other is open)."""
        j = self.key.size
        if j == 0:
            return np.zeros(0, dtype=bool)
        # The joint's widest opening over its ends.
        opening = self.opening(body_q)
        joint_end = self._end_joint >= 0
        widest = np.full(j, -np.inf)
        np.maximum.at(widest, self._end_joint[joint_end], opening[joint_end])
        # Loaded current contact points per joint, and the joint's normal force.
        key = self._pair_key(contact_body)
        pos = np.minimum(np.searchsorted(self.key, key), j - 1)
        member = self.key[pos] == key
        idx = pos[member]
        force = np.asarray(contact_rn)[member] / dt
        loaded = force > 0.0
        n_loaded = np.bincount(idx, weights=loaded, minlength=j)
        total = np.bincount(idx, weights=np.where(loaded, force, 0.0), minlength=j)
        return (n_loaded == 1) & (widest > OPENING) & (total >= self.min_force)

    def hinge_points(self, contact_body, contact_point, contact_rn, hinged) -> np.ndarray:
        """(H, 2) m: the loaded contact points of the hinged joints (the hinges themselves)."""
        loaded = (np.asarray(contact_rn) > 0) & np.isin(self._pair_key(contact_body), self.key[hinged])
        return np.asarray(contact_point)[loaded].copy()

    def _pair_key(self, contact_body) -> np.ndarray:
        body = np.asarray(contact_body, dtype=np.int64).reshape(-1, 2)
        return body[:, 0] * self.body_count + body[:, 1]
