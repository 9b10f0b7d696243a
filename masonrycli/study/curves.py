"""What a study's curves show, once for both pictures: the series of the fragility and threshold curves.

Each curve is a list of :class:`Series` — legend label, colour, marker, points — that ``study.plots``
draws in the PNG (matplotlib) and ``recording.study`` in the recording (rerun), so a colour and its legend
entry mean the same in both. Before, they were chosen apart and disagreed: red was "the fraction collapsed
per scale" in the PNG and "a collapsed run" in the recording, the runs grey ticks in one and coloured by
state in the other, and a threshold search that found none (``no collapse up to amp = 1.5``) was in
neither.

Colours are hex strings chosen to read on the PNG's white and the viewer's near-black backgrounds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

STATE_COLOURS = {"intact": "#2e9e5b", "damaged": "#f0a030", "collapsed": "#d03030", "": "#a0a0a0"}
"""A run's state (``""``: failed) -> colour: the state map's cells, the fragility curve's runs."""
FRACTION_COLOUR = "#9b59d0"  # purple: no state's colour (it was red, a collapsed run's colour, in the PNG)
FIT_COLOUR = "#1f5fa8"
GROUP_COLOURS = ("#1f5fa8", "#9b59d0", "#17a2b8", "#8c564b", "#e377c2", "#7f8c2a")
"""The fit and fraction of each value of a record study's other parameter (``fit_by``): none a state's colour."""
THRESHOLD_COLOUR = "#d03030"
NOT_FOUND_COLOUR = "#8c8c8c"  # grey: no threshold in the searched range


class _ParamUnits:
    """A swept parameter's unit, by its last dotted part: ``UNITS.get(name, default)``, the unit
    geometry_library.values.unit_of reads it in (the one registry), ``default`` when it has none. A dict of
    five names here left the others bare: a study over ``pga_g`` (g), ``length`` (m) or ``density`` (kg/m³)
    had axes and ``masonry inspect`` columns without their unit."""

    def get(self, name: str, default: str | None = None) -> str | None:
        from geometry_library.values import unit_of

        return unit_of(name) or default


UNITS = _ParamUnits()


@dataclass(frozen=True)
class Series:
    """One legend entry: ``label``, ``colour`` (hex), ``marker`` ("line", "circle", "tick", "diamond", "up",
    "down"), and its points (``x``, ``y``, finite)."""

    key: str  # the entity name under the curve's path in the recording
    label: str
    colour: str
    marker: str
    x: np.ndarray
    y: np.ndarray


def rgb(colour: str) -> tuple[int, int, int]:
    """``"#d03030"`` -> (208, 48, 48)."""
    return tuple(int(colour[i : i + 2], 16) for i in (1, 3, 5))


def with_unit(name: str) -> str:
    unit = UNITS.get(name.rpartition(".")[2], "")
    return f"{name} ({unit})" if unit else name


def _number(value) -> float:
    return float(value) if isinstance(value, (int, float)) else math.nan


def axis_positions(rows: list[dict], x: str | None) -> tuple[np.ndarray, list[str] | None]:
    """Each row's position along parameter ``x``: its value; for names (records), the index of its name
    in their sorted list, with that list; without a parameter, the row's index."""
    if not x:
        return np.arange(len(rows), dtype=np.float64), None
    values = [r.get(x) for r in rows]
    if any(isinstance(v, str) for v in values):
        names = sorted({str(v) for v in values})
        return np.array([names.index(str(v)) for v in values], dtype=np.float64), names
    return np.array([_number(v) for v in values], dtype=np.float64), None


def map_axis(rows: list[dict], name: str) -> tuple[list, list[str]]:
    """The state map's cells along parameter ``name``, for both pictures: its swept values in order
    (numbers by value, then names), one cell each, and their tick texts as ``:g`` writes them ("0.1", "2"),
    the exact values where ``:g`` would give two cells one text."""
    values = sorted({r[name] for r in rows}, key=lambda v: (isinstance(v, str), 0 if isinstance(v, str) else v, str(v)))
    short = [v if isinstance(v, str) else f"{v:g}" for v in values]
    return values, short if len(set(short)) == len(short) else [str(v) for v in values]


def searched_range(request) -> tuple[float, float]:
    """The lowest and highest value a threshold search of ``request`` (``--find``) tries first."""
    values = next(a.values for a in request.axes if a.name == request.find)
    return float(min(values)), float(max(values))


