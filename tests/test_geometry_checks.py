"""Polygon normalisation (geometry_library/checks.py) and what it means for an assembly's check: every error
names the body, on one line. The assembly's own checks (overlaps, names, warnings): test_geometry_assembly_checks.py."""

import dataclasses

import numpy as np
import pytest
from geometry_helpers import asm, raises_one_line
from shapely.geometry import Polygon, box

from geometry_library import (
    Assembly,
    Block,
    Support,
    build_aqueduct,
    build_arch,
    build_wall,
    checks,
    float32,
    polygon_from_coords,
    validate_assembly,
)

SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]


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
        ([[0, 0], [1e-6, 0], [1e-6, 1e-6], [0, 1e-6]], r"zero or too small$"),  # near the origin: no degrees hint
        # a 0.3 × 0.2 m block exported by QGIS in longitude / latitude (GeoJSON's default) said only "too small"
        (
            [[4.63, 43.68], [4.63 + 2.7e-6, 43.68], [4.63 + 2.7e-6, 43.68 + 1.8e-6], [4.63, 43.68 + 1.8e-6]],
            r"zero or too small \(longitude / latitude in degrees\? coordinates are metres: export in a projected CRS\)",
        ),
        ([[0, 0], [1e4, 0], [1e4, 1e4], [0, 1e4]], "absurd"),
        ([[0, 0], [1, 0], [np.nan, 1]], "NaN or infinite"),
        ([[0, 0], [1, 0], [np.inf, 1]], "NaN or infinite"),
        # Found by hypothesis: products of such coordinates overflow and the convexity test accepted it.
        ([[0, 0], [-1e300, 1e300], [0, 5], [2.4e288, -1.8e8]], "vertex 1 at"),
        # a survey in a map grid (Lambert-93 northings are 6.1e6-7.1e6 m) was called "absurd (coordinates must
        # be metres …)": they are metres, far from the origin
        ([[0, 0], [1, 0], [1, 2e6], [0, 1]], r"vertex 2 at \(1, 2e\+06\) is more than 1e\+06 m from the origin .*UTM"),
    ],
)
def test_bad_polygons_are_rejected_naming_the_block(coords, message):
    text = raises_one_line(message, polygon_from_coords, coords, 7, "c3-b2")
    assert text.startswith('block 8 ("c3-b2"): ')  # index 7: the eighth block, numbered from 1


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
    checked, once (the clean-up leaves it as it was, so it is remembered: an unpickled scenario's polygons
    were cleaned at every Scenario made from it); a non-convex one is still refused."""
    made = polygon_from_coords(SQUARE, 0, "a")
    calls = _counting(monkeypatch)
    ground = Support(box(-1, -1, 2, 0), "ground")
    assert validate_assembly(Assembly((Block(made, "a"),), (ground,))) == []
    assert calls[0] == 1  # the ground only
    copy = Block(Polygon(made.exterior.coords), "a")
    assert validate_assembly(Assembly((copy,), (ground,))) == []
    assert calls[0] == 2  # the copy; the ground, already clean as drawn, is remembered
    assert validate_assembly(Assembly((copy,), (ground,))) == []
    assert calls[0] == 2
    assert checks.normalise_polygon(copy.polygon, 0, "a") is copy.polygon
    concave = Polygon([(0, 0), (2, 0), (2, 2), (1, 0.5), (0, 2)])
    raises_one_line(r'block 1 \("a"\): polygon is not convex', validate_assembly, Assembly((Block(concave, "a"),)))


# --- Tolerances relative to the block: float32 / 0.1 mm rounding accepted and cleaned, real defects refused ---


def f32(xy) -> np.ndarray:
    """Coordinates as a float32 export writes them (np.float32(x).item() of each)."""
    return np.asarray(xy, dtype=np.float64).astype(np.float32).astype(np.float64)


def with_midpoints(xy) -> np.ndarray:
    """A vertex in the middle of every edge, as a CAD polyline split where a neighbour's corner is."""
    xy = np.asarray(xy, dtype=np.float64)
    return np.stack([xy, (xy + np.roll(xy, -1, axis=0)) / 2], axis=1).reshape(-1, 2)


def exported(assembly: Assembly, transform) -> Assembly:
    """The assembly with every body's vertices passed through ``transform`` (unchecked polygons)."""
    blocks = tuple(dataclasses.replace(b, polygon=Polygon(transform(b.vertices))) for b in assembly.blocks)
    supports = tuple(dataclasses.replace(s, polygon=Polygon(transform(s.vertices))) for s in assembly.supports)
    return Assembly(blocks, supports)


def assert_same_ring(got, want, tol: float) -> None:
    """Same vertices, in the same cyclic order, each within ``tol`` (m) of the reference."""
    got, want = np.asarray(got)[:, :2], np.asarray(want)[:, :2]
    if np.array_equal(got[0], got[-1]):
        got = got[:-1]
    if np.array_equal(want[0], want[-1]):
        want = want[:-1]
    assert got.shape == want.shape, (got, want)
    errors = [np.abs(np.roll(got, k, axis=0) - want).max() for k in range(len(got))]
    assert min(errors) <= tol, (min(errors), tol)


