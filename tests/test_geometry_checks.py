"""Polygon normalisation and assembly validation: every error names the body, on one line."""

import time

import numpy as np
import pytest
from shapely.geometry import Polygon, box

from geometry_library import (
    Assembly,
    Block,
    GeometryError,
    Support,
    build_aqueduct,
    polygon_from_coords,
    validate_assembly,
)

SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]


def raises_one_line(match: str, fn, *args, **kwargs) -> str:
    with pytest.raises(GeometryError, match=match) as info:
        fn(*args, **kwargs)
    message = str(info.value)
    assert "\n" not in message
    return message


def test_normalises_orientation_closing_repeat_and_collinear_vertices():
    cw_closed = [[0, 0], [0, 1], [0.5, 1], [1, 1], [1, 0], [0.5, 0], [0, 0]]
    poly = polygon_from_coords(cw_closed, 0, "a")
    xy = np.asarray(poly.exterior.coords)[:-1]
    assert len(xy) == 4  # the two mid-edge points are gone
    assert poly.exterior.is_ccw
    assert poly.area == pytest.approx(1.0)


def test_float_noise_on_a_straight_edge_is_not_a_reflex_vertex():
    # A clipped edge with a vertex 1e-17 m off the line, as shapely produces.
    xy = [[0, 0], [0.3, 0], [0.3, 0.1 + 1e-17], [0.3, 0.2], [0, 0.2]]
    assert len(polygon_from_coords(xy, 3, "n").exterior.coords) == 5


@pytest.mark.parametrize(
    "coords, message",
    [
        ([[0, 0], [2, 0], [2, 2], [1, 0.5], [0, 2]], "not convex"),
        ([[0, 0], [1, 0], [0, 0]], "fewer than 3 distinct"),
        ([[0, 0], [1, 0], [1, 0], [0, 0]], "fewer than 3 distinct"),
        ([[0, 0], [1, 1], [1, 0], [0, 1]], "self-intersects"),
        ([[0, 0], [1, 0], [2, 0], [3, 0]], "zero area"),
        ([[0, 0], [1e-6, 0], [1e-6, 1e-6], [0, 1e-6]], "zero or too small"),
        ([[0, 0], [1e4, 0], [1e4, 1e4], [0, 1e4]], "absurd"),
        ([[0, 0], [1, 0], [np.nan, 1]], "NaN or infinite"),
        ([[0, 0], [1, 0], [np.inf, 1]], "NaN or infinite"),
        # Found by hypothesis: products of such coordinates overflow and the convexity test accepted it.
        ([[0, 0], [-1e300, 1e300], [0, 5], [2.4e288, -1.8e8]], "vertex 1 at"),
        ([[0, 0], [1, 0], [1, 2e6], [0, 1]], "vertex 2 at .* is absurd"),
    ],
)
def test_bad_polygons_are_rejected_naming_the_block(coords, message):
    text = raises_one_line(message, polygon_from_coords, coords, 7, "c3-b2")
    assert text.startswith('block 8 ("c3-b2"): ')  # index 7: the eighth block, numbered from 1


def asm(*polys, supports=(), names=None):
    names = names or [f"b{i}" for i in range(len(polys))]
    return Assembly(tuple(Block(p, n) for p, n in zip(polys, names)), tuple(supports))


GROUND = Support(box(-5, -1, 5, 0), "ground")


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


def _counting(monkeypatch):
    """Count passes of the polygon clean-up (checks.normalise_coords) from here on."""
    from geometry_library import checks

    calls = [0]
    real = checks.normalise_coords

    def counted(coords, label):
        calls[0] += 1
        return real(coords, label)

    monkeypatch.setattr(checks, "normalise_coords", counted)
    return calls


@pytest.mark.parametrize(
    "builder, options",
    [("wall", {}), ("wall", {"blocks": 248}), ("arch", {"voussoirs": 300}), ("aqueduct", {})],
    ids=["wall-51", "wall-248", "arch-300", "aqueduct"],
)
def test_built_polygons_are_cleaned_once(builder, options, monkeypatch):
    """A builder's polygons are normalised when built and not again by validate_assembly (it ran the clean-up
    twice: 2 × 8070 passes for an 8000-voussoir arch, ~0.2 ms each); what validate_assembly finds is what the
    second pass found, as the clean-up gives a normalised ring back unchanged."""
    from geometry_library import checks
    from geometry_library.builders import BUILDERS

    calls = _counting(monkeypatch)
    assembly = BUILDERS[builder](**options).build()
    bodies = assembly.blocks + assembly.supports
    assert calls[0] == len(bodies)
    warnings = validate_assembly(assembly)
    assert calls[0] == len(bodies)  # 2 × len(bodies) before
    for body in bodies:  # idempotent: a second pass gives each polygon back exactly
        again = checks.normalise_coords(np.asarray(body.polygon.exterior.coords)[:, :2], body.name)
        np.testing.assert_array_equal(again, np.asarray(body.polygon.exterior.coords)[:-1])
    checks._NORMALISED.clear()  # forget them: validate_assembly cleans every body up again, same answer
    assert validate_assembly(assembly) == warnings
    assert calls[0] == 3 * len(bodies)


def test_a_polygon_not_made_by_the_clean_up_is_still_checked(monkeypatch):
    """The skip is by identity: a hand-made polygon, even one equal to a cleaned-up one, is cleaned up and
    checked; a non-convex one is still refused."""
    made = polygon_from_coords(SQUARE, 0, "a")
    calls = _counting(monkeypatch)
    ground = Support(box(-1, -1, 2, 0), "ground")
    assert validate_assembly(Assembly((Block(made, "a"),), (ground,))) == []
    assert calls[0] == 1  # the ground only
    assert validate_assembly(Assembly((Block(Polygon(made.exterior.coords), "a"),), (ground,))) == []
    assert calls[0] == 3
    concave = Polygon([(0, 0), (2, 0), (2, 2), (1, 0.5), (0, 2)])
    raises_one_line(r'block 1 \("a"\): polygon is not convex', validate_assembly, Assembly((Block(concave, "a"),)))
