"""``--record`` on the command line: the ground moves as the record says, intensity in summary and history."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from masonrycli.cli.app import app
from masonrycli.records.read import G_STANDARD, record_motion
from masonrycli.study.store import read_rows

from cli_helpers import words
from synthetic_records import band_limited, write_at2

DATA = Path(__file__).parent / "data"
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], terminal_width=200)


@pytest.fixture
def at2(tmp_path):
    t, u, v, a = band_limited(2.0, 0.01, [1.5, 3.0], [0.01, 0.004], seed=3)
    write_at2(tmp_path / "quake.AT2", a / G_STANDARD, 0.01)
    return tmp_path / "quake.AT2"


def test_simulate_wall_with_record_and_scale(at2, tmp_path):
    npz = tmp_path / "h.npz"
    result = invoke(
        "simulate", "wall", "--blocks", 12, "--record", at2, "--scale", 0.5, "--duration", 0.2, "--dt", 1e-3,
        "--record-every", 1, "--no-recording", "--history", npz,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "ground motion (ground)" in result.output and "PGA" in result.output
    h = np.load(npz)
    motion = record_motion(at2, scale=0.5)
    np.testing.assert_array_equal(h["support_v"][:, 0, :], motion.velocity_at(h["time"]))
    acc = np.diff(motion.velocity_at(np.arange(201) * 1e-3)[:, 0]) / 1e-3
    assert float(h["intensity_pga"]) == pytest.approx(np.abs(acc).max(), rel=1e-12)
    assert float(h["intensity_pgv"]) == pytest.approx(np.abs(h["support_v"][:, 0, 0]).max(), rel=1e-12)


def test_arch_record_shakes_both_foundations_and_run_overrides_scenario_motion(at2, tmp_path):
    npz = tmp_path / "a.npz"
    result = invoke("simulate", "arch", "--record", at2, "--duration", 0.02, "--no-recording", "--history", npz)
    assert result.exit_code == 0, result.output
    h = np.load(npz)
    np.testing.assert_array_equal(h["support_v"][:, 0], h["support_v"][:, 1])
    assert np.abs(h["support_v"][:, 0, 0]).max() > 0
    npz = tmp_path / "r.npz"
    result = invoke(
        "run", DATA / "quake_record.toml", "--record", at2, "--scale", 2, "--no-recording", "--history", npz
    )
    assert result.exit_code == 0, result.output
    h = np.load(npz)
    np.testing.assert_array_equal(h["support_v"][:, 0, :], record_motion(at2, scale=2).velocity_at(h["time"]))


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["simulate", "wall", "--record", "RECORD", "--amp", 1], "--amp 1: choose one loading"),
        (
            ["simulate", "arch", "--record", "RECORD", "--settlement", 0.01],
            "with --settlement 0.01: choose one loading",
        ),
        (["simulate", "wall", "--scale", 2], "--scale 2 goes with --record"),
        (["simulate", "wall", "--record", "nope.AT2"], "nope.AT2: cannot read record"),
        (["run", DATA / "block_on_ground.toml", "--scale", 2], "--scale 2 goes with --record"),
        (["run", DATA / "column_5.toml", "--record", "RECORD"], "has no shaking support"),
    ],
)
def test_record_option_errors_are_one_line(at2, args, fragment):
    result = invoke(*[at2 if a == "RECORD" else a for a in args])
    assert result.exit_code == 2, result.output
    lines = [ln for ln in result.output.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and fragment in lines[0], result.output


def test_record_on_a_geometry_file_shakes_its_support_or_says_how_to_choose(at2, tmp_path):
    # `run wall.geojson --record q.AT2` of a wall on its one ground was refused ("holds no motion … shake one in
    # a scenario file"): the record shakes that ground. A file of several supports does not say which one shakes:
    # a scenario file names it.
    geo = tmp_path / "wall.geojson"
    assert invoke("build", "wall", "--blocks", 7, "--out", geo).exit_code == 0
    # marked driven (QGIS attribute support_role): its warning "driven, but given no motion, so fixed" is not said
    geo.write_text(geo.read_text().replace('"support_role": "fixed"', '"support_role": "driven"'))
    assert "driven, but given no motion" in invoke("check", geo).output
    result = invoke("check", geo, "--record", at2)
    assert result.exit_code == 0, result.output
    assert "loading │ ground: record of acceleration (quake.AT2" in words(result.output)
    assert "driven, but given no motion" not in result.output
    out = tmp_path / "s.csv"
    result = invoke("sweep", geo, "--records", at2, "--scale", 1, "--duration", 0.1, "--workers", 0, "--out", out)
    assert result.exit_code == 0 and "driven, but given no motion" not in result.output, result.output
    arch = tmp_path / "arch.geojson"
    assert invoke("build", "arch", "--out", arch).exit_code == 0
    result = invoke("run", arch, "--record", at2)
    assert result.exit_code == 2
    assert words(result.output) == (
        "error: --record: arch.geojson holds no motion and 2 supports (left-foundation, right-foundation); say "
        'which the record shakes: mark them "support_role": "driven" in the file (WKT: support NAME driven: …), or '
        'write a scenario file [structure] file = "arch.geojson" with a [[support]] name = "left-foundation" and '
        'motion = { kind = "record", file = ... } (masonry docs scenario-format)'
    )


def test_stop_at_collapse_ends_the_run_when_the_block_overturns(tmp_path):
    (tmp_path / "slender.toml").write_text(
        """
