"""A surveyed file read and written back keeps what was traced: its fills as outlines and its ground lines as lines
(write_geojson, write_wkt), so reading the written file gives the same assembly to the bit. Before, write_wkt dropped
a traced fill (11 % of a bridge's dead load, without a word) and both writers wrote a ground line as the polygon made
from it."""

from __future__ import annotations

import json

import numpy as np
import pytest
from traced_bridge import FILL, STONE, write

from geometry_library import GeometryError, read_geojson, read_wkt, write_geojson, write_wkt
from geometry_library.builders import ArchSpec
from geometry_library.survey import Survey

LAMBERT = (651000.25, 6861000.5)  # the bridge traced on the map, to the mm


def _bridge(tmp_path):
    path = tmp_path / "bridge.geojson"
    write(path, offset=LAMBERT, ndigits=3)
    return read_geojson(path, survey=Survey(trim_overlaps=0.003))


def _same(a, b) -> None:
    assert [x.name for x in a.blocks] == [x.name for x in b.blocks]
    for x, y in zip(a.blocks, b.blocks):
        np.testing.assert_array_equal(x.vertices, y.vertices)
        assert (x.carried_mass, x.carried_at, x.thickness) == (y.carried_mass, y.carried_at, y.thickness), x.name
    assert [(s.name, s.role, s.line) for s in a.supports] == [(s.name, s.role, s.line) for s in b.supports]
    for x, y in zip(a.supports, b.supports):
        np.testing.assert_array_equal(x.vertices, y.vertices)
    assert [(f.name, f.density) for f in a.fills] == [(f.name, f.density) for f in b.fills]
    for x, y in zip(a.fills, b.fills):
        np.testing.assert_array_equal(np.asarray(x.outline.exterior.coords), np.asarray(y.outline.exterior.coords))


def test_a_surveyed_bridge_written_as_geojson_keeps_its_fill_and_ground_lines(tmp_path):
    read = _bridge(tmp_path)
    assert [f.name for f in read.fills] == ["fill"] and all(s.line is not None for s in read.supports)
    path = write_geojson(read, tmp_path / "back.geojson")
    features = json.loads(path.read_text())["features"]
    fills = [f for f in features if f["properties"]["role"] == "fill"]
    assert [f["properties"] for f in fills] == [{"role": "fill", "name": "fill", "density": FILL}]
    assert [f["geometry"]["type"] for f in features if f["properties"]["role"] == "support"] == ["LineString"] * 2
    assert not any("carried_mass" in f["properties"] for f in features)  # the fill's weight is its outline's
    back = read_geojson(path)
    _same(read, back)
    _same(back, read_geojson(write_geojson(back, tmp_path / "again.geojson")))


def test_a_surveyed_bridge_written_as_wkt_keeps_its_fill_and_ground_lines(tmp_path):
    read = _bridge(tmp_path)
    path = write_wkt(read, tmp_path / "back.wkt")
    text = path.read_text()
    assert f"\nfill fill {FILL!r}: POLYGON ((" in text
    assert (
        "\nsupport left-ground driven: LINESTRING (" in text and "\nsupport right-ground driven: LINESTRING (" in text
    )
    _same(read, read_wkt(path, density=STONE))


def test_a_wkt_survey_round_trips_through_both_writers(tmp_path):
    path = tmp_path / "haunch.wkt"
    path.write_text(
        "block a: POLYGON ((0 0, 1 0, 1 0.5, 0 0.5, 0 0))\n"
        "block b: POLYGON ((1 0, 2 0, 2 0.5, 1 0.5, 1 0))\n"
        "fill road 1800: POLYGON ((0 0.5, 0 1.2, 2 1.0, 2 0.5, 0 0.5))\n"  # clockwise, a cambered top
        "support ground fixed: LINESTRING (-1 0, 3 0.002, 4 0)\n"
    )
    read = read_wkt(path)
    assert read.blocks[0].carried_mass > 0 and read.fills[0].density == 1800.0
    text = write_wkt(read, tmp_path / "back.wkt").read_text()
    assert (
        "fill road 1800.0: POLYGON" in text
        and "support ground fixed: LINESTRING (-1.0 0.0, 3.0 0.002, 4.0 0.0)" in text
    )
    _same(read, read_wkt(tmp_path / "back.wkt"))
    _same(read, read_geojson(write_geojson(read, tmp_path / "back.geojson"), density=2500.0))


def test_a_trimmed_ground_is_written_as_its_polygon(tmp_path):
    # a ground line whose ground a stone's trim cut is no longer that line's ground: its polygon is written
    path = tmp_path / "sunk.wkt"
    path.write_text(
        "block a: POLYGON ((0 0.001, 1 0.001, 1 0.5, 0 0.5, 0 0.001))\nsupport ground: LINESTRING (-1 0, 0.5 0.002, 2 0)\n"
    )
    read = read_wkt(path, survey=Survey(trim_overlaps=0.003))
    assert read.supports[0].polygon.bounds[3] < 0.002  # the ground's crown under the stone cut off
    text = write_wkt(read, tmp_path / "back.wkt").read_text()
    assert "LINESTRING" not in text
    back = read_wkt(tmp_path / "back.wkt")
    np.testing.assert_array_equal(back.supports[0].vertices, read.supports[0].vertices)


def test_wkt_refuses_a_carried_mass_it_cannot_hold(tmp_path):
    # the builder's fill is each block's carried mass, which WKT has no way to say: it was dropped without a word
    arch = ArchSpec(fill_to=1.0).build()
    with pytest.raises(GeometryError, match=r"carries .* kg \(a fill's weight\), which WKT cannot hold: write GeoJSON"):
        write_wkt(arch, tmp_path / "arch.wkt")
    assert not (tmp_path / "arch.wkt").exists()
