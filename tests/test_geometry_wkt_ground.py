"""A ground traced as a line in a WKT file (geometry_library.wkt): a LINESTRING, or a MULTILINESTRING of one part,
is the support under it, as a GeoJSON LineString is (docs/scenario-format.md, "A surveyed wall"). It said
'geometry must be a POLYGON, MULTIPOLYGON or GEOMETRYCOLLECTION, got LineString' (exit 2), so a survey exported
both ways ran from its GeoJSON and not from its WKT."""

from __future__ import annotations

import json

import pytest
from shapely.geometry import box

from geometry_library import GeometryError, read_geojson, read_wkt
from geometry_library.survey import Survey

from cli_helpers import assert_one_line_error, invoke

STONES = [
    "block s1: POLYGON ((0 0, 0.4 0, 0.4 0.2, 0 0.2, 0 0))",
    "block s2: POLYGON ((0 0.2, 0.4 0.2, 0.4 0.4, 0 0.4, 0 0.2))",
]


def _wkt(tmp_path, *lines: str, name: str = "w.wkt"):
    path = tmp_path / name
    path.write_text("\n".join([*STONES, *lines]) + "\n")
    return path


@pytest.mark.parametrize(
    ("line", "name"),
    [
        ("LINESTRING (-1 0, 0.2 0, 1.4 0)", "ground"),
        ("support base: LINESTRING (-1 0, 0.2 0, 1.4 0)", "base"),
        ("base: MULTILINESTRING ((-1 0, 0.2 0, 1.4 0))", "base"),
        ("support driven: LINESTRING (-1 0, 0.2 0, 1.4 0)", "ground"),
    ],
)
def test_a_wkt_ground_line_is_the_ground_under_it(tmp_path, line, name):
    """The line y = 0 from x = -1 to 1.4: the ground is the box down to 0.5 m below it (the convex hull of the line
    and of two points 0.5 m under its lowest), what the same line in GeoJSON gives."""
    notes = []
    walls = read_wkt(_wkt(tmp_path, line), notes=notes)
    assert walls.block_count == 2 and walls.support_count == 1
    assert walls.supports[0].name == name and walls.supports[0].polygon.equals(box(-1.0, -0.5, 1.4, 0.0))
    assert walls.supports[0].role == ("driven" if "driven" in line else "fixed")
    assert any("line 3: a" in n and "LINESTRING read as the ground under it, 0.5 m deep" in n for n in notes), notes
    feature = {
        "type": "Feature",
        "properties": {},
        "geometry": {"type": "LineString", "coordinates": [[-1, 0], [1.4, 0]]},
    }
    (tmp_path / "g.geojson").write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    assert read_geojson(tmp_path / "g.geojson").supports[0].polygon.equals(walls.supports[0].polygon)


def test_a_wkt_ground_line_in_a_map_grid_and_millimetres(tmp_path):
    """Read as the polygons are: moved near the origin with them (by whole km: 1000 m is left of 651 000), in the
    file's unit; 0.5 m deep below its lowest point, its 3 mm dip bridged."""
    e, n = 651000.0, 6861000.0

    def mm(points) -> str:
        return ", ".join(f"{(e + x) * 1e3:.0f} {(n + y) * 1e3:.0f}" for x, y in points)

    lines = [
        f"block s0: POLYGON (({mm([(0, 0), (0.4, 0), (0.4, 0.2), (0, 0.2), (0, 0)])}))",
        f"block s1: POLYGON (({mm([(0, 0.2), (0.4, 0.2), (0.4, 0.4), (0, 0.4), (0, 0.2)])}))",
        f"LINESTRING ({mm([(-1, 0), (0.2, -0.003), (1.4, 0)])})",
    ]
    path = tmp_path / "l93.wkt"
    path.write_text("\n".join(lines) + "\n")
    notes = []
    walls = read_wkt(path, survey=Survey(units="mm"), notes=notes)
    ground = box(999.0, 1000.0 - 0.503, 1001.4, 1000.0)
    assert walls.supports[0].polygon.symmetric_difference(ground).area < 1e-8  # m², the mm grid read to 2e-11 m
    assert walls.blocks[0].polygon.symmetric_difference(box(1000.0, 1000.0, 1000.4, 1000.2)).area < 1e-9
    assert any("dips up to 3 mm bridged" in n for n in notes), notes


@pytest.mark.parametrize(
    ("line", "said"),
    [
        ("block g: LINESTRING (-1 0, 1.4 0)", "line 3: a LINESTRING is the ground under it: label it 'support NAME:'"),
        ("MULTILINESTRING ((-1 0, 0 0), (0.5 0, 1.4 0))", "line 3: a MULTILINESTRING of 2 parts; a ground line is one"),
        ("LINESTRING (0.2 0, 0.2 -1)", 'line 3: support 1 ("ground"): a ground line runs along the wall\'s foot'),
        ("LINESTRING (-1 0, 0.5 0, 0.51 -0.03, 1.4 -0.03)", "the ground line dips 29.7 mm"),
        ("ground LINESTRING (-1 0, 1.4 0)", "'ground' before LINESTRING: a label ends with a colon"),
    ],
)
def test_a_bad_wkt_ground_line_is_one_line(tmp_path, line, said):
    with pytest.raises(GeometryError, match=None) as exc:
        read_wkt(_wkt(tmp_path, line))
    assert said in str(exc.value) and "\n" not in str(exc.value)
    assert_one_line_error(invoke("check", _wkt(tmp_path, line, name="c.wkt")), said)


def test_check_and_limit_run_a_wkt_file_with_a_ground_line(tmp_path):
    """Two stones 0.4 × 0.2 m stacked on the traced ground: tilted, the column overturns at tan ψ = B/H = 1
    (0.4 / 0.4) unless it slides first at μ = 0.6: λ = 0.6."""
    path = _wkt(tmp_path, "LINESTRING (-1 0, 0.2 0, 1.4 0)")
    result = invoke("check", path)
    assert result.exit_code == 0, result.output
    data = json.loads(invoke("limit", path, "--load", "tilt", "--json").stdout)
    assert data["load_factor"] == pytest.approx(0.6, rel=1e-9)


def test_a_wkt_surveys_density_is_said_where_it_goes(tmp_path):
    """WKT has no density column and --density is refused on a file: the refusal said only 'a file, which gives its
    own geometry', and the researcher with a 2300 kg/m³ survey found no way in. It now names the way, which
    gives 2 stones × 0.08 m² × 2300 kg/m³."""
    path = _wkt(tmp_path, "LINESTRING (-1 0, 0.2 0, 1.4 0)")
    for command in ("check", "limit"):
        assert_one_line_error(invoke(command, path, "--density", 2300), "[material] density")
    (tmp_path / "s.toml").write_text(f'[structure]\nfile = "{path.name}"\n\n[material]\ndensity = 2300\n')
    result = invoke("check", tmp_path / "s.toml")
    assert result.exit_code == 0, result.output
    assert f"{2 * 0.08 * 2300:g} kg" in result.stdout
