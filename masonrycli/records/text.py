"""The numbers of a record file's text: a careful per-line reading, and a vectorised one that gives the same.

The per-line reading (:func:`csv_lines`, :func:`at2_lines`) is the definition: it says what a line holds
and words every error (``<file>:<line>: <problem>``). It costs ~3 µs a line in Python, ~9 s for a
3-million-sample record (4 h at 200 Hz). So the text is cut into chunks of whole lines (~1 MB) and
each chunk is first read with numpy, which must give bit for bit what the per-line reading gives:

    for each chunk of whole lines:
        rows = the chunk read by numpy, when the chunk is of a layout where that is provably the
               per-line reading (see _fast_csv_rows), else nothing
        if rows and every sample is finite and the times keep increasing:
            keep rows                          # the common case: no Python per line
        else:
            read the chunk line by line        # raises the error at its own line, or reads a
                                               # layout numpy does not (blank lines, "1_000", ...)

The per-line reading of one chunk takes ~0.1 s, so an error on line 2 000 001 is named as fast as one
on line 2. Numbers are parsed the same way on both paths: numpy's text reader converts a field with
``PyOS_string_to_double``, as ``float()`` does (it refuses the underscores ``float()`` takes: such a
chunk goes line by line). :func:`csv_reference` reads a whole text line by line, for the tests.
"""

from __future__ import annotations

import io
import math
import re

import numpy as np

from masonrycli.errors import InputError
from masonrycli.records.units import MAX_AT2_G, check_at2_sample
from masonrycli.scenario.values import format_value, shorten

_SPLIT = re.compile(r"\s*[,;]\s*|\s+")
CHUNK_CHARS = 1 << 20
"""Characters of a chunk (~45 000 lines of a two-column record): large enough that numpy's per-call cost
is nothing, small enough that reading one chunk line by line (an error's message) takes ~0.1 s."""
# line breaks of str.splitlines other than "\n" in ASCII text: a chunk holding one is read line by line
# (numpy would see one line where splitlines sees two, and every later line number would be off)
_OTHER_BREAKS = "\r\v\f\x1c\x1d\x1e"


class CsvState:
    """What the lines read so far say about the next: the column count (0 before the first sample),
    whether the one header line was seen, the last sample's time (None before the first, and in a
    one-column file), whether the file is read as one value per line (a time step was given)."""

    def __init__(self, one_column: bool = False):
        self.ncol = 0
        self.header_seen = False
        self.last_time: float | None = None
        self.one_column = one_column


ANY_TIME_STEP = "--record-dt SECONDS (a scenario's record table: time_step = SECONDS)"
"""How a one-column file read without a time step is told to give one, by a caller that does not know which
way its command has (a file of one value per line has no times)."""


class NoTimeStep(InputError):
    """A file of one value per line read without a time step, at ``where`` (``file:line``). The message
    names ``how`` to give one; a command that has one way says it with :meth:`give` (``masonry run s.toml``
    was told ``--record-dt``, which goes with ``--record``, of the scenario's own record file)."""

    def __init__(self, where: str, how: str = ANY_TIME_STEP):
        self.where, self.how = where, how
        super().__init__(f"{where}: one value per line, no times: give the time between samples: {how}")

    def give(self, how: str) -> NoTimeStep:
        """The same refusal, naming ``how`` (``--record-dt SECONDS``) as the way to give the time step."""
        return NoTimeStep(self.where, how)

    def __reduce__(self):  # pickled with the arguments of __init__, not the message it makes of them
        return NoTimeStep, (self.where, self.how)


class TimeStepNotUsed(InputError):
    """A time step given for a file that has its own times (a time column, an .AT2 file's DT), at ``where``
    (``file:line`` or ``file``). ``problem`` says why, with ``{key}`` where the time step is named: the
    command line's ``--record-dt``, a scenario's ``time_step`` (the default, the Python keyword); a caller
    words it as its user gave it with :meth:`named` (both names in one line told neither which to leave out)."""

    def __init__(self, where: str, problem: str, key: str = "time_step"):
        self.where, self.problem, self.key = where, problem, key
        super().__init__(f"{where}: {problem.format(key=key)}")

    def named(self, key: str) -> TimeStepNotUsed:
        """The same refusal, naming the time step ``key`` (``--record-dt``)."""
        return TimeStepNotUsed(self.where, self.problem, key)

    def __reduce__(self):  # pickled with the arguments of __init__, not the message it makes of them
        return TimeStepNotUsed, (self.where, self.problem, self.key)


