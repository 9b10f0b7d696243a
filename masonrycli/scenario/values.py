"""Checked input values and their TOML spelling, shared by the scenario reader, writer and motions.

``check_real`` / ``check_int`` / ``check_vector`` / ``field_error`` turn a bad value into a one-line
:class:`~masonrycli.errors.InputError` naming the key (what a valid number is, :func:`is_real` included,
is defined once in :mod:`geometry_library.values`); ``format_value`` / ``quote_string`` / ``quote_key``
write Python values as TOML text that ``tomllib`` reads back bit for bit.
"""

from __future__ import annotations

import difflib
import itertools
import math
import re
import unicodedata

import numpy as np

from geometry_library.blocks import LINE_BREAKING
from geometry_library.values import SETTING_UNITS, is_real, number_problem, shown
from masonrycli.errors import InputError


def format_value(value) -> str:
    """A value as it would be written in TOML (for error messages and the emitter)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(float(value))  # a numpy float64 (a float too) would say np.float64(0.5)
    if isinstance(value, str):
        return quote_string(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(format_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{quote_key(k)} = {format_value(v)}" for k, v in value.items()) + " }"
    if isinstance(value, np.generic):
        return format_value(value.item())
    if isinstance(value, np.ndarray):
        return format_value(value.tolist())
    return repr(value)


def quote_string(text: str) -> str:
    """A TOML basic string (double quotes, escapes for quote, backslash and control characters)."""
    out = ['"']
    for ch in text:
        code = ord(ch)
        if ch == '"':
            out.append('\\"')
        elif ch == "\\":
            out.append("\\\\")
        elif ch == "\n":
            out.append("\\n")
        elif ch == "\t":
            out.append("\\t")
        elif ch == "\r":
            out.append("\\r")
        elif unicodedata.category(ch) in LINE_BREAKING:  # U+0085, U+2028 too: a message stays one line
            out.append(f"\\u{code:04x}")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def quote_key(key: str) -> str:
    return key if _BARE_KEY.match(key) else quote_string(key)


def did_you_mean(key, known) -> str:
    """`` (did you mean "density"?)`` for a near-miss of a ``known`` key (``densty``), else ""."""
    close = difflib.get_close_matches(str(key), list(known), n=1)
    return f' (did you mean "{close[0]}"?)' if close else ""


def unknown_key(key, known) -> str:
    """``unknown key "densty" (did you mean "density"?)``, or the known keys when none is close: the TOML
    reader's message for a key it does not read (the GeoJSON reader's warning shares :func:`did_you_mean`)."""
    hint = did_you_mean(key, known) or f" (expected one of: {', '.join(known)})"
    return f"unknown key {quote_string(str(key))}{hint}"


def shorten(value, limit: int = 60) -> str:
    """``value`` for a message, cut to ``limit`` characters: as typed (an option's :class:`TypedNumber`,
    ``shown``), else as the scenario file writes it (``format_value``)."""
    text = shown(value, format_value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def option_text(value) -> str:
    """A command-line option's value for a message: as typed (a :class:`TypedNumber`, ``shown``), else a float
    in the shortest of ``:g`` and repr that gives it back exactly ("1e+07", "2", not "10000000.0", "2.0"),
    anything else as str (a value given in Python)."""
    return shown(value, _exact_short)


def _exact_short(value) -> str:
    if isinstance(value, float) and math.isfinite(value):
        short = f"{value:g}"
        return short if float(short) == value else repr(float(value))
    return str(value)


def field_error(key: str, value, reason: str) -> InputError:
    """``InputError('key = value: reason')`` with the value shortened to keep the message one line."""
    return InputError(f"{key} = {shorten(value)}: {reason}")


def check_real(key: str, value, *, gt=None, ge=None, le=None, lt=None, allow_inf: bool = False) -> float:
    """Return ``value`` as a float or raise ``InputError`` naming ``key``."""
    problem = number_problem(value, gt=gt, ge=ge, lt=lt, le=le, allow_inf=allow_inf, unit=SETTING_UNITS.get(key))
    if problem is not None:
        raise field_error(key, value, problem)
    return float(value)


def check_int(key: str, value, *, ge: int, le: int) -> int:
    """Return ``value`` as an int or raise ``InputError`` naming ``key``."""
    problem = number_problem(value, integer=True, ge=ge, le=le, unit=SETTING_UNITS.get(key))
    if problem is not None:
        raise field_error(key, value, problem)
    return int(value)


def check_vector(key: str, value, size: int = 2, names: str | None = None) -> tuple[float, ...]:
    """Return ``value`` as a tuple of ``size`` finite floats or raise ``InputError`` naming ``key``;
    ``names`` spells the expected form in the message (default ``[x, y]`` / ``[vx, vy, omega]``)."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if not isinstance(value, (list, tuple)) or len(value) != size or not all(is_real(v) for v in value):
        names = names or {2: "[x, y]", 3: "[vx, vy, omega]"}.get(size, f"{size} numbers")
        raise field_error(key, value, f"must be {size} numbers {names}")
    try:
        out = tuple(float(v) for v in value)
    except OverflowError:  # an int of 400 digits (TOML reads any size)
        out = (math.inf,)
    if not all(math.isfinite(v) for v in out):
        raise field_error(key, value, "must be finite numbers")
    return out


