"""Reading a surveyed wall (geometry_library/survey.py): a map grid's coordinates moved near the origin, units,
y pointing down, convex hulls and overlaps trimmed — each against the same wall drawn in metres near the origin
or a figure worked out by hand. The trimming of two bodies: test_geometry_trim.py."""

import json

import numpy as np
import pytest
import surveyed_wall
from shapely.geometry import box

from geometry_library import Assembly, Block, GeometryError, Support, read_geojson, read_wkt, validate_assembly
from geometry_library.survey import Survey
from geometry_library.trim import trim_overlaps

EXACT = dict(slip=0.0, ndigits=9)  # the stones as they tile the face, to a nanometre


def wall_file(tmp_path, name, **options):
    path = tmp_path / name
    surveyed_wall.write(path, **options)
    return path


def vertices(assembly):
    return [b.vertices for b in (*assembly.blocks, *assembly.supports)]


def test_a_wall_in_lambert93_is_read_moved_by_whole_kilometres(tmp_path):
    # every vertex was refused: "more than 1e+06 m from the origin (… move a map grid's … to a local origin)"
    local = read_geojson(wall_file(tmp_path, "local.geojson", **EXACT))
    notes = []
    far = read_geojson(wall_file(tmp_path, "l93.geojson", offset=surveyed_wall.LAMBERT93, **EXACT), notes=notes)
    assert far.block_count == local.block_count == 72 and far.support_count == 1
    # x − 651 000, y − 6 861 000: the local wall plus the offset's last (234.12, 210.55) m
    for a, b in zip(vertices(far), vertices(local)):
        np.testing.assert_allclose(a, b + [234.12, 210.55], rtol=0, atol=1e-8)
    assert validate_assembly(far) == []  # float64 keeps the survey's nanometres there
    assert any("read moved by (-651000, -6861000) m" in n and "add (651000, 6861000)" in n for n in notes), notes


def test_a_refusal_in_a_moved_file_says_how_to_find_its_coordinates_on_the_map(tmp_path):
    path = wall_file(tmp_path, "l93.geojson", offset=surveyed_wall.LAMBERT93, dent=3e-3, dents=1, ndigits=6)
    with pytest.raises(GeometryError, match=r"not convex .* add \(651000, 6861000\) for the map's"):
        read_geojson(path)


def test_a_wall_near_the_origin_is_read_as_it_is(tmp_path):
    # 9 km east: not moved (RECENTRE_BEYOND is 10 km), no note
    notes = []
    near = read_geojson(wall_file(tmp_path, "near.geojson", offset=(9000.0, 0.0), **EXACT), notes=notes)
    assert near.bounds()[0] == pytest.approx(8999.7) and notes == []


def test_millimetres_read_with_their_unit_and_said_when_not(tmp_path):
    local = read_geojson(wall_file(tmp_path, "m.geojson", **EXACT))
    mm = wall_file(tmp_path, "mm.geojson", scale=1000.0, **EXACT)
    for a, b in zip(vertices(read_geojson(mm, survey=Survey(units="mm"))), vertices(local)):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-9)
    # read as metres the foundation's 1.38e6 m² is refused as absurd: the refusal says why
    with pytest.raises(GeometryError, match=r"median \d+ m\): are the coordinates millimetres\? --units mm"):
        read_geojson(mm)


def test_y_pointing_down_is_read_up_and_said_when_not(tmp_path):
    local = read_geojson(wall_file(tmp_path, "up.geojson", **EXACT))
    down = wall_file(tmp_path, "down.geojson", flip_y=True, **EXACT)
    for a, b in zip(vertices(read_geojson(down, survey=Survey(flip_y=True))), vertices(local)):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
    notes = []
    read_geojson(down, notes=notes)  # the ground above the stones: gravity would pull the wall off it
    assert any("the support lies above half the blocks" in n and "--flip-y" in n for n in notes), notes


def square_feature(ring, name):
    closed = [*ring, ring[0]]
    return {"type": "Feature", "properties": {"name": name}, "geometry": {"type": "Polygon", "coordinates": [closed]}}


