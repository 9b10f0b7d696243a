"""GeoJSON / WKT reading and writing: round trips and one-line errors naming file and feature."""

import json

import numpy as np
import pytest
from shapely.geometry import box

from geometry_library import (
    Assembly,
    Block,
    GeometryError,
    Support,
    build_arch,
    read_geojson,
    read_wkt,
    write_geojson,
    write_wkt,
)


def same_assembly(a: Assembly, b: Assembly, *, materials: bool = True) -> None:
    assert [x.name for x in a.blocks] == [x.name for x in b.blocks]
    assert [(s.name, s.role) for s in a.supports] == [(s.name, s.role) for s in b.supports]
    for x, y in zip(a.blocks + a.supports, b.blocks + b.supports):
        np.testing.assert_array_equal(x.vertices, y.vertices)
    if materials:
        for x, y in zip(a.blocks, b.blocks):
            assert (x.density, x.thickness, x.velocity) == (y.density, y.thickness, y.velocity)


def test_geojson_round_trip_is_exact(tmp_path):
    arch = build_arch()
    blocks = list(arch.blocks)
    blocks[3] = Block(blocks[3].polygon, blocks[3].name, 2100.0, 0.6, (0.1, -0.2, 0.3))
    original = Assembly(
        tuple(blocks), (arch.supports[0], Support(arch.supports[1].polygon, "right-foundation", "driven"))
    )
    path = write_geojson(original, tmp_path / "arch.geojson")
    data = json.loads(path.read_text())
    assert data["type"] == "FeatureCollection" and len(data["features"]) == 100
    assert data["features"][-1]["properties"] == {
        "role": "support",
        "name": "right-foundation",
        "support_role": "driven",
    }
    same_assembly(original, read_geojson(path))


def feature(coords, **props):
    return {"type": "Feature", "properties": props, "geometry": {"type": "Polygon", "coordinates": [coords]}}


def write(tmp_path, features, name="in.geojson"):
    path = tmp_path / name
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


