"""``masonry sweep`` as a user drives it (in process, --workers 0): records and a fragility curve, the
state map, the recording, resume, and one-line errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from masonrycli.cli import app
from masonrycli.errors import InputError
from masonrycli.records import G_STANDARD
from masonrycli.study.store import read_rows

from synthetic_records import band_limited, write_at2

runner = CliRunner()
BLOCK = """
[run]
duration = 1.0
dt = 2e-3
[material]
friction = 0.8
[[block]]
polygon = [[-0.1, 0.0], [0.1, 0.0], [0.1, 0.6], [-0.1, 0.6]]
[[support]]
name = "ground"
polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]
motion = { kind = "sine", amplitude = 0.1, frequency = 2.0 }
"""


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], terminal_width=200)


@pytest.fixture
def block(tmp_path) -> Path:
    (tmp_path / "block.toml").write_text(BLOCK)
    return tmp_path / "block.toml"


def test_records_sweep_fits_a_fragility_curve_and_records_the_study(block, tmp_path):
    folder = tmp_path / "records"
    folder.mkdir()
    for seed in range(3):
        t, u, v, a = band_limited(1.0, 0.01, [1.0 + 0.4 * seed, 2.5], [0.03, 0.01], seed=seed)
        write_at2(folder / f"syn{seed}.AT2", a / G_STANDARD, 0.01)
    out, rrd = tmp_path / "ida.csv", tmp_path / "ida.rrd"
    result = invoke(
        "sweep", block, "--records", folder, "--scale", "0.5:8:4", "--workers", 0, "--out", out, "--recording", rrd
    )
    assert result.exit_code == 0, result.output
    rows = read_rows(out)
    assert len(rows) == 12 and {r["record"] for r in rows} == {"syn0.AT2", "syn1.AT2", "syn2.AT2"}
    states = {r["state"] for r in rows}
    assert "collapsed" in states and states & {"intact", "damaged"}
    # the IM of a row is the record as applied: PGA grows with the scale, for each record
    for name in ("syn0.AT2", "syn1.AT2"):
        pga = [r["pga"] for r in rows if r["record"] == name]
        scale = [r["scale"] for r in rows if r["record"] == name]
        np.testing.assert_allclose(np.array(pga) / pga[0], np.array(scale) / scale[0], rtol=1e-6)
    said = " ".join(result.output.split())  # the console wraps long lines
    # these runs are separated by the PGA (every collapse above every run that stood): the line says the
    # dispersion is not resolved and where the gap is (it printed "dispersion β = 0.0..", the fit's bound)
    stood = max(r["pga"] for r in rows if r["state"] != "collapsed")
    fell = min(r["pga"] for r in rows if r["state"] == "collapsed")
    assert f"fragility (pga): not resolved — every collapse (pga ≥ {fell:.4g} m/s²)" in said
    assert f"(≤ {stood:.4g} m/s²)" in said and "dispersion β → 0" in said
    assert (tmp_path / "ida.png").stat().st_size > 0

    import rerun as rr

    paths = {ch.entity_path for ch in rr.chunk.RrdReader(str(rrd)).stream()}
    assert {"/study/fragility/fit", "/study/fragility/runs/collapsed", "/study/plot", "/study/rows"} <= paths
    check_fragility_reads_as_a_plot(rrd, rows)
    shown = invoke("inspect", rrd)  # a study has no time line: a dash, not Python's "None"
    assert shown.exit_code == 0 and "None" not in shown.output and "time_span      │ —" in shown.output
    # the plot and the recording exist now: --force replaces them and still reuses every finished row
    again = invoke("sweep", block, "--records", folder, "--scale", "0.5:8:4", "--workers", 0, "--out", out, "--force")
    assert again.exit_code == 0 and "(0 runs now, 12 rows already there" in " ".join(again.output.split())
    # records given as files (repeatable) make the same study as their folder
    files = [a for f in sorted(folder.iterdir()) for a in ("--records", f)]
    again = invoke("sweep", block, *files, "--scale", "0.5:8:4", "--workers", 0, "--out", out, "--force")
    assert again.exit_code == 0 and "(0 runs now, 12 rows already there" in " ".join(again.output.split())
    twice = invoke("sweep", block, "--records", folder, "--records", folder / "syn0.AT2", "--out", out)
    assert twice.exit_code == 2 and "two records named syn0.AT2" in twice.output


def check_fragility_reads_as_a_plot(rrd: Path, rows: list[dict]) -> None:
    """The fragility curve opens as a plot with its own axes: P(collapse) 0-1 against the IM from 0 to
    past the largest run (in a 2-D view with one scale for both it read as a flat line 60 m/s² long and
    1 high), each run at 0 or 1 at its own PGA, the fitted curve rising from 0 to 1."""
    import rerun as rr

    from masonrycli.recording.readback import blueprint_views

    # the view's name gives its axes (the plot draws none) and how to read the x ticks, "#2000" (2 m/s² of
    # pga): the name said "pga (mm/s²)" alone
    name = "fragility: P(collapse) against pga in mm/s² (#1000 = 1 m/s²)"
    assert blueprint_views(rrd)[name]["kind"] == "TimeSeries"
    assert panel_states(rrd) == {"/blueprint_panel": "collapsed", "/selection_panel": "collapsed"}
    reader = rr.chunk.RrdReader(str(rrd))
    layout = {}
    for chunk in reader.stream(store=reader.blueprints()[0]):
        batch = chunk.to_record_batch()
        layout |= {n: batch.column(n).to_pylist()[-1][0] for n in batch.schema.names if ":" in n}
    timeline = "pga (mm/s²)"  # thousandths of the IM's unit: a sequence time line is an integer
    assert layout["TimePanelBlueprint:timeline"] == timeline  # the time line the plot is drawn against
    assert layout["ScalarAxis:range"] == [-0.05, 1.05]
    top = max(r["pga"] for r in rows)
    assert layout["TimeAxis:view_range"]["start"] == 0 and layout["TimeAxis:view_range"]["end"] >= 1000 * top
    series: dict[str, tuple[list, list]] = {}
    for chunk in reader.stream():
        if not chunk.is_static and chunk.entity_path.startswith("/study/fragility/"):
            batch = chunk.to_record_batch()
            ticks, values = series.setdefault(chunk.entity_path.rsplit("/", 1)[1], ([], []))
            ticks += batch.column(timeline).to_pylist()
            values += [v[0] for v in batch.column("Scalars:scalars").to_pylist()]
    for state in ("intact", "damaged", "collapsed"):
        expected = sorted(round(1000 * r["pga"]) for r in rows if r["state"] == state)
        ticks, values = series.get(state, ([], []))
        assert sorted(ticks) == expected and set(values) <= {1.0 if state == "collapsed" else 0.0}
    ticks, p = series["fit"]
    assert ticks[0] == 0 and p[0] == 0.0 and p[-1] > 0.99 and np.all(np.diff(p) >= 0)


def panel_states(rrd: Path) -> dict[str, str]:
    """The blueprint and selection panels' states: open (Rerun's default) they took two fifths of the
    window from the study's three views."""
    import rerun as rr

    names = {1: "hidden", 2: "collapsed", 3: "expanded"}
    reader = rr.chunk.RrdReader(str(rrd))
    out = {}
    for chunk in reader.stream(store=reader.blueprints()[0]):
        batch = chunk.to_record_batch()
        if "PanelBlueprint:state" in batch.schema.names:
            out[chunk.entity_path] = names[batch.column("PanelBlueprint:state").to_pylist()[-1][0]]
    return out


