"""Rerun recording of a study (``masonry sweep --recording study.rrd``).

The state map as coloured points over the two swept parameters (``study/state_map``), the PNG the
command also wrote (``study/plot``), and the rows as a markdown table (``study/rows``), all static; the
fragility curve of a records study (``study/fragility``) and the threshold curve of ``--find``
(``study/thresholds``) are plots on their own time lines (below). Axes are in the parameters' own units, so a 2-D view shows them
as they are; the PNG is the annotated picture.

Rerun's 2-D views draw y downward: each picture entity gets a static y-flip transform and its view looks
at it from ``study`` (an origin's own transform is not applied in its view), so larger values are up, as
in the PNG — before, the state map showed freq = 1 Hz above 2 Hz and the fragility curve upside down.
The state map's labels ("amp=0.25 freq=1: intact") are shown on hover only: drawn, a 6 × 2 grid's
overlapped into an unreadable line. Its axes are drawn as labels, each swept value once below the lowest
row and left of the leftmost column (``study/state_map/axes``); every view's name says what its axes are
(the plots draw no axis title, the 2-D view no axis), and the side panels open collapsed.

The fragility curve is a probability (0–1) against an intensity (pga 1–60 m/s², pgv 0.1–5 m/s): a 2-D
view has one scale for both axes, so it showed the curve as a flat line 60 units long and 1 high, without
axes. It is drawn in a time-series view instead, whose axes are scaled apart and labelled: the x axis is
a sequence time line in thousandths of the intensity's unit (``pga (mm/s²)``: a sequence is an integer,
so 1 mm/s² is its resolution), y the probability fixed at [−0.05, 1.05]; the runs are points at 0 or 1
coloured by state, the fraction collapsed at each scale and the fitted lognormal as in the PNG.

The threshold curve read flat the same way (``amp_threshold`` 0.08–0.23 m/s against ``blocks`` 12–48
or ``friction`` 0.1–0.3): it is plotted the same way, against the other swept parameter's own time line
(``blocks``, whole numbers, in its unit; ``friction (/1000)``, ``freq (mHz)`` in thousandths), y from 0
to 1.1 × the largest threshold.
"""

from __future__ import annotations

import math
import uuid
from pathlib import Path

import numpy as np
import pyarrow as pa
import rerun as rr
import rerun.blueprint as rrb

from masonrycli.intensity import UNITS
from masonrycli.recording.document import viewer_safe_text
from masonrycli.recording.recorder import APPLICATION_ID
from masonrycli.study.plots import UNITS as PARAM_UNITS

STATE_RGBA = {
    "intact": (46, 158, 91, 255),
    "damaged": (240, 160, 48, 255),
    "collapsed": (208, 48, 48, 255),
    "": (160, 160, 160, 255),
}