def fit_label(fit, unit: str) -> str:
    if fit.separated:
        return "lognormal: not resolved (runs separated: β → 0)"
    if getattr(fit, "unbounded", False):
        return "lognormal: not resolved (collapses not above the runs that stood: β → ∞)"
    return f"lognormal: θ = {fit.median:.3g} {unit}, β = {fit.dispersion:.2f}"


def short_fit_label(fit, unit: str) -> str:
    """:func:`fit_label` in one line of the viewer's legend beside a group's name (``friction = 0.5: θ = 3.09
    m/s², β = 0.31``): the group's fraction and fit share that one entry (``masonrycli.recording.study``)."""
    if fit is None:
        return "fraction collapsed per scale"
    if fit.separated:
        return "not resolved (β → 0)"
    if getattr(fit, "unbounded", False):
        return "not resolved (β → ∞)"
    return f"θ = {fit.median:.3g} {unit}, β = {fit.dispersion:.2f}"


def point_groups(rows: list[dict], by: list[str]) -> list[tuple[str, list[int]]]:
    """``(label, row indices)`` of each combination of the values of parameters ``by`` in ``rows``, in the rows'
    order (``friction = 0.5``); one group ``("", every row)`` when ``by`` is empty."""
    groups: dict[tuple, list[int]] = {}
    for i, r in enumerate(rows):
        groups.setdefault(tuple(r.get(k) for k in by), []).append(i)
    return [
        (", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in zip(by, values)), members)
        for values, members in groups.items()
    ]


def fragility_series(rows: list[dict], im: str, fit, unit: str, groups=None) -> list[Series]:
    """The runs at 0 or 1 by state, the fraction collapsed per scale (at the scale's mean IM), the
    fitted lognormal from IM = 0 to 1.2 × the largest (300 points); ``rows`` without the failed runs.
    ``groups`` (``fragility.fit_by``, more than one): the fraction and the fit of each group instead, in its
    colour, its label first (``friction = 0.5: lognormal: θ = …``); ``fit`` is then not used."""
    x = np.array([_number(r.get(im)) for r in rows], dtype=np.float64)
    out = []
    for state in ("intact", "damaged", "collapsed"):
        sel = np.array([r.get("state") == state for r in rows], dtype=bool) & np.isfinite(x)
        y = np.full(int(sel.sum()), 1.0 if state == "collapsed" else 0.0)
        out.append(Series(f"runs/{state}", f"runs: {state}", STATE_COLOURS[state], "tick", x[sel], y))
    if not np.isfinite(x).any():
        return out
    # from IM = 0 in steps of 1/1000 of the unit (the recording's time line is in thousandths)
    grid = np.unique(np.rint(np.linspace(0, np.nanmax(x) * 1.2, 300) * 1000.0)) / 1000.0
    per = "per PGA" if rows and "pga_g" in rows[0] else "per scale"  # the records scaled to each pga_g, or by scale
    if groups is None or len(groups) < 2:
        out += _fraction(rows, im, "fraction", f"fraction collapsed {per}", FRACTION_COLOUR)
        if fit is not None:
            out.append(Series("fit", fit_label(fit, unit), FIT_COLOUR, "line", grid, fit.probability(grid)))
        return out
    for i, g in enumerate(groups):
        colour = GROUP_COLOURS[i % len(GROUP_COLOURS)]
        out += _fraction(g.rows, im, f"fraction/{i}", f"{g.label}: fraction collapsed {per}", colour)
        if g.fit is not None:
            label = f"{g.label}: {fit_label(g.fit, unit)}"
            out.append(Series(f"fit/{i}", label, colour, "line", grid, g.fit.probability(grid)))
    return out


def _fraction(rows: list[dict], im: str, key: str, label: str, colour: str) -> list[Series]:
    """The fraction of ``rows`` collapsed at each scale (or PGA the records were scaled to, ``pga_g``), at its
    mean IM (none without either)."""
    by = next((k for k in ("scale", "pga_g") if rows and k in rows[0]), None)
    if by is None:
        return []
    x = np.array([_number(r.get(im)) for r in rows], dtype=np.float64)
    collapsed = np.array([r.get("state") == "collapsed" for r in rows], dtype=bool)
    scales = sorted({r[by] for r in rows})
    pick = [np.array([r[by] == s for r in rows]) for s in scales]
    mean_x = np.array([np.nanmean(x[p]) if np.isfinite(x[p]).any() else np.nan for p in pick])
    fraction = np.array([collapsed[p].mean() for p in pick])
    ok = np.isfinite(mean_x)
    return [Series(key, label, colour, "diamond", mean_x[ok], fraction[ok])]


def collapsed_per_level(rows: list[dict]) -> tuple[str, list[tuple[float, int, int]]] | None:
    """``(by, [(level, collapsed, runs), …])``: how many of ``rows`` collapsed at each scale, or PGA the records
    were scaled to (``by``: ``scale`` or ``pga_g``), levels increasing; None without either. The fraction
    collapsed per level of the fragility plot, as counts for the summary."""
    by = next((k for k in ("scale", "pga_g") if rows and k in rows[0]), None)
    if by is None:
        return None
    at = {level: [r for r in rows if r[by] == level] for level in sorted({r[by] for r in rows})}
    return by, [(level, sum(r.get("state") == "collapsed" for r in runs), len(runs)) for level, runs in at.items()]


def threshold_series(
    rows: list[dict], find: str, at: np.ndarray, searched: tuple[float, float], joined: bool = True, by=()
) -> list[Series]:
    """``<find>_threshold`` at ``at`` (each row's position on the x axis) as a line with its points (points
    alone unless ``joined``: along record names, whose order is alphabetical, a line between two records
    reads as a trend between them that does not exist), and
    the points where the search found none, marked at the searched range's top (``searched`` = the
    lowest and highest value tried first) when the outcome was not reached up to it, at its bottom when
    it was reached already there; a failed search (status error) is left out. The line's label says when
    the outcome holds below the threshold (``holds``). ``by``: the other swept parameters than the x axis's
    (``friction`` beside ``record``): one line a value of them, in its colour, its label first (two
    frictions' thresholds were one red line, their points two at each record, which was which unsaid)."""
    at = np.asarray(at, dtype=np.float64)
    y = np.array([_number(r.get(f"{find}_threshold")) for r in rows], dtype=np.float64)
    hi = np.array([_number(r.get(f"{find}_hi")) for r in rows], dtype=np.float64)
    searched_ok = np.array([r.get("status") != "error" for r in rows], dtype=bool)
    found = np.isfinite(y) & np.isfinite(at)
    none = ~np.isfinite(y) & np.isfinite(at) & searched_ok
    above, below = none & ~np.isfinite(hi), none & np.isfinite(hi)  # hi: the lowest value that reached it
    label = f"{with_unit(find).replace(find, find + '_threshold', 1)}"
    outcome = next((r.get("outcome") for r in rows if r.get("outcome")), "outcome")
    sides = {r.get("holds") for r, f in zip(rows, found) if f}
    if sides == {"below"}:  # --find friction --outcome sliding: the curve bounds the outcome from above
        label += f": {outcome} below it"
    elif "below" in sides:
        label += f": {outcome} above it, below where holds = below"
    lo_v, hi_v = searched
    groups = point_groups(rows, list(by))
    curves = []
    for g, (name, members) in enumerate(groups):
        mine = np.zeros(len(rows), dtype=bool)
        mine[members] = True
        pick = found & mine
        order = np.argsort(at[pick], kind="stable")
        x_found, y_found = at[pick][order], y[pick][order]
        key, colour = ("", THRESHOLD_COLOUR) if len(groups) == 1 else (f"/{g}", GROUP_COLOURS[g % len(GROUP_COLOURS)])
        shown = f"{name}: {label}" if len(groups) > 1 else label
        if joined:
            curves.append(Series("line" + key, shown, colour, "line", x_found, y_found))
        curves.append(
            Series("points" + key, shown + (": points" if joined else ""), colour, "circle", x_found, y_found)
        )
    return [
        *curves,
        Series(
            "not_found/above",
            f"none found: no {outcome} up to {find} = {hi_v:g}",
            NOT_FOUND_COLOUR,
            "up",
            at[above],
            np.full(int(above.sum()), float(hi_v)),
        ),
        Series(
            "not_found/below",
            f"none found: {outcome} already at {find} = {lo_v:g}",
            NOT_FOUND_COLOUR,
            "down",
            at[below],
            np.full(int(below.sum()), float(lo_v)),
        ),
    ]