def test_a_dented_stone_is_read_as_its_hull_with_the_area_it_adds(tmp_path):
    # a 0.4 × 0.2 m stone whose bottom edge is pushed 2 mm in at its middle: the hull adds the triangle
    # 0.4 × 0.002 / 2 = 4e-4 m² to 0.08 − 4e-4 m², i.e. 0.503 %
    dented = [[0, 0], [0.2, 0.002], [0.4, 0], [0.4, 0.2], [0, 0.2]]
    path = tmp_path / "dent.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [square_feature(dented, "S1")]}))
    with pytest.raises(GeometryError, match="not convex"):
        read_geojson(path)
    notes = []
    hulled = read_geojson(path, survey=Survey(convex_hull=True), notes=notes)
    assert hulled.blocks[0].polygon.equals(box(0, 0, 0.4, 0.2))
    assert any(f"adding {4e-4 / (0.08 - 4e-4):.2%}" in n and 'block 1 ("S1")' in n for n in notes), notes


def test_a_stone_of_another_shape_is_not_hulled():
    # an L of three 0.2 m squares: its hull adds half a square, 16.7 % — no tracing slip
    from geometry_library.survey import hull_of

    ell = np.array([[0, 0], [0.4, 0], [0.4, 0.2], [0.2, 0.2], [0.2, 0.4], [0, 0.4]])
    with pytest.raises(GeometryError, match=r"would add 16.7% of its area.*split it into convex stones"):
        hull_of(ell, "block 1")


def test_the_traced_wall_is_trimmed_whatever_the_order_of_its_features(tmp_path):
    # the cuts are all found before any is made: reversing the features gives the same stones (to rounding:
    # an intersection's vertices come in another order)
    data = surveyed_wall.write(tmp_path / "a.geojson", dent=2e-3, dents=4)
    data["features"] = data["features"][::-1]
    (tmp_path / "b.geojson").write_text(json.dumps(data))
    survey = Survey(convex_hull=True, trim_overlaps=0.003)
    a = read_geojson(tmp_path / "a.geojson", survey=survey)
    b = read_geojson(tmp_path / "b.geojson", survey=survey)
    assert validate_assembly(a) == [] and validate_assembly(b) == []
    for x, y in zip(a.blocks, b.blocks[::-1]):
        assert x.polygon.hausdorff_distance(y.polygon) < 1e-12


def test_wkt_is_read_the_same_way(tmp_path):
    path = tmp_path / "w.wkt"
    x, y = surveyed_wall.LAMBERT93
    path.write_text(f"S1: POLYGON (({x} {y}, {x + 0.4} {y}, {x + 0.4} {y + 0.2}, {x} {y + 0.2}, {x} {y}))\n")
    notes = []
    stone = read_wkt(path, survey=Survey(), notes=notes).blocks[0]
    assert stone.polygon.bounds == pytest.approx((234.12, 210.55, 234.52, 210.75), abs=1e-8)
    assert "read moved by (-651000, -6861000) m" in notes[0]


def test_an_unmarked_foundation_is_named(tmp_path):
    # the foundation polygon of a QGIS layer, layer = "foundation" and no "role": 73 blocks and no support
    notes = []
    wall = read_geojson(wall_file(tmp_path, "w.geojson", mark_ground=False, **EXACT), notes=notes)
    assert wall.support_count == 0 and wall.block_count == 73
    assert any(
        'block 73 ("id-73") lies lowest and spans the structure' in n and '"role": "support"' in n for n in notes
    )
    notes = []
    read_geojson(wall_file(tmp_path, "m.geojson", **EXACT), notes=notes)  # marked: nothing to say
    assert not any("lies lowest" in n for n in notes)


