"""The study's rows as the terminal shows them: one line per row at any width, units in a legend.

Headers are short (``collapse``, ``drift``, ``open``) and every value is in the unit the legend names,
with a fixed number of decimals, so a row stays on one line. When the columns do not fit the console,
the least needed ones go first (``sweeps``, ``peak``, ``wall``, ``hinges``, ``open``, the intensity
measure, ``drift``, ``collapse``; the parameters and the state always stay) and the legend says which
are not shown; a cell still too wide ends in "…". A parameter of one value over the study has no column: the legend
says it once. Failed rows are listed under the table with their
error. Every column is in the table file whatever the terminal shows.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from rich.console import Console, Group
from rich.measure import Measurement
from rich.table import Table
from rich.text import Text

from masonrycli.records.intensity import UNITS as IM_UNITS
from masonrycli.study.curves import UNITS as PARAM_UNITS

SHOWN_ROWS = 40
"""Rows shown in the terminal (the rest are in the table file)."""
SHOWN_ERRORS = 5


@dataclass(frozen=True)
class Column:
    """One terminal column: its ``header``, the row's value as text, the legend's words for it, and its
    ``drop`` rank (0: always shown; the highest goes first when the console is too narrow)."""

    header: str
    cell: Callable[[dict], str]
    legend: str = ""
    drop: int = 0


def _number(value, fmt: str, scale: float = 1.0) -> str:
    """``value × scale`` as ``fmt``; "" for a missing or NaN value; "0.00", never "-0.00"."""
    if not isinstance(value, (int, float)) or math.isnan(value):
        return ""
    text = format(value * scale, fmt)
    return text[1:] if text.startswith("-") and float(text) == 0 else text


def _count(value) -> str:
    return str(int(value)) if isinstance(value, (int, float)) and not math.isnan(value) else ""


def _param(value) -> str:
    if isinstance(value, float):
        return "" if math.isnan(value) else f"{value:.4g}"
    return "" if value is None else str(value)


NAME_WIDTH = 28
"""Characters of a text parameter (a record's file name) shown in a cell: a PEER name of 60 took the whole
80 columns, the state read "inta…" and every other column was dropped."""


def _short(text: str) -> str:
    """``text`` cut in the middle to ``NAME_WIDTH`` (both ends tell records apart: the event, the component)."""
    if len(text) <= NAME_WIDTH:
        return text
    head = (NAME_WIDTH - 1) // 2
    return text[:head] + "…" + text[-(NAME_WIDTH - 1 - head) :]


def _params(names: list[str]) -> list[Column]:
    columns = []
    for n in names:
        unit = PARAM_UNITS.get(n.rpartition(".")[2])
        cell = lambda r, n=n: _short(_param(r.get(n))) if isinstance(r.get(n), str) else _param(r.get(n))  # noqa: E731
        columns.append(Column(n, cell, f"{n} {unit}" if unit else ""))
    return columns


def grid_columns(names: list[str], im: str) -> list[Column]:
    """The terminal columns of a grid or record study, with ``im`` the intensity measure shown."""
    return _params(names) + [
        Column("state", lambda r: str(r.get("state") or "failed")),
        Column("collapse", lambda r: _number(r.get("collapse_time"), ".2f"), "collapse: time of collapse, s", 1),
        Column("drift", lambda r: _number(r.get("residual_drift"), ".2f", 100.0), "drift: residual, % of height", 2),
        Column(im, lambda r: _number(r.get(im), ".3g"), f"{im} {IM_UNITS[im]}", 3),
        Column("open", lambda r: _number(r.get("max_opening"), ".1f", 1000.0), "open: largest opening, mm", 4),
        Column("hinges", lambda r: _count(r.get("hinges")), "", 5),
        # "took", not "wall": in a study of the wall a column "wall" read as something of the structure
        Column("took", lambda r: _number(r.get("wall_time"), ".1f"), "took: run time, s", 6),
        Column("peak", lambda r: _number(r.get("peak_drift"), ".2f", 100.0), "peak: drift, % of height", 7),
        Column("sweeps", lambda r: _number(r.get("sweeps_mean"), ".0f"), "sweeps: NLGS per step, mean", 8),
    ]


def find_columns(names: list[str], find: str) -> list[Column]:
    """The terminal columns of a threshold search (``--find``)."""
    unit = PARAM_UNITS.get(find.rpartition(".")[2], "")
    return _params(names) + [
        # a unitless parameter (friction) has no legend entry: it read "friction_threshold  · runs: ..."
        Column(
            f"{find}_threshold",
            lambda r: _number(r.get(f"{find}_threshold"), ".4g"),
            unit and f"{find}_threshold {unit}",
        ),
        # which side of the threshold the outcome is on: "below" for --find friction --outcome sliding
        Column("holds", lambda r: str(r.get("holds") or ""), "holds: the outcome above / below the threshold"),
        Column("runs", lambda r: _count(r.get("evaluations")), "runs: evaluations", 1),
        Column("note", lambda r: str(r.get("note") or "")),
    ]


def study_table(
    rows: list[dict], columns: list[Column], names: list[str], console: Console, where, fixed: dict | None = None
) -> Group:
    """The table (as many ``columns`` as ``console.width`` holds), its legend, and the failed rows (their
    point: the parameters ``names``); ``where``: the table file; ``fixed``: the parameters of one value over
    the study (no column of their own: the legend says them once, ``every row: courses = 6, length = 0.6``)."""
    shown = list(columns)
    table = _table(rows, shown)
    while _natural_width(console, table) > console.width and max(c.drop for c in shown) > 0:
        last = max(c.drop for c in shown)
        shown = [c for c in shown if c.drop != last]
        table = _table(rows, shown)
    legend = [c.legend for c in shown if c.legend]
    if fixed:
        legend.insert(0, "every row: " + ", ".join(f"{k} = {_param(v)}" for k, v in fixed.items()))
    headers = {c.header for c in columns}
    hidden = [c.header for c in columns if c not in shown]
    if hidden:
        legend.append(f"not shown at this width: {', '.join(hidden)}")
    # the file holds SI values: drift 0.0004 there is the terminal's 0.04 %, an opening 0.0007 m its 0.7 mm
    # (a threshold search's table has neither: "in SI units (drifts × height, openings m)" under amp_threshold)
    scaled = [what for header, what in (("drift", "drifts × height"), ("open", "openings m")) if header in headers]
    legend.append(f"every column in {where}, in SI units" + (f" ({', '.join(scaled)})" if scaled else ""))
    parts = [table, Text(" · ".join(legend))]
    failed = [r for r in rows if r.get("status") == "error"]
    for r in failed[:SHOWN_ERRORS]:
        point = " ".join(f"{n}={_param(r.get(n))}" for n in names)
        parts.append(Text(f"failed: {point}: {r.get('error') or ''}"))
    if len(failed) > SHOWN_ERRORS:
        parts.append(Text(f"… {len(failed) - SHOWN_ERRORS} more failed rows (their error column in {where})"))
    return Group(*parts)


def _natural_width(console: Console, table: Table) -> int:
    # measured without the console's limit (rich clamps a measure to the width it is given); the minimum,
    # so a note is counted at its longest word (it wraps), every other cell whole (one word, no wrap)
    return Measurement.get(console, console.options.update_width(1 << 16), table).minimum


def _table(rows: list[dict], columns: list[Column]) -> Table:
    count = f"{len(rows)} row" + ("" if len(rows) == 1 else "s")  # a --find of one point said "study (1 rows)"
    table = Table(title=f"study ({count})", title_justify="left")
    for c in columns:
        words = c.header == "note"  # wrapped rather than cut
        table.add_column(c.header, no_wrap=not words, overflow="fold" if words else "ellipsis")
    for r in rows[:SHOWN_ROWS]:
        table.add_row(*(c.cell(r) for c in columns))
    if len(rows) > SHOWN_ROWS:
        table.add_row(*(["…"] * len(columns)))
    return table
