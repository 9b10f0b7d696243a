"""Reading ground-motion records from files into :class:`~masonrycli.records.motion.Record` motions.

Four formats, chosen by the file's extension:

* ``.AT2`` (PEER NGA): acceleration in g, one component per file, a 4-line header whose last line
  gives ``NPTS`` and ``DT`` (see :func:`load_at2`); samples at t = 0, DT, 2 DT, ...
* ``.ASC`` (ESM / ITACA): ``KEY: value`` header lines giving ``SAMPLING_INTERVAL_S``, ``NDATA`` and
  ``UNITS`` (acceleration in cm/s², or velocity), then one sample a line (:mod:`masonrycli.records.esm`);
* ``.NS`` / ``.EW`` / ``.UD`` (K-NET; ``.NS1`` … ``.UD2`` KiK-net): a 17-line header giving the sampling
  frequency and the counts' scale factor, then the counts (:mod:`masonrycli.records.knet`);
* ``.VT2`` / ``.DT2`` (PEER's velocity and displacement series) are refused, naming the .AT2;
* anything else is CSV: one sample per line, ``time,value`` or ``time,x,y``, or one ``value`` per line
  given a time step (samples at t = 0, dt, 2 dt, ...; see :func:`load_record_csv`).

:func:`record_motion` makes the motion (scale, window, optional vertical component, baseline
correction); :func:`record_fields` does the same for a scenario's ``motion = { kind = "record", ... }``.
"""

from __future__ import annotations

import math
import os
import re
import warnings

import numpy as np

from masonrycli.errors import (
    InputError,
    RecordWarning,
    file_kind,
    input_path,
    not_a_file,
)
from masonrycli.records.esm import esm_text, esm_vertical, is_esm, looks_like_esm
from masonrycli.records.knet import is_knet, knet_text, knet_vertical
from masonrycli.records.motion import MAX_ACCELEROGRAM_STEP, Record, time_step_problem
from masonrycli.records.text import NoTimeStep, TimeStepNotUsed, at2_text, csv_text, number
from masonrycli.records.units import G_STANDARD, check_at2_header, check_csv_header, header_quantity, input_text
from masonrycli.scenario.values import format_value, quote_string, shorten


def load_record_csv(path, display: str | None = None, time_step: float | None = None):
    """Read a tabulated motion record.

    Format: one sample per line, ``time,value`` (2 columns: a value along the motion's direction) or
    ``time,x,y`` (3 columns: a vector); with ``time_step`` (s), one ``value`` per line (1 column, no
    times: the samples are at t = 0, time_step, 2 time_step, ...; a file with times is refused).
    Separators: comma, semicolon or white space; on a line with semicolons, commas are decimal commas
    (``0,01;0,5``). Blank lines and lines starting with ``#`` are skipped; a single non-numeric header
    line before the first sample is allowed. Times in s, strictly increasing, at least 2 samples; all
    values finite.

    Returns ``(time (n,), value (n,) or (n, 2))`` float64 arrays.
    Raises :class:`InputError` with a one-line message ``<file>:<line>: <problem>``.
    ``display`` is the file name used in messages (default: ``path`` as given).
    """
    name = display if display is not None else str(path)
    text = _read_text(path, name)
    try:
        return csv_text(text, name, time_step)
    except InputError:
        lines, _ = _head(text, 4)  # a PEER record saved as .txt said 'q.txt:2: not a number: "SYNTH"'
        stem = os.path.splitext(os.path.basename(os.fspath(path)))[0]
        if len(lines) == 4 and (_AT2_NEW.search(lines[3]) or _AT2_OLD.search(lines[3])):
            raise InputError(
                f"{name}: a PEER .AT2 record (its line 4 gives NPTS and DT) read as a CSV: the file's suffix "
                f"chooses the format, name it {stem}.AT2"
            ) from None
        if looks_like_esm(_head(text, 80)[0]):
            raise InputError(
                f"{name}: an ESM record (its header gives SAMPLING_INTERVAL_S and NDATA) read as a CSV: the "
                f"file's suffix chooses the format, name it {stem}.ASC"
            ) from None
        raise


def _read_text(path, name: str) -> str:
    return input_text(path, name, "cannot read record")