def blueprint_layout(rrd: Path) -> dict:
    """The last value of every blueprint property of the recording (``"ScalarAxis:range"`` ...)."""
    import rerun as rr

    reader = rr.chunk.RrdReader(str(rrd))
    layout = {}
    for chunk in reader.stream(store=reader.blueprints()[0]):
        batch = chunk.to_record_batch()
        layout |= {n: batch.column(n).to_pylist()[-1][0] for n in batch.schema.names if ":" in n}
    return layout


def test_find_threshold_curve_reads_as_a_plot(block, tmp_path):
    """The threshold curve (amp_threshold in m/s against friction 0.1-0.2) opens as a plot with its own
    axes: in a 2-D view with one scale for both it read as a flat line; each point at its own friction
    on the time line in thousandths of it, the y axis from 0 to above the largest threshold."""
    import rerun as rr

    from masonrycli.recording.readback import blueprint_views

    out, rrd = tmp_path / "find.csv", tmp_path / "find.rrd"
    args = ["-p", "amp=0.02:0.4:3", "--find", "amp", "-p", "friction=0.1,0.2", "--outcome", "sliding"]
    result = invoke("sweep", block, *args, "--duration", 0.3, "--workers", 0, "--out", out, "--recording", rrd)
    assert result.exit_code == 0, result.output
    rows = read_rows(out)
    found = {r["friction"]: r["amp_threshold"] for r in rows}
    assert len(found) == 2 and all(np.isfinite(v) for v in found.values())
    # how to read the x ticks "#100 … #200" (the name said "friction (/1000)")
    assert blueprint_views(rrd)["thresholds: amp (m/s) against friction × 1000 (#1000 = 1)"]["kind"] == "TimeSeries"
    assert panel_states(rrd) == {"/blueprint_panel": "collapsed", "/selection_panel": "collapsed"}
    layout = blueprint_layout(rrd)
    timeline = "friction (×1000)"  # a sequence time line is an integer: thousandths of the friction
    assert layout["TimePanelBlueprint:timeline"] == timeline
    low, high = layout["ScalarAxis:range"]
    assert low == 0.0 and max(found.values()) < high < 2 * max(found.values())
    view = layout["TimeAxis:view_range"]
    assert view["start"] <= 100 and view["end"] >= 200 + 0.05 * 100  # a margin beside the last point
    # The view shows no more than the time line holds: its ends are marked on it (outside the plot), else
    # the last point sat on the right edge, half cut.
    extent = [
        ch.to_record_batch().column(timeline).to_pylist()
        for ch in rr.chunk.RrdReader(str(rrd)).stream()
        if ch.entity_path == "/study/extent"
    ]
    assert extent == [[view["start"], view["end"]]]
    series = {}
    for chunk in rr.chunk.RrdReader(str(rrd)).stream():
        if not chunk.is_static and chunk.entity_path.startswith("/study/thresholds/"):
            batch = chunk.to_record_batch()
            values = [v[0] for v in batch.column("Scalars:scalars").to_pylist()]
            series[chunk.entity_path] = dict(zip(batch.column(timeline).to_pylist(), values))
    expected = {round(1000 * f): t for f, t in found.items()}
    # the line and its points are one entity, one legend entry (two listed "amp_threshold (m/s)" and
    # "amp_threshold (m/s): points"), as in the PNG
    assert series == {"/study/thresholds/line": expected}
    styles = {}
    for chunk in rr.chunk.RrdReader(str(rrd)).stream():
        if chunk.is_static and chunk.entity_path == "/study/thresholds/line":
            batch = chunk.to_record_batch()
            styles |= {n: batch.column(n).to_pylist()[-1] for n in batch.schema.names if n.endswith(":names")}
    assert styles == {"SeriesLines:names": ["amp_threshold (m/s)"], "SeriesPoints:names": ["amp_threshold (m/s)"]}


