"""Joint openings, sliding ratio and hinges against hand computations."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.analysis.mechanism import OPENING, JointTracker, mobilised_friction
from masonrycli.outputs.frame import CONTACT_OPEN, CONTACT_SLIP, CONTACT_STICK

# Block 0: unit square on [0,1]x[0,1]; block 1: unit square on [0,1]x[1,2]; body 2: a support below.
Q0 = np.array([[0.5, 0.5, 0.0], [0.5, 1.5, 0.0], [0.5, -0.5, 0.0]])
BODY = np.array([[0, 1], [0, 1], [0, 2], [0, 2]])
POINT = np.array([[0.0, 1.0], [1.0, 1.0], [0.0, 0.0], [1.0, 0.0]])
NORMAL = np.array([[0.0, 1.0], [0.0, 1.0], [0.0, -1.0], [0.0, -1.0]])
GAP = np.zeros(4)


def tracker():
    return JointTracker(BODY, POINT, NORMAL, GAP, Q0, block_count=2, mean_block_weight=10.0)


def test_joints_are_face_contacts():
    jt = tracker()
    np.testing.assert_array_equal(jt.joint_body, [[0, 1], [0, 2]])


def test_opening_of_a_lifted_and_rocked_block():
    jt = tracker()
    q = Q0.copy()
    q[1, 1] += 0.002  # lift the upper block 2 mm
    np.testing.assert_allclose(jt.opening(q), [0.002, 0.002, 0.0, 0.0], atol=1e-15)
    # Rock the upper block clockwise (φ < 0) about its bottom-right corner (1, 1): its bottom-left
    # corner rises by sin|φ| (lever 1 m), the right corner stays.
    phi = -0.01
    q = Q0.copy()
    c, s = np.cos(phi), np.sin(phi)
    centroid_rel = np.array([-0.5, 0.5])
    q[1, :2] = np.array([1.0, 1.0]) + np.array(
        [c * centroid_rel[0] - s * centroid_rel[1], s * centroid_rel[0] + c * centroid_rel[1]]
    )
    q[1, 2] = phi
    np.testing.assert_allclose(jt.opening(q), [-np.sin(phi), 0.0, 0.0, 0.0], atol=1e-14)
    fields = jt.block_fields(q, np.zeros((0, 2), int), np.zeros((0, 2)), np.zeros(0, np.int8))
    np.testing.assert_allclose(fields["block_max_opening"], [-np.sin(phi), -np.sin(phi)], atol=1e-14)


def test_opening_is_relative_to_the_initial_gap_and_follows_rotation_of_a():
    jt = JointTracker(BODY[:2], POINT[:2], NORMAL[:2], np.array([1e-4, 1e-4]), Q0, 2, 10.0)
    q = Q0.copy()
    q[:2, 0] += 0.3  # both blocks translate together: nothing opens
    np.testing.assert_allclose(jt.opening(q), [1e-4, 1e-4], atol=1e-15)


def test_sliding_ratio_is_load_weighted():
    jt = tracker()
    body = np.array([[0, 1], [0, 1], [0, 2], [0, 2]])
    r = np.array([[0.0, 3.0], [0.0, 1.0], [0.0, 4.0], [0.0, 0.0]])
    status = np.array([CONTACT_SLIP, CONTACT_STICK, CONTACT_SLIP, CONTACT_OPEN], np.int8)
    f = jt.block_fields(Q0, body, r, status)
    # block 0: slipping load 3 + 4 of closed load 3 + 1 + 4; block 1: 3 of 3 + 1.
    np.testing.assert_allclose(f["block_sliding_ratio"], [7 / 8, 3 / 4])


def test_hinge_needs_one_loaded_end_and_an_opened_other_end():
    jt = tracker()
    dt = 1e-3
    body = np.array([[0, 1], [0, 2], [0, 2]])
    q = Q0.copy()
    # Rocked upper block: only its right corner (one contact) is loaded.
    phi = -10 * OPENING  # clockwise about the right corner: the left end opens by ~10 × OPENING
    q[1, :2] = [1.0 - 0.5 * np.cos(phi) - 0.5 * np.sin(phi), 1.0 - 0.5 * np.sin(phi) + 0.5 * np.cos(phi)]
    q[1, 2] = phi
    rn = np.array([1.0, 0.5, 0.5]) * dt * 10.0
    hinged = jt.hinged(q, body, rn, dt)
    np.testing.assert_array_equal(hinged, [True, False])
    # Not opened (flat): both ends detected, only one loaded -> still no hinge.
    body2 = np.array([[0, 1], [0, 1]])
    assert not jt.hinged(Q0, body2, np.array([1.0, 0.0]) * dt * 10.0, dt)[0]
    # Too little load: not reported.
    assert not jt.hinged(q, body, np.array([1e-6, 0.5, 0.5]) * dt, dt)[0]


@pytest.mark.parametrize("n_blocks", [0])
def test_no_joints(n_blocks):
    jt = JointTracker(np.zeros((0, 2), int), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), Q0, 2, 1.0)
    assert jt.hinged(Q0, np.zeros((0, 2), int), np.zeros(0), 1e-3).shape == (0,)


def test_reported_status_keeps_slip_only_when_sliding():
    from masonrycli.analysis.mechanism import SLIP_SPEED, reported_status

    status = np.array([CONTACT_SLIP, CONTACT_SLIP, CONTACT_STICK, CONTACT_OPEN], np.int8)
    ut = np.array([0.5 * SLIP_SPEED, -2 * SLIP_SPEED, 5.0, 5.0])
    np.testing.assert_array_equal(
        reported_status(status, ut), [CONTACT_STICK, CONTACT_SLIP, CONTACT_STICK, CONTACT_OPEN]
    )


def test_corner_contacts_do_not_count_as_openings():
    # Block 1 touches block 0 only at a corner (one initial contact): sliding there is not an opening.
    body = np.array([[0, 1]])
    jt = JointTracker(body, np.array([[1.0, 1.0]]), np.array([[0.6, 0.8]]), np.zeros(1), Q0, 2, 10.0)
    q = Q0.copy()
    q[1, 0] += 0.01
    assert jt.opening(q)[0] > 0  # the end itself separates along its normal
    f = jt.block_fields(q, np.zeros((0, 2), int), np.zeros((0, 2)), np.zeros(0, np.int8))
    np.testing.assert_array_equal(f["block_max_opening"], [0.0, 0.0])


def test_mobilised_friction_is_the_used_share_of_coulomb_friction():
    # μ = 0.6. Stick at half the limit, slip at the limit (either sign of r_t), an open contact carrying
    # a stale impulse, and a closed contact without normal impulse (no friction available).
    r = np.array([[0.3, 1.0], [-1.2, 2.0], [1.2, 2.0], [0.5, 1.0], [0.1, 0.0]])
    status = np.array([CONTACT_STICK, CONTACT_SLIP, CONTACT_SLIP, CONTACT_OPEN, CONTACT_STICK], dtype=np.int8)
    got = mobilised_friction(r, status, 0.6)
    np.testing.assert_allclose(got, [0.5, 1.0, 1.0, 0.0, 0.0], rtol=1e-15)
    assert mobilised_friction(np.zeros((0, 2)), np.zeros(0, dtype=np.int8), 0.6).shape == (0,)


def test_blocks_facing_across_a_gap_are_not_a_joint():
    # A raised alert distance also detects block 1's top face against a block 2 hanging 0.15 m above it:
    # two initial "contacts" with gap 0.15 m. They were a joint opened by 150 mm from the start (a wall at
    # rest reported damaged); only contacts within JOINT_GAP are joint ends.
    from masonrycli.analysis.mechanism import JOINT_GAP

    q0 = np.vstack([Q0, [[0.5, 2.65, 0.0]]])
    body = np.vstack([BODY, [[1, 3], [1, 3]]])
    point = np.vstack([POINT, [[0.0, 2.0], [1.0, 2.0]]])
    normal = np.vstack([NORMAL, [[0.0, 1.0], [0.0, 1.0]]])
    gap = np.concatenate([GAP, [0.15, 0.15]])
    jt = JointTracker(body, point, normal, gap, q0, block_count=3, mean_block_weight=10.0)
    np.testing.assert_array_equal(jt.joint_body, [[0, 1], [0, 2]])
    f = jt.block_fields(q0, np.zeros((0, 2), int), np.zeros((0, 2)), np.zeros(0, np.int8))
    np.testing.assert_array_equal(f["block_max_opening"], [0.0, 0.0, 0.0])
    # a joint built with a gap within JOINT_GAP (a hand-drawn geometry) stays a joint
    gap[4:] = 0.5 * JOINT_GAP
    jt = JointTracker(body, point, normal, gap, q0, block_count=3, mean_block_weight=10.0)
    np.testing.assert_array_equal(jt.joint_body, [[0, 1], [0, 2], [1, 3]])


def test_key_row_finds_what_a_binary_search_finds_from_any_hint():
    """engine.joints._key_row (galloping from the last row found) against np.searchsorted: the same row for
    every key present, −1 for keys absent, below, between and above, whatever the hint."""
    from masonrycli.engine.joints import _key_row

    rng = np.random.default_rng(2)
    for n in (0, 1, 2, 7, 300):
        key = np.unique(rng.integers(0, 4 * n + 1, n).astype(np.int64))[: max(n, 0)]
        for k in range(-2, 4 * n + 4):
            i = int(np.searchsorted(key, k))
            expected = i if i < len(key) and key[i] == k else -1
            for hint in {0, len(key) // 2, max(len(key) - 1, 0), len(key), int(rng.integers(0, len(key) + 1))}:
                assert _key_row(key, np.int64(k), hint) == expected, (n, k, hint)