def test_pixels_of_a_photograph_read_with_their_size(tmp_path):
    # traced on an image in pixels of 2.5 mm, rows counting down: --units 0.0025 --flip-y gives the metres back
    local = read_geojson(wall_file(tmp_path, "m.geojson", **EXACT))
    pixels = wall_file(tmp_path, "px.geojson", scale=400.0, flip_y=True, slip=0.0, ndigits=9)
    for a, b in zip(vertices(read_geojson(pixels, survey=Survey(units="0.0025", flip_y=True))), vertices(local)):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-9)
    for bad in ("0", "-1", "nan", "ft", "2000"):
        with pytest.raises(GeometryError, match="units must be one of m, cm, mm or metres per unit"):
            Survey(units=bad)


def test_a_ground_line_is_the_ground_under_it(tmp_path):
    # the foundation traced as a LineString along the wall's foot (y = 0, 6 vertices): one convex support, the
    # rectangle down to 0.5 m below the line; no role needed (a line is no block)
    notes = []
    wall = read_geojson(wall_file(tmp_path, "w.geojson", ground_line=True, mark_ground=False, **EXACT), notes=notes)
    assert (
        wall.block_count == 72 and wall.support_count == 1 and wall.supports[0].name == "id-73"
    )  # its id column; "ground" without
    assert wall.supports[0].polygon.equals(box(-0.3, -0.5, 4.3, 0.0))
    assert any("feature 73: a LineString read as the ground under it, 0.5 m deep" in n for n in notes), notes
    assert validate_assembly(wall) == []


def test_a_ground_line_with_a_step_is_refused(tmp_path):
    # a 3 cm step down in the middle: the hull over it would bury the stones on the lower side
    line = [[0, 0], [1, 0], [1.01, -0.03], [2, -0.03]]
    feature = {"type": "Feature", "properties": {}, "geometry": {"type": "LineString", "coordinates": line}}
    path = tmp_path / "step.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    with pytest.raises(GeometryError, match=r"feature 1: support 1 \(\"ground\"\): the ground line dips 29.7 mm"):
        read_geojson(path)
    feature["properties"]["role"] = "block"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    with pytest.raises(GeometryError, match="role must be 'support' \\(a line is the ground under it\\)"):
        read_geojson(path)


@pytest.mark.parametrize("line", [[[0, 0], [0, 1]], [[0.2, 0], [0.2, 0]]])
def test_a_ground_line_of_no_width_is_refused_in_one_line(tmp_path, line):
    # a vertical line, or one point given twice: their hull has no area ('check' ended in an AttributeError
    # traceback: 'LineString' object has no attribute 'exterior')
    from cli_helpers import assert_one_line_error, invoke

    block = [[0, 0], [0.4, 0], [0.4, 0.8], [0, 0.8], [0, 0]]
    features = [
        {"type": "Feature", "properties": {"name": "B"}, "geometry": {"type": "Polygon", "coordinates": [block]}},
        {"type": "Feature", "properties": {}, "geometry": {"type": "LineString", "coordinates": line}},
    ]
    path = tmp_path / "line.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    assert_one_line_error(invoke("check", path), 'feature 2: support 1 ("ground"): a ground line', "span no width")


def test_coordinates_beyond_any_map_grid_are_refused_as_before(tmp_path):
    # 1e12 m out float64 keeps only ±0.1 mm: not moved, refused naming the vertex (as every far file was)
    x = 1e12
    ring = [[x, 0], [x + 0.4, 0], [x + 0.4, 0.2], [x, 0.2], [x, 0]]
    feature = {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [ring]}}
    path = tmp_path / "far.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    with pytest.raises(GeometryError, match=r"vertex 0 at \(1e\+12, 0\) is more than 1e\+06 m from the origin"):
        read_geojson(path)


