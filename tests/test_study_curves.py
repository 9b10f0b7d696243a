"""The study's curves mean the same in the PNG and the recording (masonrycli.study.curves).

The PNG's figure is caught at ``savefig``; the recording is read back: every legend entry of one has the
same label and colour in the other. Before, red was "fraction collapsed per scale" in the PNG and "runs:
collapsed" in the recording, and a threshold search that found none was in neither.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
import rerun as rr
from matplotlib.colors import to_rgb

from masonrycli.recording.colormap import unpack_rgba
from masonrycli.recording.study import record_study
from masonrycli.study import plots
from masonrycli.study.curves import NOT_FOUND_COLOUR, STATE_COLOURS, rgb, threshold_series
from masonrycli.study.fragility import fit_by, fit_lognormal

# 12 runs of 3 records at 4 scales: collapses from pga 5.5 m/s² up but one (7.2) and one below (3.0),
# so the lognormal fit is resolved
FRAGILITY_ROWS = [
    {
        "record": f"r{k}",
        "scale": s,
        "pga": 2.0 * s * (1 + 0.1 * k),
        "state": "collapsed"
        if (2.0 * s * (1 + 0.1 * k) > 5.5) != ((k, s) in ((2, 3.0), (0, 1.5)))
        else ("damaged" if s > 1 else "intact"),
        "status": "completed",
    }
    for k in range(3)
    for s in (0.5, 1.5, 3.0, 4.0)
]


@pytest.fixture
def png_figures(monkeypatch):
    """The figures the PNG writers save, legend entries as {label: (r, g, b)} (0-255)."""
    import matplotlib.figure

    caught: list[dict] = []

    def catch(fig, path, **kwargs):
        handles, labels = fig.axes[0].get_legend_handles_labels()
        caught.append({lab: tuple(round(255 * c) for c in to_rgb(h.get_color())) for h, lab in zip(handles, labels)})
        with open(path, "wb") as fh:
            fh.write(b"\x89PNG")

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", catch)
    return caught


def recorded_series(rrd, base: str) -> dict[str, dict]:
    """{entity: {"label", "rgb", "x" (time line ticks), "y"}} of the recording's series under ``base``."""
    out: dict[str, dict] = {}
    for ch in rr.chunk.RrdReader(str(rrd)).stream():
        if not ch.entity_path.startswith(f"/{base}/"):
            continue
        batch = ch.to_record_batch()
        entry = out.setdefault(ch.entity_path, {"x": [], "y": []})
        names = batch.schema.names
        for kind in ("SeriesPoints", "SeriesLines"):
            if f"{kind}:names" in names:
                entry["label"] = batch.column(f"{kind}:names").to_pylist()[-1][0]
                packed = batch.column(f"{kind}:colors").to_pylist()[-1][0]
                entry["rgb"] = tuple(int(v) for v in unpack_rgba(np.array([packed]))[0, :3])
        if "Scalars:scalars" in names:
            time_line = next(n for n in names if ":" not in n and not n.startswith("rerun") and n != "log_time")
            entry["x"] += batch.column(time_line).to_pylist()
            entry["y"] += [v[0] for v in batch.column("Scalars:scalars").to_pylist()]
    return out


def test_the_fragility_curve_has_the_same_colours_and_legend_in_the_png_and_the_recording(png_figures, tmp_path):
    rows = FRAGILITY_ROWS
    fit = fit_lognormal([r["pga"] for r in rows], [r["state"] == "collapsed" for r in rows], "pga")
    plots.fragility_curve(rows, "pga", fit, tmp_path / "f.png", "fragility", "m/s²")
    request = SimpleNamespace(axes=[SimpleNamespace(name="record", values=("r0", "r1", "r2"))], find=None)
    rrd = record_study(tmp_path / "f.rrd", "s", rows, request, fit, "pga", tmp_path / "f.png")
    png = png_figures[0]
    drawn = {s["label"]: s["rgb"] for s in recorded_series(rrd, "study/fragility").values() if s["x"]}
    assert png == drawn  # the same entries, the same colours
    # the runs are coloured by their state in both (the PNG's were grey ticks, "runs (collapsed = 1)")
    for state in ("intact", "damaged", "collapsed"):
        assert png[f"runs: {state}"] == rgb(STATE_COLOURS[state])
    assert len(set(png.values())) == len(png)  # no colour means two things
    assert fit.separated is None and f"lognormal: θ = {fit.median:.3g} m/s², β = {fit.dispersion:.2f}" in png