def csv_lines(lines, first: int, name: str, state: CsvState) -> tuple[list, list]:
    """``(times, values)`` of CSV ``lines``, the first being line ``first`` of the file (the reference
    reading; see :func:`masonrycli.records.read.load_record_csv` for the format). Raises :class:`InputError`."""
    times: list[float] = []
    values: list = []
    for lineno, line in enumerate(lines, start=first):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        fields = _fields(stripped)
        try:
            nums = [float(f) for f in fields]
        except ValueError:
            if state.ncol == 0 and not state.header_seen:
                state.header_seen = True
                continue
            bad = next(f for f in fields if not is_float(f))
            raise InputError(f"{name}:{lineno}: not a number: {shorten(bad, 40)}") from None
        if state.ncol == 0:
            _first_columns(len(nums), f"{name}:{lineno}", state.one_column)
            state.ncol = len(nums)
        elif len(nums) != state.ncol:
            columns = "1 column" if state.ncol == 1 else f"{state.ncol} columns"
            raise InputError(f"{name}:{lineno}: expected {columns} like the first sample, got {len(nums)}")
        if not all(math.isfinite(x) for x in nums):
            raise InputError(f"{name}:{lineno}: values must be finite, got {shorten(stripped, 40)}")
        if state.ncol == 1:
            values.append(nums[0])  # no time: the caller spaces the samples by the time step
            continue
        if state.last_time is not None and not nums[0] > state.last_time:
            raise InputError(
                f"{name}:{lineno}: time {format_value(nums[0])} is not after the previous sample's "
                f"{format_value(state.last_time)} (times must be strictly increasing)"
            )
        times.append(nums[0])
        values.append(nums[1] if state.ncol == 2 else (nums[1], nums[2]))
        state.last_time = nums[0]
    return times, values


def _first_columns(count: int, where: str, one_column: bool) -> None:
    """Raise :class:`InputError` unless the first sample's ``count`` columns are a layout the file may have:
    1 with a time step given, else 2 (time, value) or 3 (time, x, y)."""
    if one_column and count != 1:
        raise TimeStepNotUsed(
            where,
            f"{count} columns, but a time step was given: it is for a file of one value per line "
            "(this one has a time column: leave out {key})",
        )
    if not one_column and count == 1:
        raise NoTimeStep(where)
    if not one_column and count not in (2, 3):
        raise InputError(f"{where}: expected 2 columns (time, value) or 3 (time, x, y), got {count}")


def _fields(line: str) -> list[str]:
    """The fields of a CSV line. A line with ``;`` is split on ``;`` alone and its decimal commas read as
    points (``0;0,5``, a European spreadsheet's CSV): split on commas too, it was taken for a
    (time, x, y) record, 0,5 becoming x = 0, y = 5 m/s, and the run said completed. A line with a tab
    and a comma is split on tabs alone likewise (``0<TAB>0,5``, the spreadsheet's tab-delimited text)."""
    separator = ";" if ";" in line else "\t" if "\t" in line and "," in line else None
    if separator == "\t" and any(f.strip().startswith(",") or f.strip().endswith(",") for f in line.split("\t")):
        separator = None  # a comma beside a tab separates: "0.01,<TAB>0.5", a CSV aligned with tabs
    if separator is None:
        return [f for f in _SPLIT.split(line) if f != ""]
    fields = [f.strip() for f in line.split(separator) if f.strip() != ""]
    return [f.replace(",", ".") if f.count(",") == 1 and "." not in f else f for f in fields]


