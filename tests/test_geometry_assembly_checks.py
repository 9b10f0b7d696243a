"""geometry_library/assembly_checks.py: validate_assembly refuses in one line naming the bodies (not convex,
holes, overlapping pairs - every pair named -, duplicate names, bad roles and densities), accepts overlaps within
the area and depth tolerances, warns of no support and of a block touching nothing, and checks 350 blocks
quickly; overlap_depth is the overlap's minimum width."""

import time

import pytest
from geometry_helpers import GROUND, asm, raises_one_line
from shapely import affinity
from shapely.geometry import Polygon, box

from geometry_library import Assembly, Block, GeometryError, Support, build_aqueduct, validate_assembly
from geometry_library.assembly_checks import overlap_depth


def test_valid_stack_passes_without_warnings():
    a = asm(box(0, 0, 1, 1), box(0, 1, 1, 2), supports=[GROUND])
    assert validate_assembly(a) == []


def test_non_convex_block_in_assembly_is_named():
    bad = Polygon([(0, 1), (2, 1), (2, 3), (1, 1.5), (0, 3)])
    text = raises_one_line("not convex", validate_assembly, asm(box(0, 0, 2, 1), bad, names=["a", "c3-b2"]))
    assert text.startswith('block 2 ("c3-b2")')


def test_holes_are_rejected():
    holed = Polygon(box(0, 0, 1, 1).exterior.coords, [box(0.4, 0.4, 0.6, 0.6).exterior.coords])
    text = raises_one_line("hole", validate_assembly, asm(holed, names=["h"]))
    assert text.startswith('block 1 ("h")')


def test_overlapping_blocks_name_both_and_the_area():
    a = asm(box(0, 0, 1, 1), box(0.9, 0, 1.9, 1), supports=[GROUND], names=["left", "right"])
    text = raises_one_line("overlap", validate_assembly, a)
    assert 'blocks 1 ("left") and 2 ("right")' in text  # numbered from 1, as every message (said 0 and 1)
    assert "0.1 m²" in text


def test_every_overlapping_pair_is_named_in_the_one_line():
    # a wall drawn in QGIS with a few slips: the line named the first pair and "(and 2 more overlapping
    # pair(s))", one more run of check per slip; now the others by name
    row = [box(i, 0, i + 1, 1) for i in range(4)]
    row[1], row[3] = box(1, 0, 2.1, 1), box(2.95, 0, 4, 1)  # into b2, and b3 from the right
    sunk = box(4.5, -0.01, 5, 1)  # into the ground
    a = asm(*row, sunk, supports=[GROUND])
    text = raises_one_line("overlap", validate_assembly, a)
    assert text.startswith('blocks 2 ("b1") and 3 ("b2") overlap by 0.1 m²')
    assert text.endswith("(and 2 more overlapping pairs: b2/b3, b4/ground)")
    many = asm(*[box(0.9 * i, 0, 0.9 * i + 1, 1) for i in range(9)], supports=[GROUND])
    assert raises_one_line("overlap", validate_assembly, many).endswith(
        "(and 7 more overlapping pairs: b1/b2, b2/b3, b3/b4, b4/b5, b5/b6, … (2 more))"
    )


def test_block_sunk_into_a_support_is_an_overlap():
    a = asm(box(0, -0.01, 1, 1), supports=[GROUND], names=["sunk"])
    text = raises_one_line("overlap", validate_assembly, a)
    assert 'block 1 ("sunk")' in text and 'support 1 ("ground")' in text and "0.01 m²" in text


def test_overlap_below_tolerance_is_accepted_and_tolerance_is_configurable():
    a = asm(box(0, 0, 1, 1), box(1 - 1e-12, 0, 2, 1), supports=[GROUND])
    assert validate_assembly(a) == []
    with pytest.raises(GeometryError, match="overlap"):
        validate_assembly(a, overlap_tolerance=1e-13)


def test_duplicate_names():
    a = asm(box(0, 0, 1, 1), box(1, 0, 2, 1), names=["x", "x"], supports=[GROUND])
    text = raises_one_line("duplicate name", validate_assembly, a)
    assert text == 'block 2 ("x"): duplicate name, also used by block 1 ("x")'


def test_block_touching_nothing_is_a_warning():
    a = asm(box(0, 0, 1, 1), box(5, 3, 6, 4), supports=[GROUND], names=["ok", "floating"])
    warnings = validate_assembly(a)
    assert len(warnings) == 1
    assert warnings[0].startswith('block 2 ("floating") touches nothing')
    # A gap below the contact distance (1e-3 m) counts as touching.
    assert validate_assembly(asm(box(0, 5e-4, 1, 1), supports=[GROUND])) == []


