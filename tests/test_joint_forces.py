"""masonrycli.joint_forces against hand-computed resultants and an independent moment balance."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.frame import CONTACT_OPEN, CONTACT_SLIP, CONTACT_STICK
from masonrycli.joint_forces import JOINT_OPEN, JOINT_SLIP, JOINT_STICK, joint_resultants, magnification


def test_a_bed_joint_under_an_eccentric_load():
    """Two contact points 0.3 m apart carrying 3 kN and 1 kN: R = 4 kN at 0.075 m from the middle, and
    the moment of R about any point equals that of the two forces (no friction here)."""
    body = [[0, 1], [0, 1]]
    point = [[-0.15, 0.0], [0.15, 0.0]]
    normal = [[0.0, 1.0], [0.0, 1.0]]
    force = [[0.0, 3000.0], [0.0, 1000.0]]
    j = joint_resultants(body, point, normal, force, [CONTACT_STICK, CONTACT_STICK])
    assert j.body.tolist() == [[0, 1]] and j.state.tolist() == [JOINT_STICK]
    np.testing.assert_allclose(j.force, [[0.0, 4000.0]])
    np.testing.assert_allclose(j.point, [[-0.075, 0.0]])
    o = np.array([0.4, -0.2])

    def cross(r, f):
        return r[0] * f[1] - r[1] * f[0]

    moment = sum(cross(np.array(p) - o, f) for p, f in zip(point, force))
    assert cross(j.point[0] - o, j.force[0]) == pytest.approx(moment)


def test_order_of_bodies_states_and_unloaded_joints():
    # pair (2, 0) written the other way round: its force is turned to be the force on body 2
    body = [[2, 0], [0, 2], [1, 3], [1, 3], [4, 5]]
    point = [[0.0, 1.0], [1.0, 1.0], [5.0, 0.0], [6.0, 0.0], [9.0, 9.0]]
    normal = [[0.0, -1.0], [0.0, 1.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    force = [[0.0, -500.0], [0.0, 1500.0], [300.0, 50.0], [0.0, 0.0], [0.0, 0.0]]
    status = [CONTACT_STICK, CONTACT_SLIP, CONTACT_STICK, CONTACT_OPEN, CONTACT_OPEN]
    j = joint_resultants(body, point, normal, force, status)
    assert j.body.tolist() == [[0, 2], [1, 3]]  # (4, 5) carries no compression: no resultant
    np.testing.assert_allclose(j.force, [[0.0, 2000.0], [300.0, 50.0]])
    np.testing.assert_allclose(j.point, [[0.75, 1.0], [5.0, 0.0]])
    assert j.state.tolist() == [JOINT_SLIP, JOINT_OPEN]


def test_magnification_draws_the_largest_displacement_at_five_percent():
    d = np.zeros((3, 10, 2))
    d[2, 4] = [0.03, -0.04]  # 5 cm
    assert magnification(d, 7.0) == 6.0  # 0.05 · 7 / 0.05 = 7 → 6 (nice, rounded down)
    assert magnification(d, 0.5) == 1.0  # already more than 5 %
    assert magnification(np.zeros((2, 3, 2)), 7.0) == 1.0


def test_unique_inverse_is_numpys_on_sorted_and_unsorted_keys():
    from masonrycli.joint_forces import _unique_inverse

    rng = np.random.default_rng(5)
    for keys in (np.sort(rng.integers(0, 50, 200)), rng.integers(0, 50, 200), np.zeros(0, np.int64), np.array([7])):
        unique, inverse = _unique_inverse(keys)
        expected, expected_inverse = np.unique(keys, return_inverse=True)
        np.testing.assert_array_equal(unique, expected)
        np.testing.assert_array_equal(inverse, expected_inverse.reshape(-1))
