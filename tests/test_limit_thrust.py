"""Line of thrust: centres of pressure against hand statics."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.limit.joints import Joints
from masonrycli.limit.thrust import thrust_line


def two_joints() -> Joints:
    """Joint 0: a horizontal face from (0, 0) to (2, 0); joint 1: a single corner contact at (5, 1)."""
    return Joints(
        contact_body=np.array([[0, 2], [0, 2], [1, 2]]),
        contact_point=np.array([[0.0, 0.0], [2.0, 0.0], [5.0, 1.0]]),
        contact_normal=np.array([[0.0, -1.0], [0.0, -1.0], [0.0, -1.0]]),
        contact_joint=np.array([0, 0, 1]),
        joint_body=np.array([[0, 2], [1, 2]]),
        joint_start=np.array([0, 2, 3]),
    )


def test_centre_of_pressure_and_eccentricity():
    # 300 N at x = 0 and 100 N at x = 2: resultant 400 N at x = 0.5, a quarter along: e = −0.5.
    force = np.array([[300.0, 10.0], [100.0, 5.0], [50.0, 0.0]])
    th = thrust_line(two_joints(), force)
    np.testing.assert_allclose(th.joint_normal_force, [400.0, 50.0])
    np.testing.assert_allclose(th.joint_shear_force, [15.0, 0.0])
    np.testing.assert_allclose(th.joint_point, [[0.5, 0.0], [5.0, 1.0]])
    assert th.joint_eccentricity[0] == pytest.approx(-0.5)
    assert np.isnan(th.joint_eccentricity[1])  # a corner has no face to be eccentric on


def test_unloaded_joint_has_no_centre_of_pressure():
    force = np.array([[0.0, 0.0], [0.0, 0.0], [50.0, 0.0]])
    th = thrust_line(two_joints(), force, loaded=1e-6)
    assert np.isnan(th.joint_point[0]).all() and np.isnan(th.joint_eccentricity[0])
