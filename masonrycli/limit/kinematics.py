"""The collapse mechanism read joint by joint: which joints hinge, which slide, which blocks move.

The mechanism is the block velocity field u = (vx, vy, ω) of the LP's dual, scaled so that the fastest
block point moves at 1. At a contact point p of joint (a, b) the relative velocity is

    Δv = v_b(p) − v_a(p),   v_i(p) = (vx_i − ω_i (p_y − y_i),  vy_i + ω_i (p_x − x_i))   (supports: 0)

split into opening Δv·n (≥ 0 by the flow rule) and sliding Δv·t. Along a straight joint the sliding
rate is the same at every point, and the opening varies linearly with the relative rotation Δω.

The words are those of the dynamic run (``masonrycli.analysis.mechanism``): a joint is named by its two bodies
``"a|b"``; it is **hinged** when its faces turn relative to each other (|Δω| × joint length above the
tolerance) about an end that stays in contact — the hinge; it is **sliding** when its faces move along each
other. A joint may do both. One whose faces turn as they part all along (no end in contact: the inner
column of a pier tipping about its outer toe, the joints of a wedge of a wall turning on one pivot) is
**opening**, not a hinge: listed as hinges, they made a wedge of 9 wall blocks turning about one point
"10 hinges". An end stays in contact when its opening is at most the dilation of its sliding (μ |Δv·t|:
the flow rule's, where the contact force may act) plus the tolerance. Single-point (corner) contacts
are never hinges (a point has no face to open), as in the dynamic detector; they may slide.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from masonrycli.limit.joints import Joints
from masonrycli.model import Model

MOTION_TOL = 1e-4
"""Relative velocities below this share of the fastest block point are rounding in the LP's dual (HiGHS
solves to ~1e-7), not motion."""


@dataclass(frozen=True, eq=False)
class JointMotion:
    """Relative motion of every joint under a mechanism (same normalisation as the mechanism)."""

    contact_opening: np.ndarray
    """(C,) opening rate Δv·n at each contact point [-]."""
    contact_sliding: np.ndarray
    """(C,) sliding rate Δv·t at each contact point [-]."""
    joint_hinged: np.ndarray
    """(J,) bool: the joint's faces turn about one of its ends, which stays in contact."""
    joint_opening: np.ndarray
    """(J,) bool: the joint's faces turn as they part all along (no end in contact; not sliding)."""
    joint_sliding: np.ndarray
    """(J,) bool: the joint's faces slide along each other."""
    joint_turn: np.ndarray
    """(J,) |Δω| × joint length [-]: how fast the joint's faces turn relative to each other (0 for corners)."""
    joint_slide: np.ndarray
    """(J,) largest |Δv·t| over the joint's points [-]."""
    hinge_point: np.ndarray
    """(H, 2) m: the end that stays closed of each hinged joint (hinged joints in order)."""
    block_moving: np.ndarray
    """(N,) bool: blocks that take part in the mechanism."""


def point_velocity(model: Model, body: np.ndarray, point: np.ndarray, block_velocity: np.ndarray) -> np.ndarray:
    """(K, 2) velocity of the material point ``point`` (K, 2) of bodies ``body`` (K,); supports do not move."""
    n = model.block_count
    on_block = body < n
    v = np.zeros((body.size, 3))
    v[on_block] = block_velocity[body[on_block]]
    r = point - model.body_q0[body, :2]
    return np.stack([v[:, 0] - v[:, 2] * r[:, 1], v[:, 1] + v[:, 2] * r[:, 0]], axis=1)


def joint_motion(model: Model, joints: Joints, block_velocity: np.ndarray, tol: float = MOTION_TOL) -> JointMotion:
    """Classify every joint under the mechanism ``block_velocity`` (N, 3), normalised to a fastest point of 1."""
    n = model.block_count
    body, point = joints.contact_body, joints.contact_point
    dv = point_velocity(model, body[:, 1], point, block_velocity) - point_velocity(
        model, body[:, 0], point, block_velocity
    )
    opening = np.einsum("ij,ij->i", dv, joints.contact_normal)
    sliding = np.einsum("ij,ij->i", dv, joints.contact_tangent)
    omega = np.zeros(model.body_count)
    omega[:n] = block_velocity[:, 2]
    turn = omega[joints.joint_body[:, 1]] - omega[joints.joint_body[:, 0]]
    first, last = joints.joint_start[:-1], joints.joint_start[1:] - 1
    length = np.hypot(*(point[last] - point[first]).T)
    face = joints.joint_points >= 2
    turn_rate = np.where(face, np.abs(turn) * length, 0.0)
    j = joints.contact_joint
    slide = np.zeros(joints.joint_count)
    np.maximum.at(slide, j, np.abs(sliding))
    in_contact = opening <= joints.contact_friction(model.friction) * np.abs(sliding) + tol
    turning = turn_rate > tol
    hinged = turning & (in_contact[first] | in_contact[last])
    # The hinge is the end that opens least: the closed end of a rotation about a joint end.
    closed = np.where(opening[first] <= opening[last], first, last)
    speed = np.hypot(*block_velocity[:, :2].T) + np.abs(block_velocity[:, 2]) * model.body_radius[:n]
    return JointMotion(
        contact_opening=opening,
        contact_sliding=sliding,
        joint_hinged=hinged,
        joint_opening=turning & ~hinged & ~(slide > tol),
        joint_sliding=slide > tol,
        joint_turn=turn_rate,
        joint_slide=slide,
        hinge_point=point[closed[hinged]].copy(),
        block_moving=speed > tol,
    )


def rigid_parts(model: Model, joints: Joints, motion: JointMotion, tol: float = MOTION_TOL) -> list[np.ndarray]:
    """The moving blocks grouped into the rigid parts of the mechanism, largest first (ties: by first block):
    blocks joined by a face joint whose faces do not move relative to each other (both its contact points'
    opening and sliding below ``tol``) move as one body. A corner contact ties nothing: two blocks may turn
    about it (the bridge on slender piers has v01 touching the pier's top course at its hinge, which put the
    pier and half the ring in one part). A still block belongs to no part."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = model.block_count
    rel = np.maximum(np.abs(motion.contact_opening), np.abs(motion.contact_sliding))
    joint_rel = np.zeros(joints.joint_count)
    np.maximum.at(joint_rel, joints.contact_joint, rel)
    a, b = joints.joint_body.T
    tied = (
        (joint_rel <= tol) & (joints.joint_points >= 2) & (a < n) & (b < n) & motion.block_moving[np.minimum(a, n - 1)]
    )
    graph = coo_matrix((np.ones(int(tied.sum())), (a[tied], b[tied])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    parts = [np.flatnonzero((label == k) & motion.block_moving) for k in np.unique(label[motion.block_moving])]
    return sorted(parts, key=lambda p: (-p.size, p[0]))
