"""What a record file's own header says about its units, checked against how it is read.

A record's samples carry no units: an .AT2 file is read as acceleration in g, a CSV file as velocity
in m/s (or what a scenario file's ``quantity`` says) or in the unit its header gives, times in s. A header
that says otherwise means the samples would be taken 100–1000× too large, or as the wrong quantity, and the
run would still say "completed". So a header that *names* other units than the file can be read in is refused
with one line saying what and where; a header that names none is taken at its word (PEER's format is g, a CSV
is SI):

* .AT2 (:func:`check_at2_header`): ``UNITS OF CM/S/S`` (anything but G), or a ``VELOCITY`` /
  ``DISPLACEMENT`` series (PEER's .VT2 / .DT2 files, renamed).
* .AT2 samples (:func:`check_at2_sample`): beyond ``MAX_AT2_G`` (10 g) they are not g — cm/s² under a
  header that says g, or a header that names no unit.
* CSV (:func:`check_csv_header`), the one text line allowed before the samples: times in ms; an
  acceleration header read as velocity or the reverse. A header giving cm/s, mm/s, in/s, ft/s, g, gal, cm/s²,
  in/s² or ft/s² is read in that unit, converted to SI, wherever a record is read (``--record``, a scenario
  file, a ``sweep --records`` set); a scale equal to that conversion (the old way to read such a file) is
  refused, it would now convert twice.

The patterns look for whole words, so ``time_ms`` and ``acc (g)`` match but ``rms`` and ``ground`` do not.
"""

from __future__ import annotations

import io
import re

from masonrycli.errors import NOT_A_FILE, InputError, not_utf8, special_file
from masonrycli.scenario.values import shorten

_AT2_UNITS = re.compile(r"UNITS\s+OF\s+([^\s,;]+)", re.IGNORECASE)
_AT2_OTHER_SERIES = re.compile(r"\b(VELOCITY|DISPLACEMENT)\b", re.IGNORECASE)


def check_at2_header(header: list[str], name: str) -> None:
    """Raise :class:`InputError` if the 3 free lines of an .AT2 ``header`` say the samples are not
    acceleration in g (``name:LINE: the header says units of CM/S/S; ...``)."""
    for lineno, line in enumerate(header, start=1):
        other = _AT2_OTHER_SERIES.search(line)
        if other and not re.search(r"\bACCELERATION\b", line, re.IGNORECASE):
            raise InputError(
                f"{name}:{lineno}: the header says {other.group(1).lower()} "
                f"({shorten(line.strip(), 50)}); an .AT2 record holds acceleration in g"
            )
        unit = _AT2_UNITS.search(line)
        if unit and unit.group(1).rstrip(".").upper() != "G":
            raise InputError(
                f"{name}:{lineno}: the header says units of {unit.group(1).rstrip('.')}; an .AT2 record holds "
                "acceleration in g (convert the samples, or give them as a CSV with quantity and scale)"
            )


MAX_AT2_G = 10.0
"""g: the strongest records ever measured peak at 3-4 g; an .AT2 sample beyond 10 g is in other units."""


def check_at2_sample(value: float, where: str) -> None:
    """Raise :class:`InputError` for an .AT2 sample beyond ``MAX_AT2_G`` (read as g, 981 cm/s² = 981 g)."""
    if abs(value) > MAX_AT2_G:
        raise InputError(
            f"{where}: sample {value:g} g is beyond {MAX_AT2_G:g} g: the samples are not in g (cm/s²?); "
            "an .AT2 record holds acceleration in g"
        )


def _words(*alternatives: str) -> re.Pattern:
    # whole words: not inside a longer run of letters ("_" and brackets are boundaries); a velocity unit is
    # not the start of an acceleration's ("cm/s" of "cm/s/s", "cm/s2", "cm/s**2")
    return re.compile(r"(?<![a-z])(" + "|".join(alternatives) + r")(?![a-z0-9^²]|/\s*s|\*\*)", re.IGNORECASE)


