"""Reading ground-motion records from files into :class:`~masonrycli.motion.Record` motions.

CSV: one sample per line, ``time,value`` or ``time,x,y`` (see :func:`load_record_csv`).
"""

from __future__ import annotations

import math
import os
import re

import numpy as np

from masonrycli.errors import InputError
from masonrycli.motion import Record
from masonrycli.values import format_value, shorten

_SPLIT = re.compile(r"\s*[,;]\s*|\s+")


def load_record_csv(path, display: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Read a tabulated motion record.

    Format: one sample per line, ``time,value`` (2 columns: a value along the motion's direction) or
    ``time,x,y`` (3 columns: a vector). Separators: comma, semicolon or white space. Blank lines and
    lines starting with ``#`` are skipped; a single non-numeric header line before the first sample is
    allowed. Times in s, strictly increasing, at least 2 samples; all values finite.

    Returns ``(time (n,), value (n,) or (n, 2))`` float64 arrays.
    Raises :class:`InputError` with a one-line message ``<file>:<line>: <problem>``.
    ``display`` is the file name used in messages (default: ``path`` as given).
    """
    name = display if display is not None else str(path)
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except IsADirectoryError:
        raise InputError(f"{name}: cannot read record: is a directory") from None
    except OSError as exc:
        raise InputError(f"{name}: cannot read record: {exc.strerror or exc}") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(f"{name}: not a UTF-8 text file (byte {exc.start})") from None

    times: list[float] = []
    values: list = []
    ncol = 0
    header_seen = False
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        fields = [f for f in _SPLIT.split(stripped) if f != ""]
        try:
            nums = [float(f) for f in fields]
        except ValueError:
            if not times and not header_seen:
                header_seen = True
                continue
            bad = next(f for f in fields if not _is_float(f))
            raise InputError(f"{name}:{lineno}: not a number: {shorten(bad, 40)}") from None
        if ncol == 0:
            if len(nums) not in (2, 3):
                raise InputError(
                    f"{name}:{lineno}: expected 2 columns (time, value) or 3 (time, x, y), got {len(nums)}"
                )
            ncol = len(nums)
        elif len(nums) != ncol:
            raise InputError(f"{name}:{lineno}: expected {ncol} columns like the first sample, got {len(nums)}")
        if not all(math.isfinite(x) for x in nums):
            raise InputError(f"{name}:{lineno}: values must be finite, got {shorten(stripped, 40)}")
        if times and not nums[0] > times[-1]:
            raise InputError(
                f"{name}:{lineno}: time {format_value(nums[0])} is not after the previous sample's "
                f"{format_value(times[-1])} (times must be strictly increasing)"
            )
        times.append(nums[0])
        values.append(nums[1] if ncol == 2 else (nums[1], nums[2]))
    if len(times) < 2:
        raise InputError(f"{name}: a record needs at least 2 samples, found {len(times)}")
    return np.asarray(times, dtype=np.float64), np.asarray(values, dtype=np.float64)


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def record_motion(
    path, *, quantity: str = "velocity", scale: float = 1.0, direction=(1.0, 0.0), display: str | None = None
) -> Record:
    """A :class:`~masonrycli.motion.Record` from a CSV file (see :func:`load_record_csv`).

    ``source`` is the absolute path of the file. ``direction`` applies to 2-column records only.
    """
    time, value = load_record_csv(path, display=display)
    return Record(
        direction=tuple(direction),
        time=tuple(time.tolist()),
        value=tuple(value.tolist()) if value.ndim == 1 else tuple(map(tuple, value.tolist())),
        quantity=quantity,
        scale=scale,
        source=os.path.abspath(os.fspath(path)),
    )