[run]
duration = 2.5
[material]
friction = 0.8
[[block]]
polygon = [[-0.125, 0.0], [0.125, 0.0], [0.125, 1.0], [-0.125, 1.0]]
[[support]]
name = "ground"
polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]
motion = { kind = "sine", amplitude = 0.5, frequency = 2.0 }
"""
    )
    npz = tmp_path / "h.npz"
    result = invoke("run", tmp_path / "slender.toml", "--stop-at-collapse", "--no-recording", "--history", npz)
    assert result.exit_code == 0, result.output
    said = words(result.output)
    assert "stopped at collapse" in said and "collapsed at t =" in said
    t_end = float(np.load(npz)["time"][-1])
    assert 0.5 < t_end < 2.5


def test_run_document_holds_the_baseline_correction(at2):
    from masonrycli.execute import run_metadata
    from masonrycli.run import Simulation
    from masonrycli.scenario.motion import Sine
    from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

    motion = record_motion(at2, scale=0.5)
    motions = {"left-foundation": motion, "right-foundation": Sine(amplitude=0.1, frequency=2.0)}
    scenario = scenario_from_builder("arch", {}, RunConfig(duration=0.01), Material(), motions)
    meta = run_metadata(scenario, Simulation(scenario))
    corr = meta["baseline_corrections"]
    assert set(corr) == {"left-foundation"} and corr["left-foundation"] == motion.baseline_correction
    assert corr["left-foundation"]["baseline"] == "quadratic" and len(corr["left-foundation"]["c1"]) == 2


def test_record_longer_than_the_run_is_run_whole_or_warned(at2, tmp_path):
    # the 2 s record on the built-in wall (default 1 s): the whole record without --duration
    npz = tmp_path / "whole.npz"
    result = invoke("simulate", "wall", "--blocks", 12, "--record", at2, "--no-recording", "--history", npz)
    assert result.exit_code == 0, result.output
    assert float(np.load(npz)["time"][-1]) == pytest.approx(2.0) and "warning" not in result.output
    # a shorter --duration: run as asked, and one line says what is left out
    result = invoke("simulate", "wall", "--blocks", 12, "--record", at2, "--duration", 0.05, "--no-recording")
    assert result.exit_code == 0, result.output
    assert (
        'warning: support "ground": the record quake.AT2 lasts 2 s but the run 0.05 s; its shaking after '
        "t = 0.05 s is not applied (--duration 2 runs it all)" in result.output
    )
    result = invoke("check", DATA / "quake_record.toml", "--record", at2)  # the file's 0.5 s
    assert result.exit_code == 0 and "the record quake.AT2 lasts 2 s but the run 0.5 s" in result.output


def test_a_wall_shaken_by_a_record_has_no_paper_figure_tabs(at2, tmp_path):
    """The paper's Figs. III.2–III.5 are the sine's (1 m/s at 2 Hz) at 0.1 s: the record's run opened on
    tabs named after them, pinned where the record had barely started, and the command said so."""
    from masonrycli.recording.readback import blueprint_views

    rrd = tmp_path / "quake.rrd"
    result = invoke("simulate", "wall", "--blocks", 12, "--record", at2, "--duration", 0.12, "--out", rrd)
    assert result.exit_code == 0, result.output
    assert "paper's Figs" not in result.output
    views = blueprint_views(rrd)
    assert not any(name.startswith("Fig.") or v["pinned"] for name, v in views.items())
    assert "Live" in views


def test_an_at2_file_with_samples_beyond_npts_says_so_once(tmp_path):
    # The samples after NPTS were dropped without a word (deliberately: the header defines the record), so
    # a header that was the mistake went unnoticed.
    at2 = tmp_path / "long.AT2"
    at2.write_text("PEER\nstation\nunits of g\nNPTS=     4, DT=   .0100 SEC\n 0.01 0.02 0.03 0.02\n 0.01 0.0\n")
    result = invoke("check", DATA / "quake_record.toml", "--record", at2)
    assert result.exit_code == 0, result.output
    # (cut at 0.02 g, the record does not end at rest: the baseline correction's warning says so too)
    said = [ln for ln in result.output.splitlines() if ln.startswith("warning:") and "at rest" not in ln]
    line = f"warning: {at2}: header says NPTS = 4 but the file holds 6 samples; the 2 after the first 4 are ignored"
    assert said == [line], result.output
    assert "4 samples" in words(result.output)  # still read as 4: the behaviour is kept


@pytest.fixture
def one_column(tmp_path):
    """A velocity record of one value per line (a header, no times) and the same record with times i·dt."""
    v = band_limited(0.3, 0.01, [3.0, 5.0], [0.002, 0.001], seed=4)[2].tolist()
    (tmp_path / "one.csv").write_text("ground velocity\n" + "".join(f"{x!r}\n" for x in v))
    (tmp_path / "two.csv").write_text("".join(f"{i * 0.01!r},{x!r}\n" for i, x in enumerate(v)))
    return tmp_path / "one.csv", tmp_path / "two.csv"


def test_record_dt_reads_a_one_column_record_on_simulate_run_and_check(one_column, tmp_path):
    one, two = one_column
    npz = tmp_path / "h.npz"
    result = invoke(
        "simulate", "wall", "--blocks", 12, "--record", one, "--record-dt", 0.01, "--scale", 0.5,
        "--duration", 0.3, "--record-every", 1, "--no-recording", "--history", npz,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    h = np.load(npz)
    np.testing.assert_array_equal(h["support_v"][:, 0, :], record_motion(two, scale=0.5).velocity_at(h["time"]))
    result = invoke(
        "run", DATA / "quake_record.toml", "--record", one, "--record-dt", 0.01, "--no-recording", "--history", npz,
        "--force",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    h = np.load(npz)
    np.testing.assert_array_equal(h["support_v"][:, 0, :], record_motion(two).velocity_at(h["time"]))
    result = invoke("check", DATA / "quake_record.toml", "--record", one, "--record-dt", 0.01)
    assert result.exit_code == 0, result.output
    said = words(result.output.replace("│", " "))  # the table's cell, wrapped over two lines
    assert "ground: record of velocity (one.csv, 31 samples every 0.01 s, 0–0.3 s) along (1, 0)" in said, said


@pytest.mark.parametrize(
    "args, line",
    [
        (
            ["--record", "ONE"],
            "error: ONE:2: one value per line, no times: give the time between samples: --record-dt SECONDS",
        ),
        (
            ["--record", "TWO", "--record-dt", 0.01],
            "error: TWO:1: 2 columns, but a time step was given: it is for a file of one value per line (this one "
            "has a time column: leave out --record-dt)",
        ),
        (
            ["--record", "AT2", "--record-dt", 0.01],
            "error: AT2: an .AT2 file gives its own time step (DT in its header): --record-dt goes with a CSV "
            "of one value per line",
        ),
        (
            ["--record-dt", 0.01],
            "error: --record-dt 0.01 goes with --record (the time between the samples of a one-column file)",
        ),
        (["--record", "ONE", "--record-dt", 0], "error: --record-dt 0: must be > 0"),
        (["--record", "ONE", "--record-dt", -0.01], "error: --record-dt -0.01: must be > 0"),
        (["--record", "ONE", "--record-dt", "nan"], "error: --record-dt nan: must be a finite number"),
        (["--record", "ONE", "--record-dt", "inf"], "error: --record-dt inf: must be a finite number"),
        (
            ["--record", "ONE", "--record-dt", 10],
            "error: --record-dt 10: must be within 1e-06–1 s, likely a typo (accelerographs sample every 1–20 ms; "
            "10 for 10 ms would stretch the record 1000-fold)",
        ),
    ],
)
@pytest.mark.parametrize("command", [["simulate", "wall"], ["run", DATA / "quake_record.toml"]])
def test_record_dt_errors_are_one_line(one_column, at2, command, args, line):
    files = {"ONE": one_column[0], "TWO": one_column[1], "AT2": at2}
    result = invoke(*command, *[files.get(a, a) if isinstance(a, str) else a for a in args], "--no-recording")
    assert result.exit_code == 2, result.output
    for name, path in files.items():
        line = line.replace(f"error: {name}", f"error: {path}")
    assert result.output.strip() == line and "Traceback" not in result.output


def test_a_csv_accelerogram_is_read_as_its_header_says(tmp_path):
    """A CSV of acceleration in m/s² (header "time (s),acc (m/s2)") was refused by --record ("the header
    says acceleration ... but the samples are read as velocity") with no option to say otherwise: it is now
    read as acceleration, exactly as a scenario file's quantity = "acceleration" reads it."""
    t, u, v, a = band_limited(0.2, 0.01, [3.0, 5.0], [0.004, 0.002], seed=4)
    csv = tmp_path / "acc.csv"
    csv.write_text("time (s),acc (m/s2)\n" + "".join(f"{ti!r},{ai!r}\n" for ti, ai in zip(t.tolist(), a.tolist())))
    npz = tmp_path / "h.npz"
    args = ["simulate", "wall", "--blocks", 12, "--record", csv, "--duration", 0.1, "--record-every", 1]
    result = invoke(*args, "--no-recording", "--history", npz)
    assert result.exit_code == 0, result.output
    h = np.load(npz)
    explicit = record_motion(csv, quantity="acceleration")
    np.testing.assert_array_equal(h["support_v"][:, 0, :], explicit.velocity_at(h["time"]))
    assert record_motion(csv).quantity == "acceleration"
    # a velocity header, or none, is velocity as before
    csv.write_text("time,v (m/s)\n0,0\n0.01,0.1\n")
    assert record_motion(csv).quantity == "velocity"
    csv.write_text("0,0\n0.01,0.1\n")
    assert record_motion(csv).quantity == "velocity"


def test_a_geometry_files_support_is_shaken_from_any_folder(tmp_path, monkeypatch):
    # a --scheduler's worker started in another folder resolved the command's relative 'wall.geojson' there:
    # every row of 'masonry sweep wall.geojson --records recs --scheduler …' was refused, "no shaking support"
    from masonrycli.scenario.record_option import shaken_supports
    from masonrycli.scenario.target import target_scenario

    (tmp_path / "study").mkdir()
    (tmp_path / "worker").mkdir()
    assert invoke("build", "wall", "--blocks", 7, "--out", tmp_path / "study" / "wall.geojson").exit_code == 0
    monkeypatch.chdir(tmp_path / "study")
    scenario = target_scenario("wall.geojson")
    monkeypatch.chdir(tmp_path / "worker")
    assert shaken_supports(scenario) == [True]


def test_a_geometry_file_shaken_by_a_record_runs_the_whole_record(at2, tmp_path):
    # a geometry file has no run settings: 'run wall.geojson --record q.AT2' ran the default 1 s of a 2 s record
    # (and a sweep over records likewise), where simulate runs the whole record
    geo = tmp_path / "wall.geojson"
    assert invoke("build", "wall", "--blocks", 7, "--out", geo).exit_code == 0
    result = invoke("check", geo, "--record", at2)
    assert result.exit_code == 0 and "time │ 2 s in 2000 steps of 0.001 s" in words(result.output), result.output
    assert "not applied" not in result.output
    result = invoke("check", geo, "--record", at2, "--dt", 0.003)  # whole steps of the dt given: 667 × 3 ms
    assert result.exit_code == 0 and "time │ 2.001 s in 667 steps of 0.003 s" in words(result.output), result.output
    result = invoke("check", geo, "--record", at2, "--duration", 0.5)  # a duration given stands
    assert "time │ 0.5 s in 500 steps" in words(result.output)
    out = tmp_path / "s.csv"
    result = invoke("sweep", geo, "--records", at2, "--scale", 0.01, "--workers", 0, "--out", out, "--no-recording")
    assert result.exit_code == 0, result.output
    (row,) = read_rows(out)
    assert row["steps"] == 2000 and "not applied" not in result.output


TWO_SUPPORTS = """{"type": "FeatureCollection", "features": [
 {"type": "Feature", "properties": {"role": "block", "name": "lintel"},
  "geometry": {"type": "Polygon", "coordinates": [[[-0.4, 0], [0.4, 0], [0.4, 0.2], [-0.4, 0.2], [-0.4, 0]]]}},
 {"type": "Feature", "properties": {"role": "support", "name": "left", "support_role": "driven"},
  "geometry": {"type": "Polygon", "coordinates": [[[-1, -0.5], [-0.05, -0.5], [-0.05, 0], [-1, 0], [-1, -0.5]]]}},
 {"type": "Feature", "properties": {"role": "support", "name": "right"},
  "geometry": {"type": "Polygon", "coordinates": [[[0.05, -0.5], [1, -0.5], [1, 0], [0.05, 0], [0.05, -0.5]]]}}
]}"""


def test_record_on_a_geometry_file_shakes_the_supports_it_marks_driven(tmp_path):
    # a lintel on two pads, the left one marked "support_role": "driven": --record shakes it, the right one stays
    # fixed (a file of several supports was refused: only a scenario file could say which one shakes)
    from masonrycli.scenario.record_option import with_record
    from masonrycli.scenario.target import target_scenario

    geo = tmp_path / "two.geojson"
    geo.write_text(TWO_SUPPORTS)
    rec = tmp_path / "v.csv"
    rec.write_text("time (s),vel (m/s)\n0,0\n0.05,0.1\n0.1,0\n")
    result = invoke("check", geo, "--record", rec)
    assert result.exit_code == 0, result.output
    said = words(result.output)
    assert "loading │ left: record of velocity (v.csv, 3 samples" in said and "right:" not in said
    assert "driven, but given no motion" not in said
    scenario = with_record(target_scenario(geo), rec, None)
    assert [m.kind for m in scenario.motions] == ["record", "fixed"]
    assert [s.role for s in scenario.assembly.supports] == ["driven", "fixed"]
    t = np.array([0.0, 0.025, 0.05, 0.2])
    np.testing.assert_array_equal(scenario.motions[0].velocity_at(t)[:, 0], [0.0, 0.05, 0.1, 0.0])  # linear
    np.testing.assert_array_equal(scenario.motions[1].velocity_at(t), np.zeros((4, 2)))
    # both marked: both shake; a sweep over records does the same
    both = tmp_path / "both.geojson"
    both.write_text(TWO_SUPPORTS.replace('"name": "right"', '"name": "right", "support_role": "Driven"'))
    assert [m.kind for m in with_record(target_scenario(both), rec, None).motions] == ["record", "record"]
    out = tmp_path / "s.csv"
    result = invoke("sweep", geo, "--records", rec, "--scale", "1,2", "--duration", 0.1, "--workers", 0, "--out", out)
    assert result.exit_code == 0 and "driven, but given no motion" not in result.output, result.output
    assert len(read_rows(out)) == 2
    # a role that is neither: one line naming the feature and the support
    bad = tmp_path / "bad.geojson"
    bad.write_text(TWO_SUPPORTS.replace('"support_role": "driven"', '"support_role": "shaken"'))
    result = invoke("run", bad, "--record", rec)
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert words(result.output) == (
        f"error: {bad}: feature 2: support 1 (\"left\"): support_role must be one of ('fixed', 'driven'), got 'shaken'"
    )