def test_a_record_study_over_friction_fits_one_curve_per_friction_in_the_png_and_the_recording(png_figures, tmp_path):
    # the 12 runs at friction 0.5, and the same runs at 0.7 collapsing from pga 7 m/s² up (but one, and one
    # below): pooled, one curve of 24 runs was the fragility of neither wall
    odd = (("r0", 3.0), ("r1", 4.0))
    stiff = [
        r
        | {
            "friction": 0.7,
            "state": "collapsed" if (r["pga"] > 7.0) != ((r["record"], r["scale"]) in odd) else "damaged",
        }
        for r in FRAGILITY_ROWS
    ]
    rows = [r | {"friction": 0.5} for r in FRAGILITY_ROWS] + stiff
    groups = fit_by(rows, "pga", ["friction"])
    assert [g.label for g in groups] == ["friction = 0.5", "friction = 0.7"]
    for g, friction in zip(groups, (0.5, 0.7)):
        own = [r for r in rows if r["friction"] == friction]
        alone = fit_lognormal([r["pga"] for r in own], [r["state"] == "collapsed" for r in own], "pga")
        assert g.rows == own and (g.fit.median, g.fit.dispersion) == (alone.median, alone.dispersion)
    assert groups[1].fit.median > 1.2 * groups[0].fit.median and all(g.fit.separated is None for g in groups)
    plots.fragility_curve(rows, "pga", None, tmp_path / "f.png", "fragility", "m/s²", groups)
    axes = [
        SimpleNamespace(name="record", values=("r0", "r1", "r2")),
        SimpleNamespace(name="friction", values=(0.5, 0.7)),
    ]
    request = SimpleNamespace(axes=axes, find=None)
    rrd = record_study(tmp_path / "f.rrd", "s", rows, request, None, "pga", tmp_path / "f.png", groups)
    png = png_figures[0]
    drawn = {s["label"]: s["rgb"] for s in recorded_series(rrd, "study/fragility").values() if s["x"]}
    runs = {k: v for k, v in png.items() if k.startswith("runs: ")}
    assert len(runs) == 3 and {k: v for k, v in drawn.items() if k.startswith("runs: ")} == runs
    colours = []
    for g in groups:  # a group's fraction and curve in one colour, its own: no state's, no other group's
        curve = png[f"{g.label}: lognormal: θ = {g.fit.median:.3g} m/s², β = {g.fit.dispersion:.2f}"]
        assert png[f"{g.label}: fraction collapsed per scale"] == curve
        # the recording: both under one legend entry of one line (5 groups' 13 entries hid the runs')
        assert drawn[f"{g.label}: θ = {g.fit.median:.3g} m/s², β = {g.fit.dispersion:.2f}"] == curve
        colours.append(curve)
    assert len(drawn) == len(runs) + len(groups)
    assert len(set(colours)) == 2 and not set(colours) & {rgb(c) for c in STATE_COLOURS.values()}


def test_the_legend_hides_no_run_of_the_fragility_curve():
    # 'masonry sweep wall --records recs --scale 1:6:4': the runs that stood at pga 21 and 29 m/s² (damaged,
    # P = 0) were drawn under the legend, at the lower right, and could not be seen
    rows = [dict(r) for r in FRAGILITY_ROWS]
    for r in rows:
        if r["scale"] == 4.0:
            r["state"] = "damaged"
    fit = fit_lognormal([r["pga"] for r in rows], [r["state"] == "collapsed" for r in rows], "pga")
    fig = plots.fragility_figure(rows, "pga", fit, "fragility", "m/s²")
    fig.canvas.draw()
    ax = fig.axes[0]
    box = ax.get_legend().get_window_extent()
    points = np.vstack([np.column_stack(line.get_data()) for line in ax.get_lines()])
    shown = ax.transData.transform(points.astype(float))
    assert not any(box.contains(x, y) for x, y in shown)


