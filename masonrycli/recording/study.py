"""Rerun recording of a study (``masonry sweep --recording study.rrd``).

The state map as coloured points over the two swept parameters (``study/state_map``) or the threshold
curve (``study/thresholds``), the PNG the command also wrote (``study/plot``), and the rows as a
markdown table (``study/rows``), all static; the fragility curve of a records study (``study/fragility``)
is a plot on its own time line (below). Axes are in the parameters' own units, so a 2-D view shows them
as they are; the PNG is the annotated picture.

Rerun's 2-D views draw y downward: each picture entity gets a static y-flip transform and its view looks
at it from ``study`` (an origin's own transform is not applied in its view), so larger values are up, as
in the PNG — before, the state map showed freq = 1 Hz above 2 Hz and the fragility curve upside down.
The state map's labels ("amp=0.25 freq=1: intact") are shown on hover only: drawn, a 6 × 2 grid's
overlapped into an unreadable line.

The fragility curve is a probability (0–1) against an intensity (pga 1–60 m/s², pgv 0.1–5 m/s): a 2-D
view has one scale for both axes, so it showed the curve as a flat line 60 units long and 1 high, without
axes. It is drawn in a time-series view instead, whose axes are scaled apart and labelled: the x axis is
a sequence time line in thousandths of the intensity's unit (``pga (mm/s²)``: a sequence is an integer,
so 1 mm/s² is its resolution), y the probability fixed at [−0.05, 1.05]; the runs are points at 0 or 1
coloured by state, the fraction collapsed at each scale and the fitted lognormal as in the PNG.
"""

from __future__ import annotations

import math
import uuid
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from masonrycli.intensity import UNITS
from masonrycli.recording.document import viewer_safe_text
from masonrycli.recording.recorder import APPLICATION_ID

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
    panels = []
    if request.find or not (fit is not None or "record" in [a.name for a in request.axes]):
        if request.find:
            _log_thresholds(rec, rows, request.find, names)
            entity, title = "study/thresholds", "thresholds"
        else:
            _log_state_map(rec, rows, names)
            entity, title = "study/state_map", "state map"
        rec.log(entity, rr.Transform3D(scale=[1.0, -1.0, 1.0]), static=True)  # y up (module doc)
        views.insert(0, rrb.Spatial2DView(origin="study", contents=[f"+ /{entity}/**"], name=title))
    else:
        timeline, end = _log_fragility(rec, rows, fit, im)
        # the whole curve from IM = 0 (a time-series view otherwise shows a window around the cursor)
        whole = rr.TimeRange(start=rrb.TimeRangeBoundary.absolute(seq=0), end=rrb.TimeRangeBoundary.absolute(seq=end))
        axis_x = rrb.TimeAxis(view_range=whole)
        axis_y = rrb.ScalarAxis(range=(-0.05, 1.05), zoom_lock=True)
        legend = rrb.PlotLegend(corner="RightBottom")  # high IM, P = 0: where runs are fewest
        views.insert(
            0,
            rrb.TimeSeriesView(
                origin="study/fragility", name="fragility", axis_x=axis_x, axis_y=axis_y, plot_legend=legend
            ),
        )
        # a time-series view plots against the time panel's time line: open on the intensity's
        panels.append(rrb.TimePanel(state="collapsed", timeline=timeline, play_state="paused"))
    rec.log("study/rows", rr.TextDocument(_markdown(name, rows), media_type=rr.MediaType.MARKDOWN), static=True)
    rec.save(path, default_blueprint=rrb.Blueprint(rrb.Grid(*views), *panels))
    rec.disconnect()
    return path


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
        keep = np.isfinite(at) & np.isfinite(values)
        rec.log(entity, style, static=True)
        if keep.any():
            order = np.argsort(at[keep], kind="stable")
            ticks = np.rint(np.asarray(at)[keep][order] * 1000.0).astype(np.int64)
            column = rr.Scalars.columns(scalars=np.asarray(values, dtype=np.float64)[keep][order])
            rec.send_columns(entity, indexes=[rr.TimeColumn(timeline, sequence=ticks)], columns=column)

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


def _log_thresholds(rec, rows: list[dict], find: str, names: list[str]) -> None:
    key = f"{find}_threshold"
    x = names[0] if names else None
    pts = np.array([[_number(r[x]) if x else float(i), _number(r[key])] for i, r in enumerate(rows)])
    pts = pts[np.isfinite(pts).all(axis=1)] if len(pts) else pts.reshape(0, 2)
    rec.log("study/thresholds", rr.LineStrips2D([pts]) if len(pts) > 1 else rr.Points2D(pts), static=True)


def _markdown(name: str, rows: list[dict]) -> str:
    if not rows:
        return f"# {name}\n\nno rows"
    columns = [c for c in rows[0] if c != "study"]
    lines = [f"# study: {name}", "", "| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for r in rows[:500]:
        cells = [f"{r[c]:.4g}" if isinstance(r[c], float) else str(r[c]) for c in columns]
        lines.append("| " + " | ".join(cells) + " |")
    return viewer_safe_text("\n".join(lines))
