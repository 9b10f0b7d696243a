"""Pictures of a study, as PNG (matplotlib, headless Agg backend).

* **state map** — one cell per run over two swept parameters, coloured intact / damaged / collapsed
  (failed runs grey), the collapse time written in collapsed cells; one swept parameter gives a strip.
* **fragility curve** — the fraction of runs collapsed at each stripe (same scale) against the mean
  intensity measure, every run as a tick at 0 or 1 coloured by its state, and the fitted lognormal curve.
* **threshold curve** — ``<param>_threshold`` against the other swept parameter (``--find``), the
  points without a threshold in the searched range marked at its end.

What the two curves show (series, colours, legend labels) is ``masonrycli.study.curves``', shared with
the recording.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from masonrycli.study.curves import (
    STATE_COLOURS,
    axis_positions,
    fragility_series,
    map_axis,
    point_groups,
    threshold_series,
    with_unit,
)

_MARKERS = {"circle": "o", "tick": "|", "diamond": "D", "up": "^", "down": "v"}


def _pyplot():
    """pyplot on Agg. Quiet about its folders: for a user whose home cannot be written (``nobody``, a
    container's user) matplotlib said on stderr, at every sweep, that it made a temporary config folder
    and that MPLCONFIGDIR should be set ('mkdir -p failed for path /nonexistent/.config/matplotlib …'):
    the temporary folder serves, the fonts are few (0.4 s for import and a figure either way)."""
    import logging

    log = logging.getLogger("matplotlib")
    level = log.level
    log.setLevel(logging.ERROR)
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    finally:
        log.setLevel(level)
    return plt


def _save(fig, path: Path) -> Path:
    # PNG whatever the name: the caller writes a temporary ".part" file (masonrycli.outputs.files.written_whole)
    fig.savefig(path, format="png", dpi=120, bbox_inches="tight")
    return path


def state_map(rows: list[dict], x: str, y: str | None, path: Path, title: str, by: tuple = ()) -> Path:
    """PNG of the states over parameters ``x`` (and ``y``): one coloured cell per run; one map a value of the
    other swept parameters ``by``, side by side, each titled with it (``friction = 0.3``): in one map a third
    axis's runs were drawn over each other, the last one's state shown for the cell."""
    plt = _pyplot()  # first: matplotlib imported quietly
    from matplotlib.patches import Patch

    xs, x_ticks = map_axis(rows, x)
    ys, y_ticks = map_axis(rows, y) if y else ([0], [])
    groups = point_groups(rows, list(by))
    cols = min(len(groups), 4)
    lines = -(-len(groups) // cols)
    size = (1.2 + 0.7 * len(xs), 1.2 + 0.55 * len(ys))
    figsize = size if cols == 1 else (size[0] * cols + 0.4 * (cols - 1), size[1] * lines + 0.3 * lines)
    fig, grid = plt.subplots(lines, cols, figsize=figsize, squeeze=False, layout="constrained" if cols > 1 else None)
    for ax, (label, members) in zip(grid.flat, groups):
        _map_cells(ax, [rows[i] for i in members], x, y, xs, ys, x_ticks, y_ticks)
        ax.set_title(label or title, fontsize=10)
    for ax in list(grid.flat)[len(groups) :]:
        ax.set_visible(False)
    handles = [Patch(color=STATE_COLOURS[s], label=s) for s in ("intact", "damaged", "collapsed")]
    grid.flat[cols - 1].legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    if len(groups) > 1:
        fig.suptitle(title, fontsize=10)
    try:
        return _save(fig, path)
    finally:
        plt.close(fig)  # also when saving fails: a long-lived process would keep every figure


def _map_cells(ax, rows: list[dict], x: str, y: str | None, xs: list, ys: list, x_ticks, y_ticks) -> None:
    """One state map: a coloured cell a run at its (x, y) values, the collapse time written in it."""
    plt = _pyplot()
    for r in rows:
        i, j = xs.index(r[x]), ys.index(r[y]) if y else 0
        colour = STATE_COLOURS.get(r.get("state") or "", STATE_COLOURS[""])
        ax.add_patch(plt.Rectangle((i - 0.5, j - 0.5), 1, 1, color=colour, ec="white", lw=1.5))
        t = r.get("collapse_time")
        if r.get("state") == "collapsed" and t == t:
            ax.text(i, j, f"{t:.2f} s", ha="center", va="center", fontsize=7, color="white")
    ax.set_xlim(-0.5, len(xs) - 0.5)
    ax.set_ylim(-0.5, len(ys) - 0.5)
    ax.set_xticks(range(len(xs)), x_ticks, rotation=45)
    ax.set_xlabel(with_unit(x))
    if y:
        ax.set_yticks(range(len(ys)), y_ticks)
        ax.set_ylabel(with_unit(y))
    else:
        ax.set_yticks([])


def _draw(ax, series) -> None:
    """The curve's series (``masonrycli.study.curves``), each with its legend entry; empty ones left out. A
    line followed by its own points (same data and colour) is drawn as one, one legend entry."""
    series = [c for c in series if len(c.x)]
    for i, c in enumerate(series):
        after = series[i + 1] if i + 1 < len(series) else None
        if c.marker == "line" and after is not None and after.colour == c.colour and np.array_equal(after.x, c.x):
            ax.plot(c.x, c.y, "o-", color=c.colour, label=c.label)
        elif (
            i
            and series[i - 1].marker == "line"
            and series[i - 1].colour == c.colour
            and np.array_equal(series[i - 1].x, c.x)
        ):
            continue  # drawn with its line
        elif c.marker == "line":
            ax.plot(c.x, c.y, "-", color=c.colour, label=c.label)
        else:
            size = 12 if c.marker == "tick" else 6
            ax.plot(c.x, c.y, _MARKERS[c.marker], color=c.colour, ms=size, linestyle="none", label=c.label)


def _legend_beside(ax) -> None:
    """The legend right of the plot, as the state map's: inside, at the lower right, it hid the runs that
    stood at the strongest shaking (P = 0 at the largest IM, the damaged runs of a fragility study) and the
    thresholds there."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)


def fragility_figure(rows: list[dict], im: str, fit, title: str, unit: str, groups=None):
    """The fragility curve's figure (``fragility_series``): runs at 0 / 1 by state, the fraction collapsed
    per scale stripe, the fitted lognormal (one of each per group of ``groups``)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    _draw(ax, fragility_series(rows, im, fit, unit, groups))
    ax.set_xlabel(f"{im} ({unit})")
    ax.set_ylabel("P(collapse)")
    ax.set_ylim(-0.05, 1.05)
    _legend_beside(ax)
    ax.set_title(title, fontsize=10)
    return fig


def fragility_curve(rows: list[dict], im: str, fit, path: Path, title: str, unit: str, groups=None) -> Path:
    """PNG of :func:`fragility_figure`."""
    fig = fragility_figure(rows, im, fit, title, unit, groups)
    try:
        return _save(fig, path)
    finally:
        _pyplot().close(fig)  # also when saving fails: a long-lived process would keep every figure


def threshold_figure(
    rows: list[dict], find: str, x: str | None, title: str, searched: tuple[float, float], by: tuple = ()
):
    """``<find>_threshold`` against parameter ``x`` (the points in order without one), one line a value of
    the other swept parameters ``by``, the points where none was found marked at the end of the searched
    range (``threshold_series``)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    at, names = axis_positions(rows, x)
    _draw(ax, threshold_series(rows, find, at, searched, joined=names is None, by=by))
    if names is not None:
        ax.set_xticks(range(len(names)), names, rotation=45)
    elif not x:  # the points in order, numbered from 1 (one point was ticked -0.04 … 0.04 around 0)
        ax.set_xticks(range(len(rows)), [str(i + 1) for i in range(len(rows))])
    ax.set_xlabel(with_unit(x) if x else "point")
    ax.set_ylabel(with_unit(find).replace(find, f"{find}_threshold", 1))
    ax.set_ylim(0.0, 1.1 * max(ax.get_ylim()[1], 0.0) or 1.0)  # room above a mark at the range's top
    if ax.get_legend_handles_labels()[0]:
        _legend_beside(ax)
    ax.set_title(title, fontsize=10)
    return fig


def threshold_curve(
    rows: list[dict], find: str, x: str | None, path: Path, title: str, searched: tuple[float, float], by: tuple = ()
) -> Path:
    """PNG of :func:`threshold_figure`."""
    fig = threshold_figure(rows, find, x, title, searched, by)
    try:
        return _save(fig, path)
    finally:
        _pyplot().close(fig)  # also when saving fails: a long-lived process would keep every figure