# "NPTS=  3930, DT=   .0100 SEC" (NGA-West2) or "3930   0.0100   NPTS, DT" (older NGA files)
_AT2_NEW = re.compile(r"NPTS\s*=\s*(\d+)\s*,?\s*DT\s*=\s*([-+0-9.eE]+)", re.IGNORECASE)
_AT2_OLD = re.compile(r"^\s*(\d+)\s+([-+0-9.eE]+)\s+NPTS", re.IGNORECASE)


def load_at2(path, display: str | None = None) -> tuple[float, np.ndarray]:
    """Read a PEER NGA ``.AT2`` file: ``(dt s, acceleration (NPTS,) in g)``.

    Layout: 3 free text lines, a 4th line with the number of points and the time step, then the NPTS
    samples, several per line. Raises :class:`InputError` (``<file>:<line>: <problem>``).
    """
    name = display if display is not None else str(path)
    text = _read_text(path, name)
    lines, pos = _head(text, 4)
    if pos is None:
        raise InputError(f"{name}: not a PEER .AT2 file (expected 4 header lines, then the samples)")
    match = _AT2_NEW.search(lines[3]) or _AT2_OLD.search(lines[3])
    if not match:
        raise InputError(
            f"{name}:4: expected NPTS and DT (e.g. NPTS=  3930, DT=   .0100 SEC), got {shorten(lines[3].strip(), 40)}"
        )
    check_at2_header(lines[:3], name)
    npts, dt = int(match.group(1)), number(match.group(2), f"{name}:4")
    if not (math.isfinite(dt) and dt > 0.0) or npts < 2:
        raise InputError(f"{name}:4: DT must be > 0 and NPTS >= 2, got DT = {format_value(dt)}, NPTS = {npts}")
    problem = time_step_problem(dt, acceleration=True)  # DT = 10 was read as a record of 70 s, without a word
    if problem:
        raise InputError(f"{name}:4: DT = {dt:g}: {problem}")
    values = at2_text(text, pos, name, npts)
    if len(values) < npts:
        raise InputError(f"{name}: header says NPTS = {npts} but the file holds {len(values)} samples")
    if len(values) > npts:
        # the header is the record's definition (trailing values are padding or another file's tail), but
        # dropping them without a word hid a header that may be the mistake
        warnings.warn(
            RecordWarning(
                f"{name}: header says NPTS = {npts} but the file holds {len(values)} samples; the "
                f"{len(values) - npts} after the first {npts} are ignored"
            ),
            stacklevel=2,
        )
    return dt, values[:npts].copy()


def _head(text: str, n: int) -> tuple[list[str], int | None]:
    """The first ``n`` lines of ``text`` (as ``splitlines`` cuts them) and where the line after them
    starts, or None if there is no such line: read from a prefix, not from every line of the file."""
    size = 4096
    while True:
        parts = text[:size].splitlines(keepends=True)
        if len(parts) > n or size >= len(text):
            break  # with a line after them, the first n are whole (a "\r\n" is not cut)
        size *= 4
    if len(parts) <= n:
        return [p.splitlines()[0] for p in parts], None
    return [p.splitlines()[0] for p in parts[:n]], sum(len(p) for p in parts[:n])


"""m/s² per g: .AT2 accelerations are in units of standard gravity."""


def is_at2(path) -> bool:
    return os.fspath(path).lower().endswith(".at2")


def load_esm(path, display: str | None = None) -> tuple[float, np.ndarray, str]:
    """Read an ESM / ITACA ``.ASC`` file: ``(dt s, samples in m/s² or m/s, quantity)``
    (:func:`masonrycli.records.esm.esm_text`)."""
    name = display if display is not None else str(path)
    return esm_text(_read_text(path, name), name)


_PEER_OTHER = {".vt2": "velocity (.VT2, cm/s)", ".dt2": "displacement (.DT2, cm)"}
"""PEER's other series of a component. Read as CSV they failed on their header's second line (`not a
number: "Imperial Valley..."`), which said nothing of the format."""


