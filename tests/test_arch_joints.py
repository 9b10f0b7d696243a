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


def _naive_face_joints(polygons, tol=1e-6, min_length=1e-3):
    """face_joints the slow way, for the check below: every pair of bodies, every pair of their edges, in
    plain Python floats; an edge pair is a joint when b's edge lies on a's line (cross products within tol)
    with the bodies on either side (the edges run opposite ways when both polygons turn the same way) and
    their shared stretch is longer than min_length. Per pair of bodies the longest, the first on a tie."""
    turn = [
        math.copysign(1.0, sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(p, p[1:] + p[:1]))) for p in polygons
    ]
    found = {}
    for i, p in enumerate(polygons):
        for j, r in enumerate(polygons):
            if j <= i:
                continue
            for k in range(len(p)):
                (ax, ay), (bx, by) = p[k], p[(k + 1) % len(p)]
                la = math.hypot(bx - ax, by - ay)
                if la <= min_length:
                    continue
                tx, ty = (bx - ax) / la, (by - ay) / la
                for m in range(len(r)):
                    (cx, cy), (dx, dy) = r[m], r[(m + 1) % len(r)]
                    lb = math.hypot(dx - cx, dy - cy)
                    if lb <= min_length:
                        continue
                    off_c, off_d = tx * (cy - ay) - ty * (cx - ax), tx * (dy - ay) - ty * (dx - ax)
                    if abs(off_c) > tol or abs(off_d) > tol:  # not on a's line
                        continue
                    if turn[i] * turn[j] * ((dx - cx) * tx + (dy - cy) * ty) > -lb * (1 - 1e-9):  # same side
                        continue
                    lo_, hi_ = sorted(((cx - ax) * tx + (cy - ay) * ty, (dx - ax) * tx + (dy - ay) * ty))
                    lo_, hi_ = max(lo_, 0.0), min(hi_, la)
                    if hi_ - lo_ > min_length and hi_ - lo_ > found.get((i, j), (0.0,))[0]:
                        found[(i, j)] = (hi_ - lo_, [(ax + lo_ * tx, ay + lo_ * ty), (ax + hi_ * tx, ay + hi_ * ty)])
    return found


def test_face_joints_are_those_of_a_naive_search():
    """The numpy search of face_joints against every pair of edges tried in plain Python: the built arch (100
    bodies) and a hand-made set (a clockwise block, turned ones, a short overlap, a gap under tol, a step, a tie)."""
    turn = np.array([[math.cos(0.3), -math.sin(0.3)], [math.sin(0.3), math.cos(0.3)]])
    hand = [
        SQUARE,
        SQUARE[::-1] + (1.0, 0.0),  # clockwise, beside 0
        SQUARE + (0.9995, 1.0),  # on 0 over 0.5 mm only (< min_length): a joint with 1, not with 0
        SQUARE + (0.0, -1.0 - 5e-7),  # under 0 by a gap within tol
        SQUARE @ turn.T + (5.0, 0.0),
        (SQUARE @ turn.T) * (1.0, -1.0) + (5.0, 0.0),  # its mirror: touches it at a vertex only
        SQUARE @ turn.T + (5.0, 0.0) + turn[:, 0],  # face to face with the turned one
        np.array([[2.0, 0.0], [3.0, 0.0], [3.0, 0.5], [2.5, 0.5], [2.5, 1.0], [2.0, 1.0]]),  # a step beside 1
        np.array(
            [[10.0, 0.0], [13.0, 0.0], [13.0, 2.0], [12.0, 2.0], [12.0, 1.0], [11.0, 1.0], [11.0, 2.0], [10.0, 2.0]]
        ),
        SQUARE + (11.0, 1.0),  # in the U's notch: three faces of 1 m, the first found is kept
    ]
    a = build_arch()
    for polygons in (hand, [np.asarray(b.vertices) for b in (*a.blocks, *a.supports)]):
        joints = face_joints(polygons)
        naive = _naive_face_joints([[tuple(map(float, v)) for v in p] for p in polygons])
        assert joints.body.tolist() == sorted(map(list, naive))
        np.testing.assert_allclose(joints.end, [naive[k][1] for k in sorted(naive)], rtol=0, atol=1e-12)
        length = np.hypot(*(joints.end[:, 1] - joints.end[:, 0]).T)
        np.testing.assert_allclose(length, [naive[k][0] for k in sorted(naive)], rtol=0, atol=1e-12)
        assert len(joints.body) == (6 if polygons is hand else 165)
