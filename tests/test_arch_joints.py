"""benchmarks/arch_joints.py, the joint measures of the LMGC90 arch comparison (no LMGC90 needed):
against hand-built joints and exact rigid-body kinematics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmarks.arch_joints import diff_stats, end_openings, face_joints, joint_resultants, joint_states
from geometry_library.builders import build_arch

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def _rotate_about(q0, pivot, phi):
    """Pose (x, y, θ) of a body with reference point q0[:2] after a rotation by phi about ``pivot``."""
    c, s = math.cos(phi), math.sin(phi)
    arm = np.asarray(q0[:2]) - pivot
    return np.array([pivot[0] + c * arm[0] - s * arm[1], pivot[1] + s * arm[0] + c * arm[1], q0[2] + phi])


def test_stacked_squares_share_one_joint_with_its_two_ends_and_normal():
    joints = face_joints([SQUARE, SQUARE + (0.5, 1.0), SQUARE + (3.0, 0.0), SQUARE + (1.0, 1.0 + 1.0)])
    # 0–1 overlap on y = 1 for x in [0.5, 1]; 2 is apart; 3's bottom edge (y = 2) lies on 1's top edge
    # for x in [1, 1.5]; 0 and 3 do not touch
    assert joints.body.tolist() == [[0, 1], [1, 3]]
    np.testing.assert_allclose(sorted(joints.end[0][:, 0]), [0.5, 1.0])
    np.testing.assert_allclose(joints.end[0][:, 1], [1.0, 1.0])
    np.testing.assert_allclose(joints.normal[0], [0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(sorted(joints.end[1][:, 0]), [1.0, 1.5])


def test_corner_to_corner_is_no_joint():
    assert face_joints([SQUARE, SQUARE + (1.0, 1.0)]).body.shape == (0, 2)


@pytest.mark.parametrize("phi", [-0.01, 0.02])
def test_a_block_rocking_on_one_end_opens_the_other_by_the_exact_arc(phi):
    joints = face_joints([SQUARE, SQUARE + (0.0, 1.0)])
    q0 = np.array([[0.5, 0.5, 0.0], [0.5, 1.5, 0.0]])
    ends = joints.end[0]
    # counter-clockwise, the upper block rocks on its left corner; clockwise, on its right one
    pivot = np.array([0.0, 1.0]) if phi > 0 else np.array([1.0, 1.0])
    q = q0.copy()
    q[1] = _rotate_about(q0[1], pivot, phi)
    opening, slip, rel = end_openings(joints, q0, q)
    lifted = 1 if np.allclose(ends[0], pivot) else 0  # the end that is not the pivot
    np.testing.assert_allclose(opening[0, 1 - lifted], 0.0, atol=1e-15)
    np.testing.assert_allclose(opening[0, lifted], abs(math.sin(phi)), rtol=1e-12)
    np.testing.assert_allclose(rel, [phi])
    state = joint_states(opening)[0]
    assert state == (1 if lifted == 1 else 2)  # hinge about the end that stayed closed


def test_rigid_motion_of_both_bodies_opens_nothing_and_lifting_opens_both_ends():
    joints = face_joints([SQUARE, SQUARE + (0.0, 1.0)])
    q0 = np.array([[0.5, 0.5, 0.0], [0.5, 1.5, 0.0]])
    q = np.array([_rotate_about(row, np.array([3.0, -2.0]), 0.3) for row in q0])
    opening, slip, rel = end_openings(joints, q0, q)
    np.testing.assert_allclose(opening, 0.0, atol=1e-14)
    np.testing.assert_allclose(slip, 0.0, atol=1e-14)
    assert joint_states(opening)[0] == 0
    q = q0 + [[0.0, 0.0, 0.0], [0.004, 0.002, 0.0]]
    opening, slip, _ = end_openings(joints, q0, q)
    np.testing.assert_allclose(opening, [[0.002, 0.002]])
    np.testing.assert_allclose(np.abs(slip), [[0.004, 0.004]])
    assert joint_states(opening)[0] == 3


def test_resultant_and_eccentricity_from_the_contacts_of_the_joint_only():
    joints = face_joints([SQUARE, SQUARE + (0.0, 1.0), SQUARE + (1.0, 0.0)])
    j = joints.body.tolist().index([0, 1])
    end1 = joints.end[j][1]
    other = joints.end[j][0]
    # 1 N at end 0, 3 N at end 1 (bodies given in either order), 5 N on another joint
    body = [[1, 0], [0, 1], [0, 2]]
    point = [other, end1, [1.0, 0.5]]
    total, ecc = joint_resultants(joints, body, point, [1.0, 3.0, 5.0])
    assert total[j] == 4.0
    np.testing.assert_allclose(ecc[j], (1.0 * -0.5 + 3.0 * 0.5) / 4.0)
    k = joints.body.tolist().index([0, 2])
    assert total[k] == 5.0
    np.testing.assert_allclose(ecc[k], 0.0, atol=1e-15)


def test_unloaded_joint_has_no_eccentricity():
    joints = face_joints([SQUARE, SQUARE + (0.0, 1.0)])
    total, ecc = joint_resultants(joints, np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0))
    assert total[0] == 0.0 and math.isnan(ecc[0])


def test_the_arch_has_29_radial_joints_the_ring_thick_and_two_springing_joints():
    a = build_arch()
    bodies = [*a.blocks, *a.supports]
    joints = face_joints([b.vertices for b in bodies])
    names = [b.name for b in bodies]
    ring = [(names[i], names[k]) for i, k in joints.body if names[i][0] == "v" and names[k][0] == "v"]
    assert len(ring) == 29 and all(int(b[1:]) == int(a_[1:]) + 1 for a_, b in ring)
    lengths = np.hypot(*(joints.end[:, 1] - joints.end[:, 0]).T)
    for (i, k), length in zip(joints.body, lengths):
        if names[i][0] == "v" and names[k][0] == "v":
            assert length == pytest.approx(0.35, rel=1e-9)
    springing = [(names[i], names[k]) for i, k in joints.body if (names[i][0] == "v") != (names[k][0] == "v")]
    assert sorted(springing) == [("left-pier-c17-b2", "v01"), ("v30", "right-pier-c17-b1")]


def test_diff_stats_of_vectors_uses_their_lengths():
    d = diff_stats([[3.0, 4.0], [0.0, 0.0], [1.0, 0.0]], np.zeros((3, 2)))
    assert d == {"median": 1.0, "rms": pytest.approx(math.sqrt(26 / 3)), "max": 5.0, "argmax": 0}


def test_eccentricity_is_read_in_the_moved_body_a_frame():
    joints = face_joints([SQUARE, SQUARE + (0.0, 1.0)])
    q0 = np.array([[0.5, 0.5, 0.0], [0.5, 1.5, 0.0]])
    q = np.array([_rotate_about(row, np.array([-2.0, 5.0]), 0.4) for row in q0])  # both moved rigidly
    e0, e1 = joints.end[0]
    point_now = _rotate_about(np.array([*(0.25 * e0 + 0.75 * e1), 0.0]), np.array([-2.0, 5.0]), 0.4)[:2]
    total, ecc = joint_resultants(joints, [[0, 1]], [point_now], [2.0], q0, q)
    assert total[0] == 2.0
    np.testing.assert_allclose(ecc[0], 0.25, atol=1e-12)  # a quarter of the face from the middle, towards end 1


def test_opening_and_slip_are_read_along_body_a_s_turned_face():
    # The lower block (a) turns by phi about its top-left corner and the upper one (b) slides by s along
    # x: the measures are taken along a's face turned with a (n = R(phi) n0, t = n turned +90 deg), which
    # only a relative rotation together with a slip tells apart from b's face (an O(phi s) difference).
    phi, s = -0.01, 0.003
    joints = face_joints([SQUARE, SQUARE + (0.0, 1.0)])
    q0 = np.array([[0.5, 0.5, 0.0], [0.5, 1.5, 0.0]])
    q = np.array([_rotate_about(q0[0], np.array([0.0, 1.0]), phi), q0[1] + (s, 0.0, 0.0)])
    opening, slip, rel = end_openings(joints, q0, q)
    right = int(joints.end[0][1, 0] > joints.end[0][0, 0])  # the end at x = 1
    # end (0, 1): on a it stays, on b it moved to (s, 1); end (1, 1): on a at (cos phi, 1 + sin phi), on b
    # at (1 + s, 1); n = (-sin phi, cos phi), t = (-cos phi, -sin phi)
    np.testing.assert_allclose(opening[0, 1 - right], -s * math.sin(phi), rtol=1e-12)
    np.testing.assert_allclose(slip[0, 1 - right], -s * math.cos(phi), rtol=1e-12)
    np.testing.assert_allclose(opening[0, right], -(1.0 + s) * math.sin(phi), rtol=1e-12)
    np.testing.assert_allclose(slip[0, right], 1.0 - (1.0 + s) * math.cos(phi), rtol=1e-9)
    np.testing.assert_allclose(rel, [-phi])
