"""Mechanism detector: which joints are hinged at a frame.

A *joint* is a pair of bodies (block–block or block–support) that touch along a face in the initial
configuration (two contact points). A joint is *hinged* when one end carries all of its normal force and
the other end is open:

* exactly one of its contact points has r_n > 0, and
* the other point is either no longer detected (opened beyond the alert distance) or open (r_n = 0)
  with a gap larger than ``OPENING`` (so a joint merely unloaded at zero gap is not a hinge), and
* the joint carries a normal force of at least ``LOAD_FRACTION`` × the mean block weight, so nearly
  unloaded joints (vertical joints of a pier, say) are not reported.

Vectorised over contacts with numpy (no Python loop over joints or contacts).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

OPENING = 1e-4
"""m: gap above which the unloaded end of a joint counts as open."""
LOAD_FRACTION = 1e-3
"""Joints carrying less than this fraction of the mean block weight are never hinges."""


@dataclass(frozen=True, eq=False)
class Joints:
    """The joints of a structure, from its initial contacts."""

    joint_body: np.ndarray
    """(J, 2) int: bodies a < b of each joint."""
    key: np.ndarray
    """(J,) int64: a·B + b, sorted (for lookup)."""
    body_count: int
    min_force: float
    """N: the load below which a joint is not reported as a hinge."""


def find_joints(contact_body: np.ndarray, body_count: int, mean_block_weight: float) -> Joints:
    """Joints = body pairs with two contact points in the initial configuration."""
    key = contact_body[:, 0].astype(np.int64) * body_count + contact_body[:, 1]
    unique, counts = np.unique(key, return_counts=True)
    joint_key = unique[counts >= 2]
    body = np.stack([joint_key // body_count, joint_key % body_count], axis=1)
    return Joints(body, joint_key, body_count, LOAD_FRACTION * mean_block_weight)


def hinged_joints(joints: Joints, contact_body: np.ndarray, contact_r_n: np.ndarray, contact_gap: np.ndarray,
                  dt: float) -> np.ndarray:
    """(J,) bool: which joints are hinged, given a frame's contacts and normal impulses r_n (N·s)."""
    j = joints.key.size
    if j == 0 or contact_body.shape[0] == 0:
        return np.zeros(j, dtype=bool)
    key = contact_body[:, 0].astype(np.int64) * joints.body_count + contact_body[:, 1]
    pos = np.minimum(np.searchsorted(joints.key, key), j - 1)
    member = joints.key[pos] == key
    idx = pos[member]
    force = contact_r_n[member] / dt
    loaded = force > 0.0
    open_end = (~loaded) & (contact_gap[member] > OPENING)
    n_points = np.bincount(idx, minlength=j)
    n_loaded = np.bincount(idx, weights=loaded, minlength=j)
    n_open = np.bincount(idx, weights=open_end, minlength=j)
    total = np.bincount(idx, weights=np.where(loaded, force, 0.0), minlength=j)
    one_loaded = n_loaded == 1
    other_open = (n_points == 1) | ((n_points == 2) & (n_open == 1))
    return one_loaded & other_open & (total >= joints.min_force)