def test_no_support_at_all_is_a_warning():
    # a GeoJSON wall whose ground had no "role": "support" ran as 52 falling blocks, reported collapsed
    warnings = validate_assembly(asm(box(0, 0, 1, 1), box(0, 1, 1, 2)))
    assert warnings == [
        "no supports: nothing holds the 2 blocks up, they fall freely (in GeoJSON a feature is a block unless "
        'its properties say "role": "support"; in WKT a line is one unless it starts with "support NAME:")'
    ]
    # a one-line WKT file: "the 1 block up, they fall" and "nearest body inf m away" before
    alone = validate_assembly(asm(box(0, 0, 1, 1), names=["solo"]))
    assert alone[0].startswith("no supports: nothing holds the 1 block up, it falls freely (")
    assert alone[1] == 'block 1 ("solo") touches nothing (it is the only body): it will fall freely'


def test_bad_support_role_and_density():
    with pytest.raises(GeometryError, match=r'support 1 \("ground"\): role'):
        validate_assembly(asm(box(0, 0, 1, 1), supports=[Support(box(-1, -1, 2, 0), "ground", "moving")]))
    bad = Assembly((Block(box(0, 0, 1, 1), "d", density=-1.0),), (GROUND,))
    raises_one_line(r'block 1 \("d"\): density', validate_assembly, bad)


def test_350_blocks_are_checked_quickly():
    aqueduct = build_aqueduct()
    start = time.perf_counter()
    assert validate_assembly(aqueduct) == []
    assert time.perf_counter() - start < 1.0


def test_a_real_1_mm_overlap_is_refused_a_0_1_mm_one_accepted():
    a = Block(box(0, 0, 0.3, 0.2), "a")
    real = asm(a.polygon, box(0.299, 0, 0.599, 0.2), supports=[GROUND], names=["a", "b"])
    # 2e-4 m² into a 0.06 m² block; tolerance 1e-3 × 0.06 m² (a sliver 0.17 mm deep along the 0.3 m face)
    assert raises_one_line("overlap", validate_assembly, real) == (
        'blocks 1 ("a") and 2 ("b") overlap by 0.0002 m², 1 mm deep (tolerance 6e-05 m², 0.5 mm deep)'
    )
    rounding = asm(a.polygon, box(0.2999, 0, 0.5999, 0.2), supports=[GROUND], names=["a", "b"])
    assert validate_assembly(rounding) == []  # 2e-5 m²


def test_a_corner_7_mm_inside_the_ground_is_refused_though_its_area_is_within_tolerance():
    """A 0.3 × 0.2 m block at 45° whose corner is d inside the ground overlaps it by d² (4.9e-5 m² at 7 mm,
    under the 6e-5 m² area tolerance): it was accepted, seven times deeper than the 1 mm contact distance.
    The overlap's depth (its minimum width: the corner's distance to the ground's face) must be ≤ 0.5 mm.
    0.6 mm (3.6e-7 m²) is also refused: the union screen, which clears by area, used to let it through."""

    def corner_in(depth):
        block = affinity.translate(affinity.rotate(box(0, 0, 0.3, 0.2), 45, origin=(0, 0)), 0, -depth)
        return asm(block, supports=[GROUND], names=["tilted"])

    assert raises_one_line("overlap", validate_assembly, corner_in(7e-3)) == (
        'block 1 ("tilted") and support 1 ("ground") overlap by 4.9e-05 m², 7 mm deep (tolerance 6e-05 m², 0.5 mm deep)'
    )
    assert "0.6 mm deep" in raises_one_line("overlap", validate_assembly, corner_in(6e-4))
    assert validate_assembly(corner_in(4e-4)) == []
    assert overlap_depth(box(0, 0, 0.3, 1e-4)) == pytest.approx(1e-4)  # a face sunk 0.1 mm: 0.1 mm


def test_an_overlap_just_under_a_decimetre_is_said_in_millimetres_written_out():
    # a stone traced 99.7 mm into its neighbour said "1e+02 mm deep"
    a = Block(box(0, 0, 0.3, 0.2), "a")
    deep = asm(a.polygon, box(0.2003, 0, 0.5003, 0.2), supports=[GROUND], names=["a", "b"])
    said = raises_one_line("overlap", validate_assembly, deep)
    assert ", 100 mm deep (tolerance" in said and "e+" not in said, said