def test_the_counts_line_says_one_row(block, tmp_path):
    # it said "1 rows in s.csv (1 runs now, 0 rows already there, 0 failed)"
    args = ["-p", "amp=0.1", "--duration", 0.02, "--workers", 0, "-o", tmp_path / "s.csv", "--no-recording"]
    result = invoke("sweep", block, *args)
    assert result.exit_code == 0, result.output
    assert f"1 row in {tmp_path / 's.csv'} (1 run now, 0 rows already there, 0 failed)" in " ".join(
        result.output.split()
    )
    again = " ".join(invoke("sweep", block, *args, "--force").output.split())
    assert "(0 runs now, 1 row already there, 0 failed)" in again


def test_grid_sweep_state_map_and_histories(block, tmp_path):
    out = tmp_path / "grid.parquet"
    args = ["-p", "amp=0.05,0.6", "-p", "friction=0.3,0.8", "--duration", 0.3, "--workers", 0, "-o", out]
    result = invoke("sweep", block, *args, "--histories", tmp_path / "h", "--recording", tmp_path / "grid.rrd")
    assert result.exit_code == 0, result.output
    rows = read_rows(out)
    assert [(r["amp"], r["friction"]) for r in rows] == [(0.05, 0.3), (0.05, 0.8), (0.6, 0.3), (0.6, 0.8)]
    assert rows[0]["state"] == "intact" and rows[0]["time"] == pytest.approx(0.3)
    assert (tmp_path / "grid.png").stat().st_size > 0
    h = np.load(tmp_path / "h" / "amp=0.6_friction=0.3.npz")
    assert float(h["intensity_pga"]) == rows[2]["pga"] and h["time"][-1] == pytest.approx(rows[2]["time"])
    assert len(list((tmp_path / "h").glob("*.npz"))) == 4

    import rerun as rr

    chunks = list(rr.chunk.RrdReader(str(tmp_path / "grid.rrd")).stream())
    assert {"/study/state_map", "/study/plot", "/study/rows"} <= {ch.entity_path for ch in chunks}
    # Drawn y up as in the PNG (Rerun's 2-D views point y down: it showed the smaller friction on top),
    # the labels on hover only (drawn, they overlapped into one unreadable line).
    found = {}
    for ch in chunks:
        if ch.entity_path == "/study/state_map":
            batch = ch.to_record_batch()
            found |= {n: batch.column(n).to_pylist()[0] for n in batch.schema.names if ":" in n}
    assert found["Transform3D:scale"] == [[1.0, -1.0, 1.0]] and found["Points2D:show_labels"] == [False]
    # The axes: each swept value drawn once beside the map, the view's name says which way each runs (it
    # was four unlabelled dots on black), the side panels collapsed.
    axes = {}
    for ch in chunks:
        if ch.entity_path == "/study/state_map/axes":
            batch = ch.to_record_batch()
            axes |= {n: batch.column(n).to_pylist()[0] for n in batch.schema.names if ":" in n}
    assert axes["Points2D:labels"] == ["amp=0.05", "amp=0.6", "friction=0.3", "friction=0.8"]
    assert axes["Points2D:show_labels"] == [True]
    x_labels, y_labels = np.array(axes["Points2D:positions"][:2]), np.array(axes["Points2D:positions"][2:])
    assert list(x_labels[:, 0]) == pytest.approx([0.05, 0.6]) and np.all(x_labels[:, 1] < 0.3)
    assert list(y_labels[:, 1]) == pytest.approx([0.3, 0.8]) and np.all(y_labels[:, 0] < 0.05)
    # The key names the colours (the recording did not; the PNG has a legend), in the PNG's colours,
    # in a row under the map's x labels
    key = {}
    for ch in chunks:
        if ch.entity_path == "/study/state_map/key":
            batch = ch.to_record_batch()
            key |= {n: batch.column(n).to_pylist() for n in batch.schema.names if ":" in n}
    from masonrycli.colormap import unpack_rgba
    from masonrycli.study.curves import STATE_COLOURS, rgb

    assert key["Points2D:labels"][0] == ["intact", "damaged", "collapsed", "failed"]
    drawn = [tuple(int(v) for v in c[:3]) for c in unpack_rgba(np.array(key["Points2D:colors"][0], np.uint32))]
    assert drawn == [rgb(STATE_COLOURS[s]) for s in ("intact", "damaged", "collapsed", "")]
    assert np.all(np.array(key["Points2D:positions"][0])[:, 1] < x_labels[:, 1].min())
    from masonrycli.recording.readback import blueprint_views

    assert blueprint_views(tmp_path / "grid.rrd")["state map: amp (m/s) right, friction up"]["kind"] == "2D"
    assert panel_states(tmp_path / "grid.rrd") == {"/blueprint_panel": "collapsed", "/selection_panel": "collapsed"}


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["-p", "bogus=1"], "--param bogus: unknown parameter"),
        (["-p", "amp=1:2"], "--param amp=1:2: a range is LO:HI:N"),
        # a repeated value ran twice, into two rows of one key
        (["-p", "amp=0.1,0.2,0.1"], "--param amp: the value 0.1 is given twice (each point runs once)"),
        (["-p", "amp=0.1:0.1:3"], "--param amp: the value 0.1 is given twice"),
        ([], "nothing to sweep"),
        (["-p", "amp=0.1,0.2", "--find", "freq"], "--find freq: give its range too"),
        (["-p", "amp=0.1,0.2", "--outcome", "fall"], "--outcome fall: expected collapse, sliding"),
        (["-p", "amp=0.1,0.2", "--out", "x.txt"], "a study is written as .parquet or .csv"),
        (["-p", "scale=1,2"], "has no record motion"),
        (["-p", "amp=0.1", "--records", "nowhere"], "--records nowhere: no such file or folder"),
        (["-p", "amp=0.1", "--workers", "2", "--scheduler", "tcp://x:1"], "--workers with --scheduler"),
        (["-p", "amp=0.1", "--recording", "x.png"], "--recording x.png: the file name must end in .rrd"),
        (["-p", "amp=0.1", "--plot", "x.jpg"], "--plot x.jpg: the file name must end in .png"),
        (["-p", "amp=0.1", "--recording", "x.rrd", "--no-recording"], "--recording x.rrd with --no-recording"),
        # these four ended in a Dask traceback (exit 1); the empty one started a LocalCluster instead
        (["-p", "amp=0.1", "--scheduler", "foo"], "--scheduler 'foo': not an address with a port from 1 to 65535"),
        (["-p", "amp=0.1", "--scheduler", "http://h:8786"], "--scheduler http://h:8786: http:// is not supported"),
        (["-p", "amp=0.1", "--scheduler", "tls://h:8786"], "tls:// is not supported (expected tcp://HOST:PORT"),
        (["-p", "amp=0.1", "--scheduler", "tcp://h:99999"], "a port from 1 to 65535"),  # waited 20 s
        (["-p", "amp=0.1", "--scheduler", ""], "--scheduler '': not an address"),
        # a bad --dt given with --duration was blamed on --duration ("--duration: dt = 0.0: must be > 0")
        (["-p", "amp=0.1", "--duration", "0.02", "--dt", "0"], "--dt: dt = 0.0: must be > 0"),
        (["-p", "amp=0.1", "--duration", "0.02", "--dt", "nan"], "--dt: dt = nan: must be a finite number"),
        (["-p", "amp=0.1", "--duration", "-1", "--dt", "0.01"], "--duration: duration = -1.0: must be > 0"),
        (["-p", "amp=0.1,1e30"], "--param amp=1e+30: "),  # it ran, exit 0
        # both rows ran at 0.5 m/s, under the names amp=0.1 and amp=0.2
        (["-p", "amp=0.1,0.2", "-p", "ground.amp=0.5"], "--param ground.amp: sets the amplitude of support 'ground'"),
        # without --find these were ignored: a grid ran and reported states, not the outcome asked for
        (["-p", "amp=0.1,0.2", "--outcome", "sliding"], "--outcome sliding: goes with --find"),
        (["-p", "amp=0.1,0.2", "--outcome", "collapse"], "--outcome collapse: goes with --find"),
        (["-p", "amp=0.1,0.2", "--rtol", "0.1"], "--rtol 0.1: goes with --find"),
        # a bad value inside an axis (only its ends were checked) ran into an error row, and the study said
        # "3 rows ... 1 failed"
        (["-p", "friction=0.5,-1,0.6"], "--param friction=-1: friction = -1.0: must be >= 0"),
        (["-p", "dt=0.002:0.004:3"], "--param dt=0.003: dt = 0.003: does not divide duration = 1.0"),
        (["-p", "amp=0.1,1e30,0.2", "-p", "freq=1,2"], "--param amp=1e+30 freq=1: "),
    ],
)
def test_sweep_errors_are_one_line(block, args, fragment, tmp_path, monkeypatch):
    # in a folder of its own: a row that ran (before its refusal existed) wrote study-block.parquet and .png
    # into the working directory, and every later row then said "--out's plot study-block.png: the file exists"
    monkeypatch.chdir(tmp_path)
    result = invoke("sweep", block, *args)
    assert result.exit_code == 2, result.output
    lines = [ln for ln in result.output.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and fragment in lines[0], result.output


def test_a_scheduler_that_cannot_be_reached_leaves_no_file(block, tmp_path, monkeypatch):
    # The table (header only) was written before the cluster was reached: the corrected command then
    # said "--out s.csv: the file exists". Connecting to a closed port takes Dask's 20 s timeout, so the
    # refusal is simulated here; the real one was checked by hand (tcp://127.0.0.1:18787: the same line).
    from masonrycli.study import runner

    def unreachable(scheduler, workers):
        raise InputError(f"--scheduler {scheduler}: cannot connect (OSError: Timed out)")

    monkeypatch.setattr(runner, "open_cluster", unreachable)
    result = invoke("sweep", block, "-p", "amp=0.1", "--scheduler", "tcp://127.0.0.1:1", "-o", tmp_path / "s.csv")
    assert result.exit_code == 2 and "--scheduler tcp://127.0.0.1:1: cannot connect" in result.output
    assert [p.name for p in tmp_path.iterdir()] == ["block.toml"]


def test_ctrl_c_while_the_scheduler_is_reached_says_nothing_was_written(block, tmp_path, monkeypatch):
    # Ctrl-C during the (up to 30 s) wait for a --scheduler said "interrupted: every finished row is in s.csv;
    # run the same command again to resume", and there was no s.csv.
    from masonrycli.study import runner

    def interrupted(scheduler, workers):
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "open_cluster", interrupted)
    result = invoke("sweep", block, "-p", "amp=0.1", "--scheduler", "tcp://127.0.0.1:1", "-o", tmp_path / "s.csv")
    said = " ".join(result.output.split())
    assert result.exit_code == 130 and "interrupted: stopped before any row was finished; nothing was written" in said
    assert [p.name for p in tmp_path.iterdir()] == ["block.toml"]


