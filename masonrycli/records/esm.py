"""ESM ASCII records: the Engineering Strong-Motion database's (esm-db.eu) and ITACA's ``.ASC`` files.

A European heritage engineer downloads her records there, not from PEER: an ESM zip holds one file per
component and series, ``IT.NRC..HNE.D.20161030.064017.C.ACC.ASC`` (acceleration), ``….VEL.ASC``,
``….DIS.ASC``, and spectra (``….SA.ASC``). Read as a CSV such a file said ``q.ASC:2: not a number:
"EVENT_ID:"``, and a ``--records`` folder of them was skipped without a word.

Layout (the "DYNA 1.2" header of ESM and ITACA): header lines ``KEY: value`` (64 in ESM, fewer in older
files), then ``NDATA`` samples, one a line, ``SAMPLING_INTERVAL_S`` apart from t = 0, in ``UNITS``. Read:

    header  = the "KEY: value" lines up to the first line that is a number (other text lines are skipped)
    dt      = SAMPLING_INTERVAL_S (s, a record's time step: 1e-6 to 1 s, at most 0.1 s for acceleration); n = NDATA (an integer >= 2)
    series  = DATA_TYPE when given: ACCELERATION or VELOCITY (DISPLACEMENT, spectra: refused, naming why)
    factor  = UNITS to SI: cm/s^2 (ESM's), gal, m/s^2, mm/s^2, g -> acceleration; cm/s, m/s, mm/s -> velocity,
              by the unit table a CSV header is read by (records/units.py, unit_factor);
              a unit of the other series than DATA_TYPE's, a length or an unknown unit: refused
    samples = the numbers after the header, each finite, n of them (fewer: refused; more: a warning, the
              first n kept, as an .AT2 file's NPTS), times 0, dt, 2 dt, ...; values x factor

Every refusal is one line naming the file and the line (``q.ASC:29: SAMPLING_INTERVAL_S: …``).
"""

from __future__ import annotations

import os
import re
import warnings

import numpy as np

from masonrycli.errors import InputError, RecordWarning
from masonrycli.records.motion import time_step_problem
from masonrycli.records.text import free_numbers
from masonrycli.records.units import unit_factor
from masonrycli.scenario.values import shorten

ESM_SUFFIX = ".asc"

_KEY = re.compile(r"^\s*([A-Za-z][A-Za-z0-9_/^.()\-]*)\s*:(.*)$")
_LENGTHS = {"cm", "m", "mm"}
_SERIES = ("ACCELERATION", "VELOCITY")


def is_esm(path) -> bool:
    """Whether ``path`` is an ESM / ITACA record: named ``….ASC`` (any case), its first line that is not blank a
    ``KEY: value`` line (``EVENT_NAME: …``; a file that cannot be opened: by its name alone, the reader says why).

    ``.asc`` is also a common name for a plain table of samples (columns of numbers, perhaps a header line), read
    as a CSV before this reader: ``--record q.asc`` of time and acceleration became 'not an ESM record: its header
    has no SAMPLING_INTERVAL_S line', and a one-column one refused --record-dt. Such a file is read as a CSV is."""
    if not str(path).lower().endswith(ESM_SUFFIX):
        return False
    if not os.path.isfile(path):  # missing, a folder, a pipe: the reader says so
        return True
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            for _, line in zip(range(50), fh):
                if line.strip("\ufeff \t\r\n"):  # a byte-order mark (a file saved again by Notepad) is no text
                    return _KEY.match(line.lstrip("\ufeff")) is not None
    except OSError:
        return True
    return True  # blank: the ESM reader says what it lacks


def looks_like_esm(lines: list[str]) -> bool:
    """Whether the first lines of a file are an ESM header (a ``SAMPLING_INTERVAL_S:`` and an ``NDATA:``
    line): such a file under another suffix (``q.txt``) is named as one."""
    keys = {m.group(1).upper() for m in map(_KEY.match, lines) if m}
    return {"SAMPLING_INTERVAL_S", "NDATA"} <= keys


def esm_text(text: str, name: str) -> tuple[float, np.ndarray, str]:
    """``(dt s, samples in SI, "acceleration" | "velocity")`` of an ESM record's ``text`` (module docstring).
    Raises :class:`InputError` with a one-line message ``<file>:<line>: <problem>``."""
    header, first = _header(text)
    if "SAMPLING_INTERVAL_S" not in header or "NDATA" not in header:
        missing = "SAMPLING_INTERVAL_S" if "SAMPLING_INTERVAL_S" not in header else "NDATA"
        raise InputError(
            f"{name}: not an ESM record: its header has no {missing} line (an ESM / ITACA .ASC file has "
            "KEY: value lines, SAMPLING_INTERVAL_S and NDATA among them, then one sample a line)"
        )
    series, factor = _series(header, name)
    dt = _dt(header, name, series == "acceleration")
    npts = _ndata(header, name)
    values = _samples(text, first, name)
    if values.size < npts:
        raise InputError(f"{name}: header says NDATA = {npts} but the file holds {values.size} samples")
    if values.size > npts:
        warnings.warn(
            RecordWarning(
                f"{name}: header says NDATA = {npts} but the file holds {values.size} samples; the "
                f"{values.size - npts} after the first {npts} are ignored"
            ),
            stacklevel=2,
        )
    return dt, values[:npts] * factor, series