def test_points_without_a_threshold_are_marked_at_the_searched_range_ends(png_figures, tmp_path):
    """``no collapse up to amp = 1.5`` (amp_threshold NaN, no bracket) was missing from both pictures: it is
    a mark at 1.5 in both, with its legend entry; one reached already at the lowest amplitude at 0.25."""
    nan = math.nan
    rows = [
        {"freq": 1.0, "amp_threshold": 1.334, "amp_lo": 1.324, "amp_hi": 1.344, "outcome": "collapse"},
        {"freq": 2.0, "amp_threshold": nan, "amp_lo": nan, "amp_hi": nan, "outcome": "collapse"},
        {"freq": 3.0, "amp_threshold": nan, "amp_lo": nan, "amp_hi": 0.25, "outcome": "collapse"},
        {"freq": 4.0, "amp_threshold": 0.9, "amp_lo": 0.89, "amp_hi": 0.91, "outcome": "collapse"},
    ]
    for r in rows:
        r |= {"status": "completed", "note": ""}
    plots.threshold_curve(rows, "amp", "freq", tmp_path / "t.png", "thresholds", (0.25, 1.5))
    axes = [SimpleNamespace(name="amp", values=(0.25, 0.875, 1.5)), SimpleNamespace(name="freq", values=(1, 2, 3, 4))]
    request = SimpleNamespace(axes=axes, find="amp")
    rrd = record_study(tmp_path / "t.rrd", "s", rows, request, None, "pga", tmp_path / "t.png")
    series = recorded_series(rrd, "study/thresholds")
    above = series["/study/thresholds/not_found/above"]
    below = series["/study/thresholds/not_found/below"]
    # on the time line "freq (Hz)" (whole numbers: in Hz)
    assert above["x"] == [2] and above["y"] == [1.5] and below["x"] == [3] and below["y"] == [0.25]
    assert series["/study/thresholds/line"]["x"] == [1, 4]
    png = png_figures[0]
    assert png[above["label"]] == png[below["label"]] == above["rgb"] == rgb(NOT_FOUND_COLOUR)
    assert above["label"] == "none found: no collapse up to amp = 1.5"
    assert png["amp_threshold (m/s)"] == series["/study/thresholds/line"]["rgb"]


def test_thresholds_along_record_names_are_points_not_a_line(png_figures, tmp_path):
    """``--records DIR --find scale``: the records sit on the x axis in alphabetical order, and a line
    joining their thresholds read as a trend from one record to the next. Points alone, in the PNG (no
    line drawn) and in the recording (no line entity), under the curve's own label."""
    rows = [
        {"record": name, "scale_threshold": t, "scale_lo": t - 0.1, "scale_hi": t + 0.1, "outcome": "collapse"}
        | {"status": "completed", "note": ""}
        for name, t in (("elcentro.AT2", 1.5), ("kobe.AT2", 0.8), ("northridge.AT2", 1.1))
    ]
    plots.threshold_curve(rows, "scale", "record", tmp_path / "t.png", "thresholds", (0.5, 3.0))
    axes = [
        SimpleNamespace(name="scale", values=(0.5, 3.0)),
        SimpleNamespace(name="record", values=[r["record"] for r in rows]),
    ]
    rrd = record_study(
        tmp_path / "t.rrd", "s", rows, SimpleNamespace(axes=axes, find="scale"), None, "pga", tmp_path / "t.png"
    )
    series = recorded_series(rrd, "study/thresholds")
    assert "/study/thresholds/line" not in series
    points = series["/study/thresholds/points"]
    # numbered from 1 on the recording's time line (a cursor below 0 hid the picture: test_recording_study)
    assert points["x"] == [1, 2, 3] and points["y"] == [1.5, 0.8, 1.1] and points["label"] == "scale_threshold"
    assert list(png_figures[0]) == ["scale_threshold"]
    # numeric x keeps its line (a threshold against friction is a curve)
    assert [c.key for c in threshold_series(rows, "scale", np.arange(3.0), (0.5, 3.0))][:2] == ["line", "points"]


def test_thresholds_over_records_and_friction_are_one_series_a_friction(png_figures, tmp_path):
    """``--records DIR --find scale --param friction=0.5,0.7``: the two frictions' thresholds were one red
    series, two points at each record, which was which unsaid. One series a friction, in its own colour, its
    label first, in the PNG and the recording alike."""
    thresholds = {0.5: (1.7, 2.3, 0.4), 0.7: (1.9, 2.5, 1.1)}
    rows = [
        {"record": name, "friction": mu, "scale_threshold": t, "scale_lo": t - 0.1, "scale_hi": t + 0.1}
        | {"outcome": "collapse", "status": "completed", "note": ""}
        for k, name in enumerate(("elcentro.AT2", "kobe.AT2", "norcia.ASC"))
        for mu, t in ((mu, thresholds[mu][k]) for mu in (0.5, 0.7))
    ]
    args = (rows, "scale", "record", tmp_path / "t.png", "thresholds", (0.25, 4.0))
    plots.threshold_curve(*args, ("friction",))
    axes = [
        SimpleNamespace(name="scale", values=(0.25, 4.0)),
        SimpleNamespace(name="record", values=("elcentro.AT2", "kobe.AT2", "norcia.ASC")),
        SimpleNamespace(name="friction", values=(0.5, 0.7)),
    ]
    request = SimpleNamespace(axes=axes, find="scale")
    rrd = record_study(tmp_path / "t.rrd", "s", rows, request, None, "pga", tmp_path / "t.png")
    series = recorded_series(rrd, "study/thresholds")
    png = png_figures[0]
    for g, mu in enumerate((0.5, 0.7)):
        points = series[f"/study/thresholds/points/{g}"]
        assert points["label"] == f"friction = {mu:g}: scale_threshold"
        assert points["x"] == [1, 2, 3] and points["y"] == list(thresholds[mu])
        assert png[points["label"]] == points["rgb"]
    assert len(png) == 2 and len(set(png.values())) == 2


