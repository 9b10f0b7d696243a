"""A study's recording (masonrycli.recording.study) as ``masonry sweep --recording`` writes it, read back:
the fragility curve of a records study and the threshold curve of ``--find`` as plots on their own time
lines, the state map of a grid with its axes and key, the side panels collapsed."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from masonrycli.records.read import G_STANDARD
from masonrycli.study.store import read_rows

from cli_helpers import words
from sweep_helpers import invoke, static_fields, write_block
from synthetic_records import band_limited, write_at2


@pytest.fixture
def block(tmp_path) -> Path:
    return write_block(tmp_path)


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
    said = words(result.output)  # the console wraps long lines
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
    assert timelines(rrd) == {"pga (mm/s²)"}  # the curve's x axis alone: no log_time, no log_tick
    shown = invoke("inspect", rrd)  # a study has no time line: a dash, not Python's "None"
    assert shown.exit_code == 0 and "None" not in shown.output and "time_span      │ —" in shown.output
    # the plot and the recording exist now: --force replaces them and still reuses every finished row
    again = invoke("sweep", block, "--records", folder, "--scale", "0.5:8:4", "--workers", 0, "--out", out, "--force")
    assert again.exit_code == 0 and "(0 runs now, 12 rows already there" in words(again.output)
    # records given as files (repeatable) make the same study as their folder
    files = [a for f in sorted(folder.iterdir()) for a in ("--records", f)]
    again = invoke("sweep", block, *files, "--scale", "0.5:8:4", "--workers", 0, "--out", out, "--force")
    assert again.exit_code == 0 and "(0 runs now, 12 rows already there" in words(again.output)
    twice = invoke("sweep", block, "--records", folder, "--records", folder / "syn0.AT2", "--out", out)
    assert twice.exit_code == 2 and "two records named syn0.AT2" in twice.output


def test_each_groups_fraction_and_fit_share_one_legend_entry_of_one_line(block, tmp_path):
    # 5 frictions' curves: the viewer's legend had 13 entries (each group's fraction and fit), 5 wrapped on two
    # lines, and "runs: intact / damaged / collapsed" were cut off below the view (headless screenshot,
    # 1920 x 1080); the viewer lists same-named series once: one entry a group, one line each
    import rerun as rr

    folder = tmp_path / "records"
    folder.mkdir()
    for seed in range(3):
        t, u, v, a = band_limited(1.0, 0.01, [1.0 + 0.4 * seed, 2.5], [0.03, 0.01], seed=seed)
        write_at2(folder / f"syn{seed}.AT2", a / G_STANDARD, 0.01)
    out, rrd = tmp_path / "s.csv", tmp_path / "s.rrd"
    args = ["--records", folder, "--scale", "5:80:4", "--param", "friction=0.4:0.8:5", "--duration", 0.2]
    result = invoke("sweep", block, *args, "--workers", 0, "--out", out, "--recording", rrd)
    assert result.exit_code == 0, result.output
    names = {}
    for chunk in rr.chunk.RrdReader(str(rrd)).stream():
        if chunk.is_static and chunk.entity_path.startswith("/study/fragility/"):
            batch = chunk.to_record_batch()
            (column,) = [n for n in batch.schema.names if n.endswith(":names")]
            names[chunk.entity_path.removeprefix("/study/fragility/")] = batch.column(column).to_pylist()[0][0]
    groups = [f"friction = {f:g}" for f in (0.4, 0.5, 0.6, 0.7, 0.8)]
    assert {f"fit/{i}" for i in range(5)} <= set(names)  # every group fitted: a curve each
    for i, group in enumerate(groups):
        assert names[f"fraction/{i}"] == names[f"fit/{i}"] and names[f"fit/{i}"].startswith(f"{group}: "), names
    entries = set(names.values())
    assert len(entries) == 8 and {"runs: intact", "runs: damaged", "runs: collapsed"} <= entries, entries
    # one line of the legend: 46 characters wrapped ("friction = 0.4: lognormal: θ = 39.5 m/s², β =" was its first)
    assert max(map(len, entries)) <= 42, entries
    assert names["fit/0"].startswith("friction = 0.4: θ = ") and " m/s², β = " in names["fit/0"], names["fit/0"]


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


def timelines(rrd: Path) -> set[str]:
    """The time lines of the recording's data (not of its blueprint, which Rerun keeps on its own
    ``log_time``): every chunk's."""
    import rerun as rr

    reader = rr.chunk.RrdReader(str(rrd))
    (recording,) = reader.recordings()
    return {name for chunk in reader.stream(store=recording) for name in chunk.timeline_names}


