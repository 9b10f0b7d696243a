"""geometry_library/trim.py: two overlapping bodies cut along the chord of their overlap (they then touch, stay
convex, give up only the overlap: a wide ground under a stone sunk at one end is left as it is), an overlap
deeper than the depth given refused naming the pair — against figures worked out by hand."""

import numpy as np
import pytest
from shapely.geometry import Polygon, box

from geometry_library import Assembly, Block, GeometryError, Support, validate_assembly
from geometry_library.trim import trim_overlaps


def two_stones(overlap: float, ground: bool = False) -> Assembly:
    """Two 1 × 0.5 m stones side by side, the right one drawn ``overlap`` m into the left one."""
    blocks = (Block(box(0, 0, 1, 0.5), "L"), Block(box(1 - overlap, 0, 2 - overlap, 0.5), "R"))
    supports = (Support(box(-1, -0.5, 3, 0.0), "ground"),) if ground else ()
    return Assembly(blocks, supports)


def test_overlapping_neighbours_are_cut_along_the_chord_of_their_overlap():
    # R 2 mm into L: each gives up 1 mm of its 0.5 m face, 5e-4 m² = 0.1 % of its area; they then meet at x = 0.999
    trimmed, note = trim_overlaps(two_stones(0.002, ground=True), 0.003)
    left, right = trimmed.blocks
    assert left.polygon.bounds == pytest.approx((0, 0, 0.999, 0.5), abs=1e-12)
    assert right.polygon.bounds == pytest.approx((0.999, 0, 1.998, 0.5), abs=1e-12)
    assert left.polygon.intersection(right.polygon).area == pytest.approx(0.0, abs=1e-15)
    assert left.polygon.distance(right.polygon) == pytest.approx(0.0, abs=1e-12)  # they touch: a contact
    assert trimmed.supports[0].polygon.equals(box(-1, -0.5, 3, 0.0))  # touching the ground is no overlap
    assert validate_assembly(trimmed) == []
    assert note.startswith("1 overlapping pair trimmed") and "deepest 2 mm" in note and "0.10% of a body's area" in note


def test_a_corner_sunk_into_the_ground_is_cut_and_both_stay_convex():
    # a stone tilted 1° with its left corner 1 mm into the ground (a triangle 1 mm deep, 5.7 cm long)
    c, s = np.cos(np.radians(1)), -np.sin(np.radians(1))  # turned 1° anticlockwise
    ring = np.array([[0, 0], [0.4, 0], [0.4, 0.2], [0, 0.2]]) @ np.array([[c, s], [-s, c]]).T + [0, -0.001]
    stone = Assembly((Block(Polygon(ring), "S"),), (Support(box(-1, -0.5, 1, 0.0), "ground"),))
    trimmed, _ = trim_overlaps(stone, 0.003)
    after = [trimmed.blocks[0].polygon, trimmed.supports[0].polygon]
    assert after[0].intersection(after[1]).area == pytest.approx(0.0, abs=1e-15)
    assert all(p.equals(p.convex_hull) for p in after)
    assert validate_assembly(trimmed) == []


def test_a_wide_ground_under_a_stone_sunk_at_one_end_is_left_as_it_is():
    # the stone's bottom crosses the ground's top 5.7 cm from its left corner, 1 mm deep there: the chord is the
    # ground's top, so the stone is cut flat on it and the ground keeps its 4 m top (a cut through the overlap's
    # middle, tilted 0.5°, lowered the ground's far end by 17 mm: the stones there were left in the air)
    c, s = np.cos(np.radians(1)), -np.sin(np.radians(1))
    ring = np.array([[0, 0], [0.4, 0], [0.4, 0.2], [0, 0.2]]) @ np.array([[c, s], [-s, c]]).T + [0, -0.001]
    ground = box(-2, -0.5, 2, 0.0)
    trimmed, _ = trim_overlaps(Assembly((Block(Polygon(ring), "S"),), (Support(ground, "ground"),)), 0.003)
    assert trimmed.supports[0].polygon.hausdorff_distance(ground) < 1e-12
    assert trimmed.blocks[0].polygon.bounds[1] == pytest.approx(0.0, abs=1e-12)
    assert trimmed.blocks[0].polygon.area == pytest.approx(
        Polygon(ring).area - 0.5 * 0.001 * 0.001 / np.tan(np.radians(1)), rel=1e-6
    )


def test_an_overlap_deeper_than_the_depth_given_is_refused_naming_the_pair():
    with pytest.raises(
        GeometryError, match=r'block 1 \("L"\) and block 2 \("R"\) overlap 5 mm deep, more than the 3 mm'
    ):
        trim_overlaps(two_stones(0.005), 0.003)
