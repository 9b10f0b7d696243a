"""The command line as a user drives it: CliRunner smoke runs, bad input, and a real Ctrl-C."""

from __future__ import annotations

import json
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from masonrycli import __version__

from cli_helpers import assert_one_line_error, invoke, words

DATA = Path(__file__).parent / "data"


def test_help_and_version():
    result = invoke("--help")
    assert result.exit_code == 0
    for command in ("simulate", "run", "check", "build", "inspect"):
        assert command in result.output
    result = invoke("--version")
    assert result.exit_code == 0 and __version__ in result.output
    result = invoke("simulate", "wall", "--help")
    assert result.exit_code == 0 and "--freq" in result.output and "--amp" in result.output


@pytest.mark.parametrize(
    "command", [(), ("simulate",), ("simulate", "wall"), ("build", "arch"), ("sweep",), ("inspect",)]
)
def test_h_is_help(command):
    # walk-through 2026-11-28: "masonry -h" said "error: No such option: -h (masonry --help lists the options)"
    result = invoke(*command, "-h")
    assert result.exit_code == 0 and result.output == invoke(*command, "--help").output


def _option_help(command: list[str]) -> dict[str, str]:
    """Each option of ``masonry COMMAND --help`` with its help text (joined over wrapped lines)."""
    from masonrycli.cli import app

    from cli_helpers import runner

    out = runner.invoke(app, [*command, "--help"], env={"COLUMNS": "250"}).output
    options, name = {}, None
    for line in out.splitlines():
        cells = line.strip("│ ").split()
        if cells and cells[0].startswith("--"):
            name = cells[0]
            options[name] = " ".join(cells[2:])
        elif name and cells and not line.startswith(("╭", "╰")):
            options[name] += " " + " ".join(cells)
    return options


def test_simulate_help_lists_only_what_the_structure_takes_with_its_defaults():
    # `simulate wall --help` offered --settlement ("Downward velocity of the right foundation"), which the
    # wall always refuses, and --freq / --amp / --scale showed no default (the wall is shaken at 1 m/s, 2 Hz).
    wall = _option_help(["simulate", "wall"])
    assert "--settlement" not in wall
    assert "(default 2)" in wall["--freq"] and "(default 1;" in wall["--amp"] and "(default 1)" in wall["--scale"]
    for name in ("arch", "aqueduct"):
        options = _option_help(["simulate", name])
        assert "(default 0.01;" in options["--settlement"] and "--settlement 0" in options["--amp"]
        assert "(default 2" in options["--freq"]


def test_run_and_check_help_give_the_scenario_files_values_as_defaults():
    # `run --help` said "(default 1e-3)" for --dt, although a file's [run] dt is what runs
    for command in (["run"], ["check"]):
        options = _option_help(command)
        assert "(default: the scenario file's value, else 1e-3)" in options["--dt"]
        assert "(default: the scenario file's value, else 0.5)" in options["--theta"]
        assert "(default: the scenario file's value, else 0.6)" in options["--friction"]
        assert (
            "(default: the scenario file's value)" in options["--duration"] and "simulate" not in options["--duration"]
        )
    simulate = _option_help(["simulate", "wall"])
    assert "(default 1e-3)" in simulate["--dt"] and "(default 0.6)" in simulate["--friction"]


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


def test_sweep_help_gives_the_default_file_names():
    # --out and --plot said nothing of where the table and the picture go when not given (study-<scenario>.parquet
    # in the working folder, the plot beside it), while --recording did
    options = _option_help(["sweep"])
    assert "default study-<scenario>.parquet" in options["--out"]
    assert "(default: beside --out, .png)" in options["--plot"]
    assert "(default: beside --out, .rrd)" in options["--recording"]


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
    said = words(result.output)
    assert "loading │ ground: record of acceleration (q.AT2, 200 samples, 0–1.99 s," in said, said
    assert "baseline-corrected) × 0.5" in said, said
    arch = words(invoke("check", DATA / "arch_settlement.toml").output)
    assert "loading │ right-foundation: constant velocity (0, -0.01) m/s" in arch, arch


@pytest.mark.parametrize(("command", "name"), [("check", "wall"), ("run", "arch")])
def test_a_built_in_name_given_as_scenario_file_points_to_simulate(command, name, tmp_path, monkeypatch):
    """QA: `masonry check wall` said "wall: cannot read scenario: No such file or directory"."""
    monkeypatch.chdir(tmp_path)  # no file called `wall` here
    result = invoke(command, name)
    assert_one_line_error(result, f"{name}: not a file", f"masonry simulate {name}")
    assert "No such file" not in result.output