def test_thresholds_along_record_names_draw_no_line_in_the_png(tmp_path, monkeypatch):
    import matplotlib.figure

    drawn = []
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda fig, path, **k: drawn.append(fig))
    rows = [
        {"record": n, "scale_threshold": t, "status": "completed", "outcome": "collapse"}
        for n, t in (("a.AT2", 1.5), ("b.AT2", 0.8))
    ]
    plots.threshold_curve(rows, "scale", "record", tmp_path / "t.png", "thresholds", (0.5, 3.0))
    styles = {line.get_linestyle() for line in drawn[0].axes[0].get_lines() if len(line.get_xdata())}
    assert styles == {"None"}


def test_a_threshold_the_outcome_holds_below_says_so_in_the_legend():
    """``--find friction --outcome sliding``: the block slides below the curve, not above it as for an
    amplitude; the line's label says which (rows of an upward search keep their label)."""
    rows = [
        {"amp": a, "friction_threshold": t, "friction_hi": t, "holds": "below", "outcome": "sliding"}
        | {"status": "completed"}
        for a, t in ((0.3, 0.384), (0.6, 0.769))
    ]
    line = threshold_series(rows, "friction", np.array([0.3, 0.6]), (0.1, 1.0))[0]
    assert line.label == "friction_threshold: sliding below it" and list(line.y) == [0.384, 0.769]
    mixed = [rows[0], rows[1] | {"holds": "above"}]
    assert threshold_series(mixed, "friction", np.array([0.3, 0.6]), (0.1, 1.0))[0].label == (
        "friction_threshold: sliding above it, below where holds = below"
    )
    upward = [r | {"holds": "above"} for r in rows]
    assert threshold_series(upward, "friction", np.array([0.3, 0.6]), (0.1, 1.0))[0].label == "friction_threshold"


@pytest.mark.parametrize("which", ["state_map", "fragility_curve", "threshold_curve"])
def test_a_figure_is_closed_when_saving_it_fails(which, monkeypatch, tmp_path):
    """A disk full (or a Ctrl-C) at savefig left the figure open: a long-lived process (a notebook, the
    Dask client) kept one more figure per study."""
    import matplotlib.figure
    import matplotlib.pyplot as plt

    def fail(fig, path, **kwargs):
        raise OSError("No space left on device")

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", fail)
    rows = FRAGILITY_ROWS
    before = set(plt.get_fignums())
    with pytest.raises(OSError):
        if which == "state_map":
            rows = [r | {"collapse_time": 1.0} for r in rows]
            plots.state_map(rows, "scale", "record", tmp_path / "m.png", "states")
        elif which == "fragility_curve":
            fit = fit_lognormal([r["pga"] for r in rows], [r["state"] == "collapsed" for r in rows], "pga")
            plots.fragility_curve(rows, "pga", fit, tmp_path / "f.png", "fragility", "m/s²")
        else:
            rows = [{"freq": 1.0, "amp_threshold": 1.3, "amp_lo": 1.2, "amp_hi": 1.4, "outcome": "collapse"}]
            plots.threshold_curve(rows, "amp", "freq", tmp_path / "t.png", "thresholds", (0.25, 1.5))
    assert set(plt.get_fignums()) == before


def test_a_search_of_one_point_is_ticked_as_that_point():
    # walk-through 2026-11-28: `masonry sweep block.toml --param amp=0.05:1.0:3 --find amp --outcome sliding`
    # (docs/sweep.md) drew its one threshold over an x axis ticked -0.04, -0.02, 0.00, 0.02, 0.04 "point"
    row = {"amp_threshold": 0.4684, "amp_lo": 0.466, "amp_hi": 0.4707, "outcome": "sliding", "status": "completed"}
    fig = plots.threshold_figure([row], "amp", None, "sliding threshold", (0.05, 1.0))
    ax = fig.axes[0]
    assert list(ax.get_xticks()) == [0] and [t.get_text() for t in ax.get_xticklabels()] == ["1"]
    assert ax.get_xlabel() == "point"