SQ = [[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]


def test_geojson_defaults_and_properties(tmp_path):
    path = write(
        tmp_path,
        [
            feature([[0, 0], [4, 0], [4, -1], [0, -1], [0, 0]], role="support", name="pad"),
            feature(SQ),
            feature([[0, 1], [1, 1], [1, 2], [0, 2], [0, 1]], name="top", density=2000, thickness=0.5),
        ],
    )
    a = read_geojson(path, density=1800.0, thickness=0.8)
    assert [(b.name, b.density, b.thickness) for b in a.blocks] == [("block-1", 1800.0, 0.8), ("top", 2000.0, 0.5)]
    assert [(s.name, s.role) for s in a.supports] == [("pad", "fixed")]
    assert a.supports[0].polygon.exterior.is_ccw


def test_geojson_a_multipolygon_of_one_part_is_that_polygon(tmp_path):
    # QGIS saves a polygon layer as MultiPolygons: "geometry must be a Polygon, got 'MultiPolygon'" refused every
    # feature of a wall edited there
    plain = [feature(SQ, name="b"), feature([[-2, -1], [3, -1], [3, 0], [-2, 0], [-2, -1]], role="support")]
    multi = [dict(f, geometry={"type": "MultiPolygon", "coordinates": [f["geometry"]["coordinates"]]}) for f in plain]
    a, b = read_geojson(write(tmp_path, plain, "plain.geojson")), read_geojson(write(tmp_path, multi, "multi.geojson"))
    assert [x.polygon.equals_exact(y.polygon, 0) for x, y in zip(a.blocks + a.supports, b.blocks + b.supports)] == [
        True,
        True,
    ]


def test_geojson_a_null_property_is_not_given(tmp_path):
    # a GIS writes an empty attribute cell as null: the block was named "None", a null density refused
    nulls = dict(role=None, name=None, density=None, thickness=None, velocity=None)
    ground = feature([[-2, -1], [3, -1], [3, 0], [-2, 0], [-2, -1]], role="support", name="g", support_role=None)
    a = read_geojson(write(tmp_path, [feature(SQ, **nulls), ground]), density=1800.0, thickness=0.8)
    assert [(b.name, b.density, b.thickness) for b in a.blocks] == [("block-1", 1800.0, 0.8)]
    assert [(s.name, s.role) for s in a.supports] == [("g", "fixed")]
    # an empty cell may be written as "" too (a blank name said 'name "" must not be empty')
    a = read_geojson(write(tmp_path, [feature(SQ, name=""), feature(SQ, name="  "), ground]))
    assert [b.name for b in a.blocks] == ["block-1", "block-2"]


def test_geojson_properties_it_does_not_use_are_listed_with_their_first_body(tmp_path):
    # a per-block friction or a misspelt densty was ignored without a word; a GIS's feature ids are not news
    ground = feature([[-2, -1], [3, -1], [3, 0], [-2, 0], [-2, -1]], role="support", name="g", fid=1, colour="grey")
    blocks = [feature(SQ, name="a", densty=2000, FID=2, friction=0.7), feature(SQ, name="b", friction=0.7, id=3)]
    unknown: dict = {}
    a = read_geojson(write(tmp_path, [ground, *blocks]), density=1800.0, unknown=unknown)
    assert unknown == {
        "colour": 'feature 1, support 1 ("g")',
        "densty": 'feature 2, block 1 ("a")',
        "friction": 'feature 2, block 1 ("a")',
    }
    assert a.blocks[0].density == 1800.0  # densty is not density
    unknown.clear()  # a null is not given: nothing to report
    read_geojson(write(tmp_path, [feature(SQ, name="a", friction=None, density=2000.0)]), unknown=unknown)
    assert unknown == {}


def test_geojson_a_property_of_the_other_role_is_listed_as_not_used(tmp_path):
    # a support's velocity was not read (the support stayed fixed) and nothing said so
    ground = feature([[-2, -1], [3, -1], [3, 0], [-2, 0], [-2, -1]], role="support", name="g", velocity=[1, 0, 0])
    pad = feature([[3, -1], [4, -1], [4, 0], [3, 0], [3, -1]], role="support", name="p", density=2000, thickness=1)
    block = feature(SQ, name="a", support_role="driven", density=1800.0, velocity=[0, 0, 0])
    unknown: dict = {}
    a = read_geojson(write(tmp_path, [ground, pad, block]), unknown=unknown)
    assert unknown == {
        "velocity": 'feature 1, support 1 ("g")',
        "density": 'feature 2, support 2 ("p")',
        "thickness": 'feature 2, support 2 ("p")',
        "support_role": 'feature 3, block 1 ("a")',
    }
    assert a.blocks[0].density == 1800.0 and [s.role for s in a.supports] == ["fixed", "fixed"]


def one_line_error(fn, *args):
    with pytest.raises(GeometryError) as info:
        fn(*args)
    text = str(info.value)
    assert "\n" not in text
    return text


def test_a_utf8_byte_order_mark_is_read_utf16_and_binary_files_named(tmp_path):
    """Notepad's "UTF-8 with BOM": a GeoJSON was "invalid JSON (Unexpected UTF-8 BOM …)", a WKT file's first label
    "'\\ufeffblock a' … is not a label" (a scenario file reads it). A UTF-16 file was "byte 0, 0xff: a character
    saved in another encoding, such as Windows-1252", a binary one "not a UTF-8 text file" at some line."""
    from geometry_library.wkt import read_wkt

    wkt = "block a: POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\nsupport g: POLYGON ((-5 -1, 5 -1, 5 0, -5 0, -5 -1))\n"
    (tmp_path / "plain.wkt").write_text(wkt, encoding="utf-8")
    (tmp_path / "bom.wkt").write_text(wkt, encoding="utf-8-sig")
    plain = read_wkt(tmp_path / "plain.wkt")
    marked = read_wkt(tmp_path / "bom.wkt")
    assert [b.name for b in marked.blocks] == ["a"] and marked.blocks[0].polygon.equals(plain.blocks[0].polygon)
    text = write_geojson(plain, tmp_path / "plain.geojson").read_text(encoding="utf-8")
    (tmp_path / "bom.geojson").write_text(text, encoding="utf-8-sig")
    marked = read_geojson(tmp_path / "bom.geojson")
    assert [b.name for b in marked.blocks] == ["a"] and marked.blocks[0].polygon.equals(plain.blocks[0].polygon)
    for name in ("u16.geojson", "u16.wkt"):
        (tmp_path / name).write_text(wkt, encoding="utf-16")
    assert one_line_error(read_geojson, tmp_path / "u16.geojson") == (
        f"{tmp_path / 'u16.geojson'}: a UTF-16 text file (it starts with UTF-16's byte-order mark); save it as UTF-8"
    )
    assert "u16.wkt: a UTF-16 text file" in one_line_error(read_wkt, tmp_path / "u16.wkt")
    (tmp_path / "bin.geojson").write_bytes(bytes(range(256)))
    assert one_line_error(read_geojson, tmp_path / "bin.geojson").endswith(
        "bin.geojson: not a text file (it holds NUL bytes: a binary file)"
    )


def test_geojson_errors_name_file_and_feature(tmp_path):
    missing = one_line_error(read_geojson, tmp_path / "nope.geojson")
    assert "nope.geojson: cannot read file" in missing

    # a GIS export in the Windows code page: it said "(UnicodeDecodeError: 'utf-8' codec can't decode byte 0xe9 …)"
    latin = tmp_path / "latin.geojson"
    latin.write_bytes(b'{"type": "FeatureCollection",\n "features": [{"properties": {"name": "pi\xe9droit"}}]}')
    assert one_line_error(read_geojson, latin) == (
        f"{latin}:2: not a UTF-8 text file (byte 71, 0xe9: a character saved in another encoding, such as "
        "Windows-1252); save it as UTF-8 (a GIS export: choose the UTF-8 encoding)"
    )

    bad_json = tmp_path / "bad.geojson"
    bad_json.write_text("{ not json")
    assert "bad.geojson: invalid JSON" in one_line_error(read_geojson, bad_json)

    not_fc = tmp_path / "fc.geojson"
    not_fc.write_text(json.dumps({"type": "Feature"}))
    assert "expected a GeoJSON FeatureCollection, got 'Feature'" in one_line_error(read_geojson, not_fc)
    not_fc.write_text(json.dumps({"name": "masonry", "version": "0.1.0"}))  # it said "got None"
    text = one_line_error(read_geojson, not_fc)
    assert text.endswith('expected a GeoJSON FeatureCollection, got a JSON object with no "type" (not GeoJSON)')
    not_fc.write_text("[1, 2]")
    assert one_line_error(read_geojson, not_fc).endswith("got a JSON list")

    point = {"type": "Feature", "properties": {"name": "p"}, "geometry": {"type": "Point", "coordinates": [0, 0]}}
    text = one_line_error(read_geojson, write(tmp_path, [feature(SQ), point], "pt.geojson"))
    assert "pt.geojson: feature 2" in text and "must be a Polygon, got 'Point'" in text

    concave = [[0, 0], [2, 0], [2, 2], [1, 0.5], [0, 2], [0, 0]]
    text = one_line_error(read_geojson, write(tmp_path, [feature(SQ), feature(concave, name="c3-b2")], "cc.geojson"))
    assert text.startswith(str(tmp_path / "cc.geojson") + ': feature 2: block 2 ("c3-b2"): polygon is not convex')

    holed = {"type": "Feature", "properties": {"name": "h"}, "geometry": {"type": "Polygon", "coordinates": [SQ, SQ]}}
    assert "hole" in one_line_error(read_geojson, write(tmp_path, [holed], "h.geojson"))

    text = one_line_error(
        read_geojson, write(tmp_path, [feature(SQ, role="support", support_role="wobbly")], "r.geojson")
    )
    assert "feature 1" in text and "support_role" in text

    text = one_line_error(read_geojson, write(tmp_path, [feature(SQ, density="heavy")], "d.geojson"))
    assert "feature 1" in text and "density" in text


_BAD_FEATURES = [  # (feature 2 of a file whose feature 1 is a good block, the body named or None, message)
    ("not a feature", {"type": "Point"}, None, "not a GeoJSON Feature"),
    ("properties", {"type": "Feature", "properties": [1], "geometry": None}, None, "'properties' must be an object"),
    ("role", feature(SQ, role="roof", name="B12"), None, "role must be 'block', 'support' or 'fill', got 'roof'"),
    (
        "point",
        {"type": "Feature", "properties": {"name": "B12"}, "geometry": {"type": "Point"}},
        "block 2",
        "geometry must be a Polygon, got 'Point'",
    ),
    (
        "empty",
        {"type": "Feature", "properties": {"name": "B12"}, "geometry": {"type": "Polygon"}},
        "block 2",
        "Polygon has no coordinates",
    ),
    (
        "holes",
        {"type": "Feature", "properties": {"name": "B12"}, "geometry": {"type": "Polygon", "coordinates": [SQ, SQ]}},
        "block 2",
        "1 hole(s)",
    ),
    (
        "multipolygon",
        {
            "type": "Feature",
            "properties": {"name": "B12"},
            "geometry": {"type": "MultiPolygon", "coordinates": [[SQ]] * 2},
        },
        "block 2",
        "a MultiPolygon of 2 parts; a feature is one body (split it into single parts",
    ),
    ("coordinates", feature([[0, 0], [1, "x"], [1, 1]], name="B12"), "block 2", "coordinates must be [x, y] number"),
    ("concave", feature([[0, 0], [2, 0], [2, 2], [1, 0.5], [0, 2], [0, 0]], name="B12"), "block 2", "not convex"),
    ("nan", feature([[0, 0], [1, 0], [1, float("nan")], [0, 0]], name="B12"), "block 2", "vertex 2 has a NaN"),
    ("density", feature(SQ, name="B12", density="heavy"), "block 2", "density"),
    ("thickness", feature(SQ, name="B12", thickness=-1), "block 2", "thickness"),
    ("velocity", feature(SQ, name="B12", velocity=[1, 2]), "block 2", "velocity must be [vx, vy, omega]"),
    ("support role", feature(SQ, role="support", name="B12", support_role="wobbly"), "support 1", "support_role"),
    (
        "support concave",
        feature([[0, 0], [2, 0], [2, 2], [1, 0.5], [0, 2]], role="support", name="B12"),
        "support 1",
        "not convex",
    ),
]


@pytest.mark.parametrize("case, bad, body, message", _BAD_FEATURES, ids=[row[0] for row in _BAD_FEATURES])
def test_geojson_errors_name_a_feature_in_one_format(tmp_path, case, bad, body, message):
    """Every GeoJSON error names the feature as ``FILE: feature K: `` and, once its role is read, the body as
    every other message does (``block 2 ("B12")``), both numbered from 1 as the user counts them: a
    polygon's checks said ``feature 1: block 1 ("B12")`` and the reader's own ``feature 1 (block 1 "B12")``
    before, and both counted from 0 ("feature 0" was the first)."""
    path = write(tmp_path, [feature(SQ, name="A1"), bad])
    text = one_line_error(read_geojson, path)
    start = f"{path}: feature 2: " + (f'{body} ("B12"): ' if body else "")
    assert text.startswith(start), text
    assert message in text[len(start) :], text


def test_wkt_lines_labels_and_supports(tmp_path):
    path = tmp_path / "blocks.wkt"
    path.write_text(
        "# two blocks and a ground\n"
        "POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\n"
        "\n"
        "top: POLYGON ((0 1, 1 1, 1 2, 0 2, 0 1))\n"
        "support ground driven: POLYGON ((-2 -1, 3 -1, 3 0, -2 0, -2 -1))\n"
    )
    a = read_wkt(path, density=2000.0)
    assert [b.name for b in a.blocks] == ["block-1", "top"]  # block-1 first, as in a TOML file
    assert a.blocks[0].density == 2000.0
    assert [(s.name, s.role) for s in a.supports] == [("ground", "driven")]


def test_wkt_collection_file_and_multipolygon(tmp_path):
    path = tmp_path / "multi.wkt"
    path.write_text("MULTIPOLYGON (((0 0, 1 0, 1 1, 0 1, 0 0)),\n ((1 0, 2 0, 2 1, 1 1, 1 0)))\n")
    assert read_wkt(path).block_count == 2
    path.write_text(
        "GEOMETRYCOLLECTION (POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0)), POLYGON ((1 0, 2 0, 2 1, 1 1, 1 0)),"
        " POLYGON ((0 1, 1 1, 1 2, 0 2, 0 1)))"
    )
    assert [b.name for b in read_wkt(path).blocks] == ["block-1", "block-2", "block-3"]


def test_wkt_round_trip(tmp_path):
    arch = build_arch()
    back = read_wkt(write_wkt(arch, tmp_path / "arch.wkt"))
    same_assembly(arch, back)


def test_wkt_errors_name_file_and_line(tmp_path):
    path = tmp_path / "bad.wkt"
    path.write_text("POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\nPOLYGON ((0 0, 1 0\n")
    text = one_line_error(read_wkt, path)
    assert "bad.wkt: line 2: cannot parse WKT" in text
    path.write_text("POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\nPOINT (0.5 2)\n")
    assert "line 2" in one_line_error(read_wkt, path)
    path.write_text("a: POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\nc3-b2: POLYGON ((0 0, 2 0, 2 2, 1 0.5, 0 2, 0 0))\n")
    assert 'line 2: block 2 ("c3-b2"): polygon is not convex' in one_line_error(read_wkt, path)
    with pytest.raises(GeometryError, match="cannot read file"):
        read_wkt(tmp_path / "missing.wkt")


@pytest.mark.parametrize(
    "line, what",
    [
        (": POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))", "nothing before the colon"),  # said "Unknown type: ':'"
        ("  :POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))", "nothing before the colon"),
        (
            "c3 b2: POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))",
            "'c3 b2' before the colon is not a label",
        ),  # "Unknown type: 'C3'"
    ],
)
def test_wkt_a_line_whose_label_is_not_one_says_what_is_expected(line, what, tmp_path):
    path = tmp_path / "labels.wkt"
    path.write_text("support ground: POLYGON ((-2 -1, 3 -1, 3 0, -2 0, -2 -1))\n" + line + "\n")
    assert one_line_error(read_wkt, path) == (
        f"{path}: line 2: {what}; expected 'NAME: POLYGON ((…))', 'block NAME: …', 'support [NAME] [fixed|driven]: "
        "…', 'fill NAME [DENSITY]: …' or the WKT alone (a name has no spaces or colons)"
    )


@pytest.mark.parametrize(
    "line, label",
    [
        ("support ground POLYGON ((-2 -1, 3 -1, 3 0, -2 0, -2 -1))", "support ground"),
        ("b1 polygon ((0 0, 1 0, 1 1, 0 0))", "b1"),
    ],
)
def test_wkt_a_label_without_its_colon_is_named(line, label, tmp_path):
    # "support ground POLYGON ((…))" said "cannot parse WKT (ParseException: Unknown type: 'SUPPORT')"
    path = tmp_path / "labels.wkt"
    path.write_text("POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\n" + line + "\n")
    assert one_line_error(read_wkt, path) == (
        f"{path}: line 2: {label!r} before POLYGON: a label ends with a colon ('{label}: POLYGON ((…))')"
    )


@pytest.mark.parametrize("name", ["polygon1", "Polygon-left", "multipolygon_a", "GeometryCollection2"])
def test_wkt_a_name_that_starts_like_a_wkt_type_is_a_name(name, tmp_path):
    """A label is a name before a colon, and WKT has no colon: "polygon1: POLYGON …" (which
    "block polygon1: …" reads) was taken for WKT and refused ("'polygon1' before the colon is not a label")."""
    path = tmp_path / "names.wkt"
    path.write_text(
        f"support ground: POLYGON ((-2 -1, 3 -1, 3 0, -2 0, -2 -1))\n{name}: POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\n"
    )
    assert [b.name for b in read_wkt(path).blocks] == [name]


def test_write_wkt_rejects_names_it_cannot_label(tmp_path):
    a = Assembly((Block(box(0, 0, 1, 1), "has space"),))
    with pytest.raises(GeometryError, match="cannot be written to WKT"):
        write_wkt(a, tmp_path / "x.wkt")


def test_wkt_a_role_without_a_name_is_that_role_named_by_number(tmp_path):
    # "support : POLYGON …" (the name left out before the colon) was read as a *block* named "support",
    # and "support fixed: …" as a support named "support"; the format says an unlabelled body is named
    # by number, so they are supports support-1, support-2 (and "block: …" is block-1).
    path = tmp_path / "roles.wkt"
    path.write_text(
        "block: POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\n"
        "support : POLYGON ((-2 -1, 3 -1, 3 0, -2 0, -2 -1))\n"
        "support driven: POLYGON ((-2 -2, 3 -2, 3 -1, -2 -1, -2 -2))\n"
        "block block: POLYGON ((0 1, 1 1, 1 2, 0 2, 0 1))\n"  # a block named "block", as write_wkt writes it
        "support fixed fixed: POLYGON ((-2 -3, 3 -3, 3 -2, -2 -2, -2 -3))\n"  # a support named "fixed"
    )
    a = read_wkt(path)
    assert [b.name for b in a.blocks] == ["block-1", "block"]
    assert [(s.name, s.role) for s in a.supports] == [
        ("support-1", "fixed"),
        ("support-2", "driven"),
        ("fixed", "fixed"),
    ]


def test_wkt_round_trip_keeps_blocks_named_like_a_support_role(tmp_path):
    # write_wkt writes a block named "fixed" as "block fixed: …": a block has no support role, so that is its
    # name (the role-only rule read it as an unnamed block, "block-1", and the round trip lost the name)
    a = Assembly(
        (Block(box(0, 0, 1, 1), "fixed"), Block(box(0, 1, 1, 2), "driven")),
        (Support(box(-2, -1, 3, 0), "ground", "fixed"),),
    )
    same_assembly(read_wkt(write_wkt(a, tmp_path / "named.wkt")), a, materials=False)


def test_geojson_roles_are_read_in_any_case(tmp_path):
    # role = "Support" was "feature 2: role must be 'block' or 'support', got 'Support'"
    ground = feature([[-2, -1], [3, -1], [3, 0], [-2, 0], [-2, -1]], role="Support", name="g", support_role="Driven")
    a = read_geojson(write(tmp_path, [feature(SQ, name="a", role="BLOCK"), ground]))
    assert [b.name for b in a.blocks] == ["a"] and [(s.name, s.role) for s in a.supports] == [("g", "driven")]


def test_arch_support_roles_are_read_in_any_case():
    arch = build_arch(voussoirs=10, pier_courses=2, right_role="Driven")
    assert [s.role for s in arch.supports] == ["fixed", "driven"]


def test_geojson_numbers_written_with_their_units(tmp_path):
    """A GIS attribute typed as text with its unit: the value to write and the unit it is read in."""
    path = write(tmp_path, [feature(SQ, name="a", density="2400 kg/m3")])
    with pytest.raises(
        GeometryError, match=r"density must be a number, not a string \(write 2400, in kg/m³, without the unit\)"
    ):
        read_geojson(path)
    path = write(tmp_path, [feature(SQ, name="a", thickness="50 cm")], name="cm.geojson")
    with pytest.raises(
        GeometryError, match=r"thickness must be a number, not a string \(it is read in m: convert 50 cm to m"
    ):
        read_geojson(path)


def test_every_refused_polygon_is_named_in_the_one_line(tmp_path):
    # a wall drawn with three dented stones: the line named the first and stopped, one run of check per stone
    dent = [[0, 0], [1, 0], [1, 1], [0.5, 0.6], [0, 1]]  # reflex vertex at (0.5, 0.6)
    bowtie = [[0, 0], [1, 1], [1, 0], [0, 1]]
    square = [[0, 0], [1, 0], [1, 1], [0, 1]]

    def shifted(ring, dx):
        return [[x + dx, y] for x, y in ring] + [[ring[0][0] + dx, ring[0][1]]]

    rings = [square, dent, square, bowtie, dent]
    features = [
        {
            "type": "Feature",
            "properties": {"name": f"s{i}"},
            "geometry": {"type": "Polygon", "coordinates": [shifted(r, 2 * i)]},
        }
        for i, r in enumerate(rings)
    ]
    path = tmp_path / "wall.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    with pytest.raises(GeometryError) as info:
        read_geojson(path)
    text = str(info.value)
    assert text.startswith(f'{path}: feature 2: block 2 ("s1"): polygon is not convex')
    assert text.endswith('(and 2 more polygons refused: block 4 ("s3"), block 5 ("s4"))') and "\n" not in text
    wkt = tmp_path / "wall.wkt"
    wkt.write_text(
        "\n".join(
            f"s{i}: POLYGON (({', '.join(f'{x} {y}' for x, y in shifted(r, 2 * i))}))" for i, r in enumerate(rings)
        )
    )
    with pytest.raises(GeometryError) as info:
        read_wkt(wkt)
    assert str(info.value).startswith(f'{wkt}: line 2: block 2 ("s1"): polygon is not convex')
    assert str(info.value).endswith('(and 2 more polygons refused: block 4 ("s3"), block 5 ("s4"))')
