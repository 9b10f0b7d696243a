"""The line of thrust at collapse: where the resultant of each joint's contact forces crosses the joint.

All contact points of a joint share the joint's normal, so the resultant of their normal forces N_k at
points p_k passes through the centre of pressure p = Σ N_k p_k / Σ N_k (the point about which the
normal forces have no moment). Its position along a face joint is given as an eccentricity
e = 2·s − 1 ∈ [−1, 1], s being the fraction of the way from the joint's first point to its last: e = 0 at
the middle, |e| = 1 at an end — where a hinge forms.

The LP's forces are one admissible set at collapse; away from the mechanism's joints the structure is
statically indeterminate, so this is *a* line of thrust (the one HiGHS's vertex solution picked), not
*the* line of thrust.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from masonrycli.limit.joints import Joints


@dataclass(frozen=True, eq=False)
class ThrustLine:
    """Resultant of each joint (J joints)."""

    joint_normal_force: np.ndarray
    """(J,) N: Σ N_k, compression > 0 (per block thickness)."""
    joint_shear_force: np.ndarray
    """(J,) N: Σ T_k along the joint tangent, on body b."""
    joint_point: np.ndarray
    """(J, 2) m: centre of pressure; NaN where the joint carries no normal force."""
    joint_eccentricity: np.ndarray
    """(J,) [-1, 1]: position of the centre of pressure along a face joint; NaN for corners and unloaded joints."""


def thrust_line(joints: Joints, contact_force: np.ndarray, loaded: float = 0.0) -> ThrustLine:
    """Resultants of ``contact_force`` (C, 2) = (N, T) per contact; joints with Σ N ≤ ``loaded`` [N] get NaN."""
    j, m = joints.contact_joint, joints.joint_count
    normal = np.bincount(j, weights=contact_force[:, 0], minlength=m)
    shear = np.bincount(j, weights=contact_force[:, 1], minlength=m)
    moment = np.stack(
        [np.bincount(j, weights=contact_force[:, 0] * joints.contact_point[:, k], minlength=m) for k in range(2)],
        axis=1,
    )
    carries = normal > loaded
    point = np.full((m, 2), np.nan)
    point[carries] = moment[carries] / normal[carries, None]
    first, last = joints.joint_start[:-1], joints.joint_start[1:] - 1
    span = joints.contact_point[last] - joints.contact_point[first]
    length2 = np.einsum("ij,ij->i", span, span)
    face = carries & (joints.joint_points >= 2) & (length2 > 0)
    ecc = np.full(m, np.nan)
    s = np.einsum("ij,ij->i", point[face] - joints.contact_point[first[face]], span[face]) / length2[face]
    ecc[face] = 2.0 * s - 1.0
    return ThrustLine(normal, shear, point, ecc)