def _velocity_csv(path: Path) -> Path:
    path.write_text("time,v\n" + "".join(f"{0.01 * i:.2f},{0.05 * (i % 2):.2f}\n" for i in range(30)))
    return path


def test_a_study_table_in_its_records_folder_is_not_read_as_a_record(block, tmp_path):
    # `--records recs --out recs/ida.csv`: the first run wrote recs/ida.csv; the same command again (to resume,
    # as the docs say) read the table as a record: "error: recs/ida.csv:2: not a number: "a.csv"", exit 2.
    folder = tmp_path / "recs"
    folder.mkdir()
    _velocity_csv(folder / "a.csv"), _velocity_csv(folder / "b.csv")
    args = ("sweep", block, "--records", folder, "--workers", 0, "--duration", 0.1, "--no-recording")
    first = invoke(*args, "--out", folder / "ida.csv")
    assert first.exit_code == 0, first.output
    again = invoke(*args, "--out", folder / "ida.csv", "--force")
    assert again.exit_code == 0, again.output
    said = " ".join(again.output.split())
    assert "2 rows in" in said and "(0 runs now, 2 rows already there, 0 failed)" in said, said
    assert {r["record"] for r in read_rows(folder / "ida.csv")} == {"a.csv", "b.csv"}


def test_a_record_edited_since_the_table_was_written_is_not_taken_as_done(block, tmp_path):
    # A study's fingerprint knew a --records file by its path, scale and sample count: a record whose values
    # were corrected (0.05 -> 0.45 m/s) kept its rows, "0 runs now, 1 row already there", pgv still 0.05 m/s.
    folder = tmp_path / "recs"
    folder.mkdir()
    record = _velocity_csv(folder / "a.csv")
    args = ("sweep", block, "--records", folder, "--workers", 0, "--duration", 0.1, "--no-recording", "--out")
    out = tmp_path / "s.csv"
    assert invoke(*args, out).exit_code == 0
    assert read_rows(out)[0]["pgv"] == pytest.approx(0.05)
    record.write_text(record.read_text().replace(",0.05\n", ",0.45\n"))
    forced = invoke(*args, out, "--force")
    assert forced.exit_code == 0 and "(1 run now, 0 rows already there" in " ".join(forced.output.split())
    assert read_rows(out)[0]["pgv"] == pytest.approx(0.45)


