"""K-NET and KiK-net ASCII records (NIED, Japan): ``MYG0041103111446.NS``, ``.EW``, ``.UD`` (K-NET) and
``….NS1`` … ``….UD2`` (KiK-net: 1 in the borehole, 2 at the surface).

Layout: 17 header lines, a key in the first 18 columns and its value after it (``Sampling Freq(Hz)
100Hz``, ``Scale Factor      3920(gal)/6182761``, ``Dir.              N-S``), the last ``Memo.``; then the
samples, integers (the digitiser's counts), 8 a line. Read:

    header  = the lines up to and with "Memo." (keys matched by their start, any case and spacing)
    dt      = 1 / Sampling Freq (Hz; "100Hz"), a record's time step (1e-6 to 0.1 s: an accelerogram)
    factor  = Scale Factor "A(gal)/B": A/B gal a count, 0.01 A/B m/s²
    samples = the numbers after the header, each finite, at least 2; times 0, dt, 2 dt, ...
    values  = (samples - their mean) x factor: NIED's files carry the instrument's offset, which its
              instructions remove as the record's mean (the baseline correction would take it out as well,
              but the intensity of the record as applied, and baseline = "none", would keep it)

Every refusal is one line naming the file and the line (``q.NS:14: Scale Factor: …``).
"""

from __future__ import annotations

import math
import re

import numpy as np

from masonrycli.errors import InputError
from masonrycli.records.motion import time_step_problem
from masonrycli.records.text import free_numbers
from masonrycli.scenario.values import shorten

KNET_SUFFIXES = (".ns", ".ew", ".ud", ".ns1", ".ew1", ".ud1", ".ns2", ".ew2", ".ud2")
_HEADER_LINES = 17  # the last one "Memo."; a file cut before it is no K-NET record
_FREQ = re.compile(r"^\s*([0-9.]+(?:[eE][-+]?\d+)?)\s*(?:Hz)?\s*$", re.IGNORECASE)
_SCALE = re.compile(
    r"^\s*([0-9.]+(?:[eE][-+]?\d+)?)\s*\(\s*gal\s*\)\s*/\s*([0-9.]+(?:[eE][-+]?\d+)?)\s*$", re.IGNORECASE
)


def is_knet(path) -> bool:
    """Whether ``path`` is named as a K-NET / KiK-net record (``.NS``, ``.EW``, ``.UD``, ``.NS1`` …)."""
    return str(path).lower().endswith(KNET_SUFFIXES)


def knet_vertical(path) -> bool:
    """Whether a K-NET / KiK-net file name is of the vertical component (``.UD``, ``.UD1``, ``.UD2``)."""
    return str(path).lower().endswith((".ud", ".ud1", ".ud2"))


def knet_text(text: str, name: str) -> tuple[float, np.ndarray]:
    """``(dt s, acceleration in m/s², the mean removed)`` of a K-NET record's ``text`` (module docstring).
    Raises :class:`InputError` with a one-line message ``<file>:<line>: <problem>``."""
    lines = text.split("\n")
    header: dict[str, tuple[str, int]] = {}
    end = None
    for lineno, line in enumerate(lines[: _HEADER_LINES + 3], start=1):
        key = " ".join(line[:18].split()).lower()
        header.setdefault(key, (line[18:].strip(), lineno))
        if key.startswith("memo"):
            end = lineno
            break
    if end is None:
        raise InputError(
            f"{name}: not a K-NET / KiK-net record: no 'Memo.' line ending its header (17 lines of a key in "
            "18 columns and its value, then the samples)"
        )
    dt = _dt(_find(header, "sampling freq", name), name)
    factor = _factor(_find(header, "scale factor", name), name)
    counts = _samples(lines[end:], end + 1, name)
    return dt, (counts - counts.mean()) * factor


def _find(header: dict, start: str, name: str) -> tuple[str, int]:
    for key, value in header.items():
        if key.startswith(start):
            return value
    raise InputError(f"{name}: the K-NET header has no '{start.title()}' line")


def _dt(found: tuple[str, int], name: str) -> float:
    text, line = found
    match = _FREQ.match(text)
    if not match:
        raise InputError(f"{name}:{line}: Sampling Freq(Hz): not a frequency: {shorten(text, 30)} (e.g. 100Hz)")
    freq = float(match.group(1))
    dt = 1.0 / freq if freq > 0 else math.inf
    problem = time_step_problem(dt, acceleration=True)  # K-NET files are accelerograms
    if problem:
        raise InputError(f"{name}:{line}: Sampling Freq(Hz) = {shorten(text, 30)}: a time step of {dt:g} s: {problem}")
    return dt


def _factor(found: tuple[str, int], name: str) -> float:
    """m/s² a count: the header's ``A(gal)/B``."""
    text, line = found
    match = _SCALE.match(text)
    if not match or float(match.group(2)) == 0.0:
        raise InputError(
            f"{name}:{line}: Scale Factor: {shorten(text, 30)}: expected A(gal)/B, gal a count (3920(gal)/6182761)"
        )
    return 0.01 * float(match.group(1)) / float(match.group(2))


def _samples(lines: list[str], first: int, name: str) -> np.ndarray:
    """The numbers of ``lines`` (the first being line ``first`` of the file), white-space separated; a field
    that is no finite number is refused at its line; at least 2."""
    values = free_numbers(lines, first, name)
    if values.size < 2:
        raise InputError(f"{name}: a record needs at least 2 samples, found {values.size}")
    return values