def _cleaned(assembly: Assembly, reference: Assembly, tol_rel: float, tol_abs: float = 0.0) -> None:
    """Each body of ``assembly`` normalised is the body of ``reference`` within ``tol_rel`` × the structure's
    largest coordinate (float32 rounds relative to the coordinate) + ``tol_abs`` m."""
    bodies = [(b, "block") for b in assembly.blocks] + [(s, "support") for s in assembly.supports]
    refs = reference.blocks + reference.supports
    largest = max(float(np.abs(body.vertices).max()) for body in refs)
    for (body, kind), ref in zip(bodies, refs):
        poly = polygon_from_coords(np.asarray(body.polygon.exterior.coords), 0, body.name, kind)
        assert_same_ring(poly.exterior.coords, ref.vertices, tol_rel * largest + tol_abs)


@pytest.mark.parametrize("build", [build_wall, build_arch, build_aqueduct], ids=["wall", "arch", "aqueduct"])
@pytest.mark.parametrize("midpoints", [False, True], ids=["as-built", "mid-edge-vertices"])
def test_a_float32_export_is_accepted_and_cleaned_back_to_the_float64_polygons(build, midpoints):
    """The built-in structures rounded to float32 (GIS / CAD export), also with a vertex in the middle of
    every edge: no error, no warning, and the normalised polygons are the float64 ones within 1e-6 of the
    structure's size (its largest coordinate). With the 1e-9 tolerances the arch's rounded mid-edge vertices that fall inside their edge
    were "not convex" (block 36 "v02"), and the aqueduct as built overlapped by 8e-9 m² where a spandrel
    block's rounded corner leaves the voussoir's sloping extrados (blocks 36 "v02" and 106 "wall-c02-b04")."""
    built = build()
    export = (lambda xy: f32(with_midpoints(xy))) if midpoints else f32
    rounded = exported(built, export)
    assert validate_assembly(rounded) == []
    _cleaned(rounded, built, 1e-6)
    if midpoints and build is build_arch:
        sides = []
        for block in built.blocks:
            xy = export(block.vertices)  # CCW: cross < 0 at a vertex inside its edge (reflex), > 0 outside
            e_in, e_out = xy - np.roll(xy, 1, axis=0), np.roll(xy, -1, axis=0) - xy
            cross = (e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0])[1::2]  # at the midpoints
            sides += np.sign(cross).tolist()
        assert sides.count(-1) > 10 and sides.count(1) > 10, sides


@pytest.mark.parametrize("build", [build_arch, build_aqueduct], ids=["arch", "aqueduct"])
def test_a_drawing_exact_to_0_1_mm_is_accepted(build):
    """Coordinates rounded to 0.1 mm (CAD), with a vertex in the middle of every edge: accepted without a
    warning, each vertex within the rounding (0.05 mm per coordinate) of the exact one. The aqueduct
    overlapped by 3e-6 m² (blocks 37 "v03" and 113 "wall-c03-b03") with the 1e-9 m² tolerance."""
    built = build()
    rounded = exported(built, lambda xy: np.round(with_midpoints(xy), 4))
    assert validate_assembly(rounded) == []
    _cleaned(rounded, built, 0.0, 0.5e-4 * np.sqrt(2.0))


def test_the_clean_up_of_rounded_vertices_is_a_fixed_point():
    """A normalised polygon comes back unchanged (the identity cache relies on it), also when rounded
    mid-edge vertices were removed to get it."""
    for block in build_arch().blocks:
        once = checks.normalise_coords(f32(with_midpoints(block.vertices)), block.name)
        np.testing.assert_array_equal(checks.normalise_coords(once, block.name), once)


RECT = [[0, 0], [0.3, 0], [0.3, 0.2]]  # a 0.3 × 0.2 m block, its top edge dented or bulged at the middle


def test_a_real_1_mm_dent_is_refused_a_0_1_mm_one_is_removed():
    # shape tolerance of this block: 2e-3 × its width, area / diagonal = 0.06 / 0.36 m: 0.33 mm
    dent = [*RECT, [0.15, 0.199], [0, 0.2]]
    assert raises_one_line("not convex", polygon_from_coords, dent, 0, "dent") == (
        'block 1 ("dent"): polygon is not convex (reflex vertex at (0.15, 0.199))'
    )
    raises_one_line("not convex", polygon_from_coords, f32(dent), 0, "dent")  # float32 changes nothing
    for y in (0.1999, 0.2001, 0.2 - 3e-4):  # 0.1 mm in, 0.1 mm out, 0.3 mm in: removed
        cleaned = polygon_from_coords([*RECT, [0.15, y], [0, 0.2]], 0, "b")
        assert_same_ring(cleaned.exterior.coords, [*RECT, [0, 0.2]], 0.0)
    bulge = polygon_from_coords([*RECT, [0.15, 0.201], [0, 0.2]], 0, "b")  # 1 mm out: a real, convex vertex
    assert len(bulge.exterior.coords) == 6