def test_a_geometry_file_is_swept_as_run_runs_it(tmp_path):
    # `sweep wall.geojson` said "wall.geojson: TOML syntax error: Invalid statement (at line 1, column 1)";
    # run, check and limit take a GeoJSON / WKT file as it is (supports fixed).
    geo = tmp_path / "wall.geojson"
    assert invoke("build", "wall", "--blocks", 7, "--out", geo).exit_code == 0
    out = tmp_path / "g.csv"
    args = ("-p", "friction=0.5,0.6", "--duration", 0.01, "--workers", 0, "--no-recording", "--out", out)
    result = invoke("sweep", geo, *args)
    assert result.exit_code == 0, result.output
    assert [r["friction"] for r in read_rows(out)] == [0.5, 0.6]


def test_the_default_table_name_stays_in_the_working_folder(tmp_path, monkeypatch):
    # name = "../../evil" in the scenario file: the default --out "study-../../evil.parquet" made a folder
    # "study-.." and wrote evil.parquet and evil.png beside it (a name with more "../" left the folder)
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    (work / "e.toml").write_text('name = "../../evil"\n' + BLOCK)
    result = invoke("sweep", "e.toml", "-p", "amp=0.1", "--duration", 0.01, "--workers", 0, "--no-recording")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in work.iterdir()) == ["e.toml", "study-evil.parquet", "study-evil.png"]
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == [
        "e.toml",
        "study-evil.parquet",
        "study-evil.png",
    ]


def test_a_record_given_as_the_study_table_is_refused_not_replaced(block, tmp_path):
    # `--records rec.csv --out rec.csv --force` replaced the record with the study's table (the record lost).
    record = _velocity_csv(tmp_path / "rec.csv")
    kept = record.read_bytes()
    result = invoke("sweep", block, "--records", record, "--workers", 0, "--out", record, "--force", "--no-recording")
    assert result.exit_code == 2
    assert result.output.strip() == f"error: --out {record}: is the record {record} (the table would replace it)"
    assert record.read_bytes() == kept and sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "rec.csv"]


def test_a_scenario_record_file_given_as_the_study_table_is_refused(tmp_path):
    record = _velocity_csv(tmp_path / "quake.csv")
    kept = record.read_bytes()
    scenario = tmp_path / "quake.toml"
    scenario.write_text(
        BLOCK.replace('{ kind = "sine", amplitude = 0.1, frequency = 2.0 }', '{ kind = "record", file = "quake.csv" }')
    )
    result = invoke(
        "sweep", scenario, "-p", "scale=0.5,1", "--workers", 0, "--out", record, "--force", "--no-recording"
    )
    assert result.exit_code == 2
    assert result.output.strip() == f"error: --out {record}: is the record {record} (the table would replace it)"
    assert record.read_bytes() == kept


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def test_a_histories_folder_that_cannot_be_made_leaves_no_file(block, tmp_path):
    # it said "error: /proc/x: No such file or directory" (no option) after writing a header-only table,
    # which the corrected command then refused as existing
    # Not a skip (the project runs on Linux): without /proc this test would prove nothing, so it fails.
    assert Path("/proc/self").is_dir(), "needs Linux's /proc, where no folder can be made"
    out, histories = tmp_path / "s.csv", Path("/proc/masonry-histories")
    result = invoke("sweep", block, "-p", "amp=0.1", "--workers", 0, "-o", out, "--histories", histories)
    said = " ".join(result.output.split())
    # refused before the folder is made: /proc is no disk (root may write there, yet no file can be made)
    assert result.exit_code == 2 and said.startswith(f"error: --histories {histories}"), said
    assert "cannot make the folder (" in said or ": cannot write in /proc (" in said, said
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml"]


