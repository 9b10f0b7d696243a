"""The commands of masonrycli/cli/app.py as a user drives them: simulate, run and check on short runs, and their
bad input as one line. build: test_cli_build.py; inspect: test_cli_inspect_file.py; options and --help:
test_cli_options.py; messages, a closed stdout and Ctrl-C: test_cli_messages.py; a run's outcomes (diverged,
failed, unconverged): test_execute.py."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest

from cli_helpers import assert_one_line_error, invoke, words

WIDE = {"COLUMNS": "250"}

DATA = Path(__file__).parent / "data"


def test_simulate_wall_short_run_writes_recording_and_history(tmp_path):
    rrd, npz = tmp_path / "wall.rrd", tmp_path / "wall.npz"
    result = invoke("simulate", "wall", "--freq", 2, "--amp", 1, "--duration", 0.05, "--out", rrd, "--history", npz)
    assert result.exit_code == 0, result.output
    assert rrd.stat().st_size > 0
    h = np.load(npz)
    assert h["block_q"].shape == (6, 51, 3)  # frames at steps 0, 10, ..., 50
    assert h["time"][-1] == pytest.approx(0.05)
    assert str(h["status"]) == "completed"
    assert "rerun " in result.output


def test_run_scenario_file(tmp_path):
    npz = tmp_path / "h.npz"
    result = invoke("run", DATA / "validation" / "column5.toml", "--duration", 0.02, "--no-recording", "--history", npz)
    assert result.exit_code == 0, result.output
    h = np.load(npz)
    assert list(h["block_name"]) == ["k5", "k4", "k3", "k2", "k1"]
    for name in ("support_force", "nlgs_iterations", "energy_kinetic", "cell_stress", "block_stress"):
        assert name in h.files


def test_check_prints_summary():
    path = DATA / "validation" / "column5.toml"
    result = invoke("check", path)
    assert result.exit_code == 0, result.output
    rows = {}
    for line in result.output.splitlines():
        cells = [c.strip() for c in line.strip().strip("│").split("│")]
        if len(cells) == 2 and cells[0]:
            rows[cells[0]] = cells[1]
    # Reference from the file itself: shoelace areas x density x the documented 1 m thickness.
    doc = tomllib.loads(path.read_text())
    polys = [np.array(b["polygon"]) for b in doc["block"]]
    area = [0.5 * abs(np.dot(p[:, 0], np.roll(p[:, 1], -1)) - np.dot(p[:, 1], np.roll(p[:, 0], -1))) for p in polys]
    mass = sum(area) * doc["material"]["density"] * 1.0
    every = np.concatenate(polys + [np.array(s["polygon"]) for s in doc["support"]])
    (xmin, ymin), (xmax, ymax) = every.min(axis=0), every.max(axis=0)
    run = doc["run"]
    assert rows.pop("recording").startswith("recordings/column5-")  # the default name `run` would write
    assert rows == {
        "scenario": "column5",
        "blocks": str(len(doc["block"])),
        "supports": str(len(doc["support"])),
        "total mass": f"{mass:.6g} kg",
        "bounding box": f"x {xmin:.4g} … {xmax:.4g} m, y {ymin:.4g} … {ymax:.4g} m",
        "friction": f"{doc['material']['friction']:g}",
        "time": f"{run['duration']:g} s in {round(run['duration'] / run['dt'])} steps of {run['dt']:g} s, "
        f"θ = {run['theta']:g}",
        "loading": "none (every support fixed)",
    }
    assert rows["total mass"] == "800 kg"  # 5 blocks of 0.4 x 0.2 m at 2000 kg/m³


def test_check_shows_how_each_support_moves(tmp_path):
    # `check` showed blocks, mass, time and outputs but not the loading: with --record q.AT2 --scale 0.5 nothing
    # on the screen said which supports the record drives, at what scale, how long it is.
    from synthetic_records import write_at2

    at2 = tmp_path / "q.AT2"
    write_at2(at2, 0.1 * np.sin(np.linspace(0.0, 6.0, 200)), 0.01)
    result = invoke("check", DATA / "quake_record.toml", "--record", at2, "--scale", 0.5)
    assert result.exit_code == 0, result.output
    said = words(result.output.replace("│", " "))  # a row's wrapped lines joined, wherever the width wraps it
    assert "loading ground: record of acceleration (q.AT2, 200 samples, 0–1.99 s, baseline-corrected) × 0.5" in said
    arch = words(invoke("check", DATA / "arch_settlement.toml").output.replace("│", " "))
    assert "loading right-foundation: constant velocity (0, -0.01) m/s" in arch, arch


def test_geojson_properties_not_used_are_warned_by_run_and_check(tmp_path):
    ring = [[0, 0], [0.3, 0], [0.3, 0.2], [0, 0.2], [0, 0]]
    ground = [[-1, -0.2], [2, -0.2], [2, 0], [-1, 0], [-1, -0.2]]
    features = [
        {"type": "Feature", "properties": props, "geometry": {"type": "Polygon", "coordinates": [xy]}}
        for props, xy in (({"role": "support", "fid": 1}, ground), ({"name": "B1", "densty": 2000}, ring))
    ]
    path = tmp_path / "w.json"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    (tmp_path / "s.toml").write_text('[structure]\nfile = "w.json"\n')
    for args in (["check", path], ["check", tmp_path / "s.toml"], ["run", path, "--duration", 0.002, "--no-recording"]):
        result = invoke(*args)
        assert result.exit_code == 0, result.output
        (line,) = [ln for ln in result.output.splitlines() if ln.startswith("warning:")]
        assert '"densty" (did you mean "density"?) first on feature 2, block 1 ("B1")' in line and "fid" not in line


@pytest.mark.parametrize("name", ["wall", "arch"])
def test_a_built_in_name_given_to_run_points_to_simulate(name, tmp_path, monkeypatch):
    """QA: `masonry run wall` said "wall: cannot read scenario: No such file or directory"."""
    monkeypatch.chdir(tmp_path)  # no file called `wall` here
    result = invoke("run", name)
    assert_one_line_error(result, f"{name}: not a file", f"masonry simulate {name}")
    assert "No such file" not in result.output


def _rows(output: str) -> dict[str, str]:
    """The check table's rows, name -> value."""
    cells = [[c.strip() for c in line.strip().strip("│").split("│")] for line in output.splitlines()]
    return {c[0]: c[1] for c in cells if len(c) == 2 and c[0]}