# --------------------------------------------------------------------------------------------------
# Motion


def _finite_floats(seq, pairs: bool = False) -> np.ndarray | None:
    """``seq`` as a float64 array when it is a float array of finite numbers, or a sequence of finite
    Python floats (``pairs``: of 2-sequences of them), what check_real / check_vector would give item by
    item; None otherwise (then they name the bad one). A record file's 3 million samples were checked one
    call each: 7 s before the run began; then built into Python tuples: 0.7 s more."""
    if isinstance(seq, np.ndarray):
        shape_ok = seq.ndim == 2 and seq.shape[1] == 2 if pairs else seq.ndim == 1
        if seq.dtype.kind != "f" or not shape_ok or not seq.size:
            return None
        numbers = seq.astype(np.float64, copy=seq.flags.writeable)  # a read-only float64 array is kept
    elif not seq:
        return None
    elif pairs:
        if not set(map(type, seq)) <= {tuple, list} or set(map(len, seq)) != {2}:
            return None
        if set(map(type, itertools.chain.from_iterable(seq))) != {float}:
            return None
        flat = np.fromiter(itertools.chain.from_iterable(seq), dtype=np.float64, count=2 * len(seq))
        numbers = flat.reshape(-1, 2)
    else:
        if set(map(type, seq)) != {float}:
            return None
        numbers = np.fromiter(seq, dtype=np.float64, count=len(seq))
    return numbers if np.isfinite(numbers).all() else None


def check_samples(key: str, seq, pairs: bool = False) -> np.ndarray:
    """``seq`` checked item by item as ``check_real`` (``pairs``: ``check_vector``) would, as a read-only
    float64 array (n,) (``pairs``: (n, 2)); a float array or plain finite floats, the common case, in one
    numpy pass (a read-only float64 array is kept as it is, not copied). ``key[i]`` names a bad item."""
    checked = _finite_floats(seq, pairs)
    if checked is None:
        items = seq.tolist() if isinstance(seq, np.ndarray) else seq
        check = check_vector if pairs else check_real
        checked = np.array([check(f"{key}[{i}]", x) for i, x in enumerate(items)], dtype=np.float64)
    checked.setflags(write=False)
    return checked


WORD_KEYS = frozenset({"solver", "quantity", "baseline"})
"""Keys whose value is a word of a fixed list, read in any case as a motion's ``kind`` and the command line's
``--solver NLGS`` (``solver = "NLGS"`` was refused)."""


def lower_words(table: dict) -> dict:
    """``table`` with the values of :data:`WORD_KEYS` stripped and in lower case."""
    return {k: v.strip().lower() if k in WORD_KEYS and isinstance(v, str) else v for k, v in table.items()}