def test_existing_outputs_are_refused_without_force_and_replaced_with_it(block, tmp_path):
    out, h = tmp_path / "s.csv", tmp_path / "h"
    grid = ["-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", out, "--histories", h]
    assert invoke("sweep", block, *grid).exit_code == 0
    before, png = _files(tmp_path), (tmp_path / "s.png").stat().st_ino
    assert {"s.csv", "s.png", "s.rrd", "amp=0.05.npz", "amp=0.1.npz"} <= set(before)
    other = ["-p", "amp=0.05,0.1", "--duration", 0.04, "--workers", 0, "-o", out]  # another study (duration)
    cases = [
        (other + ["--no-recording", "--plot", tmp_path / "o.png"], f"--out {out}: the file exists"),
        # the same study: resumable, but its plot exists (it said "--plot s.png", an option not given)
        (grid, f"--out's plot {tmp_path / 's.png'}: the file exists"),
        (grid + ["--plot", tmp_path / "n.png", "--recording", tmp_path / "s.rrd"], "--recording"),
        (grid + ["--plot", tmp_path / "n.png"], f"--out's recording {tmp_path / 's.rrd'}: the file exists"),
        (grid[:-1] + [h] + ["-p", "friction=0.8", "--no-recording", "--plot", tmp_path / "n.png"], "--out"),
    ]
    for args, fragment in cases:
        result = invoke("sweep", block, *args)
        assert result.exit_code == 2, result.output
        lines = result.output.strip().splitlines()
        assert len(lines) == 1 and fragment in lines[0] and "(add --force to replace it)" in lines[0], lines
        assert _files(tmp_path) == before  # untouched, no temporary file left
    # the histories of runs still to make: one of them exists
    more = ["-p", "amp=0.1,0.2", "--duration", 0.02, "--workers", 0, "-o", tmp_path / "t.csv", "--histories", h]
    result = invoke("sweep", block, *more)
    assert result.exit_code == 2 and f"--histories {h / 'amp=0.1.npz'}: the file exists" in result.output
    assert _files(tmp_path) == before
    # --force replaces: the other study's rows go, the plot and the recording are new
    result = invoke("sweep", block, *other, "--force")
    assert result.exit_code == 0, result.output
    assert [r["time"] for r in read_rows(out)] == [pytest.approx(0.04)] * 2
    after = _files(tmp_path)
    assert (tmp_path / "s.png").stat().st_ino != png and after["s.rrd"] != before["s.rrd"]  # a new file each
    assert not [name for name in after if name.endswith(".part") or "journal" in name]


def test_ctrl_c_leaves_no_partial_file_and_the_same_command_resumes(block, tmp_path, monkeypatch):
    from masonrycli.history import HistoryFile

    out, h = tmp_path / "s.parquet", tmp_path / "h"
    args = ["-p", "amp=0.05,0.1,0.2", "--duration", 0.02, "--workers", 0, "-o", out, "--histories", h]
    frame = HistoryFile.on_frame
    calls = []

    def interrupted_third_run(self, f):  # Ctrl-C in the middle of the third run, its history half written
        calls.append(int(f.step))
        if calls.count(0) == 3 and int(f.step) > 0:
            raise KeyboardInterrupt
        frame(self, f)

    monkeypatch.setattr(HistoryFile, "on_frame", interrupted_third_run)
    result = invoke("sweep", block, *args)
    assert result.exit_code == 130 and "run the same command again to resume" in result.output
    assert sorted(p.name for p in h.iterdir()) == ["amp=0.05.npz", "amp=0.1.npz"]  # no .part, no .rows
    assert [r["amp"] for r in read_rows(out)] == [0.05, 0.1]
    table = out.read_bytes()

    import pyarrow.parquet as pq

    def cut_short(table, where):  # Ctrl-C while the table is being written: half a file on disk
        Path(where).write_bytes(b"PAR1 half")
        raise KeyboardInterrupt

    monkeypatch.setattr(HistoryFile, "on_frame", frame)
    monkeypatch.setattr(pq, "write_table", cut_short)
    result = invoke("sweep", block, *args)
    assert result.exit_code == 130
    assert out.read_bytes() == table and not [p for p in tmp_path.iterdir() if p.name.endswith(".part")]
    assert len(read_rows(out)) == 3  # the third row is in the journal
    monkeypatch.undo()
    result = invoke("sweep", block, *args)
    assert result.exit_code == 0 and "(0 runs now, 3 rows already there" in " ".join(result.output.split())
    assert [r["amp"] for r in read_rows(out)] == [0.05, 0.1, 0.2]


def test_a_signal_while_the_pictures_are_written_says_what_is_missing(block, tmp_path, monkeypatch):
    # The study is done, the plot and recording are being written. SIGTERM there killed the command
    # outright (exit -15, a hidden .s.png.<pid>.part beside the table); Ctrl-C said "stopped before any
    # output was written" with the whole table written.
    import os
    import signal

    import masonrycli.recording.study as recording_study
    import masonrycli.study.plots as plots

    out = tmp_path / "s.csv"
    args = ["sweep", block, "-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", out]
    drawn = plots.state_map

    def ctrl_c_in_the_plot(rows, x, y, path, title):
        Path(path).write_bytes(b"half a PNG")
        raise KeyboardInterrupt

    monkeypatch.setattr(plots, "state_map", ctrl_c_in_the_plot)
    result = invoke(*args)
    said = " ".join(result.output.split())
    assert result.exit_code == 130, result.output
    assert f"interrupted: every row is in {out}, but not written: {tmp_path / 's.png'}, {tmp_path / 's.rrd'}" in said
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "s.csv"]  # no .part left
    monkeypatch.setattr(plots, "state_map", drawn)

    def sigterm_in_the_recording(*args):
        os.kill(os.getpid(), signal.SIGTERM)  # the command's handler turns it into Ctrl-C's way out
        raise AssertionError("not stopped")

    monkeypatch.setattr(recording_study, "record_study", sigterm_in_the_recording)
    result = invoke(*args)
    said = " ".join(result.output.split())
    assert result.exit_code == 143, result.output
    assert f"interrupted (SIGTERM): every row is in {out}, but not written: {tmp_path / 's.rrd'}; " in said
    assert "run the same command with --force (no run is made again)" in said  # the plot is there now
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "s.csv", "s.png"]
    monkeypatch.undo()
    result = invoke(*args, "--force")
    assert result.exit_code == 0 and "(0 runs now, 2 rows already there" in " ".join(result.output.split())
    assert (tmp_path / "s.rrd").stat().st_size > 0