def csv_text(text: str, name: str, time_step: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(time (n,), value (n,) or (n, 2))`` of a CSV record's text, chunk by chunk (module docstring).
    With ``time_step`` (s) the file holds one value per line, at t = 0, time_step, 2 time_step, ..."""
    state = CsvState(one_column=time_step is not None)
    times: list[np.ndarray] = []
    values: list[np.ndarray] = []

    def keep(t, v):
        if len(v):
            times.append(np.asarray(t, dtype=np.float64))
            values.append(np.asarray(v, dtype=np.float64))

    # the lines before the first sample (blank, "#", the header) one at a time: the first sample sets
    # the column count the chunks are read with
    pos, lineno = 0, 1
    while state.ncol == 0 and pos < len(text):
        end = _line_end(text, pos)
        lines = (text[pos:end] + "\n").splitlines()  # one line, or more split at another break
        keep(*csv_lines(lines, lineno, name, state))
        pos, lineno = end + 1, lineno + len(lines)
    for chunk in _chunks(text, pos):
        rows = _fast_csv_rows(chunk, state.ncol)
        if rows is not None and _rows_hold(rows, None if state.ncol == 1 else state.last_time):
            if len(rows) and state.ncol == 1:
                keep((), rows[:, 0])
            elif len(rows):
                keep(rows[:, 0], rows[:, 1] if state.ncol == 2 else rows[:, 1:])
                state.last_time = float(rows[-1, 0])
            lineno += chunk.count("\n") + 1
        else:
            lines = (chunk + "\n").splitlines()
            keep(*csv_lines(lines, lineno, name, state))
            lineno += len(lines)
    return _samples(times, values, name, time_step)


def csv_reference(text: str, name: str, time_step: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`csv_text` read line by line only: the reference the chunked reading is tested against."""
    times, values = csv_lines(text.splitlines(), 1, name, CsvState(one_column=time_step is not None))
    return _samples([times], [values] if values else [], name, time_step)


def _samples(times: list, values: list, name: str, time_step: float | None) -> tuple[np.ndarray, np.ndarray]:
    """The record's ``(time, value)`` from its parts, at least 2 samples; a one-column file's times spaced
    by ``time_step`` (as an .AT2 file's are by its DT)."""
    count = sum(len(v) for v in values)
    if count < 2:
        raise InputError(f"{name}: a record needs at least 2 samples, found {count}")
    value = np.concatenate([np.asarray(v, dtype=np.float64) for v in values])
    if time_step is not None:
        return np.arange(count) * time_step, value
    return np.concatenate([np.asarray(t, dtype=np.float64) for t in times]), value


def _fast_csv_rows(chunk: str, ncol: int) -> np.ndarray | None:
    """The ``(lines, ncol)`` samples of a chunk of CSV lines read by numpy, or None where that might differ
    from :func:`csv_lines`: a chunk that is not ASCII, holds another line break, a ``#``, a blank line, a
    line of other columns, or mixes separators in a way that needs :func:`_fields`'s per-line rules.

    Three layouts, each a case of ``_fields`` (numpy's reader refuses an empty field, ``;;`` or a
    trailing comma, which ``_fields`` skips: such a chunk goes line by line):

    * ``;`` (decimal commas), no blank or tab: every line with ``;`` is split on ``;`` and its one-comma
      fields read with a point; with no ``.`` in the chunk that is replacing every comma (a field of two
      commas is no number either way). A line without ``;`` is then one field: refused by the column count.
    * tab and comma, no ``;``, blank or ``.``, no comma beside a tab or a line's end: split on tabs,
      commas read as points; a line without a tab is one field again.
    * otherwise (no ``;``, not both tab and comma): split on commas, or on white space if there is none.
    """
    body = chunk.rstrip()  # trailing blank lines and spaces: skipped by csv_lines too
    if not body:
        return np.empty((0, ncol))
    if not body.isascii() or "#" in body or any(c in body for c in _OTHER_BREAKS):
        return None
    if ";" in body:
        if " " in body or "\t" in body or ("," in body and "." in body):
            return None
        body, delimiter = body.replace(",", "."), ";"
    elif "\t" in body and "," in body:
        beside = (",\t", "\t,", ",\n", "\n,")
        if " " in body or "." in body or any(s in body for s in beside) or body[0] == "," or body[-1] == ",":
            return None
        body, delimiter = body.replace(",", "."), "\t"
    else:
        delimiter = "," if "," in body else None
    try:
        rows = np.loadtxt(io.StringIO(body), dtype=np.float64, delimiter=delimiter, comments=None, ndmin=2)
    except ValueError:
        return None
    # numpy skips blank lines, which would shift every later line number: then line by line
    return rows if rows.shape == (body.count("\n") + 1, ncol) else None


def _rows_hold(rows: np.ndarray, last_time: float | None) -> bool:
    """True when ``rows`` pass :func:`csv_lines`'s checks: finite, times increasing from ``last_time``
    (one-column rows: finite only)."""
    if not len(rows):
        return True
    if rows.shape[1] == 1:
        return bool(np.isfinite(rows).all())
    t = rows[:, 0]
    return bool(np.isfinite(rows).all() and (last_time is None or t[0] > last_time) and (t[1:] > t[:-1]).all())


# --------------------------------------------------------------------------------------------------- .AT2


def at2_lines(lines, first: int, name: str, npts: int, count: int) -> list[float]:
    """The samples of .AT2 data ``lines`` (the first is line ``first`` of the file), ``count`` samples
    having been read before: finite numbers, and within ``MAX_AT2_G`` up to the NPTS-th (the reference)."""
    values: list[float] = []
    for lineno, line in enumerate(lines, start=first):
        for field in line.split():
            x = number(field, f"{name}:{lineno}")
            if not math.isfinite(x):
                raise InputError(f"{name}:{lineno}: values must be finite, got {shorten(field, 40)}")
            if count + len(values) < npts:
                check_at2_sample(x, f"{name}:{lineno}")
            values.append(x)
    return values


def at2_text(text: str, pos: int, name: str, npts: int) -> np.ndarray:
    """The samples of an .AT2 file whose data start at ``text[pos]``, line 5, chunk by chunk: a chunk's
    white-space separated fields are the fields of its lines in order (every line break is white
    space to ``str.split``), each read with ``float()`` as :func:`at2_lines` reads them."""
    parts: list[np.ndarray] = []
    count, lineno = 0, 5
    for chunk in _chunks(text, pos):
        x = _fast_at2_samples(chunk, npts - count)
        if x is not None and not any(c in chunk for c in _OTHER_BREAKS):
            lines = chunk.count("\n") + 1
        else:
            split = (chunk + "\n").splitlines()
            if x is None:  # line by line: the error, named at its line
                x = np.asarray(at2_lines(split, lineno, name, npts, count), dtype=np.float64)
            lines = len(split)
        parts.append(x)
        count, lineno = count + x.size, lineno + lines
    return np.concatenate(parts) if parts else np.empty(0)


def _fast_at2_samples(chunk: str, checked: int) -> np.ndarray | None:
    """The samples of a chunk, or None if one is no number, not finite, or beyond ``MAX_AT2_G`` among
    the first ``checked`` (those up to NPTS)."""
    try:
        x = np.array(list(map(float, chunk.split())), dtype=np.float64)
    except ValueError:
        return None
    if not np.isfinite(x).all() or (np.abs(x[: max(checked, 0)]) > MAX_AT2_G).any():
        return None
    return x


def at2_reference(lines: list[str], name: str, npts: int) -> np.ndarray:
    """:func:`at2_text` read line by line only (``lines`` from the 5th on), for the tests."""
    return np.asarray(at2_lines(lines, 5, name, npts, 0), dtype=np.float64)


# ----------------------------------------------------------------------------------------------- shared


def _line_end(text: str, pos: int) -> int:
    end = text.find("\n", pos)
    return len(text) if end < 0 else end


def _chunks(text: str, pos: int):
    """``text[pos:]`` in pieces of whole lines cut at "\\n" (the cut "\\n" belongs to neither piece):
    the lines of ``(piece + "\\n").splitlines()``, piece after piece, are those of ``text[pos:]``."""
    while pos < len(text):
        end = _line_end(text, min(pos + CHUNK_CHARS, len(text)))
        yield text[pos:end]
        pos = end + 1


def number(text: str, where: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise InputError(f"{where}: not a number: {shorten(text, 40)}") from None


def is_float(text: str) -> bool:
    """Whether ``float`` reads ``text`` (a record's field, a lab file's header cell)."""
    try:
        float(text)
    except ValueError:
        return False
    return True


def free_numbers(lines: list[str], first: int, name: str) -> np.ndarray:
    """The numbers of ``lines`` (the first being line ``first`` of the file), white-space separated, any count
    a line (the sample blocks of ESM and K-NET files); a field that is no finite number is refused at its
    line. Read by numpy at once; only a text it refuses is walked line by line, to name the line."""
    try:
        values = np.array(list(map(float, " ".join(lines).split())), dtype=np.float64)
    except ValueError:
        values = None
    if values is None or not np.isfinite(values).all():
        for lineno, line in enumerate(lines, start=first):
            for field in line.split():
                try:
                    x = float(field)
                except ValueError:
                    raise InputError(f"{name}:{lineno}: not a number: {shorten(field, 40)}") from None
                if not math.isfinite(x):
                    raise InputError(f"{name}:{lineno}: values must be finite, got {shorten(field, 40)}")
    return values