def test_check_takes_the_options_simulate_takes_for_a_built_in(tmp_path, monkeypatch):
    # a user checking what `simulate arch --span 8 --rise 2` would run could not: check took files only
    # ("arch: not a file") and no --span ("No such option"). Reference: the same structure written by
    # `build` and read back as a geometry file.
    monkeypatch.chdir(tmp_path)
    assert invoke("build", "arch", "--span", 8, "--rise", 2, "--out", "a.geojson").exit_code == 0
    built = _rows(invoke("check", "a.geojson").output)
    result = invoke("check", "arch", "--span", 8, "--rise", 2)
    assert result.exit_code == 0, result.output
    rows = _rows(result.output)
    for row in ("blocks", "supports", "total mass", "bounding box"):
        assert rows[row] == built[row], row
    assert rows["bounding box"] != _rows(invoke("check", "arch").output)["bounding box"]  # the span is taken
    # the loading and time of `simulate arch` (DESIGN: right foundation settles at 1 cm/s for 5 s)
    assert rows["loading"] == "right-foundation: constant velocity (0, -0.01) m/s"
    assert rows["time"].startswith("5 s in 5000 steps")
    wall = _rows(invoke("check", "wall", "--courses", 3, "--length", 3, "--amp", 0.5, "--freq", 3).output)
    # 3 m of 0.30 m blocks: 10 in courses 1 and 3, 9 and two halves in course 2 (running bond)
    assert wall["blocks"] == "31" and "0.5" in wall["loading"] and "3 Hz" in wall["loading"], wall


@pytest.mark.parametrize(
    "args, fragments",
    [
        (("wall", "--span", 8), ["--span: not an option of the wall", "masonry simulate wall --help"]),
        (("arch", "--blocks", 8), ["--blocks: not an option of the arch"]),
        (("wall", "--settlement", 0.1), ["--settlement", "the wall stands on one ground"]),
        ((DATA / "arch_settlement.toml", "--rise", 1, "--amp", 2), ["--rise, --amp: shape a built-in", "is a file"]),
    ],
)
def test_check_refuses_the_builtin_options_that_cannot_apply(args, fragments):
    assert_one_line_error(invoke("check", *args), *fragments)