# a length over a time, and over a time squared: "cm/s", "cm/sec", "cm s-1"; "cm/s2", "cm/s^2", "cm/s²",
# "cm/s**2", "cm/s/s", "cm/sec^2", "cm s-2", "cm s^-2". Before, "cm/s/s", "in/s/s" and "cm/s**2" were read as
# velocity in cm/s and in/s, and "cm/s²", "mm/s2", "cm/sec^2" and "cm s-2" named no unit, their samples read
# in m/s² (100x, 1000x too strong), without a word
_PER_S = r"/\s*s(?:ec)?"
_S = r"\s*s(?:ec)?"  # "cm s-1", "cm s^-2": a negative power of s after a blank, metric lengths only ("in s-1")


def _metric(lengths: str) -> str:
    return "|".join(unit for unit in lengths.split("|") if unit in ("cm", "mm", "m"))


def _speed(lengths: str) -> str:
    return f"(?:(?:{lengths}){_PER_S}|(?:{_metric(lengths)}){_S}(?:\\^?-1|⁻¹))"


def _accel(lengths: str) -> str:
    return f"(?:(?:{lengths}){_PER_S}(?:\\^?2|²|\\*\\*2|{_PER_S})|(?:{_metric(lengths)}){_S}(?:\\^?-2|⁻²))"


_SPEED, _ACCEL = _speed("cm|mm|m|in|ft"), _accel("cm|mm|m|in|ft")
# g, the unit, but not a one-letter symbol's subscript: a_g, v_g, u_g are the ground's acceleration, velocity and
# displacement (EC8's a_g, in m/s²; this project's v_g). "time,v_g" was read as acceleration in g: refused by
# --record with "a scale of 9.81 converts them" (a velocity then run as an acceleration), converted by 9.81
# without a word in a sweep --records set
_G_UNIT = r"(?<!\b[a-z]_)g"
_TIME_MS = _words("ms", "msec", "milliseconds?")
_ACCELERATION = _words("acc", "accel", "accn", "accelerations?", "a_g", _ACCEL, "gal", _G_UNIT)
_VELOCITY = _words("vel", "velocity", "velocities", "speed", "v_g", _SPEED)
# a displacement series was read as velocity in m/s (a header "time (s),disp (m)"), with no word
_DISPLACEMENT = _words("disp", "displ", "displacements?")
# units that need a scale to be SI, in their canonical spelling (:func:`unit_key`) -> (quantity, the factor
# to m/s or m/s²)
SCALED_UNITS = {
    "cm/s": ("velocity", 0.01),
    "mm/s": ("velocity", 0.001),
    "g": ("acceleration", 9.81),
    "gal": ("acceleration", 0.01),
    "cm/s2": ("acceleration", 0.01),
    "mm/s2": ("acceleration", 0.001),
    # US units: read as SI they were 39x (in) and 3.3x (ft) too large, without a word
    "in/s": ("velocity", 0.0254),
    "ft/s": ("velocity", 0.3048),
    "in/s2": ("acceleration", 0.0254),
    "ft/s2": ("acceleration", 0.3048),
}
_SCALED_UNIT = _words(_accel("cm|mm|in|ft"), _speed("cm|mm|in|ft"), "gal", _G_UNIT)  # m/s, m/s² are SI already


def unit_key(unit: str) -> str:
    """The :data:`SCALED_UNITS` key of a unit as written: ``CM/SEC^2``, ``cm/s/s``, ``cm/s²``, ``cm s-2`` -> ``cm/s2``;
    ``cm/sec``, ``cm s-1`` -> ``cm/s``; ``g``, ``gal`` as they are."""
    key = re.sub(r"\s+", "", unit.lower()).replace("sec", "s")
    length = re.fullmatch(r"(cm|mm|in|ft|m)/?s(.*)", key)
    if length is None:
        return key
    squared = length.group(2) in ("2", "^2", "²", "**2", "/s", "-2", "^-2", "⁻²")
    return f"{length.group(1)}/s{'2' if squared else ''}"