def test_a_float32_export_far_away_is_said_once_moved(tmp_path):
    # 12 km out a float32 keeps ±0.7 mm: moved near the origin the coordinates are no float32 values any more,
    # so the checks' float32 warning could not fire — the reader says it, and with a refusal
    data = surveyed_wall.write(tmp_path / "w.geojson", offset=(12000.0, 5000.0), slip=0.0, ndigits=9)
    for feature in data["features"]:
        rings = feature["geometry"]["coordinates"][0]
        rings[0] = [[float(np.float32(x)), float(np.float32(y))] for x, y in rings[0]]
    (tmp_path / "f32.geojson").write_text(json.dumps(data))
    notes = []
    read_geojson(tmp_path / "f32.geojson", survey=Survey(trim_overlaps=0.003), notes=notes)
    assert any("float32 values, exact only to ±0.00072 m that far" in n for n in notes), notes
    with pytest.raises(GeometryError, match="float32 values, exact only to ±0.00072 m there"):
        feature = data["features"][0]["geometry"]["coordinates"][0][0]
        feature.insert(2, [float(np.float32(12000.2)), float(np.float32(5000.01))])  # a dent: refused
        (tmp_path / "f32.geojson").write_text(json.dumps(data))
        read_geojson(tmp_path / "f32.geojson")


def test_a_stone_drawn_twice_is_named_so(tmp_path):
    # a QGIS slip: the same stone digitised twice (a copy 1 mm off): not a tracing overlap, said so either way
    stones = (Block(box(0, 0, 0.4, 0.2), "S1"), Block(box(0.001, 0, 0.401, 0.2), "S1-copy"))
    twice = Assembly(stones, (Support(box(-1, -0.5, 1, 0.0), "ground"),))
    with pytest.raises(
        GeometryError, match="200 mm deep, more than the 3 mm trimmed \\(one covers the other: the same"
    ):
        trim_overlaps(twice, 0.003)
    with pytest.raises(GeometryError, match=r"0\.2 m deep — one covers the other: the same stone drawn twice\?"):
        validate_assembly(twice)
    with pytest.raises(GeometryError, match=r"overlap by 0\.0002 m², 1 mm deep \(tolerance"):  # a slip: not said
        validate_assembly(Assembly((stones[0], Block(box(0.399, 0, 0.8, 0.2), "S2")), twice.supports))


def test_stones_are_named_by_their_id_column(tmp_path):
    # the layer's id column names the stones (block 4 of a file whose foundation comes first is feature 5):
    # the foundation first, so block k is feature k + 1 and id k
    data = surveyed_wall.write(tmp_path / "w.geojson", **EXACT)
    data["features"] = data["features"][-1:] + data["features"][:-1]
    data["features"][3]["geometry"]["coordinates"][0][0].insert(2, [0.95, 0.05])  # stone id 3 dented: refused
    (tmp_path / "f.geojson").write_text(json.dumps(data))
    with pytest.raises(GeometryError, match=r'feature 4: block 3 \("id-3"\): polygon is not convex'):
        read_geojson(tmp_path / "f.geojson")
    data["features"][5]["properties"]["id"] = 3  # two stones with id 3: no names from ids, the defaults
    (tmp_path / "f.geojson").write_text(json.dumps(data))
    with pytest.raises(GeometryError, match=r'feature 4: block 3 \("block-3"\): polygon is not convex'):
        read_geojson(tmp_path / "f.geojson")


def test_units_that_make_no_stone_are_said_as_such(tmp_path):
    """A wall in metres read with --units mm has stones half a millimetre across: it was refused for overlaps
    0.0007 mm deep, with no word of the units; --units 1e-12 on a map grid's file was asked whether it was in
    degrees. Both now say the unit read with, and the one that makes stones of them."""
    metres = wall_file(tmp_path, "m.geojson", **EXACT)
    with pytest.raises(GeometryError, match=r"0\.32–0\.716 mm across read with --units mm \(median 0\.47 mm\): are the "
                       r"coordinates metres\? without --units they are read so$"):  # fmt: skip
        read_geojson(metres, survey=Survey(units="mm"))
    with pytest.raises(GeometryError, match=r"read with --units 0\.0025 .*are the coordinates metres"):
        read_geojson(metres, survey=Survey(units="0.0025"))
    far = wall_file(tmp_path, "l93.geojson", offset=surveyed_wall.LAMBERT93, **EXACT)
    with pytest.raises(
        GeometryError, match=r"too small \(a stone 4\.8e-13 m across read with --units 1e-12: is"
    ) as err:
        read_geojson(far, survey=Survey(units="1e-12"))
    assert "longitude" not in str(err.value) and "\n" not in str(err.value)