def record_study(path: Path, name: str, rows: list[dict], request, fit, im: str, plot: Path) -> Path:
    """Write the study's ``.rrd`` at ``path`` (closed, with its blueprint); the caller writes it under
    a temporary name and renames it (``masonrycli.outputs.written_whole``)."""
    path = Path(path)
    rec = rr.RecordingStream(APPLICATION_ID, recording_id=str(uuid.uuid4()))
    views = [rrb.TextDocumentView(origin="study/rows", name="rows")]
    if plot and Path(plot).exists():
        rec.log("study/plot", rr.EncodedImage(path=plot), static=True)
        views.insert(0, rrb.Spatial2DView(origin="study/plot", name="plot"))
    names = [a.name for a in request.axes if a.name != request.find and len(a.values) > 1]
    # The views fill the window: the blueprint, selection and time panels (Rerun's defaults: open) took
    # two fifths of it; the plots' time panel stays collapsed, it only names the x axis's time line.
    panels = [rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed")]
    if request.find:
        timeline, start, end, y_range = _log_thresholds(rec, rows, request.find, names)
        legend = rrb.PlotLegend(corner="RightBottom")  # below a rising or flat curve (y from 0)
        unit = PARAM_UNITS.get(request.find.rpartition(".")[2], "")
        title = viewer_safe_text(
            f"thresholds: {request.find}" + (f" ({unit})" if unit else "") + f" against {timeline}"
        )
        _time_line_extent(rec, timeline, start, end)
        view, panel = _plot_view("study/thresholds", title, timeline, (start, end), y_range, legend)
        views.insert(0, view)
        panels.append(panel)
    elif fit is None and "record" not in [a.name for a in request.axes]:
        _log_state_map(rec, rows, names)
        rec.log("study/state_map", rr.Transform3D(scale=[1.0, -1.0, 1.0]), static=True)  # y up (module doc)
        axes = ", ".join(f"{_with_unit(n)} {way}" for n, way in zip(names, ("right", "up")))
        title = viewer_safe_text(f"state map: {axes}" if axes else "state map")
        views.insert(0, rrb.Spatial2DView(origin="study", contents=["+ /study/state_map/**"], name=title))
        panels.append(rrb.TimePanel(state="collapsed"))
    else:
        timeline, end = _log_fragility(rec, rows, fit, im)
        legend = rrb.PlotLegend(corner="RightBottom")  # high IM, P = 0: where runs are fewest
        title = viewer_safe_text(f"fragility: P(collapse) against {timeline}")
        view, panel = _plot_view("study/fragility", title, timeline, (0, end), (-0.05, 1.05), legend)
        views.insert(0, view)
        panels.append(panel)
    rec.log("study/rows", rr.TextDocument(_markdown(name, rows), media_type=rr.MediaType.MARKDOWN), static=True)
    rec.save(path, default_blueprint=rrb.Blueprint(rrb.Grid(*views), *panels))
    rec.disconnect()
    return path


def _plot_view(origin: str, name: str, timeline: str, x_range, y_range, legend):
    """A time-series view of ``origin`` plotted against the sequence time line ``timeline`` (module doc),
    x shown over ``x_range`` (ticks), y fixed at ``y_range``, and the time panel that opens on that time
    line (a time-series view plots against the time panel's time line)."""
    # the whole curve (a time-series view otherwise shows a window around the cursor)
    start, end = (rrb.TimeRangeBoundary.absolute(seq=int(t)) for t in x_range)
    axis_x = rrb.TimeAxis(view_range=rr.TimeRange(start=start, end=end))
    axis_y = rrb.ScalarAxis(range=tuple(float(v) for v in y_range), zoom_lock=True)
    view = rrb.TimeSeriesView(origin=origin, name=name, axis_x=axis_x, axis_y=axis_y, plot_legend=legend)
    return view, rrb.TimePanel(state="collapsed", timeline=timeline, play_state="paused")


def _time_line_extent(rec, timeline: str, start: int, end: int) -> None:
    """Mark ``start`` and ``end`` on the time line, outside the plots: a time-series view shows no more
    than the time line holds, whatever its view range says (the last point sat on the right edge)."""
    column = rr.AnyValues.columns(time_line_extent=pa.array([float(start), float(end)]))
    rec.send_columns("study/extent", indexes=[rr.TimeColumn(timeline, sequence=[start, end])], columns=column)


def _series(rec, entity: str, timeline: str, per_unit: float, at, values, style) -> None:
    """``values`` against ``at`` (sorted; non-finite pairs dropped) as scalars on the sequence time line
    ``timeline`` whose tick is ``1 / per_unit`` of ``at``'s unit; ``style`` names and colours the series."""
    at, values = np.asarray(at, dtype=np.float64), np.asarray(values, dtype=np.float64)
    keep = np.isfinite(at) & np.isfinite(values)
    rec.log(entity, style, static=True)
    if keep.any():
        order = np.argsort(at[keep], kind="stable")
        ticks = np.rint(at[keep][order] * per_unit).astype(np.int64)
        column = rr.Scalars.columns(scalars=values[keep][order])
        rec.send_columns(entity, indexes=[rr.TimeColumn(timeline, sequence=ticks)], columns=column)


def _with_unit(name: str) -> str:
    unit = PARAM_UNITS.get(name.rpartition(".")[2], "")
    return f"{name} ({unit})" if unit else name


def _number(value) -> float:
    return float(value) if isinstance(value, (int, float)) else math.nan


def _log_state_map(rec, rows: list[dict], names: list[str]) -> None:
    # a string axis (record names) is drawn by index
    def coord(r, n):
        if not n:
            return 0.0
        values = sorted({row[n] for row in rows}, key=str)
        return _number(r[n]) if not isinstance(r[n], str) else float(values.index(r[n]))

    x, y = (names + [None, None])[:2]
    pos = np.array([[coord(r, x), coord(r, y)] for r in rows], dtype=np.float32).reshape(-1, 2)
    colours = np.array([STATE_RGBA.get(r.get("state") or "", STATE_RGBA[""]) for r in rows], dtype=np.uint8)
    labels = [
        viewer_safe_text(" ".join(f"{n}={r[n]}" for n in names) + f": {r.get('state') or 'failed'}") for r in rows
    ]
    span = np.ptp(pos, axis=0) if len(pos) else np.ones(2)
    radius = 0.02 * float(max(span.max(), 1e-9))
    points = rr.Points2D(pos, colors=colours, labels=labels, radii=radius, show_labels=False)
    rec.log("study/state_map", points, static=True)
    # The axes, as drawn labels (a 2-D view has none): each swept value once, below the lowest row and
    # left of the leftmost column — the map was unlabelled dots on black.
    ticks, texts = [], []
    if len(pos):
        lo, span = pos.min(axis=0), np.maximum(np.ptp(pos, axis=0), 1e-9)
        for axis, n in enumerate(names[:2]):
            for value in sorted({r[n] for r in rows}, key=lambda v: coord({n: v}, n)):
                at = (
                    [coord({n: value}, n), lo[1] - 0.12 * span[1]]
                    if axis == 0
                    else [lo[0] - 0.2 * span[0], coord({n: value}, n)]
                )
                ticks.append(at)
                texts.append(viewer_safe_text(f"{n}={value}"))
    axes = rr.Points2D(
        np.array(ticks, dtype=np.float32).reshape(-1, 2),
        labels=texts,
        radii=0.0,
        colors=(220, 220, 220, 255),
        show_labels=True,
    )
    rec.log("study/state_map/axes", axes, static=True)


def fragility_timeline(im: str) -> str:
    """The sequence time line the fragility curve is plotted on: thousandths of the IM's unit."""
    return f"{im} (m{UNITS[im]})"


def _log_fragility(rec, rows: list[dict], fit, im: str) -> tuple[str, int]:
    """Runs, fraction collapsed per scale and fitted curve as scalars on the IM's time line (module doc);
    returns the time line's name and the end of the curve on it (1.2 × the largest IM, in its ticks)."""
    timeline = fragility_timeline(im)
    good = [r for r in rows if r.get("status") != "error"]
    x = np.array([_number(r.get(im)) for r in good], dtype=np.float64)
    collapsed = np.array([r.get("state") == "collapsed" for r in good], dtype=bool)

    def series(entity: str, at, values, style) -> None:
        _series(rec, entity, timeline, 1000.0, at, values, style)

    for state in ("intact", "damaged", "collapsed"):
        sel = np.array([r.get("state") == state for r in good], dtype=bool)
        style = rr.SeriesPoints(colors=[STATE_RGBA[state][:3]], names=[f"runs: {state}"], marker_sizes=[4.0])
        series(f"study/fragility/runs/{state}", x[sel], collapsed[sel].astype(np.float64), style)
    if good and "scale" in good[0]:
        scales = sorted({r["scale"] for r in good})
        pick = [np.array([r["scale"] == s for r in good]) for s in scales]
        mean_x = np.array([np.nanmean(x[p]) if np.isfinite(x[p]).any() else np.nan for p in pick])
        fraction = np.array([collapsed[p].mean() for p in pick])
        style = rr.SeriesPoints(
            colors=[(235, 235, 235)], names=["fraction collapsed per scale"], markers=["diamond"], marker_sizes=[5.0]
        )
        series("study/fragility/fraction", mean_x, fraction, style)
    if fit is not None and np.isfinite(x).any():
        # from IM = 0 (P = 0), so the time line starts at 0 and the axis is labelled in round numbers
        grid = np.unique(np.rint(np.linspace(0, np.nanmax(x) * 1.2, 300) * 1000.0)) / 1000.0
        text = f"median {fit.median:.3g}, dispersion {fit.dispersion:.2f}"
        label = viewer_safe_text("lognormal: " + ("not resolved (runs separated)" if fit.separated else text))
        style = rr.SeriesLines(colors=[(31, 95, 168)], names=[label], widths=[2.0])
        series("study/fragility/fit", grid, fit.probability(grid), style)
    top = np.nanmax(x) if np.isfinite(x).any() else 1.0
    return timeline, int(np.rint(1200.0 * top)) + 1


def _log_thresholds(rec, rows: list[dict], find: str, names: list[str]) -> tuple[str, int, int, tuple]:
    """``<find>_threshold`` against the first other swept parameter (the point's index without one) as
    scalars on that parameter's time line (module doc): in its own unit when every value is a whole
    number (``blocks``), else in thousandths of it (``friction (/1000)``, ``freq (mHz)``); a record name
    is drawn by its index. Returns the time line, the x range in its ticks and the y range."""
    x = names[0] if names else None
    values = [r.get(x) for r in rows] if x else list(range(len(rows)))
    if any(isinstance(v, str) for v in values):
        order = sorted(set(values), key=str)
        at, timeline, per_unit = np.array([order.index(v) for v in values], dtype=np.float64), f"{x} (index)", 1.0
    else:
        at = np.array([_number(v) for v in values], dtype=np.float64)
        unit = PARAM_UNITS.get(x.rpartition(".")[2], "") if x else ""
        whole = bool(np.all(at[np.isfinite(at)] == np.rint(at[np.isfinite(at)])))
        per_unit = 1.0 if whole else 1000.0
        name = x or "point"
        timeline = (
            (f"{name} ({unit})" if unit else name) if whole else (f"{name} (m{unit})" if unit else f"{name} (/1000)")
        )
    threshold = np.array([_number(r.get(f"{find}_threshold")) for r in rows], dtype=np.float64)
    unit = PARAM_UNITS.get(find.rpartition(".")[2], "")
    label = viewer_safe_text(f"{find}_threshold ({unit})" if unit else f"{find}_threshold")
    _series(
        rec,
        "study/thresholds/line",
        timeline,
        per_unit,
        at,
        threshold,
        rr.SeriesLines(colors=[(208, 48, 48)], names=[label], widths=[2.0]),
    )
    style = rr.SeriesPoints(colors=[(208, 48, 48)], names=[label + ": points"], marker_sizes=[4.0])
    _series(rec, "study/thresholds/points", timeline, per_unit, at, threshold, style)
    ok = np.isfinite(at) & np.isfinite(threshold)
    # Every swept point is in the view, found or not, with a margin beside the outermost: the range was
    # the found points' alone, so one found point (friction 0.6; none at 0.3) sat on the right edge, cut.
    swept = np.isfinite(at)
    ticks = np.rint(at[swept] * per_unit) if swept.any() else np.zeros(1)
    span = max(float(ticks.max() - ticks.min()), 0.1 * float(np.abs(ticks).max()), 1.0)
    x_range = (int(np.floor(min(0.0, ticks.min() - 0.05 * span))), int(np.ceil(ticks.max() + 0.05 * span)))
    top = float(threshold[ok].max()) if ok.any() else 1.0
    low = float(threshold[ok].min()) if ok.any() else 0.0
    y_range = (min(0.0, 1.1 * low), 1.1 * top if top > 0 else 1.0)
    return timeline, x_range[0], x_range[1], y_range


def _markdown(name: str, rows: list[dict]) -> str:
    if not rows:
        return f"# {name}\n\nno rows"
    columns = [c for c in rows[0] if c != "study"]
    lines = [f"# study: {name}", "", "| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for r in rows[:500]:
        cells = [f"{r[c]:.4g}" if isinstance(r[c], float) else str(r[c]) for c in columns]
        lines.append("| " + " | ".join(cells) + " |")
    return viewer_safe_text("\n".join(lines))