def esm_vertical(text_head: list[str]) -> bool:
    """Whether an ESM header (its first lines) is of a vertical component: ``COMPONENT: Z`` or a channel
    ending in Z (``HNZ``, ``HGZ``)."""
    for line in text_head:
        m = _KEY.match(line)
        if m and m.group(1).upper() == "COMPONENT" and m.group(2).strip().upper() in ("Z", "UP", "V", "VERTICAL"):
            return True
        if m and m.group(1).upper() == "CHANNEL" and m.group(2).strip().upper().endswith("Z"):
            return True
    return False


def esm_series(path) -> str:
    """The ``DATA_TYPE`` an ESM file's header gives (upper case; "" when it gives none or cannot be read):
    a ``--records`` folder of an ESM download holds each component's ACCELERATION, VELOCITY and
    DISPLACEMENT files and spectra, and reads the first alone."""
    return _header_value(path, "DATA_TYPE").upper()


def esm_units(path) -> tuple[str, float] | None:
    """The ``UNITS`` an ESM file's header gives, as written (``cm/s^2``, ``cm/s``), and the factor its samples
    were multiplied by on reading (0.01 for cm/s² or cm/s); None when it gives none masonry reads. A warning
    about a scale that converts the file a second time names the file's own unit (a velocity file is in cm/s,
    not in gal)."""
    units = _header_value(path, "UNITS")
    known = unit_factor(units)
    return (units, known[1]) if known else None


def _header_value(path, key: str) -> str:
    """The value of ``KEY:`` in an ESM file's first 100 lines ("" when it has none or cannot be read)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            head = [fh.readline() for _ in range(100)]
    except OSError:
        return ""
    for line in head:
        m = _KEY.match(line.lstrip("\ufeff"))
        if m and m.group(1).upper() == key:
            return m.group(2).strip()
    return ""


def _header(text: str) -> tuple[dict[str, tuple[str, int]], int]:
    """``({KEY: (value, line)}, index of the first sample line's start)``: the ``KEY: value`` lines up to the
    first line that holds a number (the first key of a name wins)."""
    header: dict[str, tuple[str, int]] = {}
    pos, lineno = 0, 1
    while pos < len(text):
        end = text.find("\n", pos)
        end = len(text) if end < 0 else end
        line = text[pos:end]
        if _is_number_line(line):
            return header, pos
        m = _KEY.match(line)
        if m:
            header.setdefault(m.group(1).upper(), (m.group(2).strip(), lineno))
        pos, lineno = end + 1, lineno + 1
    return header, len(text)


def _is_number_line(line: str) -> bool:
    fields = line.split()
    if not fields:
        return False
    try:
        [float(f) for f in fields]
    except ValueError:
        return False
    return True


def _series(header: dict, name: str) -> tuple[str, float]:
    """The series the samples are (``acceleration`` / ``velocity``) and their factor to SI, from DATA_TYPE and
    UNITS."""
    data_type, type_line = header.get("DATA_TYPE", ("", 0))
    kind = data_type.upper()
    if kind and kind not in _SERIES:
        if kind.startswith("DISPLACEMENT"):
            why = "a displacement series: give the same component's acceleration file (….ACC.ASC), which masonry integrates"
        else:
            why = "not an acceleration or velocity time series (a spectrum?): give the component's ….ACC.ASC file"
        raise InputError(f"{name}:{type_line}: DATA_TYPE: {shorten(data_type, 40)}: {why}")
    if "UNITS" not in header:
        raise InputError(f"{name}: the ESM header has no UNITS line: the samples' units are not known")
    units, line = header["UNITS"]
    unit = "".join(units.split()).lower()
    if unit in _LENGTHS:
        raise InputError(
            f"{name}:{line}: UNITS: {units}: a displacement series: give the same component's acceleration "
            "file (….ACC.ASC), which masonry integrates"
        )
    known = unit_factor(units)
    if known is None:
        raise InputError(
            f"{name}:{line}: UNITS: {shorten(units, 30)}: not a unit masonry reads (cm/s^2, gal, m/s^2, g; cm/s, m/s)"
        )
    series, factor = known
    if kind and kind.lower() != series:
        raise InputError(
            f"{name}:{line}: UNITS: {units} is {series}, but DATA_TYPE (line {type_line}) says {data_type}"
        )
    return series, factor


def _dt(header: dict, name: str, acceleration: bool) -> float:
    text, line = header["SAMPLING_INTERVAL_S"]
    try:
        dt = float(text)
    except ValueError:
        raise InputError(f"{name}:{line}: SAMPLING_INTERVAL_S: not a number: {shorten(text, 40)}") from None
    problem = time_step_problem(dt, acceleration)
    if problem:
        raise InputError(f"{name}:{line}: SAMPLING_INTERVAL_S = {shorten(text, 40)}: {problem}")
    return dt


def _ndata(header: dict, name: str) -> int:
    text, line = header["NDATA"]
    try:
        npts = int(text)
    except ValueError:
        raise InputError(f"{name}:{line}: NDATA: not a whole number: {shorten(text, 40)}") from None
    if npts < 2:
        raise InputError(f"{name}:{line}: NDATA = {npts}: a record needs at least 2 samples")
    return npts


def _samples(text: str, first: int, name: str) -> np.ndarray:
    """The numbers of ``text[first:]`` (white-space separated, several a line allowed); a field that is no finite number is refused at its line."""
    return free_numbers(text[first:].splitlines(), text.count("\n", 0, first) + 1, name)