def vertical_at2(path) -> bool:
    """An .AT2 file of a vertical component: PEER's file name ends in UP or DWN (RSN6_IMPVALL.I_I-ELCUP.AT2)
    or its header's second line ends with the component ("…, EL CENTRO ARRAY #6, UP"); an ESM .ASC file
    whose header says ``COMPONENT: Z`` (or a channel ``HNZ``)."""
    path = os.fspath(path)
    stem, suffix = os.path.splitext(os.path.basename(path))
    if is_knet(path):
        return knet_vertical(path)
    if is_esm(path):
        try:
            with open(path, encoding="utf-8", errors="replace") as fh:
                return esm_vertical([fh.readline() for _ in range(80)])
        except OSError:
            return False
    if suffix.lower() != ".at2":
        return False
    if stem.upper().endswith(("UP", "DWN")):
        return True
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            fh.readline()
            second = fh.readline()
    except OSError:
        return False
    return second.rsplit(",", 1)[-1].strip().upper() in ("UP", "DWN", "VERT", "VERTICAL") if "," in second else False


def check_not_peer_other(path, name: str) -> None:
    """Raise :class:`InputError` for a PEER .VT2 / .DT2 file: masonry reads the .AT2 of the component."""
    what = _PEER_OTHER.get(os.path.splitext(os.fspath(path))[1].lower())
    if what is not None:
        raise InputError(
            f"{name}: a PEER {what} record; give the same component's acceleration record (.AT2, in g), "
            "which masonry integrates, or a CSV of velocity"
        )


def _read_at2(path, display, name) -> tuple:
    dt, acc = load_at2(path, display)
    return np.arange(acc.size) * dt, acc * G_STANDARD, "acceleration"


def _read_esm(path, display, name) -> tuple:
    dt, samples, quantity = load_esm(path, display)
    return np.arange(samples.size) * dt, samples, quantity


def _read_knet(path, display, name) -> tuple:
    dt, acc = knet_text(_read_text(path, name), name)
    return np.arange(acc.size) * dt, acc, "acceleration"


_HEADED_FORMATS = (
    (is_at2, "an .AT2 file", "DT", _read_at2),
    (is_esm, "an ESM .ASC file", "SAMPLING_INTERVAL_S", _read_esm),
    (is_knet, "a K-NET file", "Sampling Freq", _read_knet),
)
"""The record formats whose header gives the time step: (is it one, its name, the header's field, its reader
giving ``(time, value, quantity)``)."""


def read_as_csv(path) -> bool:
    """Whether :func:`read_record` reads ``path`` as a CSV: none of the formats whose header gives the time
    step (a .csv, a .txt, a plain table named .asc)."""
    return not any(is_kind(path) for is_kind, *_ in _HEADED_FORMATS)


RECORD_FILE = "a ground-motion record (a PEER .AT2 file, an ESM .ASC file, a K-NET file or a CSV)"


def read_record(path, display: str | None = None, time_step: float | None = None) -> tuple:
    """``(time (n,) s, value (n,) or (n, 2), quantity)`` of a record file: an .AT2 file gives its
    acceleration in m/s² and quantity ``"acceleration"``, an ESM .ASC file its series in SI and its quantity;
    a CSV file gives its columns as they are and quantity None (the caller says what the values are).
    ``time_step``: the CSV holds one value per line at that spacing (s); an .AT2 or .ASC file has its own
    (its header's DT, SAMPLING_INTERVAL_S) and is refused with one."""
    name = display if display is not None else str(path)
    check_not_peer_other(path, name)
    other = file_kind(path, RECORD_FILE, (".csv", ".at2", ".asc"), name)
    if other is not None and os.path.isfile(path):  # a missing one: the reader says so
        raise other
    for is_kind, kind, field, read in _HEADED_FORMATS:
        if is_kind(path):
            if time_step is not None:
                raise TimeStepNotUsed(
                    display or str(path),
                    f"{kind} gives its own time step ({field} in its header): {{key}} goes with a CSV of one value "
                    "per line",
                )
            return read(path, display, name)
    time, value = load_record_csv(path, display, time_step)
    return time, value, None


