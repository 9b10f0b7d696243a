"""A lab's CSV (``masonry export H.npz --times lab.csv``): its header, its cells, and its sample times.

A shake-table test leaves a table of its own: one header row naming the columns (units in the name, ``time
(s)``, ``LVDT top (mm)``), then one row per sample, at the lab's own times. :func:`read_lab_file` reads it
as it is — every cell kept as text, so the export writes the lab's columns back unchanged beside masonry's —
and the time column as numbers in seconds:

* the time column is the one whose name is ``time`` or ``t`` (any case, ``Time [s]``, ``time_ms``, ``t (ms)``),
  or the one ``--time-column`` names; its unit s (also when it names none) or ms;
* separators: a comma; a semicolon when the header has one; a tab when the header has a tab and no comma
  (with a semicolon or a tab, decimal commas read as points: a European spreadsheet's CSV or text file). Blank lines and ``#`` lines are skipped,
  before the header and after it;
* every time a finite number, strictly increasing; at least one sample.

Anything else is one line, ``FILE:LINE: problem`` (:class:`InputError`).
"""

from __future__ import annotations

import csv
import io
import os
import re
from dataclasses import dataclass

import numpy as np

from masonrycli.errors import InputError
from masonrycli.records.text import is_float
from masonrycli.records.units import decoded, input_bytes
from masonrycli.scenario.values import shorten

_TIME_NAME = re.compile(
    r"^\s*(?:time|t)(?:\s*[\(\[]\s*(?P<unit>[^\)\]]*?)\s*[\)\]]|[_ ](?P<suffix>s|ms|sec))?\s*$", re.IGNORECASE
)
_TIME_UNITS = {"": 1.0, "s": 1.0, "sec": 1.0, "ms": 1e-3}


@dataclass(frozen=True)
class LabFile:
    """The lab's table: ``header`` (its column names), ``rows`` (its cells as text, one list per sample, as
    wide as the header), ``time_column`` (the index of the time column) and ``time`` (s, (n,))."""

    path: str
    header: list[str]
    rows: list[list[str]]
    time_column: int
    time: np.ndarray
    lines: list[int]
    """The file's line number of each row (for messages about one sample)."""


def _text(path, shown: str) -> str:
    """The file's text, or one line saying why it is no CSV (missing, a folder, a pipe, a workbook, UTF-16)."""
    if os.path.isdir(path):
        raise InputError(f"{shown}: is a folder, not a CSV")
    raw = input_bytes(path, shown, "cannot read")
    if raw.startswith(b"PK\x03\x04"):  # a zip: an .xlsx workbook, or an .npz history
        what = "an .npz archive (a history?)" if b".npy" in raw[:4096] else "a zip file (an Excel workbook?)"
        raise InputError(f"{shown}: {what}, not a CSV (save the sheet as CSV: a header row, then one row a sample)")
    return decoded(raw, shown)


def _split(line: str, separator: str) -> list[str]:
    cells = next(csv.reader([line], delimiter=separator))
    cells = [c.strip() for c in cells]
    if separator != ",":  # decimal commas (a semicolon or tab file has no comma between cells): "0,5" is 0.5
        cells = [
            c.replace(",", ".") if re.fullmatch(r"[-+]?\d*,\d*(e[-+]?\d+)?", c, re.IGNORECASE) else c for c in cells
        ]
    return cells


def _time_column(header: list[str], named: str | None, where: str) -> tuple[int, float]:
    """(index, factor to s) of the time column (module docstring)."""
    if named is not None:
        if named not in header:
            raise InputError(f"--time-column {named}: no such column in {where} (columns: {', '.join(header)})")
        index = header.index(named)
        match = _TIME_NAME.match(named)
    else:
        found = [i for i, name in enumerate(header) if _TIME_NAME.match(name)]
        if not found:
            columns = shorten(", ".join(header), 80)
            raise InputError(
                f"{where}: no time column (a header field named time or t, e.g. 'time (s)'; or name it with "
                f"--time-column): the header is {columns}"
            )
        if len(found) > 1:
            names = ", ".join(header[i] for i in found)
            raise InputError(f"{where}: {len(found)} time columns ({names}): name one with --time-column")
        index = found[0]
        match = _TIME_NAME.match(header[index])
    unit = ((match.group("unit") or match.group("suffix") or "") if match else "").lower()
    if unit not in _TIME_UNITS:
        raise InputError(f"{where}: time column '{header[index]}': its unit {unit} is not s or ms")
    return index, _TIME_UNITS[unit]


def read_lab_file(path, time_column: str | None = None) -> LabFile:
    """The lab's table at ``path`` (module docstring). Raises :class:`InputError` (one line, where)."""
    shown = os.fspath(path)
    text = _text(path, shown)
    lines = [(n, line.strip()) for n, line in enumerate(io.StringIO(text, newline=None), start=1)]
    lines = [(n, line) for n, line in lines if line and not line.startswith("#")]
    if not lines:
        raise InputError(f"{shown}: an empty file (a CSV: a header row, then one row a sample)")
    head_line, head = lines[0]
    separator = ";" if ";" in head else "\t" if "\t" in head and "," not in head else ","
    header = _split(head, separator)
    if all(is_float(cell) for cell in header):
        raise InputError(f"{shown}:{head_line}: no header row (the first row names the columns: time (s), …)")
    index, factor = _time_column(header, time_column, f"{shown}:{head_line}")
    rows, numbers, where, previous = [], [], [], ""
    for n, line in lines[1:]:
        cells = _split(line, separator)
        if len(cells) > len(header):
            raise InputError(f"{shown}:{n}: {len(cells)} cells, the header names {len(header)} columns")
        cells += [""] * (len(header) - len(cells))
        cell = cells[index]
        try:
            t = float(cell) * factor
        except ValueError:
            problem = f"time {cell[:30]} is not a number" if cell else "an empty time cell"
            raise InputError(f"{shown}:{n}: {problem}") from None
        if not np.isfinite(t):
            raise InputError(f"{shown}:{n}: time {cell} is not a finite number")
        if numbers and not t > numbers[-1]:
            raise InputError(
                f"{shown}:{n}: time {cell} is not after the previous sample's {previous}"
                " (times must be strictly increasing)"
            )
        rows.append(cells)
        numbers.append(t)
        previous = cell
        where.append(n)
    if not rows:
        raise InputError(f"{shown}: a header and no sample")
    return LabFile(shown, header, rows, index, np.array(numbers), where)