def record_text(raw: bytes) -> str:
    """The text of a record file's bytes: UTF-8 (a byte-order mark dropped), else Windows-1252, Latin-1 where
    a byte is undefined there. Raises UnicodeDecodeError (UTF-8's) for UTF-16 or bytes that are not text.

    Excel's "CSV (comma delimited)" is in the Windows code page and accelerograms name their station in
    Latin-1: a header's "(m/s²)" or "données" made the file "not a UTF-8 text file (byte 28)". The samples
    are ASCII in any of these, so only the header and comments read differently — and a header's units
    (², µ) read right in the code page, not as replacement characters."""
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        if raw[:2] in (b"\xff\xfe", b"\xfe\xff") or b"\x00" in raw:  # UTF-16, or not text at all
            raise
    try:
        return raw.decode("cp1252")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def input_text(path, name: str, cannot: str) -> str:
    """The text of an input file a user names (a record, a lab's CSV): one line, ``NAME: CANNOT: why``, for a
    device or a pipe (reading ``/dev/zero`` or a named pipe never ended), a folder or an unreadable file; a
    UTF-16 or binary file named as such (:func:`masonrycli.errors.not_utf8`); Windows line ends as ``\n``."""
    return decoded(input_bytes(path, name, cannot), name)


def input_bytes(path, name: str, cannot: str) -> bytes:
    """The bytes of the input file at ``path`` (:func:`input_text`, undecoded)."""
    if special_file(path):
        raise InputError(f"{name}: {cannot}: {NOT_A_FILE}")
    try:
        with open(path, "rb") as fh:
            return fh.read()
    except IsADirectoryError:
        raise InputError(f"{name}: {cannot}: is a directory") from None
    except OSError as exc:
        raise InputError(f"{name}: {cannot}: {exc.strerror or exc}") from None


def decoded(raw: bytes, name: str) -> str:
    """:func:`record_text` of an input's bytes, or one line (UTF-16, binary, the line of a bad byte)."""
    try:
        text = record_text(raw)  # UTF-8, else the Windows code page (a spreadsheet's CSV)
    except UnicodeDecodeError as exc:
        raise not_utf8(name, raw, exc) from None
    if "\r" in text and text.count("\r") == text.count("\r\n"):
        # Windows line ends: the same lines to splitlines, and chunks numpy can read (record_text)
        text = text.replace("\r\n", "\n")
    return text


def csv_header(path) -> tuple[int, str] | None:
    """``(line number, text)`` of the header line of a CSV record (the one non-numeric line before the
    first sample, after blank and ``#`` lines), or None. The file was read once already."""
    with open(path, "rb") as raw:
        text = record_text(raw.read())
    with io.StringIO(text, newline=None) as fh:  # lines as a text-mode open cuts them
        for lineno, line in enumerate(fh, start=1):
            stripped = line.strip()
            if not stripped or stripped.startswith("#"):
                continue
            fields = [f for f in re.split(r"\s*[,;]\s*|\s+", stripped) if f]
            try:
                [float(f) for f in fields]
            except ValueError:
                return lineno, stripped
            return None
    return None


def header_quantity(path) -> str | None:
    """ "acceleration" or "velocity" when the header of the CSV record at ``path`` names that quantity or its
    units and not the other one, else None. Where no option or key says what a CSV holds (``--record``,
    ``--records``), this is how it is read: an accelerogram with a header "time (s), acc (m/s²)" could not be
    run or swept at all (refused as read as velocity, with no option to say otherwise)."""
    found = csv_header(path)
    if found is None:
        return None
    says_acc, says_vel = bool(_ACCELERATION.search(found[1])), bool(_VELOCITY.search(found[1]))
    return "acceleration" if says_acc and not says_vel else "velocity" if says_vel and not says_acc else None


G_STANDARD = 9.80665
"""m/s² per g, exact: the factor a header's g converts by (9.81 is the message's round figure), as an .AT2
file's and an ESM file's g."""


def header_factor(path, quantity: str) -> tuple[str, float] | None:
    """``(unit, factor to SI)`` when the header of the CSV record at ``path`` gives ``quantity`` in a unit that
    needs one (g, gal, cm/s², cm/s, mm/s, in/s, …), else None (:func:`check_csv_header` applies it)."""
    found = csv_header(path)
    unit = _SCALED_UNIT.search(found[1]) if found else None
    if unit is None:
        return None
    kind, factor = SCALED_UNITS[unit_key(unit.group(1))]
    if kind != quantity:
        return None
    return unit.group(1), G_STANDARD if unit_key(unit.group(1)) == "g" else factor