def combine_vertical(time, value, vtime, vvalue, name: str, vname: str) -> tuple[np.ndarray, np.ndarray]:
    """(time, (x, y) pairs) from a horizontal and a vertical component sampled alike (the shorter
    sets the length). Raises :class:`InputError` when the two are sampled differently."""
    if value.ndim != 1 or vvalue.ndim != 1:
        raise InputError(f"{vname}: a vertical component goes with 1-component records (time, value)")
    n = min(time.size, vtime.size)
    if not np.allclose(time[:n], vtime[:n], rtol=1e-9, atol=1e-12):
        raise InputError(f"{vname}: not sampled like {name} (the two components need the same times)")
    return time[:n], np.stack([value[:n], vvalue[:n]], axis=1)


def record_motion(
    path,
    *,
    quantity: str | None = None,
    scale: float = 1.0,
    direction=(1.0, 0.0),
    vertical=None,
    window=None,
    baseline: str = "quadratic",
    display: str | None = None,
    time_step: float | None = None,
) -> Record:
    """A :class:`~masonrycli.records.motion.Record` from a record file (.AT2, .ASC or CSV, see :func:`read_record`).

    ``quantity`` defaults to "acceleration" for .AT2 files (the only one they hold) and, for CSV, to the
    quantity its header names (:func:`~masonrycli.records.units.header_quantity`), else "velocity". ``vertical`` is the file of the vertical component (the record then acts along x and y and
    ``direction`` is not used). ``source`` is the absolute path of the file. ``time_step`` (s): the
    files hold one value per line at that spacing (checked before they are read). A CSV whose header gives its
    unit (``acc (g)``, ``vel (cm/s)``) is converted by it to SI, as an .AT2 file's g, ``scale`` multiplying the
    record as recorded (:func:`~masonrycli.records.units.check_csv_header`; a scale equal to the conversion is
    refused).
    """
    time_step = _time_step(time_step, "time_step")
    time, value, native = read_record(path, display, time_step)
    if native is not None and quantity not in (None, native):
        kind = "an .AT2 file" if is_at2(path) else "a K-NET file" if is_knet(path) else "this ESM file"
        raise InputError(f"{display or path}: {kind} holds {native}, not {quantity}")
    quantity = quantity or native or header_quantity(path) or "velocity"  # a CSV: as its header says, else m/s
    _coarse_acceleration(display or str(path), time_step, quantity)
    if native is None:
        value = _in_si(value, check_csv_header(path, display or str(path), quantity, scale))
    vertical_source = ""
    if vertical is not None:
        vtime, vvalue, vnative = read_record(vertical, time_step=time_step)
        if vnative is None:
            vvalue = _in_si(vvalue, check_csv_header(vertical, str(vertical), quantity, scale))
        if vnative != native:
            raise InputError(f"{vertical}: the vertical component must be in the same format as {path}")
        time, value = combine_vertical(time, value, vtime, vvalue, str(path), str(vertical))
        vertical_source = os.path.abspath(os.fspath(vertical))
    return Record(
        direction=tuple(direction),
        time=time,
        value=value,
        quantity=quantity,
        scale=scale,
        window=window,
        baseline=baseline,
        source=os.path.abspath(os.fspath(path)),
        vertical_source=vertical_source,
        time_step=time_step,
    )


def _in_si(value: np.ndarray, factor: float) -> np.ndarray:
    """A CSV's samples in SI: times the factor its header's unit gives (the same array when it names none, so a
    file in SI is read bit for bit as before)."""
    return value if factor == 1.0 else value * factor


def _coarse_acceleration(name: str, time_step: float | None, quantity: str) -> None:
    """Refuse acceleration samples one a line given a time step over :data:`MAX_ACCELEROGRAM_STEP` (an .AT2's DT
    is held to it as well): ``--record-dt 0.5`` on an ``acc (g)`` column ran, 2 samples a second."""
    if time_step is not None and quantity == "acceleration" and time_step > MAX_ACCELEROGRAM_STEP:
        raise InputError(
            f"{name}: acceleration samples {time_step:g} s apart (the time step given) hold nothing above "
            f"{0.5 / time_step:.3g} Hz, where earthquakes shake and walls rock (accelerographs sample every 5–20 ms): "
            f"an acceleration record's time step is at most {MAX_ACCELEROGRAM_STEP:g} s"
        )


