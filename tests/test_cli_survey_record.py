"""What a run of a traced wall writes says how its file was read: the history's run metadata, the recording's
Parameters table and ``masonry inspect`` carry the map shift, the units, the flip, the hulls, the trims and
the settling — a history reopened months later says which reading of its file it is of."""

import json
import re

import numpy as np
import pytest
import surveyed_wall

from cli_helpers import assert_one_line_error, invoke, words


@pytest.fixture
def traced_mm(tmp_path):
    """72 stones in Lambert-93 millimetres, y as image rows, 4 stones dented 2 mm, slips of up to 1 mm."""
    path = tmp_path / "wall.geojson"
    surveyed_wall.write(path, offset=surveyed_wall.LAMBERT93, scale=1000.0, flip_y=True, ndigits=0, dent=2e-3, dents=4)
    return path


def _added(text: str) -> list[float]:
    """The (x, y) a message says to add for the map's coordinates."""
    x, y = re.search(r"add \((-?\d+), (-?\d+)\)", text).groups()
    return [float(x), float(y)]


@pytest.mark.slow
def test_a_runs_history_and_recording_say_how_its_file_was_read(traced_mm, tmp_path):
    reading = ["--units", "mm", "--flip-y"]
    refused = invoke("check", traced_mm, *reading)  # its stones not convex: the refusal names the shift
    assert_one_line_error(refused, "polygon is not convex", "for the map's")
    options = [*reading, "--convex-hull", "--trim-overlaps", "0.003", "--settle", "0.05"]
    history, recording = tmp_path / "h.npz", tmp_path / "r.rrd"
    result = invoke("run", traced_mm, *options, "--duration", "0.01", "--history", history, "--out", recording)
    assert result.exit_code == 0, result.output
    said = words(result.output)
    run = json.loads(str(np.load(history)["run"]))
    read = run["reading"]
    assert read["map_origin_m"] == _added(said.split("read moved by")[1]) == _added(refused.output)
    assert read["units"] == "mm" and read["metres_per_unit"] == 0.001 and read["flip_y"] is True
    hull = re.search(r"(\d+) non-convex polygons read as their convex hulls", said)
    assert read["convex_hull"]["stones"] == int(hull.group(1)) == 4
    assert 0.0 < read["convex_hull"]["area_added_m2"] < 4 * 0.05 * 0.2  # a few % of stones ~0.2 m² at most
    pairs = re.search(r"(\d+) overlapping pairs trimmed", said)
    assert read["trim_overlaps"]["depth_m"] == 0.003 and read["trim_overlaps"]["pairs"] == int(pairs.group(1)) > 0
    assert 0.0 < read["trim_overlaps"]["deepest_m"] <= 0.003
    assert read["settle_s"] == 0.05

    from masonrycli.recording import inspect_recording

    table = inspect_recording(recording)["metadata"].split("## Parameters")[1]
    origin = read["map_origin_m"]
    for row in (
        f"| reading.map_origin_m | {origin} |",
        "| reading.units | mm |",
        "| reading.flip_y | True |",
        "| reading.convex_hull.stones | 4 |",
        "| reading.trim_overlaps.depth_m | 0.003 |",
        "| reading.settle_s | 0.05 |",
    ):
        assert row in table
    from masonrycli.outputs.inspect_history import inspect_history, run_rows

    assert "reading" in invoke("inspect", history).output
    shown = dict(run_rows(inspect_history(history)))["reading"]
    assert f"moved near the origin: add ({origin[0]:.0f}, {origin[1]:.0f}) m for the map's coordinates" in shown
    assert "--units mm (0.001 m per unit); --flip-y; --convex-hull: 4 stones read as their hulls" in shown
    assert f"--trim-overlaps 0.003: {pairs.group(1)} overlapping pairs trimmed; --settle 0.05" in shown


def test_a_file_read_as_it_is_and_a_builder_record_no_reading(tmp_path):
    from masonrycli.execute import run_metadata
    from masonrycli.run import Simulation
    from masonrycli.scenario.builtin import builtin
    from masonrycli.scenario.target import target_scenario

    surveyed_wall.write(tmp_path / "exact.geojson", slip=0.0, ndigits=9)
    for scenario in (target_scenario(tmp_path / "exact.geojson"), builtin("wall")):
        assert "reading" not in run_metadata(scenario, Simulation(scenario))


def test_a_scenario_files_structure_keys_are_recorded_as_the_options_are(tmp_path):
    from masonrycli.execute import run_metadata
    from masonrycli.run import Simulation
    from masonrycli.scenario.toml_file import load_scenario

    surveyed_wall.write(tmp_path / "l93.geojson", offset=surveyed_wall.LAMBERT93, slip=0.0, ndigits=9)
    (tmp_path / "s.toml").write_text('[structure]\nfile = "l93.geojson"\nconvex_hull = true\n')
    scenario = load_scenario(tmp_path / "s.toml")
    assert run_metadata(scenario, Simulation(scenario))["reading"] == {
        "map_origin_m": [651000.0, 6861000.0],
        "convex_hull": {"stones": 0, "area_added_m2": 0.0},
    }


def test_simulate_settles_a_built_in_as_run_does(tmp_path):
    # `masonry simulate` had no --settle ('No such option') where run, check, sweep and limit take it
    history = tmp_path / "h.npz"
    result = invoke(
        "simulate", "wall", "--settle", "0.05", "--duration", "0.01", "--history", history, "--no-recording"
    )
    assert result.exit_code == 0, result.output
    assert "settled 0.05 s under its own weight" in words(result.output)
    assert json.loads(str(np.load(history)["run"]))["reading"] == {"settle_s": 0.05}
    assert_one_line_error(invoke("simulate", "arch", "--settle", "0"), "--settle 0: must be in (0, ")
