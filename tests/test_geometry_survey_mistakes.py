"""A surveyed bridge's file with a researcher's mistake in it (tests/traced_bridge.py, traced in Lambert-93): each
is one line saying what and where, exit 2 (or, where the answer does not change, a note that says where). Before,
the bridge in millimetres read as metres was refused as 'carried_at … absurd (a likely typo)', or ran with a
warning when it had no fill; Lambert-93 in millimetres said only 'more than 1e+06 m from the origin'; a fill's
outline drawn 30 cm into the ring was said as an area 'not counted', no stone named."""

from __future__ import annotations

import json

import pytest
from traced_bridge import write

from geometry_library.io import read_geojson
from geometry_library.survey import Survey

from cli_helpers import assert_one_line_error, invoke

MAP = (651000.25, 6861000.5)


def _bridge(tmp_path, name: str, move=None, fill: bool = True):
    """The traced bridge as GeoJSON, each point (x, y) -> move(x, y), its fill left out with ``fill=False``."""
    path = tmp_path / name
    write(path, offset=MAP, ndigits=3)
    data = json.loads(path.read_text())
    data["features"] = [f for f in data["features"] if fill or f["properties"].get("role") != "fill"]
    for f in data["features"]:
        g = f["geometry"]
        if move is not None and g["type"] == "Polygon":
            g["coordinates"] = [[list(move(x, y)) for x, y in g["coordinates"][0]]]
        elif move is not None:
            g["coordinates"] = [list(move(x, y)) for x, y in g["coordinates"]]
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize("fill", [True, False])
def test_a_bridge_in_millimetres_read_as_metres_is_refused_naming_the_unit(tmp_path, fill):
    path = _bridge(tmp_path, "mm.geojson", lambda x, y: ((x - MAP[0]) * 1000, (y - MAP[1]) * 1000), fill)
    assert_one_line_error(
        invoke("check", path), "mm.geojson: the blocks are", "are the coordinates millimetres? --units mm reads them so"
    )
    assert invoke("check", path, "--units", "mm", "--trim-overlaps", "0.003").exit_code == 0


def test_a_map_grid_in_millimetres_names_the_unit(tmp_path):
    path = _bridge(tmp_path, "l93mm.geojson", lambda x, y: (x * 1000, y * 1000))
    assert_one_line_error(invoke("check", path), "a map grid's in millimetres? --units mm reads them so")
    assert invoke("check", path, "--units", "mm", "--trim-overlaps", "0.003").exit_code == 0


def test_a_fill_drawn_into_the_ring_is_said_naming_the_stone(tmp_path):
    """The outline's lower edge 30 cm into the ring: the weight is the same (the fill reaches down to the stones'
    top), but the note names where it reaches into them."""
    path = _bridge(tmp_path, "into.geojson")
    data = json.loads(path.read_text())
    fill = next(f for f in data["features"] if f["properties"].get("role") == "fill")
    ring = fill["geometry"]["coordinates"][0]
    fill["geometry"]["coordinates"][0] = [
        [x, y - 0.3] if MAP[1] + 2.01 < y < MAP[1] + 5.99 else [x, y] for x, y in ring
    ]
    path.write_text(json.dumps(data))
    notes, clean = [], []
    survey = Survey(trim_overlaps=0.003)
    into = read_geojson(path, survey=survey, notes=notes)
    exact = read_geojson(_bridge(tmp_path, "exact.geojson"), survey=Survey(trim_overlaps=0.003), notes=clean)
    said = [n for n in notes if "a fill of" in n]
    assert len(said) == 1 and 'it reaches into 17 stones, the deepest block 9 ("v09") about' in said[0], said
    assert not any("reaches into" in n for n in clean)
    carried = sum(b.carried_mass for b in into.blocks)
    assert carried == pytest.approx(sum(b.carried_mass for b in exact.blocks), rel=1e-4)
