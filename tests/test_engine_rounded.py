"""A corner on a corner in the engine (masonrycli/engine/rounded.py): the rounded corners' normal.

The sharp detection gave a corner on a corner the normal of whichever edge separated the two blocks most, which
a survey's 1 mm rounding turned by 47–87° on the aqueduct: tilted to 0.090 g, the exact aqueduct stood (0.036 mm
in 2 s) and the one rounded to 1 mm collapsed at t = 1.20 s (0.195 s rounded in Lambert-93).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from masonrycli.engine.collision import ContactBuffers, detect_contacts
from masonrycli.engine.narrowphase import collide_polygons
from masonrycli.engine.rounded import CORNER_RADIUS, rounded_normal

import naive_collision as nv
from limit_helpers import surveyed_aqueduct

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
POST = SQUARE - 1.0  # [-1, 0]²: its top-right corner (0, 0) under the square's bottom-left corner
GROUND = np.array([[0.5, -1.0], [2.0, -1.0], [2.0, 0.0], [0.5, 0.0]])  # the square's right half rests on it


def corner_normal(square, post=POST):
    """The engine's normal (post → square) of the corner-on-corner contact, detected as in the time loop
    (detect_contacts: broad phase, narrow phase) with the ground beside it."""
    body_q, start, local, dynamic = nv.model_from_polygons([post, GROUND, square], n_supports=0)
    dynamic[:2] = False
    buffers = ContactBuffers(start)
    count = detect_contacts(body_q, start, local, dynamic, 1e-3, buffers)
    c = buffers.view()
    rows = np.flatnonzero((c.contact_body[:count, 0] == 0) & (c.contact_body[:count, 1] == 2))
    assert rows.size == 1
    return c.contact_normal[rows[0]]


@pytest.mark.parametrize(
    "vertex, shift",
    [(0, (0.001, 0.0)), (0, (0.0, 0.001)), (1, (0.0, 0.001)), (1, (0.001, -0.0005)), (3, (-0.001, 0.0))],
)
def test_a_millimetre_turns_a_corner_on_a_corners_normal_by_degrees(vertex, shift):
    """Both corners are right angles: the rounded ones touch on the diagonal. Moving one of the square's
    vertices by 1 mm (its corner, or the far end of an edge, which turns that edge) turns the normal by
    ≲ 1 mm / (2√2 r) = 1.0°; the sharp detection turned it by 45° (to the post's top or side face)."""
    diagonal = np.array([math.sqrt(0.5)] * 2)
    np.testing.assert_allclose(corner_normal(SQUARE), diagonal, atol=1e-15)
    moved = SQUARE.copy()
    moved[vertex] += shift
    normal = corner_normal(moved)
    turn = math.degrees(math.acos(min(1.0, float(normal @ diagonal))))
    assert turn <= 3.0, turn
    assert turn <= math.degrees(0.0011 / (2 * math.sqrt(2) * CORNER_RADIUS)), turn


def test_a_rotated_survey_turns_the_normal_by_degrees():
    """The whole pair turned by 1 mm over a block (1e-3 rad) about a far point, then a vertex rounded to 1 mm:
    the normal turns with the pair (0.06°) and the rounding (≤ 1°), not by a quadrant."""
    turned = [nv.rotate(p, 1e-3, centre=(37.0, -12.0)) for p in (SQUARE, POST, GROUND)]
    rounded = [np.round(p, 3) for p in turned]
    body_q, start, local, dynamic = nv.model_from_polygons([rounded[1], rounded[2], rounded[0]])
    dynamic[:2] = False
    buffers = ContactBuffers(start)
    count = detect_contacts(body_q, start, local, dynamic, 2e-3, buffers)
    c = buffers.view()
    rows = np.flatnonzero((c.contact_body[:count, 0] == 0) & (c.contact_body[:count, 1] == 2))
    diagonal = nv.rotate(np.array([[math.sqrt(0.5)] * 2]), 1e-3)[0]
    turn = math.degrees(math.acos(min(1.0, float(c.contact_normal[rows[0]] @ diagonal))))
    assert rows.size == 1 and turn <= 3.0, turn


def test_a_corner_on_a_face_keeps_the_detected_normal_bit_for_bit():
    """Away from a face's ends the rounded normal is the face's: the detected one is kept to the bit, and so
    are the contacts of a joint (two points): the built-in wall and arch at rest keep their contacts."""
    for shift in (0.3, 0.05, -0.6, -0.95):
        tilted = nv.rotate(SQUARE, 0.2, centre=(0.0, 0.0)) + np.array([shift, 0.0])
        ground = np.array([[-1.0, -1.0], [2.0, -1.0], [2.0, 0.0], [-1.0, 0.0]])
        _, normal, _, _ = collide_polygons(ground, tilted + np.array([0.0, 1e-4]), 1e-3)
        np.testing.assert_array_equal(normal, [[0.0, 1.0]])
    _, normal, _, _ = collide_polygons(POST, SQUARE - np.array([0.5, 0.0]), 1e-3)
    np.testing.assert_array_equal(normal, [[0.0, 1.0], [0.0, 1.0]])


def test_the_rounded_normal_is_the_closest_points_of_the_eroded_polygons():
    """Against shapely (mitred inward buffer, nearest points) on random convex pairs near each other."""
    rng = np.random.default_rng(7)
    compared = 0
    for _ in range(400):
        a = nv.random_convex_polygon(rng, aspect=float(rng.choice([0.6, 1.0, 1.7])))
        b = nv.rotate(nv.random_convex_polygon(rng), rng.uniform(0.0, 2.0 * math.pi))
        b = b - b.mean(axis=0) + a.mean(axis=0) + rng.normal(0.0, 0.6, 2)
        ours, theirs = rounded_normal(a, b), nv.rounded_normal(a, b, CORNER_RADIUS)
        assert (ours is None) == (theirs is None)
        if ours is not None:
            compared += 1
            np.testing.assert_allclose(ours[0], theirs, atol=1e-10)
            swapped = rounded_normal(b, a)
            np.testing.assert_array_equal(swapped[0], 0.0 - ours[0])  # the same pair of points, either order
    assert compared > 200


def test_a_block_thinner_than_two_radii_keeps_the_detected_normal():
    sliver = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.03], [0.0, 0.03]])
    assert rounded_normal(sliver, POST) is None
    _, normal, _, _ = collide_polygons(POST, sliver + np.array([0.0, 1e-4]), 1e-3)
    assert abs(float(normal[0] @ np.array([math.sqrt(0.5)] * 2))) < 0.99  # a face's normal, as detected


@pytest.mark.slow
def test_the_tilted_aqueduct_stands_exact_and_rounded_to_a_millimetre(tmp_path):
    """Tilted to 0.090 g (limit.verify's run: fixed supports, NLGS at 1e-6) for 2 s: the exact drawing and the
    ones rounded to 1 mm at the origin and in Lambert-93 all stand (moved < 0.1 mm; before: 0.036 mm exact,
    collapsed at t = 1.20 s and 0.195 s rounded)."""
    from masonrycli.limit.analysis import analyse
    from masonrycli.limit.problem import LiveLoad
    from masonrycli.limit.verify import run_check

    for name, digits, dx, dy in (
        ("exact", 12, 0.0, 0.0),
        ("origin", 3, 0.0, 0.0),
        ("l93", 3, 700000.0004, 6600000.0006),
    ):
        structure = surveyed_aqueduct(tmp_path, name, digits, dx, dy)
        result = analyse(structure, LiveLoad())
        check = run_check(structure, result, 0.090 / result.load_factor)
        assert not check.collapsed and check.max_displacement < 1e-4, (name, check.time, check.max_displacement)