def test_the_table_fits_80_columns_in_a_real_terminal_width(block, tmp_path):
    import os
    import subprocess
    import sys

    out = tmp_path / "s.csv"
    args = ["-p", "amp=0.05,0.6", "-p", "freq=1,2.5", "--duration", 0.02, "--workers", 0, "-o", out, "--no-recording"]
    env = os.environ | {"COLUMNS": "80", "RERUN_ANALYTICS": "0"}
    cmd = [sys.executable, "-m", "masonrycli", "sweep", str(block), *map(str, args)]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert max(len(line) for line in lines) <= 80, done.stdout
    body = [line for line in lines if line.startswith("│")]
    assert len(body) == 4 and all(line.split("│")[3].strip() in ("intact", "damaged", "collapsed") for line in body), (
        done.stdout
    )
    assert "collapse: time of collapse, s" in done.stdout and "every column in" in done.stdout


def test_records_run_whole_on_a_built_in_and_a_shorter_run_is_warned(block, tmp_path):
    # the built-in wall's 1 s cut every record to its first second: without --duration the runs last the
    # longest record; a scenario file keeps its [run] duration, and a record longer than the runs is named
    folder = tmp_path / "records"
    folder.mkdir()
    t, u, v, a = band_limited(1.5, 0.01, [1.0, 2.5], [0.003, 0.001], seed=0)
    write_at2(folder / "long.AT2", a / G_STANDARD, 0.01)
    (folder / "short.csv").write_text("time,velocity\n0,0\n0.2,0.01\n0.4,0\n")
    out = tmp_path / "whole.csv"
    result = invoke("sweep", "wall", "--records", folder, "--workers", 0, "--out", out, "--no-recording")
    assert result.exit_code == 0, result.output
    assert {(r["record"], r["steps"]) for r in read_rows(out)} == {("long.AT2", 1500), ("short.csv", 1500)}
    assert "warning" not in result.output
    result = invoke("sweep", block, "--records", folder, "--workers", 0, "--out", tmp_path / "b.csv", "--no-recording")
    assert result.exit_code == 0, result.output
    assert {r["steps"] for r in read_rows(tmp_path / "b.csv")} == {500}  # the file's 1 s at dt = 2e-3
    assert (
        "warning: the runs' 1 s are shorter than 1 of 2 records (longest 1.5 s, long.AT2): their shaking after "
        "t = 1 s is not applied" in " ".join(result.output.split())
    )
    # bad input stays one line: the warning comes once the request is checked, not beside its error
    fixed = tmp_path / "fixed.toml"
    fixed.write_text(BLOCK.replace('motion = { kind = "sine", amplitude = 0.1, frequency = 2.0 }', ""))
    result = invoke("sweep", fixed, "--records", folder, "--workers", 0, "--out", tmp_path / "f.csv")
    assert result.exit_code == 2 and result.output.strip().splitlines() == [
        "error: record: fixed has no shaking support (give one a sine or record motion)"
    ]


def test_a_second_ctrl_c_while_the_table_is_written_is_ignored(block, tmp_path, monkeypatch, capfd):
    # A second Ctrl-C during the shutdown cut the table being written (only the journal left, under
    # "every finished row is in s.parquet"). Now only the first signal stops; a repeat is acknowledged.
    import os
    import signal
    import time

    from masonrycli.study import runner, store

    out = tmp_path / "s.parquet"
    ran, written = runner.run_task, store.write_rows

    def ctrl_c_in_the_second_run(base, params, *args):
        if params["amp"] == 0.1:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5)  # the handler raises here
            raise AssertionError("not stopped")
        return ran(base, params, *args)

    def ctrl_c_again_while_written(*args):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.2)  # the handler runs here (it raised KeyboardInterrupt: no table)
        return written(*args)

    monkeypatch.setattr(runner, "run_task", ctrl_c_in_the_second_run)
    monkeypatch.setattr(store, "write_rows", ctrl_c_again_while_written)
    result = invoke("sweep", block, "-p", "amp=0.05,0.1,0.2", "--duration", 0.02, "--workers", 0, "-o", out)
    assert result.exit_code == 130, result.output
    assert f"interrupted: every finished row is in {out}; run the same command again" in " ".join(result.output.split())
    assert [r["amp"] for r in read_rows(out)] == [0.05]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "s.parquet"]  # the journal went with it
    assert "Ctrl-C: already stopping — finishing the output files" in capfd.readouterr().err


@pytest.mark.slow
def test_a_second_ctrl_c_on_the_way_out_ends_like_the_first(block, tmp_path):
    # A real process, two real Ctrl-C: the first mid-study, the second as the "interrupted" line comes out
    # (Python puts its handlers back to the default when it exits: that one killed the process, exit -2).
    import os
    import signal
    import subprocess
    import sys
    import time

    root = Path(__file__).resolve().parent.parent
    env = os.environ | {"RERUN_ANALYTICS": "0", "PYTHONUNBUFFERED": "1", "PYTHONPATH": str(root)}
    out = tmp_path / "s.csv"
    journal = tmp_path / "s.csv.journal.jsonl"
    sweep = [sys.executable, "-m", "masonrycli", "sweep", "wall", "--param", "blocks=12", "--duration", "5"]
    sweep += ["--param", "amp=0.1:0.25:6", "--workers", "0", "--out", out]
    proc = subprocess.Popen(
        sweep, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env, cwd=tmp_path, text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # as in a terminal
    )  # fmt: skip
    try:
        end = time.monotonic() + 240
        while not (journal.exists() and journal.read_text().endswith("}\n")):  # a finished row
            assert proc.poll() is None and time.monotonic() < end, proc.stdout.read()
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        lines = []
        for line in proc.stdout:
            lines.append(line)
            if line.startswith("interrupted"):
                proc.send_signal(signal.SIGINT)
                break
        lines += proc.stdout.readlines()
        assert proc.wait(timeout=120) == 130, lines
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    said = [ln for ln in lines if ln.strip() and not ln.startswith("Ctrl-C: already stopping")]  # the 2nd's
    assert said[-1].startswith("interrupted: every finished row is in"), lines
    assert not any("Traceback" in ln or "KeyboardInterrupt" in ln for ln in lines), lines
    assert 1 <= len(read_rows(out)) < 6 and not journal.exists()