@pytest.mark.parametrize(
    "args, fragments",
    [
        (("run", "no-such-file.toml"), ["no-such-file.toml"]),
        (("check", "no-such-file.toml"), ["no-such-file.toml"]),
        (("run", DATA / "validation" / "column5.toml", "--dt", -1), ["dt"]),
        (("run", DATA / "validation" / "column5.toml", "--theta", 0.2), ["theta"]),
        (("run", DATA / "validation" / "column5.toml", "--friction", "nan"), ["friction"]),
        (("simulate", "wall", "--blocks", 0, "--duration", 0.01), ["block count", "0"]),
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


def _frames_in(rrd: Path) -> int:
    """Frames shown in the recording (the initial state, t = 0, first: the history's frames)."""
    from masonrycli.recording import inspect_recording

    info = inspect_recording(rrd)
    assert info["application_id"] == "masonry"
    return info["frames"]


def test_divergence_leaves_complete_outputs(tmp_path, monkeypatch):
    import masonrycli.run as run_module

    monkeypatch.setattr(run_module, "DIVERGENCE_SPEED", 0.05)  # the shaken wall exceeds it quickly
    rrd, npz = tmp_path / "div.rrd", tmp_path / "div.npz"
    result = invoke("simulate", "wall", "--duration", 0.5, "--out", rrd, "--history", npz)
    assert result.exit_code == 3, result.output
    assert "diverged" in result.output
    h = np.load(npz)
    assert str(h["status"]) == "diverged"
    assert _frames_in(rrd) == len(h["time"])


def test_engine_error_mid_run_keeps_frames(tmp_path, monkeypatch):
    from masonrycli.run import Simulation

    original = Simulation.step

    def failing(self):
        if self.state.step == 25:
            raise FloatingPointError("synthetic failure")
        return original(self)

    monkeypatch.setattr(Simulation, "step", failing)
    rrd, npz = tmp_path / "err.rrd", tmp_path / "err.npz"
    result = invoke("simulate", "wall", "--duration", 0.1, "--out", rrd, "--history", npz)
    assert result.exit_code == 1, result.output
    assert "Traceback" not in result.output and "synthetic failure" in result.output
    h = np.load(npz)
    assert str(h["status"]) == "failed"
    assert list(h["step"]) == [0, 10, 20]
    assert _frames_in(rrd) == 3


def test_build_says_one_block_in_the_singular(tmp_path):
    # "wall: 1 blocks and 1 support → w.geojson"
    result = invoke("build", "wall", "--blocks", 1, "--out", tmp_path / "w.geojson")
    said = words(result.output)  # the console wraps a long path
    assert result.exit_code == 0 and f"wall: 1 block and 1 support → {tmp_path / 'w.geojson'}" in said


@pytest.mark.parametrize(
    "builder, args, blocks, supports",
    [
        ("wall", ["--blocks", "51"], 51, 1),
        ("wall", ["--blocks", "248"], 248, 1),
        ("arch", [], 98, 2),
    ],
)
def test_build_writes_geojson_that_runs(builder, args, blocks, supports, tmp_path):
    """`masonry build` output: the right counts, convex, non-overlapping (checked with shapely), and the
    same format runs directly and from a scenario file that gives its support a motion."""
    from shapely.geometry import shape
    from shapely.strtree import STRtree

    out = tmp_path / f"{builder}.{'json' if supports == 2 else 'geojson'}"  # .json: `run` reads it as GeoJSON
    result = invoke("build", builder, *args, "--out", out)
    assert result.exit_code == 0, result.output
    features = json.loads(out.read_text())["features"]
    polys = [shape(f["geometry"]) for f in features if f["properties"]["role"] == "block"]
    assert len(polys) == blocks
    assert sum(f["properties"]["role"] == "support" for f in features) == supports
    for p in polys:
        assert p.convex_hull.area - p.area < 1e-12
    tree = STRtree(polys)
    for i, p in enumerate(polys):
        for j in tree.query(p):
            if j > i:
                assert p.intersection(polys[j]).area < 1e-9
    if builder == "wall" and blocks == 51:
        npz = tmp_path / "direct.npz"
        result = invoke("run", out, "--duration", 0.01, "--no-recording", "--history", npz)
        assert result.exit_code == 0, result.output
        assert np.load(npz)["block_q"].shape[1] == 51
        scen = tmp_path / "shaken.toml"
        scen.write_text(
            f'[run]\nduration = 0.02\n[structure]\nfile = "{out.name}"\n[[support]]\nname = "ground"\n'
            'motion = { kind = "sine", amplitude = 1.0, frequency = 2.0 }\n'
        )
        result = invoke("run", scen, "--no-recording", "--history", npz, "--force")
        assert result.exit_code == 0, result.output
        assert np.load(npz)["support_v"][-1, 0, 0] == pytest.approx(np.sin(2 * np.pi * 2 * 0.02))


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


def test_geometry_file_errors_are_one_line(tmp_path):
    bad = tmp_path / "bad.geojson"
    bad.write_text("{ not json")
    assert_one_line_error(invoke("run", bad, "--no-recording"), "bad.geojson")
    scen = tmp_path / "s.toml"
    scen.write_text('[structure]\nfile = "missing.geojson"\n')
    assert_one_line_error(invoke("check", scen), "missing.geojson", "no such file")


def test_inspect_summarises_a_recording(tmp_path):
    rrd = tmp_path / "w.rrd"
    assert invoke("simulate", "wall", "--duration", 0.03, "--out", rrd).exit_code == 0
    result = invoke("inspect", rrd)
    assert result.exit_code == 0, result.output
    assert "masonry" in result.output and "/structure/plane/xy/blocks" in result.output
    assert "steps          │ 0 … 30" in result.output  # from the initial frame (it began at 10)
    bad = tmp_path / "bad.rrd"
    bad.write_bytes(b"not a recording")
    assert_one_line_error(invoke("inspect", bad), "bad.rrd")
    assert_one_line_error(invoke("inspect", tmp_path / "missing.rrd"), "missing.rrd")


def test_unconverged_steps_are_counted_and_warned(tmp_path):
    """A sweep cap too low for the tolerance: the summary, the history and a warning say how many steps."""
    npz = tmp_path / "h.npz"
    r = invoke("simulate", "wall", "--duration", "0.02", "--max-iterations", "2", "--no-recording", "--history", npz)
    assert r.exit_code == 0, r.output
    assert "warning: 20 of 20 steps ended unconverged" in words(r.output)
    assert "20 at the 2-sweep cap, the worst " in words(r.output)  # none stalled: not said
    # (what stalled steps go through, by solver: test_execute.py, unconverged_warning)
    h = np.load(npz)
    assert h["nlgs_unconverged"][-1] == 20
    assert np.all(h["nlgs_iterations"][1:] == 2) and np.all(h["nlgs_residual"][1:] > 1e-5)
    # the worst step's residual is at least the largest the history's frames kept, said at a step's time
    worst = re.search(r"the worst (\S+) m/s \((\S+)× the tolerance\) at t = (\S+) s\); their", words(r.output))
    residual, times, t = float(worst[1]), float(worst[2]), float(worst[3])
    assert residual >= h["nlgs_residual"][1:].max() and times == pytest.approx(residual / 1e-5, rel=0.05)
    assert 0 < t <= 0.02 and round(t / 1e-3) == pytest.approx(t / 1e-3, abs=1e-9)
    npz = tmp_path / "h_default.npz"
    r = invoke("simulate", "wall", "--duration", "0.02", "--no-recording", "--history", npz)
    assert r.exit_code == 0 and "unconverged" in r.output and "warning" not in r.output, r.output
    h = np.load(npz)
    assert h["nlgs_unconverged"][-1] == 0 and np.all(h["nlgs_residual"] <= 1e-5)


def test_solver_option_runs_either_solver_to_the_same_motion(tmp_path):
    """--solver nlgs (plain Gauss–Seidel, the reference) and the default accelerated solver both converge
    every step, and their motions agree to within what the tolerance allows (velocities are unique)."""
    q = {}
    for solver in ("nlgs", "nlgs-accel32", "nlgs-accel", None):
        npz = tmp_path / f"h_{solver}.npz"
        extra = ("--solver", solver) if solver else ()
        r = invoke("simulate", "wall", "--duration", "0.1", "--no-recording", "--history", npz, *extra)
        assert r.exit_code == 0, r.output
        h = np.load(npz)
        assert h["nlgs_unconverged"][-1] == 0 and np.all(h["nlgs_residual"] <= 1e-5)
        q[solver] = h["block_q"]
    np.testing.assert_array_equal(q[None], q["nlgs-accel32"])  # the default
    for solver in ("nlgs-accel32", "nlgs-accel"):
        assert np.abs(q["nlgs"][..., :2] - q[solver][..., :2]).max() < 5e-4  # m, after 0.1 s of shaking


def test_command_list_keeps_each_summary_on_one_line():
    # The list showed run's and check's docstrings with their source line breaks ("options given here" /
    # "override the file's values." on two lines of a 120-column terminal).
    from masonrycli.cli import app

    from cli_helpers import runner

    out = runner.invoke(app, ["--help"], env={"COLUMNS": "250"}).output
    assert "options given here override the file's values." in out
    assert "print a summary (blocks, supports, mass" in out


def test_a_two_step_run_completes():
    # It wrote its outputs, then ended in "internal error: IndexError" (exit 1) computing D5–95.
    result = invoke("simulate", "wall", "--duration", 0.002, "--no-recording")
    assert result.exit_code == 0, result.output
    assert "D5–95 nan s" in words(result.output)


def test_a_closed_stdout_is_not_bad_input(tmp_path):
    # `masonry limit arch --json | head -c 10` printed "error: Broken pipe" and exit 2 (bad input); now it
    # stops quietly as click does for the other commands (exit 1, nothing on stderr).
    import os
    import subprocess
    import sys

    env = os.environ | {"RERUN_ANALYTICS": "0"}
    cmd = [sys.executable, "-m", "masonrycli", "limit", DATA / "validation" / "column5.toml", "--json"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    proc.stdout.close()  # the reader is gone before the first write
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 1 and err == "", err


def test_ctrl_c_before_the_run_is_one_line_and_exit_130(monkeypatch):
    # a Ctrl-C while the structure is built (before the run's own signal handling) exited 130 without a word
    import masonrycli.builtin

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(masonrycli.builtin, "builtin", interrupted)
    result = invoke("simulate", "wall", "--duration", 0.01, "--no-recording")
    assert result.exit_code == 130
    assert result.output.strip() == "error: Ctrl-C: stopped before any output was written"


def test_ctrl_c_while_masonry_starts_is_one_line_and_exit_130(monkeypatch, capsys):
    # a Ctrl-C in the first half second (Python importing typer, rich, numpy) printed a KeyboardInterrupt
    # traceback: the entry point imports the command line inside its own try
    import importlib.abc
    import sys

    from masonrycli.__main__ import main

    class Interrupted(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name == "masonrycli.cli":
                raise KeyboardInterrupt

    monkeypatch.delitem(sys.modules, "masonrycli.cli")
    monkeypatch.setattr(sys, "meta_path", [Interrupted(), *sys.meta_path])
    with pytest.raises(SystemExit) as exc:
        main()
    assert exc.value.code == 130
    assert capsys.readouterr().err == "error: Ctrl-C while masonry was starting: nothing was run\n"


def test_choice_options_take_any_case_and_help_lists_the_lower_case(tmp_path):
    # "sweep --im PGV" said "--im PGV: expected one of pga, pgv, arias, sa"; "limit --load Tilt",
    # "--direction -X", "--outcome Sliding" and "--solver NLGS" likewise
    r = invoke("limit", "wall", "--load", "Tilt", "--direction", "-X", "--json")
    assert r.exit_code == 0, r.output
    r = invoke("simulate", "wall", "--solver", "NLGS", "--duration", "0.01", "--no-recording")
    assert r.exit_code == 0, r.output
    out = tmp_path / "s.csv"
    sweep = ("sweep", "wall", "-p", "amp=0.1,0.2", "--find", "amp", "--outcome", "Sliding", "--im", "PGV")
    r = invoke(*sweep, "--duration", "0.05", "--workers", "0", "--no-recording", "-o", out)
    assert r.exit_code == 0, r.output
    assert "pga, pgv, arias, sa" in invoke("sweep", "--help").output


def test_a_tilde_the_shell_left_is_the_home_folder(tmp_path, monkeypatch):
    # "--out=~/runs/w.rrd" (no expansion after "=") made a folder named "~" in the working folder and wrote
    # there; --history and build --out alike.
    home, work = tmp_path / "home", tmp_path / "work"
    work.mkdir()
    (home / "runs").mkdir(parents=True)
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir(work)
    result = invoke("simulate", "wall", "--duration", 0.01, "--out=~/runs/w.rrd", "--history=~/runs/w.npz")
    assert result.exit_code == 0, result.output
    assert invoke("build", "wall", "--out=~/runs/w.geojson").exit_code == 0
    assert sorted(p.name for p in (home / "runs").iterdir()) == ["w.geojson", "w.npz", "w.rrd"]
    assert list(work.iterdir()) == []
