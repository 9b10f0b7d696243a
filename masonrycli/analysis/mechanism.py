"""Joint states: how far each joint has opened, how much of a block's load slides, which joints hinge.

*Joint ends* are the contact points of the initial configuration (blocks against blocks or supports).
Each end is followed with the two bodies: its material point on a and on b and the normal, which turns
with body a. The **opening** of an end is the normal separation of its two material points,

    opening = (X_b − X_a) · n(θ_a) + g₀        (m; > 0 open, 0 closed as built, < 0 penetrating)

so it keeps growing when the joint opens beyond the alert distance (where contact detection stops
seeing it). A *joint* is a body pair with two initial ends (the two ends of a face-to-face contact).
Only initial contacts closer than ``JOINT_GAP`` are ends: a raised ``alert_distance`` also detects
blocks that face each other across a gap (two courses apart), and those are not joints.

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
its other end has opened by more than ``OPENING`` since the start (beyond its initial gap g₀ when that is
positive: a joint drawn open at one end is no hinge until it opens further), and it carries at least
``LOAD_FRACTION`` × the mean block weight (nearly unloaded joints are not reported).

The loops over ends, joints and contacts are the kernels of :mod:`masonrycli.engine.joints`.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine import joints as _kernels

SLIP_SPEED = 1e-3
"""m/s: a contact at the friction limit is reported as slipping only when its faces slide faster than
this; slower, it is reported as sticking (the solver's "slide" branch also covers contacts that are
merely at the limit, creeping by a few µm per step)."""
OPENING = 1e-4
"""m: opening above which the unloaded end of a joint counts as open (0.1 mm)."""
JOINT_GAP = 1e-3
"""m: initial contacts with a larger gap are not joint ends (the default alert distance, so default runs
keep every initial contact; with alert_distance = 0.15 m on the 248-block wall, pairs 0.15 m apart were
joints "opened" by 150 mm from the start, and a wall at rest was reported damaged)."""
LOAD_FRACTION = 1e-3
"""Joints carrying less than this fraction of the mean block weight are never hinges."""
JOINT_FIELDS = {
    "block_sliding_ratio": ((), "1", "share of the block's normal contact load carried by sliding contacts"),
    "block_max_opening": ((), "m", "largest opening of the block's joints (followed kinematically), ≥ 0"),
}
"""Per-block fields of :meth:`JointTracker.block_fields`: name → (shape after N, unit, description)."""


def reported_status(status: np.ndarray, tangential_velocity: np.ndarray) -> np.ndarray:
    """(C,) int8: the solver's contact status with slip kept only where |u_t| > ``SLIP_SPEED``."""
    return contact_states(status, tangential_velocity, np.zeros((len(status), 2)), 0.0)[0]


def mobilised_friction(contact_r: np.ndarray, status: np.ndarray, friction: float) -> np.ndarray:
    """(C,) |r_t| / (μ r_n) of the closed contacts (status not open), 0 for open ones or where μ r_n ≤ 0.

    ``contact_r`` (C, 2) holds the local impulses (r_t, r_n); ``friction`` is the Coulomb coefficient μ.
    """
    # Only open / closed matters here, which the tangential speed (0 here) never changes.
    return contact_states(status, np.zeros(len(status)), contact_r, friction)[1]


def contact_states(status, tangential_velocity, contact_r, friction: float) -> tuple[np.ndarray, np.ndarray]:
    """(:func:`reported_status`, :func:`mobilised_friction` of that status) in one pass."""
    status = np.ascontiguousarray(status, dtype=np.int8)
    ut = np.ascontiguousarray(tangential_velocity, dtype=np.float64)
    r = np.ascontiguousarray(contact_r, dtype=np.float64).reshape(-1, 2)
    return _kernels.contact_states(status, ut, r, friction, SLIP_SPEED)


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
        near = np.asarray(contact_gap, dtype=np.float64) <= JOINT_GAP
        body = np.asarray(contact_body, dtype=np.int64).reshape(-1, 2)[near]
        contact_point, contact_normal = np.asarray(contact_point)[near], np.asarray(contact_normal)[near]
        contact_gap = np.asarray(contact_gap)[near]
        self.block_count = int(block_count)
        self.body_count = int(body_q0.shape[0])
        self.end_body = np.ascontiguousarray(body)
        """(E, 2) bodies a, b of each joint end."""
        q0 = np.asarray(body_q0)
        # Material points and normal in the bodies' frames (θ = 0 initially, so only a translation).
        self._local_a = np.ascontiguousarray(np.asarray(contact_point) - q0[body[:, 0], :2])
        self._local_b = np.ascontiguousarray(np.asarray(contact_point) - q0[body[:, 1], :2])
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
        self._end_joint = np.ascontiguousarray(np.where(is_joint[inverse], joint_of_pair[inverse], -1), dtype=np.int64)
        self.min_force = LOAD_FRACTION * mean_block_weight

    def opening(self, body_q: np.ndarray) -> np.ndarray:
        """(E,) m: opening of every joint end in configuration ``body_q`` (B, 3)."""
        q = np.ascontiguousarray(body_q, dtype=np.float64)
        return _kernels.openings(q, self.end_body, self._local_a, self._local_b, self._normal0, self._gap0)

    def block_fields(self, body_q, contact_body, contact_r, contact_status, opening=None) -> dict[str, np.ndarray]:
        """``JOINT_FIELDS`` for configuration ``body_q`` and the current contacts (impulses r = (r_t, r_n)).
        ``opening``: :meth:`opening` of ``body_q`` if already computed."""
        # Only the ends of joints: a corner-to-corner contact has no face whose opening could be read,
        # and its normal may lie along a face that slides (the slip would be counted as opening).
        opening = self.opening(body_q) if opening is None else opening
        body = np.ascontiguousarray(contact_body, dtype=np.int64).reshape(-1, 2)
        status = np.ascontiguousarray(contact_status, dtype=np.int8)
        max_opening, ratio = _kernels.block_fields(
            opening, self.end_body, self._end_joint, self.block_count, body, np.asarray(contact_r)[:, 1], status
        )
        return {"block_sliding_ratio": ratio, "block_max_opening": max_opening}

    def hinged(self, body_q, contact_body, contact_rn, dt: float, opening=None) -> np.ndarray:
        """(J,) bool: which joints are hinged (one end carries all the normal force, the other is open).
        ``opening``: :meth:`opening` of ``body_q`` if already computed."""
        if self.key.size == 0:
            return np.zeros(0, dtype=bool)
        opening = self.opening(body_q) if opening is None else opening
        # opened since the start: an end drawn apart (a traced wall's faces meet at one end, the other 0.1-1 mm
        # off) is no hinge at rest — a settled traced wall was "damaged", 37 hinges, with nothing moving
        opened = np.ascontiguousarray(opening - np.maximum(self._gap0, 0.0))
        body = np.ascontiguousarray(contact_body, dtype=np.int64).reshape(-1, 2)
        return _kernels.hinged(
            opened, self._end_joint, self.key, self.body_count, body, contact_rn, dt, OPENING, self.min_force
        )

    def hinge_points(self, contact_body, contact_point, contact_rn, hinged) -> np.ndarray:
        """(H, 2) m: the loaded contact points of the hinged joints (the hinges themselves)."""
        if not np.any(hinged):
            return np.zeros((0, 2))
        body = np.ascontiguousarray(contact_body, dtype=np.int64).reshape(-1, 2)
        loaded = _kernels.hinge_contacts(self.key, hinged, self.body_count, body, contact_rn)
        return np.asarray(contact_point)[loaded].copy()
