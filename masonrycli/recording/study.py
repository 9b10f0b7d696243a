"""Rerun recording of a study (``masonry sweep --recording study.rrd``).

The state map as coloured points over the two swept parameters (``study/state_map``, with a key of its colours), the PNG the
command also wrote (``study/plot``), and the rows as the terminal shows them, units under the table
(``study/rows``), all static, on no time line: its time panel is hidden (the viewer filled an empty one
with a ``log_time`` of its own, a name that meant nothing there); the
fragility curve of a records study (``study/fragility``) and the threshold curve of ``--find``
(``study/thresholds``) are plots on their own time lines (below), their axes in the parameters' own units;
the state map, as the PNG's, has one cell per swept value (below); the PNG is the annotated picture.

Rerun's 2-D views draw y downward: each picture entity gets a static y-flip transform and its view looks
at it from ``study`` (an origin's own transform is not applied in its view), so larger values are up, as
in the PNG — before, the state map showed freq = 1 Hz above 2 Hz and the fragility curve upside down.
The state map's labels ("amp=0.25 freq=1: intact") are shown on hover only: drawn, a 6 × 2 grid's
overlapped into an unreadable line. Its axes are drawn as labels, each swept value once below its
column and left of its row (``study/state_map/axes``), the axes' names once (``…/axes/names``). Drawn
at the values, in their units, amp = 0.1, 0.2 beside freq = 1, 2 were dots 0.1 apart on a map 1 high and
their labels overlapped ("amp=0.amp=0.2"; 0.1, 0.105 beside 1.0 merged the dots too): the dots sit at
the values' ranks, and the labels, of a size fixed on screen, are laid out for the view's estimated scale
(:func:`map_scale_px`), in two lanes where a cell is narrower than they are, every 2nd, 5th … value
where two lanes cannot hold them all (the rest on hover). Every view's name says what its axes are
(the plots draw no axis title, the 2-D view no axis), and the side panels open collapsed.

The fragility curve is a probability (0–1) against an intensity (pga 1–60 m/s², pgv 0.1–5 m/s): a 2-D
view has one scale for both axes, so it showed the curve as a flat line 60 units long and 1 high, without
axes. It is drawn in a time-series view instead, whose axes are scaled apart and labelled: the x axis is
a sequence time line in thousandths of the intensity's unit (``pga (mm/s²)``: a sequence is an integer,
so 1 mm/s² is its resolution), y the probability fixed at [−0.05, 1.05]; the runs are points at 0 or 1
coloured by state, the fraction collapsed at each scale and the fitted lognormal: the series, colours
and legend labels of the PNG (``masonrycli.study.curves``; red was a collapsed run here and the fraction
per scale there). With a curve per value of another swept parameter, a group's fraction and fit share one
legend entry, one line long (:func:`_one_entry_a_group`): 5 groups' 13 entries ran off the view's bottom,
the runs' own with them.

The threshold curve read flat the same way (``amp_threshold`` 0.08–0.23 m/s against ``blocks`` 12–48
or ``friction`` 0.1–0.3): it is plotted the same way, against the other swept parameter's own time line
(``blocks``, whole numbers, in its unit; ``friction (×1000)``, ``freq (mHz)`` in thousandths), y from 0
to 1.1 × the largest threshold; the points without one are marked at the searched range's end.

The plot's x ticks read "#1000 … #7000" whatever the time line's name: Rerun 0.41 draws a sequence as
"#n", a duration as "+n ms", and a time-series view has no x-axis title nor a scalar x axis (a bar chart
has one, but draws bars). So the view's name states the scale with an example, "pga in mm/s² (#1000 = 1
m/s²)", "friction × 1000 (#1000 = 1)" (:func:`x_scale`); before, only "(mm/s²)" or "(/1000)" hinted it.
"""

from __future__ import annotations

import dataclasses
import math
import uuid
from pathlib import Path

import numpy as np
import pyarrow as pa
import rerun as rr
import rerun.blueprint as rrb

from masonrycli.recording.document import viewer_safe_text
from masonrycli.recording.readback import check_complete, wait_written
from masonrycli.recording.recorder import APPLICATION_ID
from masonrycli.records.intensity import UNITS
from masonrycli.study.curves import (
    STATE_COLOURS,
    axis_positions,
    fragility_series,
    map_axis,
    point_groups,
    rgb,
    searched_range,
    short_fit_label,
    threshold_series,
)
from masonrycli.study.curves import UNITS as PARAM_UNITS
from masonrycli.study.table import find_columns, grid_columns