def test_a_signal_just_after_the_plot_is_renamed_does_not_call_it_missing(block, tmp_path, monkeypatch):
    # A signal between the plot's rename and the command's record of it said "not written: s.png, s.rrd"
    # with s.png in place. The rename and the record are one step for signals now.
    import os
    import signal
    import time

    from masonrycli.outputs import OutputFile

    out = tmp_path / "s.csv"
    commit = OutputFile.commit

    def ctrl_c_right_after_the_rename(self):
        where = commit(self)
        if where.suffix == ".png":
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.2)  # the handler runs here (it raised: the plot was not recorded as written)
        return where

    monkeypatch.setattr(OutputFile, "commit", ctrl_c_right_after_the_rename)
    result = invoke("sweep", block, "-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", out)
    said = " ".join(result.output.split())
    assert result.exit_code == 130, result.output
    assert f"interrupted: every row is in {out}, but not written: {tmp_path / 's.rrd'}; " in said
    assert "run the same command with --force (no run is made again)" in said
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "s.csv", "s.png"]


def test_a_signal_held_while_the_plot_s_rename_fails_reports_the_error(block, tmp_path, monkeypatch):
    # A Ctrl-C held around the plot's rename, and the rename then fails: the error is what the user needs
    # (the plot is missing because of it), in one line with its exit code, as without the signal — not an
    # "interrupted" line, and no traceback.
    import errno
    import os
    import signal
    import time

    from masonrycli.outputs import OutputFile

    out = tmp_path / "s.csv"
    commit = OutputFile.commit

    def ctrl_c_then_a_failed_rename(self):
        if self.path.suffix != ".png":
            return commit(self)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.2)  # the handler runs here and holds the signal
        raise OSError(errno.EACCES, "Permission denied", str(self.path))

    monkeypatch.setattr(OutputFile, "commit", ctrl_c_then_a_failed_rename)
    result = invoke("sweep", block, "-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", out)
    said = " ".join(result.output.split())
    assert result.exit_code == 2, result.output
    assert f"error: {tmp_path / 's.png'}: Permission denied" in said
    assert "interrupted" not in said and "Traceback" not in said
    assert len(read_rows(out)) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "s.csv"]  # no .s.png.<pid>.part


def test_failed_rows_give_exit_5_after_the_whole_table(block, tmp_path, monkeypatch):
    # Two of three runs failed (histories on a full disk): the study said "2 failed" and exited 0, so a
    # script took it for a complete study.
    from masonrycli import run

    real = run.simulate

    def full_disk(scenario, sinks, **kw):
        if scenario.motions[0].amplitude > 0.15:
            raise OSError(28, "No space left on device")
        return real(scenario, sinks, **kw)

    monkeypatch.setattr(run, "simulate", full_disk)
    out = tmp_path / "s.csv"
    args = ["-p", "amp=0.1,0.2,0.3", "--duration", 0.02, "--workers", 0, "-o", out, "--no-recording"]
    result = invoke("sweep", block, *args)
    assert result.exit_code == 5, result.output
    assert len(read_rows(out)) == 3 and (tmp_path / "s.png").exists()  # the table and the plot are whole
    said = " ".join(result.output.split())
    assert f"error: 2 of 3 rows failed (the reason is in their error column in {out}); run the same" in said, said
    monkeypatch.setattr(run, "simulate", real)
    again = invoke("sweep", block, *args, "--force")  # --force: the plot exists
    assert again.exit_code == 0 and "(2 runs now, 1 row already there, 0 failed)" in again.output, again.output


def test_diverged_rows_give_exit_3_as_simulate_does(block, tmp_path, monkeypatch):
    # A diverged run (exit 3 from `masonry simulate`) left a row with status diverged and exit 0.
    import dataclasses

    from masonrycli import run

    real = run.simulate

    def diverging(scenario, sinks, **kw):
        result = real(scenario, sinks, **kw)
        if scenario.motions[0].amplitude > 0.15:
            return dataclasses.replace(result, status="diverged", message="diverged at t = 0.0100 s")
        return result

    monkeypatch.setattr(run, "simulate", diverging)
    out = tmp_path / "s.csv"
    result = invoke(
        "sweep", block, "-p", "amp=0.1,0.2", "--duration", 0.02, "--workers", 0, "-o", out, "--no-recording"
    )
    assert result.exit_code == 3, result.output
    assert [r["status"] for r in read_rows(out)] == ["completed", "diverged"]
    said = " ".join(result.output.split())
    assert f"error: 1 of 2 rows diverged (their error column in {out} says when); a smaller" in said
    assert [r["error"] for r in read_rows(out)] == ["", "diverged at t = 0.0100 s"]


@pytest.mark.parametrize("option", ["--out", "--plot", "--recording", "--histories", "--records"])
def test_an_empty_path_is_said_to_be_empty(option):
    # Path("") is ".": sweep took --out "" as the folder "."
    from cli_helpers import assert_one_line_error, invoke

    assert_one_line_error(invoke("sweep", "wall", "--param", "amp=0.1", option, ""), option, "the path is empty")
