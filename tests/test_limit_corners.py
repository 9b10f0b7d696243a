"""A corner on a corner in limit analysis (masonrycli/limit/corners.py): the rounded corners' normal, no friction.

The aqueduct's λ moved by 18 % when a survey's coordinates were rounded to 1 mm (0.1122 exact, 0.1327 rounded at
the origin, 0.1053 rounded in Lambert-93): ten single-point contacts where a voussoir's corner meets a spandrel
block's corner took whichever edge's normal the detection's last digit picked, and the friction cone with it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import box

from masonrycli.limit.analysis import analyse
from masonrycli.limit.corners import CORNER_RADIUS, rounded_corner_normal
from masonrycli.limit.joints import find_joints
from masonrycli.limit.problem import LiveLoad
from masonrycli.model import build_model

from limit_helpers import scenario, surveyed_aqueduct


def block_on_a_corner(friction: float = 0.6):
    """A unit block whose bottom face rests from x = 0.5 to 1 on a ground, and whose bottom-left corner (0, 0)
    sits on the top-right corner of a second support, [-1, 0] × [-1, 0]: a corner on a corner."""
    return scenario(
        [("block", box(0.0, 0.0, 1.0, 1.0))],
        [("ground", box(0.5, -1.0, 2.0, 0.0)), ("post", box(-1.0, -1.0, 0.0, 0.0))],
        friction,
    )


def test_a_corner_on_a_corner_pushes_along_the_diagonal_without_friction():
    joints = find_joints(build_model(block_on_a_corner()))
    corner = joints.contact_point[:, 0] == 0.0
    assert corner.sum() == 1 and joints.joint_count == 2
    # both corners are right angles, so the rounded ones touch on the diagonal, whatever the radius
    np.testing.assert_allclose(np.abs(joints.contact_normal[corner][0]), [math.sqrt(0.5)] * 2, atol=1e-12)
    np.testing.assert_array_equal(joints.contact_friction(0.6), np.where(corner, 0.0, 0.6))


def test_the_block_on_a_corner_leans_on_it_until_the_push_through_its_centroid_carries_it_all():
    """By hand: pushed towards −x, the block is held by the post's push f (1, 1)/√2 at (0, 0), whose line passes
    through the centroid (0.5, 0.5), and by the ground's forces N_a, N_b ≥ 0, |T| ≤ μ N at x = 0.5 and 1.
    Moments about the centroid: 0.5 T_a + 0.5 (N_b + T_b) = 0; so x: f/√2 − N_b = λ W, y: f/√2 + N_a + N_b = W,
    and λ W = W − N_a − 2 N_b ≤ W: λ = 1, all of the weight on the post's corner. (The detection gave that corner
    the post's vertical face's normal and its friction cone: λ = 0.474.)"""
    result = analyse(block_on_a_corner(), LiveLoad("horizontal", "-x"))
    assert result.load_factor == pytest.approx(1.0, abs=1e-6)


def test_a_millimetre_turns_the_normal_by_degrees_not_by_a_quadrant():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    post = square - 1.0
    exact, grip = rounded_corner_normal(square, post)
    assert grip == 0.0
    for shift in ([0.001, -0.0007], [-0.0007, 0.001], [0.0007, 0.0007]):
        moved, _ = rounded_corner_normal(square, post + np.array(shift))
        turn = math.degrees(math.acos(min(1.0, float(moved @ exact))))
        # the eroded corners are 2 √2 r apart on the diagonal: a 1 mm shift turns their line by ≲ 1 mm / (2√2 r)
        assert turn < math.degrees(0.0013 / (2 * math.sqrt(2) * CORNER_RADIUS)) + 1e-9


def test_a_corner_on_a_face_keeps_the_faces_normal_and_friction():
    joints = find_joints(build_model(scenario([("b", box(0.0, 0.0, 1.0, 1.0))], [("g", box(-1, -1, 3, 0))], 0.6)))
    np.testing.assert_array_equal(joints.contact_normal, [[0.0, -1.0], [0.0, -1.0]])
    np.testing.assert_array_equal(joints.contact_friction(0.6), [0.6, 0.6])


def _surveyed(tmp_path, name: str, digits: int, dx: float = 0.0, dy: float = 0.0) -> float:
    """λ of the aqueduct moved by (dx, dy) and rounded to ``digits`` decimals (limit_helpers.surveyed_aqueduct)."""
    return analyse(surveyed_aqueduct(tmp_path, name, digits, dx, dy), LiveLoad()).load_factor


@pytest.mark.slow
def test_the_aqueducts_load_factor_survives_a_surveys_millimetre(tmp_path):
    """Rounded to 1 mm near the origin and in Lambert-93 (rounded there: other millimetres), λ within 1 % of the
    exact drawing's: the rounding moves each vertex by ≤ 0.7 mm, so the joints' ends (the lever arms) by ≤ 0.35 %
    of a 0.2 m course and the corners' normals by a few degrees; the old normals moved λ by −6 … +18 %."""
    exact = _surveyed(tmp_path, "exact", 12)
    for name, dx, dy in (
        ("origin", 0.0, 0.0),
        ("lambert93", 700000.0004, 6600000.0006),
        ("lambert93b", 651233.517, 6861988.262),
    ):
        assert _surveyed(tmp_path, name, 3, dx, dy) == pytest.approx(exact, rel=0.01), name