STATE_RGBA = {state: (*rgb(colour), 255) for state, colour in STATE_COLOURS.items()}


def record_study(path: Path, name: str, rows: list[dict], request, fit, im: str, plot: Path, groups=None) -> Path:
    """Write the study's ``.rrd`` at ``path`` (closed, with its blueprint); the caller writes it under
    a temporary name and renames it (``masonrycli.outputs.files.written_whole``)."""
    path = Path(path)
    rec = rr.RecordingStream(APPLICATION_ID, recording_id=str(uuid.uuid4()))
    # to the file from the start, the blueprint sent at the end: a save at the end handed rerun's writer the
    # whole backlog at once, and when a write failed (a full disk) save waited for it forever
    rec.save(path)
    # named for what they hold: "rows" and "plot" said little beside "state map: freq (Hz) right, amp (m/s) up"
    views = [
        rrb.TextDocumentView(origin="study/rows", name=viewer_safe_text(f"runs of {name} (units under the table)"))
    ]
    if plot and Path(plot).exists():
        rec.log("study/plot", rr.EncodedImage(path=plot), static=True)
        views.insert(
            0, rrb.Spatial2DView(origin="study/plot", name=viewer_safe_text(f"{Path(plot).name} (the picture)"))
        )
    names = [a.name for a in request.axes if a.name != request.find and len(a.values) > 1]
    # The views fill the window: the blueprint, selection and time panels (Rerun's defaults: open) took
    # two fifths of it; the plots' time panel stays collapsed, it only names the x axis's time line.
    panels = [rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed")]
    if request.find:
        timeline, against, start, end, y_range = _log_thresholds(
            rec, rows, request.find, names, searched_range(request)
        )
        legend = rrb.PlotLegend(corner="RightBottom")  # below a rising or flat curve (y from 0)
        unit = PARAM_UNITS.get(request.find.rpartition(".")[2], "")
        title = viewer_safe_text(f"thresholds: {request.find}" + (f" ({unit})" if unit else "") + f" against {against}")
        _time_line_extent(rec, timeline, start, end)
        view, panel = _plot_view("study/thresholds", title, timeline, (start, end), y_range, legend)
        views.insert(0, view)
        panels.append(panel)
    elif fit is None and "record" not in [a.name for a in request.axes]:
        _log_state_map(rec, rows, names)
        rec.log("study/state_map", rr.Transform3D(scale=[1.0, -1.0, 1.0]), static=True)  # y up (module doc)
        axes = ", ".join(f"{_with_unit(n)} {way}" for n, way in zip(names, ("right", "up")))
        # a third parameter's runs side by side in each cell (_log_state_map): which is which, left to right
        beside = "; ".join(f"{n} {' | '.join(map_axis(rows, n)[1])} left to right in a cell" for n in names[2:])
        title = viewer_safe_text(f"state map: {axes}{'; ' + beside if beside else ''}" if axes else "state map")
        views.insert(0, rrb.Spatial2DView(origin="study", contents=["+ /study/state_map/**"], name=title))
        # hidden: the map, the picture and the rows are static, on no time line, and the viewer fills an
        # empty time panel with a "log_time" of its own, which meant nothing here (module doc)
        panels.append(rrb.TimePanel(state="hidden"))
    else:
        timeline, end = _log_fragility(rec, rows, fit, im, groups)
        legend = rrb.PlotLegend(corner="RightBottom")  # high IM, P = 0: where runs are fewest
        title = viewer_safe_text(f"fragility: P(collapse) against {x_scale(im, UNITS[im], 1000.0)[1]}")
        view, panel = _plot_view("study/fragility", title, timeline, (0, end), (-0.05, 1.05), legend)
        views.insert(0, view)
        panels.append(panel)
    keys = [a.name for a in request.axes if a.name != request.find]  # what a row is keyed by
    columns = find_columns(keys, request.find) if request.find else grid_columns(keys, im)
    rows_text = _markdown(name, rows, columns)
    rec.log("study/rows", rr.TextDocument(rows_text, media_type=rr.MediaType.MARKDOWN), static=True)
    rec.send_blueprint(rrb.Blueprint(rrb.Grid(*views), *panels), make_active=True, make_default=True)
    wait_written(rec, path)  # a writer stopped by a full disk: OSError, no disconnect (it hung)
    rec.disconnect()
    check_complete(path)
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
    ``timeline`` whose tick is ``1 / per_unit`` of ``at``'s unit; ``style`` (archetypes) names and colours
    the series."""
    at, values = np.asarray(at, dtype=np.float64), np.asarray(values, dtype=np.float64)
    keep = np.isfinite(at) & np.isfinite(values)
    rec.log(entity, *style, static=True)
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


# The viewer draws a label in a box of fixed size on screen, whatever the zoom: about 8 px a character plus
# 10 px ("freq=2.0" 62 px, "collapsed" 72 px on a headless 1920 x 1080 screenshot) and 24 px high. A view
# fits the map's points into it, here taken as 600 x 1000 px (the map's view beside the picture and the rows
# at 1920 x 1080: 640 x 1030) and only 55 % filled (0.61 and 0.81 of the height measured): the scale is
# underestimated, so labels laid out for it stand further apart on screen, never closer.
LABEL_CHAR_PX, LABEL_PAD_PX, LABEL_HEIGHT_PX, LABEL_GAP_PX = 8.0, 10.0, 24.0, 6.0
MAP_VIEW_PX, MAP_FILL = (600.0, 1000.0), 0.55
DOT_RADIUS = 0.25  # of the grid's cell
# the key's dots, smaller: as large and as far apart as the runs', the key under a one-row map ('masonry
# sweep wall --param amp=0.2:1:3') read as a second row of runs, of values intact, damaged, collapsed, failed
KEY_RADIUS = 0.4 * DOT_RADIUS
KEY_STATES = ("intact", "damaged", "collapsed", "")


def label_width_px(text: str) -> float:
    """Estimated width on screen of a drawn label (module constants above)."""
    return LABEL_CHAR_PX * len(text) + LABEL_PAD_PX


def map_scale_px(points: np.ndarray) -> float:
    """Estimated pixels per unit of the map's view: the points' extent (dots' edges, labels' anchors)
    fitted into the view, as the viewer does, less its margin (module constants above)."""
    span = np.ptp(points, axis=0) if len(points) else np.ones(2)
    span = np.maximum(span, 1e-9)
    return MAP_FILL * min(MAP_VIEW_PX[0] / span[0], MAP_VIEW_PX[1] / span[1])


def _lanes(count: int, sizes_px, px: float) -> tuple[list[int], list[int]]:
    """The labels of an axis's ``count`` cells, ``sizes_px`` long on screen at ``px`` pixels a cell: which are
    drawn and the lane (row under the map, column left of it) of each, the first where it stands clear of
    the lane's previous label. Every value where one or two lanes hold them; else every 2nd, 5th, 10th …
    (a lane more for each would pile the labels up further than the map is long)."""
    for every in (k * 10**e for e in range(7) for k in (1, 2, 5)):
        shown, lanes, last = list(range(0, count, every)), [], []  # last: per lane, its last label's (cell, size)
        for i in shown:
            ends = [i0 + (s0 + sizes_px[i]) / 2.0 / px + LABEL_GAP_PX / px for i0, s0 in last]
            lane = next((k for k, end in enumerate(ends) if i >= end), len(last))
            last[lane : lane + 1] = [(i, sizes_px[i])]
            lanes.append(lane)
        if len(last) <= 2:
            return shown, lanes
    return shown[:1], lanes[:1]


def _map_labels(names: list[str], ticks: list[list[str]], n: tuple[int, int], px: float):
    """Positions of the map's labels at ``px`` pixels a unit: each axis's values (``ticks``) beside its
    cells (x: rows under the map, y: columns left of it, in lanes: :func:`_lanes`), the axes' names with
    their units after them (x under, y above), and the key of the colours under all; returns (value
    anchors, value texts, name anchors, name texts, key dots, key names' anchors)."""
    h, gap, r = LABEL_HEIGHT_PX / px, LABEL_GAP_PX / px, DOT_RADIUS
    clear = max(r, h / 2.0)  # a label's edge from a dot's centre, or from a label of the other axis
    at, texts, title_at, titles = [], [], [], []
    bottom, left = -r, 0.0
    if names:
        shown, rows = _lanes(n[0], [label_width_px(t) for t in ticks[0]], px)
        at += [[i, -clear - gap - h / 2.0 - k * (h + gap)] for i, k in zip(shown, rows)]
        texts += [ticks[0][i] for i in shown]
        bottom = -clear - gap - (max(rows) + 1) * (h + gap)
        title_at.append([(n[0] - 1) / 2.0, bottom - h / 2.0])
        titles.append(_with_unit(names[0]))
        bottom -= h + gap
    if len(names) > 1:
        widest = max(label_width_px(t) for t in ticks[1]) / px
        shown, columns = _lanes(n[1], [LABEL_HEIGHT_PX] * n[1], px)
        at += [[-clear - gap - widest / 2.0 - k * (widest + gap), j] for j, k in zip(shown, columns)]
        texts += [ticks[1][j] for j in shown]
        left = -clear - gap - widest / 2.0 - max(columns) * (widest + gap)
        title_at.append([-clear - gap - widest / 2.0, n[1] - 1 + clear + gap + h / 2.0])
        titles.append(_with_unit(names[1]))
    # The key, a row under the map's x labels (the PNG's legend), from the y labels' left to at least the
    # map's right: its names in the axes' grey under its dots (drawn by the dots, they sat on them in their
    # colour: "intact" green on green), each clear of the next.
    widths = [label_width_px(s or "failed") / px for s in KEY_STATES]
    steps = [max((w0 + w1) / 2.0 + gap, 4.0 * r) for w0, w1 in zip(widths, widths[1:])]
    spread = max(1.0, (n[0] - 1 - left) / sum(steps))
    key_y = bottom - gap - KEY_RADIUS
    key_at = [[left + spread * sum(steps[:i]), key_y] for i in range(len(KEY_STATES))]
    key_names_at = [[x, key_y - max(KEY_RADIUS, h / 2.0) - gap - h / 2.0] for x, _ in key_at]
    return at, texts, title_at, titles, key_at, key_names_at


def _log_state_map(rec, rows: list[dict], names: list[str]) -> None:
    """The runs as dots on a grid, one cell per swept value as in the PNG (evenly spaced whatever the
    values: amp = 0.1, 0.2 beside freq = 1, 2 were dots 0.1 apart on a map 1 high, their labels drawn over
    each other, "amp=0.amp=0.2"), with the values, the axes' names and the key as labels laid out not to
    overlap at the view's estimated scale (:func:`map_scale_px`). The values are on hover."""
    names, by = names[:2], names[2:]
    values, ticks = zip(*(map_axis(rows, name) for name in names)) if names else ((), ())
    index = [{v: i for i, v in enumerate(vs)} for vs in values]
    n = (len(values[0]) if names else 1, len(values[1]) if len(names) > 1 else 1)
    pos = np.array(
        [[index[k][r[name]] if k < len(names) else 0 for k, name in enumerate((*names, None, None)[:2])] for r in rows],
        dtype=np.float32,
    ).reshape(-1, 2)
    # a third swept parameter's runs side by side in their cell (drawn at one place, the last hid the others),
    # in the order of its values, smaller; the PNG draws one map a value
    groups = point_groups(rows, by)
    radius = DOT_RADIUS if len(groups) == 1 else min(DOT_RADIUS, 0.4 / len(groups))
    for g, (_, members) in enumerate(groups):
        pos[members, 0] += (g - (len(groups) - 1) / 2) * 2.2 * radius if len(groups) > 1 else 0.0
    colours = np.array([STATE_RGBA.get(r.get("state") or "", STATE_RGBA[""]) for r in rows], dtype=np.uint8)
    labels = [
        viewer_safe_text(" ".join(f"{n}={r[n]}" for n in (*names, *by)) + f": {r.get('state') or 'failed'}")
        for r in rows
    ]
    points = rr.Points2D(pos, colors=colours, labels=labels, radii=radius, show_labels=False)
    rec.log("study/state_map", points, static=True)
    ticks = [[viewer_safe_text(t) for t in texts] for texts in ticks]
    # The scale depends on the labels' extent, which depends on the scale (a label's size in map units is
    # its size on screen over the scale): the largest scale, in steps of 10 %, at which the labels laid out
    # for it leave an extent that gives at least that scale (then they stand at least as far apart).
    dots = np.array([[-DOT_RADIUS, -DOT_RADIUS], [n[0] - 1 + DOT_RADIUS, n[1] - 1 + DOT_RADIUS]])
    px = map_scale_px(dots)
    for _ in range(100):
        layout = _map_labels(names, ticks, n, px)
        key = np.array(layout[4])
        anchors = [np.array(a, dtype=np.float64).reshape(-1, 2) for a in (layout[0], layout[2], layout[5])]
        if map_scale_px(np.concatenate([dots, *anchors, key - KEY_RADIUS, key + KEY_RADIUS])) >= px:
            break
        px *= 0.9
    at, texts, title_at, titles, key_at, key_names_at = layout
    grey = (220, 220, 220, 255)

    def drawn(where, text):
        return rr.Points2D(
            np.array(where, np.float32).reshape(-1, 2), labels=text, radii=0.0, colors=grey, show_labels=True
        )

    # The axes, as drawn labels (a 2-D view has none): the map was unlabelled dots on black
    rec.log("study/state_map/axes", drawn(at, texts), static=True)
    rec.log("study/state_map/axes/names", drawn(title_at, [viewer_safe_text(t) for t in titles]), static=True)
    key_colours = np.array([STATE_RGBA[s] for s in KEY_STATES], dtype=np.uint8)
    key = rr.Points2D(np.array(key_at, np.float32), colors=key_colours, radii=KEY_RADIUS)
    rec.log("study/state_map/key", key, static=True)
    rec.log("study/state_map/key/names", drawn(key_names_at, [s or "failed" for s in KEY_STATES]), static=True)


def fragility_timeline(im: str) -> str:
    """The sequence time line the fragility curve is plotted on: thousandths of the IM's unit."""
    return x_scale(im, UNITS[im], 1000.0)[0]


def x_scale(name: str, unit: str, per_unit: float) -> tuple[str, str]:
    """(time line name, what the view's name says of the x axis) for ``name`` in ``unit`` plotted at
    ``per_unit`` ticks per unit (1 or 1000): the ticks read "#n", so in thousandths the example "#1000 =
    1 unit" says how to read them (module doc)."""
    if per_unit == 1.0:
        timeline = f"{name} ({unit})" if unit else name
        return timeline, timeline
    if unit:
        return f"{name} (m{unit})", f"{name} in m{unit} (#1000 = 1 {unit})"
    return f"{name} (×1000)", f"{name} × 1000 (#1000 = 1)"


def _send_curve(rec, base: str, timeline: str, per_unit: float, series) -> None:
    """The curve's series (``masonrycli.study.curves``: the PNG draws the same ones) under ``base``.

    A line followed by its own points (same data and colour; the threshold curve) is one entity with both
    styles under the line's name, one legend entry as in the PNG: as two entities the legend listed
    "amp_threshold (m/s)" and "amp_threshold (m/s): points"."""
    series = list(series)
    for i, c in enumerate(series):
        before = series[i - 1] if i else None
        if before is not None and before.marker == "line" and _same_points(before, c):
            continue  # sent with its line
        after = series[i + 1] if i + 1 < len(series) else None
        label = viewer_safe_text(c.label)
        if c.marker == "line":
            style = [rr.SeriesLines(colors=[rgb(c.colour)], names=[label], widths=[2.0])]
            if after is not None and after.marker != "line" and _same_points(c, after):
                style.append(_points_style(after, label))
        else:
            style = [_points_style(c, label)]
        _series(rec, f"{base}/{c.key}", timeline, per_unit, c.x, c.y, style)


def _same_points(a, b) -> bool:
    return a.colour == b.colour and np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)


def _points_style(c, label: str) -> rr.SeriesPoints:
    marker = {"tick": "circle"}.get(c.marker, c.marker)  # a tick reads as a dot at this size
    size = 6.0 if c.marker in ("up", "down") else 4.0
    return rr.SeriesPoints(colors=[rgb(c.colour)], names=[label], markers=[marker], marker_sizes=[size])


def _log_fragility(rec, rows: list[dict], fit, im: str, groups=None) -> tuple[str, int]:
    """Runs, fraction collapsed per scale and fitted curve (of each of ``groups``) as scalars on the IM's time
    line (module doc); returns the time line's name and the end of the curve on it (1.2 × the largest IM,
    in its ticks)."""
    timeline = fragility_timeline(im)
    good = [r for r in rows if r.get("status") != "error"]
    series = _one_entry_a_group(fragility_series(good, im, fit, UNITS[im], groups), groups, UNITS[im])
    _send_curve(rec, "study/fragility", timeline, 1000.0, series)
    x = np.array([_number(r.get(im)) for r in good], dtype=np.float64)
    top = np.nanmax(x) if np.isfinite(x).any() else 1.0
    return timeline, int(np.rint(1200.0 * top)) + 1


def _one_entry_a_group(series, groups, unit: str) -> list:
    """The fragility ``series`` with each group's fraction and fit under one name, ``friction = 0.5: θ = 3.09
    m/s², β = 0.31`` (:func:`~masonrycli.study.curves.short_fit_label`): the viewer's legend lists series of
    the same name once, in their colour. With 5 groups (``--param friction=0.4:0.8:5``) it had 13 entries, 5
    of them wrapped on two lines, and the runs' 3 (``runs: intact / damaged / collapsed``) were cut off below
    the view (a headless screenshot at 1920 x 1080); now 8, each one line. The PNG keeps its own entries."""
    if not groups or len(groups) < 2:
        return list(series)
    names = {str(i): f"{g.label}: {short_fit_label(g.fit, unit)}" for i, g in enumerate(groups)}
    out = []
    for c in series:
        kind, _, i = c.key.partition("/")
        out.append(dataclasses.replace(c, label=names[i]) if kind in ("fraction", "fit") and i in names else c)
    return out


def _log_thresholds(rec, rows: list[dict], find: str, names: list[str], searched) -> tuple[str, str, int, int, tuple]:
    """``<find>_threshold`` against the first other swept parameter (the point's index without one) as
    scalars on that parameter's time line (module doc): in its own unit when every value is a whole
    number (``blocks``), else in thousandths of it (``friction (×1000)``, ``freq (mHz)``); a record name
    is drawn by its index. The points without a threshold are marked at the end of the ``searched``
    range. Returns the time line, the view name's x part (:func:`x_scale`), the x range in its ticks and
    the y range."""
    x = names[0] if names else None
    at, by_name = axis_positions(rows, x)
    if by_name is not None or x is None:  # an index: from 1, as the PNG numbers the points (and see below)
        at = at + 1.0
    if by_name is not None:
        timeline, per_unit = f"{x} (index)", 1.0
        against = timeline
    else:
        unit = PARAM_UNITS.get(x.rpartition(".")[2], "") if x else ""
        whole = bool(np.all(at[np.isfinite(at)] == np.rint(at[np.isfinite(at)])))
        per_unit = 1.0 if whole else 1000.0
        timeline, against = x_scale(x or "point", unit, per_unit)
    series = threshold_series(rows, find, at, searched, joined=by_name is None, by=names[1:])
    _send_curve(rec, "study/thresholds", timeline, per_unit, series)
    # Every swept point is in the view, found or not, with a margin beside the outermost: the range was
    # the found points' alone, so one found point (friction 0.6; none at 0.3) sat on the right edge, cut.
    swept = np.isfinite(at)
    ticks = np.rint(at[swept] * per_unit) if swept.any() else np.zeros(1)
    span = max(float(ticks.max() - ticks.min()), 0.1 * float(np.abs(ticks).max()), 1.0)
    x_range = (int(np.floor(min(0.0, ticks.min() - 0.05 * span))), int(np.ceil(ticks.max() + 0.05 * span)))
    if ticks.min() >= 0:
        # The viewer opens with the time cursor at the time line's start, and Rerun 0.41 draws no static image
        # while the cursor is below 0: a search of one point (index 0, its margin at -1) opened on the
        # picture's view saying "No data available" (headless screenshot, 2026-11-29)
        x_range = (max(x_range[0], 0), x_range[1])
    # the y range holds the found thresholds and the marks of the points without one
    shown = np.concatenate([c.y for c in series if c.marker != "line"])
    shown = shown[np.isfinite(shown)]
    top = float(shown.max()) if shown.size else 1.0
    low = float(shown.min()) if shown.size else 0.0
    y_range = (min(0.0, 1.1 * low), 1.1 * top if top > 0 else 1.0)
    return timeline, against, x_range[0], x_range[1], y_range


def _markdown(name: str, rows: list[dict], columns) -> str:
    """The rows as the terminal shows them (``masonrycli.study.table``): short headers, values in the
    units the legend under the table names, blank where there is none. The table file's every column,
    SI values and no units (26 columns for a grid study, "nan" for a run that did not collapse) ran off
    the view's right edge after the first ten, with no unit anywhere."""
    if not rows:
        return f"# {name}\n\nno rows"
    headers = [c.header for c in columns]
    lines = [f"# study: {name}", "", "| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    for r in rows[:500]:
        lines.append("| " + " | ".join(c.cell(r).replace("|", "/") for c in columns) + " |")
    legend = [c.legend for c in columns if c.legend]
    lines += ["", " · ".join(legend), "", "Every column, in SI units, is in the table file (masonry docs sweep)."]
    if len(rows) > 500:
        lines.append(f"The first 500 of {len(rows)} rows.")
    return viewer_safe_text("\n".join(lines))