@pytest.mark.parametrize(
    "args, fragments",
    [
        (("run", "no-such-file.toml"), ["no-such-file.toml"]),
        (("check", "no-such-file.toml"), ["no-such-file.toml"]),
        (("run", DATA / "validation" / "column5.toml", "--dt", -1), ["dt"]),
        (("run", DATA / "validation" / "column5.toml", "--theta", 0.2), ["theta"]),
        (("run", DATA / "validation" / "column5.toml", "--friction", "nan"), ["friction"]),
        (("simulate", "wall", "--blocks", 0, "--duration", 0.01), ["--blocks 0", "positive integer"]),
        (("simulate", "wall", "--density", -5, "--duration", 0.01), ["density"]),
        (("simulate", "arch", "--settlement", -1, "--duration", 0.01), ["--settlement"]),
        # a sine the steps alias (1e9 Hz at dt = 1e-3 s sampled 0 at every step: the ground never moved)
        (("simulate", "wall", "--freq", 1e9, "--duration", 0.01), ['"ground": frequency = 1e+09 Hz', "500 Hz"]),
        (
            ("check", DATA / "validation" / "harmonic_ground.toml", "--dt", 0.5),
            ["harmonic_ground.toml", "2 Hz", "1 Hz"],
        ),
        # absurd block counts used to build for minutes with no word
        (("simulate", "wall", "--blocks", 10**8, "--duration", 0.01), ["100000000 blocks", "likely typo"]),
        (
            ("simulate", "wall", "--duration", 0.01, "--magnify", 1e300),
            ["--magnify 1e+300: must be between 1 and 1e+06"],
        ),
        (("simulate", "wall", "--duration", 0.01, "--magnify", 0.5), ["--magnify 0.5: must be between 1"]),
        # Path("") is ".": "--out .: the file name must end in .rrd", "--record ''" ".: is a directory"
        (("simulate", "wall", "--duration", 0.01, "--history", ""), ["--history", "the path is empty"]),
        (("simulate", "wall", "--duration", 0.01, "--record", ""), ["--record", "the path is empty"]),
        (("build", "wall", "--out", ""), ["--out", "the path is empty"]),
        (("build", "wall", "--out", "w.txt"), ["--out w.txt: the file name must end in .geojson or .json"]),
        # --out was ignored: the recording asked for was silently not written
        (("simulate", "wall", "--duration", 0.01, "--out", "x.rrd"), ["--out x.rrd with --no-recording"]),
    ],
)
def test_bad_input_is_one_line_exit_2(args, fragments, tmp_path):
    result = invoke(*args, *(["--no-recording"] if args[0] in ("run", "simulate") else []))
    assert_one_line_error(result, *fragments)


def test_non_convex_block_is_named(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('[[block]]\nname = "dart"\npolygon = [[0, 0], [2, 0], [1, 0.5], [1, 2]]\n')
    assert_one_line_error(invoke("check", path), "dart", "convex")


def test_overlapping_blocks_are_named(tmp_path):
    path = tmp_path / "overlap.toml"
    path.write_text(
        '[[block]]\nname = "a"\npolygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\n'
        '[[block]]\nname = "b"\npolygon = [[0.5, 0], [1.5, 0], [1.5, 1], [0.5, 1]]\n'
    )
    assert_one_line_error(invoke("check", path), '"a"', '"b"', "overlap")


def test_geometry_file_errors_are_one_line(tmp_path):
    bad = tmp_path / "bad.geojson"
    bad.write_text("{ not json")
    assert_one_line_error(invoke("run", bad, "--no-recording"), "bad.geojson")
    scen = tmp_path / "s.toml"
    scen.write_text('[structure]\nfile = "missing.geojson"\n')
    assert_one_line_error(invoke("check", scen), "missing.geojson", "no such file")


def test_a_float32_geojson_with_split_joints_runs(tmp_path):
    """The built-in aqueduct exported by a GIS / CAD tool in float32, a vertex in the middle of every edge: it
    was refused (exit 2: a rounded mid-edge vertex "not convex", or blocks 36 and 106 overlapping by 8e-9 m²);
    it runs (exit 0), without a warning."""
    out = tmp_path / "aqueduct.geojson"
    assert invoke("build", "aqueduct", "--out", out).exit_code == 0
    data = json.loads(out.read_text())
    for feature in data["features"]:
        ring = np.array(feature["geometry"]["coordinates"][0][:-1])
        split = np.stack([ring, (ring + np.roll(ring, -1, axis=0)) / 2], axis=1).reshape(-1, 2)
        coords = [[np.float32(x).item(), np.float32(y).item()] for x, y in split]
        feature["geometry"]["coordinates"] = [coords + coords[:1]]
    out.write_text(json.dumps(data))
    result = invoke("run", out, "--duration", 0.05, "--no-recording")
    assert result.exit_code == 0, result.output
    assert "warning" not in result.output.lower(), result.output