def unit_factor(unit: str) -> tuple[str, float] | None:
    """``(quantity, factor to SI)`` of a unit written alone, as an ESM header's ``UNITS`` gives it (``cm/s^2``,
    ``gal``, ``g``, ``m/s``; blanks and case aside), by the spellings and the table a CSV header is read by
    (:data:`SCALED_UNITS`, m/s and m/s² as they are); None for anything else (a length, "counts")."""
    text = "".join(unit.split())
    if not (_SI_OR_SCALED.fullmatch(text) or text.lower() in ("g", "gal")):
        return None
    key = unit_key(text)
    if key in ("m/s", "m/s2"):
        return ("velocity" if key == "m/s" else "acceleration"), 1.0
    quantity, factor = SCALED_UNITS[key]
    return quantity, G_STANDARD if key == "g" else factor


_SI_OR_SCALED = re.compile(f"{_ACCEL}|{_SPEED}", re.IGNORECASE)


CONVERTED_AGAIN = 0.005
"""Relative width around a CSV header's conversion (9.80665 for g, 0.01 for gal) within which a ``scale`` is
taken for that conversion given a second time (9.81, 9.807, 9.8; 0.01): refused. Narrow: a scale of 10 on a
record in g is a choice, not the conversion."""

NEAR_CONVERSION = 0.02
"""Relative width within which a scale reads as a unit conversion given again, where it is only warned about:
a ``sweep --scale`` axis value, an ESM / K-NET file's 0.01, an .AT2 file's 9.81."""


def converts_again(scale: float, factor: float, width: float = CONVERTED_AGAIN) -> bool:
    """Whether ``scale`` is, within ``width`` (relative, either sign), the conversion ``factor`` a record was
    already read with: the same conversion applied a second time."""
    return abs(abs(scale) / factor - 1) < width


def check_csv_header(path, name: str, quantity, scale) -> float:
    """The factor to SI of the CSV record at ``path`` read as ``quantity`` ("velocity" m/s or "acceleration"
    m/s²): what its header's unit says (9.80665 for ``acc (g)``, 0.01 for ``vel (cm/s)``, 1 when it names none).
    The samples are multiplied by it on reading, as an .AT2 file's g or an ESM file's cm/s² are, wherever a
    record is read (``--record``, a scenario's record table, a ``sweep --records`` set, ``check``), and ``scale``
    then multiplies the record as recorded.

    Raises :class:`InputError` if the header names units that disagree with ``quantity``, gives times in ms,
    or if ``scale`` is the conversion itself (:data:`CONVERTED_AGAIN`): before, such a file was read in SI and
    its scale was the conversion, so ``scale = 9.81`` on a file in g was right, and now would make it 9.81 times
    stronger without a word. Values that are not a known quantity or a number are left to the Record's checks."""
    found = csv_header(path)
    if found is None or quantity not in ("velocity", "acceleration"):
        return 1.0
    lineno, text = found
    where, shown = f"{name}:{lineno}", shorten(text, 40)
    if _TIME_MS.search(text):
        raise InputError(f"{where}: the header gives times in ms ({shown}); record times are read in s")
    says_acc, says_vel = bool(_ACCELERATION.search(text)), bool(_VELOCITY.search(text))
    if _DISPLACEMENT.search(text) and not (says_acc or says_vel):
        raise InputError(
            f"{where}: the header says displacement ({shown}) but a record is read as velocity (m/s) or "
            "acceleration (m/s²): give its velocity or acceleration series"
        )
    other = "acceleration" if quantity == "velocity" else "velocity"
    if (says_acc and not says_vel and quantity == "velocity") or (says_vel and not says_acc and quantity != "velocity"):
        unit = "m/s" if quantity == "velocity" else "m/s²"
        raise InputError(
            f"{where}: the header says {other} ({shown}) but the samples are read as {quantity}, {unit} "
            f'(a scenario file\'s record motion takes quantity = "{other}")'
        )
    unit = header_factor(path, quantity)
    if unit is None:
        return 1.0
    factor = unit[1]
    if isinstance(scale, (int, float)) and not isinstance(scale, bool) and converts_again(scale, factor):
        si = "m/s" if quantity == "velocity" else "m/s²"
        times = f"{1 / factor:.3g} times too weak" if factor < 1 else f"{factor:.3g} times too strong"
        raise InputError(
            f"{where}: the header gives {quantity} in {unit[0]} ({shown}), converted to {si} on reading: scale "
            f"{scale:g} would convert it again ({times}); drop the scale (it multiplies the record as recorded)"
        )
    return factor