def test_a_wide_support_keeps_a_3_mm_crown_and_refuses_a_3_mm_hollow():
    """A 20 × 2 m ground's width (1 m) made its tolerance 4 mm: a 3 mm crown at mid-top was removed, and a
    block resting on it floated 3 mm above the cleaned ground (it fell at t = 0, "touches nothing"); a 3 mm
    hollow was filled. The tolerance stops at half the contact detection distance, as on a 0.3 m block."""
    top = [[-10, -2], [10, -2], [10, 0]]
    crown = polygon_from_coords([*top, [0, 0.003], [-10, 0]], 0, "ground", "support")
    assert_same_ring(crown.exterior.coords, [*top, [0, 0.003], [-10, 0]], 0.0)
    rests = Block(box(-0.15, 0.003, 0.15, 0.203), "b")
    assert validate_assembly(Assembly((rests,), (Support(crown, "ground"),))) == []  # it touches the crown
    assert raises_one_line("not convex", polygon_from_coords, [*top, [0, -0.003], [-10, 0]], 0, "g", "support") == (
        'support 1 ("g"): polygon is not convex (reflex vertex at (0, -0.003))'
    )
    rounded = polygon_from_coords([*top, [0, 1e-4], [-10, 0]], 0, "ground", "support")  # 0.1 mm: removed
    assert_same_ring(rounded.exterior.coords, [*top, [-10, 0]], 0.0)


def test_float32_on_a_local_grid_1000_m_off_is_accepted_with_one_warning():
    """x, y + 1000 m (a site grid) in float32: rounded by at most 2⁻²⁴ × 1003 m = 6e-5 m, a quarter of the smallest block's
    shape tolerance (half blocks 0.15 × 0.2 m: 0.24 mm). Accepted, cleaned to the float64 polygons within that
    rounding, with one line saying so; 10 km off, rounding (6e-4 m) exceeds the tolerance and the split arch
    is refused, saying to shift the coordinates."""
    for built in (build_wall(), build_arch()):
        shifted = exported(built, lambda xy: xy + 1000.0)
        rounded = exported(built, lambda xy: f32(with_midpoints(xy + 1000.0)))
        warnings = validate_assembly(rounded)
        far = f"{max(np.abs(b.vertices).max() for b in shifted.blocks + shifted.supports):,.0f}"
        assert len(warnings) == 1 and warnings[0].startswith(
            f"coordinates are all float32 values reaching {far} m from the origin, where float32 keeps only ±6e-05 m"
        ), warnings
        assert warnings[0].endswith("shift them near the origin or export them in float64 for exact geometry")
        _cleaned(rounded, shifted, 0.0, 2.0 * 2.0**-24 * 1010.0)
        assert validate_assembly(exported(built, lambda xy: f32(xy))) == []  # near the origin: silent
    far = exported(build_arch(), lambda xy: f32(with_midpoints(xy + [1e4, 0.0])))
    assert raises_one_line("not convex", validate_assembly, far) == (
        'block 40 ("v06"): polygon is not convex (reflex vertex at (9998.49, 4.37901)); its coordinates are float32 '
        "values, exact only to ±0.0006 m this far (9,999 m) from the origin: shift them near the origin or export "
        "them in float64"
    )


def test_short_decimals_far_from_the_origin_are_typed_not_float32_rounded():
    # 1 × 0.5 m blocks drawn at x = 5000 m: every coordinate is a float32 value, but nothing was rounded;
    # they were told to "shift them near the origin or export them in float64" (review, 2026-11-27)
    ground = Support(box(4990, -1, 5010, 0), "ground")
    typed = asm(box(5000, 0, 5001, 0.5), box(5001, 0, 5002, 0.5), supports=[ground], names=["a", "b"])
    assert validate_assembly(typed) == []
    # the same blocks 0.3 m over: 5000.3 is no float32 value; rounded to one it is an export, and warned
    over = [box(5000.3, 0, 5001.3, 0.5), box(5001.3, 0, 5002.3, 0.5)]
    exported_f32 = asm(
        *[Polygon(np.asarray(p.exterior.coords).astype(np.float32).astype(np.float64)) for p in over],
        supports=[ground],
        names=["a", "b"],
    )
    warnings = validate_assembly(exported_f32)
    assert warnings == [  # the tolerance of 1 × 0.5 m blocks is the cap, 0.5 mm (not 2e-3 × 0.447 m = 0.89 mm)
        "coordinates are all float32 values reaching 5,010 m from the origin, where float32 keeps only ±0.0003 m "
        "(60% of the narrowest body's shape tolerance, 0.0005 m): shift them near the origin or export them in "
        "float64 for exact geometry"
    ]
    assert float32._significant_digits(5000.5) == 5 and float32._significant_digits(float(np.float32(5000.3))) > 9