def test_the_state_maps_cells_and_ticks_are_the_same_for_both_pictures():
    from masonrycli.study.curves import map_axis

    rows = [{"amp": a} for a in (0.2, 0.1, 1.0, 0.2)]
    assert map_axis(rows, "amp") == ([0.1, 0.2, 1.0], ["0.1", "0.2", "1"])
    # ":g" keeps six significant digits: two values it would write alike are written exactly
    assert map_axis([{"amp": 0.1}, {"amp": 0.1000001}], "amp")[1] == ["0.1", "0.1000001"]
    assert map_axis([{"record": "b.AT2"}, {"record": "a.AT2"}], "record") == (["a.AT2", "b.AT2"], ["a.AT2", "b.AT2"])


def test_a_grid_of_three_parameters_maps_each_value_of_the_third_apart(tmp_path, monkeypatch):
    """``--param amp=0.5,1.5 --param freq=1,2 --param friction=0.3,0.7``: one map drew both frictions' runs in
    each cell, the last one's state shown. One map a friction in the PNG, each cell its own run's colour; in the
    recording the two runs of a cell side by side, their hover naming the friction."""
    import matplotlib.figure

    rows = [
        {"amp": a, "freq": f, "friction": mu, "status": "completed", "collapse_time": math.nan}
        | {"state": "collapsed" if a > 1 and mu < 0.5 else "damaged" if a > 1 else "intact"}
        for a in (0.5, 1.5)
        for f in (1.0, 2.0)
        for mu in (0.3, 0.7)
    ]
    maps: dict[str, dict] = {}

    def catch(fig, path, **kwargs):
        for ax in fig.axes:
            if ax.get_visible() and ax.patches:
                cells = {(round(p.get_x() + 0.5), round(p.get_y() + 0.5)): p.get_facecolor()[:3] for p in ax.patches}
                maps[ax.get_title()] = {k: tuple(round(255 * c) for c in v) for k, v in cells.items()}
        with open(path, "wb") as fh:
            fh.write(b"\x89PNG")

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", catch)
    plots.state_map(rows, "amp", "freq", tmp_path / "m.png", "wall", ("friction",))
    assert sorted(maps) == ["friction = 0.3", "friction = 0.7"]
    for r in rows:
        cell = ([0.5, 1.5].index(r["amp"]), [1.0, 2.0].index(r["freq"]))
        assert maps[f"friction = {r['friction']:g}"][cell] == rgb(STATE_COLOURS[r["state"]])
    axes = [
        SimpleNamespace(name=n, values=v)
        for n, v in (("amp", (0.5, 1.5)), ("freq", (1.0, 2.0)), ("friction", (0.3, 0.7)))
    ]
    rrd = record_study(tmp_path / "m.rrd", "wall", rows, SimpleNamespace(axes=axes, find=None), None, "pga", None)
    for ch in rr.chunk.RrdReader(str(rrd)).stream():
        batch = ch.to_record_batch()
        if ch.entity_path == "/study/state_map" and "Points2D:positions" in batch.schema.names:
            positions = [tuple(p) for p in batch.column("Points2D:positions").to_pylist()[0]]
            labels = batch.column("Points2D:labels").to_pylist()[0]
    assert len(set(positions)) == 8  # every run its own dot
    from masonrycli.recording.readback import blueprint_views

    # the view's name says which dot of a cell is which friction
    assert "state map: amp (m/s) right, freq (Hz) up; friction 0.3 | 0.7 left to right in a cell" in blueprint_views(
        rrd
    )
    assert labels[0] == "amp=0.5 freq=1.0 friction=0.3: intact"


def test_a_user_whose_home_cannot_be_written_gets_no_matplotlib_warning(tmp_path):
    # 'nobody', a container's user: matplotlib said on stderr at every sweep that it made a temporary folder
    import os
    import subprocess
    import sys

    home = tmp_path / "home"
    home.write_text("a file: no folder can be made in it, whoever runs this")
    env = {k: v for k, v in os.environ.items() if k not in ("MPLCONFIGDIR", "XDG_CONFIG_HOME", "XDG_CACHE_HOME")}
    code = (
        "from masonrycli.study import plots\n"
        "plots.state_map([{'amp': 0.1, 'state': 'intact'}, {'amp': 0.2, 'state': 'collapsed', 'collapse_time': 0.5}],"
        " 'amp', None, 'm.png', 'states')\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], env=dict(env, HOME=str(home)), cwd=tmp_path, capture_output=True
    )
    assert done.returncode == 0, done.stderr
    assert done.stderr == b""  # before: 'mkdir -p failed for path …/.config/matplotlib' and 'Matplotlib created …'
    assert (tmp_path / "m.png").stat().st_size > 0