def _time_step(value, key: str) -> float | None:
    """``value`` checked as a record's time step (None: not given); ``key`` names it in the message."""
    if value is None:
        return None
    problem = time_step_problem(value)
    if problem:
        raise InputError(f"{key} = {format_value(value)[:40]}: {problem}")
    return float(value)


def record_fields(table: dict, base_dir: str) -> dict:
    """The :class:`~masonrycli.records.motion.Record` arguments for the data of a scenario's record table:
    ``file`` (and ``vertical``) read relative to ``base_dir``, or inline ``time`` and ``value``.

    Raises :class:`InputError` with a message naming the key (``motion.file = "q.csv": no such file ...``).
    """
    has_file = "file" in table
    has_inline = "time" in table or "value" in table
    if has_file and has_inline:
        raise InputError("motion.file: give either file or inline time and value, not both")
    if "vertical" in table and not has_file:
        raise InputError("motion.vertical: goes with file (the horizontal component's file)")
    if "time_step" in table and not has_file:
        raise InputError("motion.time_step: goes with file, a CSV of one value per line (inline samples give time)")
    if has_file:
        time_step = _time_step(table.get("time_step"), "motion.time_step")
        time, value, native, source, quantity = _table_file(table, "file", base_dir, time_step)
        out = {"source": source, "time_step": time_step}
        if native is None and "quantity" not in table:
            out["quantity"] = quantity  # a CSV: as its header says, as --record reads it, else velocity
        if "vertical" in table:
            vtime, vvalue, vnative, vsource, _ = _table_file(table, "vertical", base_dir, time_step, quantity)
            if vnative != native:
                raise InputError(f"motion.vertical: must be in the same format as {table['file']}")
            try:
                time, value = combine_vertical(time, value, vtime, vvalue, table["file"], table["vertical"])
            except InputError as exc:
                raise InputError(f"motion.vertical: {exc}") from None
            out["vertical_source"] = vsource
        if value.ndim == 2 and "direction" in table:
            if "vertical" in table:
                raise InputError("motion.direction: not used with a vertical component (the record acts along x, y)")
            raise InputError(f"motion.direction: not used by a 3-column record ({table['file']} gives x and y)")
        if native is not None:
            if table.get("quantity", native) != native:
                raise InputError(f"motion.quantity: {table['file']} holds {native}")
            out["quantity"] = native
        return out | {"time": time, "value": value}
    for key in ("time", "value"):
        if key not in table:
            raise InputError(f'motion.{key}: missing (kind "record" needs file, or time and value)')
        if not isinstance(table[key], list):
            raise InputError(f"motion.{key} = {format_value(table[key])[:40]}: must be an array")
    value = table["value"]
    if value and all(isinstance(v, list) for v in value) and "direction" in table:
        raise InputError("motion.direction: not used by a vector record (value holds [x, y] pairs)")
    return {"time": table["time"], "value": value}


def _table_file(table: dict, key: str, base_dir: str, time_step: float | None, quantity: str | None = None):
    """``(time, value, native quantity or None, resolved path, quantity)`` of the record table's ``key`` file: a
    CSV in SI, read as ``quantity`` (default: the table's, else as its header says, else velocity)."""
    file = table[key]
    if not isinstance(file, str) or not file:
        raise InputError(f"motion.{key} = {format_value(file)[:40]}: must be a file name")
    resolved = input_path(base_dir, file)
    if not os.path.isfile(resolved):
        raise InputError(f"motion.{key} = {quote_string(file)}: {not_a_file(resolved)} (looked for {resolved})")
    try:
        time, value, native = read_record(resolved, display=file, time_step=time_step)
        if native is None:  # in the unit its header gives, converted to SI
            quantity = quantity or table.get("quantity") or header_quantity(resolved) or "velocity"
            _coarse_acceleration(file, time_step, quantity)
            value = _in_si(value, check_csv_header(resolved, file, quantity, table.get("scale", 1.0)))
    except NoTimeStep as exc:  # --record-dt goes with --record, not with the scenario's own record file
        raise InputError(f"motion.{key}: {exc.give('time_step = SECONDS in the record table')}") from None
    except InputError as exc:
        raise InputError(f"motion.{key}: {exc}") from None
    return time, value, native, resolved, quantity