def test_a_state_map_study_shows_no_time_line(tmp_path):
    """`masonry sweep wall -p amp=… -p freq=…`: the map, the picture and the rows have no time. They are
    static, on no time line, and the viewer filled the (collapsed) time panel with its own "log_time",
    a name that meant nothing to the user (seen on a headless viewer's screenshot); the time panel is
    hidden now."""
    args = ["-p", "amp=0.1,0.2", "-p", "freq=1,2", "--duration", 0.05, "--workers", 0, "-o", tmp_path / "s.parquet"]
    result = invoke("sweep", "wall", *args, "--recording", tmp_path / "s.rrd")
    assert result.exit_code == 0, result.output
    assert timelines(tmp_path / "s.rrd") == set()
    assert blueprint_layout(tmp_path / "s.rrd")["TimePanelBlueprint:state"] == 1  # hidden (2: collapsed)


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
    assert timelines(rrd) == {timeline}  # the curve's x axis alone: no log_time, no log_tick
    styles = {}
    for chunk in rr.chunk.RrdReader(str(rrd)).stream():
        if chunk.is_static and chunk.entity_path == "/study/thresholds/line":
            batch = chunk.to_record_batch()
            styles |= {n: batch.column(n).to_pylist()[-1] for n in batch.schema.names if n.endswith(":names")}
    assert styles == {"SeriesLines:names": ["amp_threshold (m/s)"], "SeriesPoints:names": ["amp_threshold (m/s)"]}


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
    # One cell per swept value as in the PNG: the dots at the values' ranks, the values under their column
    # and left of their row, the axes' names once (every value read "amp=0.05": close values collided).
    assert axes["Points2D:labels"] == ["0.05", "0.6", "0.3", "0.8"]
    assert axes["Points2D:show_labels"] == [True]
    assert static_fields(chunks, "/study/state_map/axes/names")["Points2D:labels"] == ["amp (m/s)", "friction"]
    assert sorted(map(tuple, found["Points2D:positions"])) == [(0, 0), (0, 1), (1, 0), (1, 1)]
    x_labels, y_labels = np.array(axes["Points2D:positions"][:2]), np.array(axes["Points2D:positions"][2:])
    assert list(x_labels[:, 0]) == [0, 1] and np.all(x_labels[:, 1] < 0)
    assert list(y_labels[:, 1]) == [0, 1] and np.all(y_labels[:, 0] < 0)
    # The key names the colours (the recording did not; the PNG has a legend), in the PNG's colours,
    # in a row under the map's x labels
    key = {}
    for ch in chunks:
        if ch.entity_path == "/study/state_map/key":
            batch = ch.to_record_batch()
            key |= {n: batch.column(n).to_pylist() for n in batch.schema.names if ":" in n}
    from masonrycli.recording.colormap import unpack_rgba
    from masonrycli.study.curves import STATE_COLOURS, rgb

    names = static_fields(chunks, "/study/state_map/key/names")
    assert names["Points2D:labels"] == ["intact", "damaged", "collapsed", "failed"]
    drawn = [tuple(int(v) for v in c[:3]) for c in unpack_rgba(np.array(key["Points2D:colors"][0], np.uint32))]
    assert drawn == [rgb(STATE_COLOURS[s]) for s in ("intact", "damaged", "collapsed", "")]
    assert np.all(np.array(key["Points2D:positions"][0])[:, 1] < x_labels[:, 1].min())
    from masonrycli.recording.readback import blueprint_views

    assert blueprint_views(tmp_path / "grid.rrd")["state map: amp (m/s) right, friction up"]["kind"] == "2D"
    assert panel_states(tmp_path / "grid.rrd") == {"/blueprint_panel": "collapsed", "/selection_panel": "collapsed"}


def test_a_study_recording_that_cannot_be_written_whole_is_exit_4_the_table_kept(tmp_path):
    # Every file limited below the study recording's size (RLIMIT_FSIZE: writes fail as on a full disk,
    # above the table's and the plot's): exit 0 with a truncated s.rrd at 50 and 66 of 68 kB, a hang for good
    # in rerun's save at 20 kB. Now exit 4, one line naming the recording, the table and plot kept, no .rrd.
    import os
    import subprocess
    import sys

    from test_recording_outputs import _LIMITED

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(os.environ, PYTHONPATH=root)
    args = ["sweep", "wall", "--param", "amp=0.1,0.2", "--duration", "0.05", "--workers", "0", "--out", "s.parquet"]
    done = subprocess.run([sys.executable, "-m", "masonrycli", *args], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    sizes = {p.name: p.stat().st_size for p in tmp_path.iterdir()}
    assert sorted(sizes) == ["s.parquet", "s.png", "s.rrd"] and sizes["s.rrd"] > 2 * max(
        sizes["s.parquet"], sizes["s.png"]
    )
    for k, share in enumerate((0.3, 0.95)):
        run = tmp_path / f"limit{k}"
        run.mkdir()
        done = subprocess.run([sys.executable, "-c", _LIMITED, str(int(share * sizes["s.rrd"])), *args], cwd=run,
                              env=env, capture_output=True, text=True, timeout=30)  # fmt: skip
        lines = [ln for ln in done.stderr.splitlines() if ln.strip() and not ln.startswith("sweep: ")]  # progress
        assert done.returncode == 4 and len(lines) == 1, (share, done.stdout[-1000:], done.stderr[-1000:])
        assert lines[0].startswith("error: cannot write --out's recording s.rrd: "), lines[0]
        assert sorted(p.name for p in run.iterdir()) == ["s.parquet", "s.png"]


def test_a_search_of_one_point_keeps_its_time_line_from_0(block, tmp_path):
    """`masonry sweep block.toml --param amp=0.05:1.0:3 --find amp`: one point, at index 0 with a margin at -1.
    The viewer opens with the cursor at the time line's start, and Rerun 0.41 draws no static image below 0:
    the picture's view said "No data available" (test_viewer_screenshot). The point is numbered 1, as in the
    PNG, and the time line starts at 0."""
    import rerun as rr

    out, rrd = tmp_path / "find.csv", tmp_path / "find.rrd"
    args = ["-p", "amp=0.02:0.4:3", "--find", "amp", "--outcome", "sliding", "--duration", 0.3, "--workers", 0]
    assert invoke("sweep", block, *args, "--out", out, "--recording", rrd).exit_code == 0
    extent = [
        ch.to_record_batch().column("point").to_pylist()
        for ch in rr.chunk.RrdReader(str(rrd)).stream()
        if ch.entity_path == "/study/extent"
    ]
    assert extent == [[0, 2]]
    view = blueprint_layout(rrd)["TimeAxis:view_range"]
    assert (view["start"], view["end"]) == (0, 2)
