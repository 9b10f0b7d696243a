"""Checked numbers: the one definition of a valid real, integer or positive value, for both packages.

:func:`number_problem` says what is wrong with a value, as the end of a sentence ("must be a number",
"must be a finite number", "must be an integer", "must be > 0", "must be >= 1"), or None. Each caller
words its message in its own style around it:

- geometry_library (builders, checks, geometry files): :func:`check_positive` and :func:`check_count`
  raise ``GeometryError("<label>: <key> must be a positive number, got <value>")``;
- masonrycli (scenario files, options, motions): ``masonrycli.scenario.values.check_real`` / ``check_int`` raise
  ``InputError("<key> = <value>: <reason>")``.

A number written as a string with its unit (``"1 s"``, ``"2500 kg/m3"``) is told the number to write and
the unit the setting is read in (:data:`SETTING_UNITS`), or, for another unit (``"20 ms"``), to convert it:
never converted here.

A bool is not a number here (``True`` is an int to Python, never a density or a count to a user).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from typing import Any

import numpy as np

from .blocks import GeometryError


class TypedNumber(float):
    """A float as the user typed it on the command line (``text``: "0", "1e-9"), for messages only: they
    echoed "--rtol 0" as "0.0" and "--thickness 1e9" as "1000000000.0". A float in repr, str, hash,
    equality, JSON, TOML (format_value) and numpy arrays, so no digest or written value changes (study
    fingerprints hash reprs); arithmetic gives plain floats, and float(x) is the plain one. Pickled, it
    stays a TypedNumber (other bytes than a float's: nothing hashes pickles, Dask tasks are pure=False)."""

    text: str

    def __new__(cls, value: float, text: str):
        number = super().__new__(cls, value)
        number.text = text.strip()
        return number

    def __getnewargs__(self):  # pickle (a Dask task's scenario) and deepcopy: __new__ takes the text too
        return float(self), self.text


def shown(value, otherwise: Callable[[Any], str] = repr) -> str:
    """``value`` for a message: as typed when it is a :class:`TypedNumber` ("--rtol 0", not "0.0"), else
    ``otherwise(value)``, the caller's format for any other value (repr here). The one place that rule lives:
    ``masonrycli.scenario.values.shorten`` and ``option_text`` call it with their formats."""
    return value.text if isinstance(value, TypedNumber) else otherwise(value)


def _g(value) -> str:
    """``value`` for a range message: as typed (a :class:`TypedNumber`: "--span 1e9" said "span 1e+09"), else
    in %g (a scenario file's or a GeoJSON's number)."""
    return shown(value, "{:g}".format)


def is_real(value) -> bool:
    """An int or a float (numpy's too), not a bool."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def is_integer(value) -> bool:
    """An int (numpy's too), not a bool."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _bound(b) -> str:
    """An integer bound as written (10**9 stays 1000000000), a float one in %g."""
    return str(b) if is_integer(b) else f"{b:g}"


SETTING_UNITS: dict[str, str] = {
    # [run]
    "duration": "s",
    "dt": "s",
    "theta": "",
    "tolerance": "m/s",
    "max_iterations": "",
    "record_every": "",
    "alert_distance": "m",
    # [material], [[block]], GeoJSON properties
    "density": "kg/m³",
    "thickness": "m",
    "friction": "",
    # motions
    "amplitude": "m/s",
    "frequency": "Hz",
    "phase": "rad",
    "until": "s",
    "scale": "",
    "time_step": "s",
    # builder options ([structure], masonry build / simulate)
    **dict.fromkeys(
        (
            "length",
            "block_length",
            "block_height",
            "ground_margin",
            "ground_depth",
            "span",
            "rise",
            "ring_thickness",
            "pier_width",
            "pier_course_height",
            "foundation_margin",
            "foundation_depth",
            "min_thickness",
            "fill_to",
            "fill_cover",
        ),
        "m",
    ),
    "fill_density": "kg/m³",
    **dict.fromkeys(("blocks", "courses", "voussoirs", "pier_courses", "wall_courses", "min_fraction"), ""),
}
"""The unit each numeric setting is read in, as docs/scenario-format.md documents it ("": a plain number,
a count or a ratio): what a value written with its unit ("1 s", "2500 kg/m3") is told to become."""

_SPELLINGS = {  # a unit -> how users write it, compared after _spelled (lower case, no spaces, ² ³ ^ ** as digits)
    "s": ("s", "sec", "secs", "second", "seconds"),
    "m": ("m", "meter", "meters", "metre", "metres"),
    "kg/m³": ("kg/m3", "kgm-3", "kg.m-3", "kg·m-3", "kg*m-3"),
    "m/s": ("m/s", "ms-1", "m.s-1", "m·s-1", "m/sec"),
    "Hz": ("hz", "hertz", "1/s", "s-1", "/s", "cps"),
    "rad": ("rad", "radian", "radians"),
    "°": ("°", "deg", "degs", "degree", "degrees"),
}
_DECIMAL_COMMA = re.compile(r"\s*([+-]?\d+),(\d+)\s*")
_PERCENT = re.compile(r"\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+))\s*%\s*")
_NUMBER_AND_UNIT = re.compile(r"\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*([A-Za-zµμ°][^\n]*?)\s*")
_SYMBOL = r"(?:[nµμumcdkg]?(?:m|s|g|t|n|pa|j|w|hz|rad|l|h|bar)|deg|°|min|hr|in|ft|yd|lbs?|kip|psi|mph|cps)"
_WORD = (  # a unit's name, maybe prefixed, maybe plural: "Seconds", "millimetres", "kilonewton"
    r"(?:(?:nano|micro|milli|centi|deci|kilo|mega|giga)?"
    r"(?:sec|second|met(?:er|re)|gram|gramme|tonne|ton|newton|pascal|joule|watt|hertz|radian|degree|minute|hour"
    r"|lit(?:er|re))s?|inch(?:es)?|foot|feet)"
)
_COUNT = r"(?:x|mu|times|(?:block|course|voussoir|pier|step|frame|sweep|iteration|core|worker)s?)"
"""What a plain number, a count or a ratio is written with ("0.5x", "0.6mu", "51 blocks", "10steps",
"2cores"): a hint only for a setting with no unit ("5x" for a thickness in m is no unit)."""


def _unit_pattern(part: str) -> re.Pattern:
    """Parts (each with one digit of power: m3, s-1, m^3) joined by / . · * or spaces, in any case."""
    part = rf"{part}(?:(?:\^|\*\*)?-?[0-9²³])?"
    return re.compile(rf"{part}(?:\s*[/.·*]\s*{part}|\s+{part})*", re.IGNORECASE)


_UNIT = _unit_pattern(f"(?:{_SYMBOL}|{_WORD})")
"""A written unit: SI symbols with a prefix or unit names ("ms", "cm/s", "kg/m^3", "kg·m-3", "3 kN",
"Seconds", "°", "ft"). "12abc" said "convert 12 abc to m", "0x10" (0 and "x10") "convert 0 x10 to m"."""
_UNITLESS = _unit_pattern(f"(?:{_SYMBOL}|{_WORD}|{_COUNT})")
"""A written unit or what a unitless setting is written with (_COUNT)."""
_NOT_A_UNIT = re.compile(
    r"\s*[+-]?(?:0[xX][0-9a-fA-F_]*|0[oO][0-7_]*|0[bB][01_]*|[\d.]+[eE]|[\d.]+\s*[xX×]\s*\d[^\n]*)\s*"
)
"""A Python hex, octal or binary literal ("0x10", "0b1", "0xff": "xff" looks like a word), a number cut
short at its exponent ("1e") or a product ("2x3", "1x10^3"): not a number and a unit."""


def _spelled(unit: str) -> str:
    text = unit.lower().replace(" ", "").replace("**", "").replace("^", "")
    return text.replace("²", "2").replace("³", "3")


def same_unit(written: str, unit: str) -> bool:
    """True when ``written`` ("kg/m^3", "Seconds") is a spelling of ``unit`` (a key of ``_SPELLINGS``)."""
    return _spelled(written) in {_spelled(s) for s in (unit, *_SPELLINGS.get(unit, ()))}


OPTION_SETTINGS: dict[str, str] = {
    "amp": "amplitude",
    "freq": "frequency",
    "settlement": "amplitude",
    "record_dt": "time_step",
}
"""The setting a command-line option or sweep axis stands for when its name is another (--amp is a
motion's amplitude, --record-dt a record's time_step): its unit is that setting's in SETTING_UNITS."""

OPTION_UNITS: dict[str, str] = {
    "rtol": "",
    "workers": "",
    "magnify": "",
    "at": "m",  # limit --at X: the abscissa of a point load
    "trim_overlaps": "m",  # the deepest overlap of a surveyed file's neighbours trimmed
    "settle": "s",  # --settle: seconds of settling under gravity
    "spread": "°",  # limit --spread: a point load's spread through the fill, from the vertical
    "pga": "g",  # --pga: the peak ground acceleration a record is scaled to (a unit may be written: 2.45m/s2)
    "pga_g": "g",  # sweep --param pga_g=…: the same, an axis
}
"""The unit of each numeric option with no scenario setting (their help: --rtol a relative width,
--workers a count, --magnify a factor): the one place they are added. (limit's --block is a block's
name, not a number.)"""


def unit_of(name: str) -> str | None:
    """The unit a setting, option or sweep axis ``name`` is read in ("": none), None when not known."""
    setting = OPTION_SETTINGS.get(name, name)
    return SETTING_UNITS[setting] if setting in SETTING_UNITS else OPTION_UNITS.get(name)


def unit_hint(text: str, unit: str | None) -> str:
    """What to write instead of ``text`` given where a number is read in ``unit`` (:func:`_string_hint`):
    the command line's options use it too (``--dt 20ms``)."""
    return _string_hint(text, unit)


def _string_hint(text: str, unit: str | None) -> str:
    """What to write instead of the string ``text``: `` (write 2500, without quotes)`` for a number in
    quotes; for a number and a unit (``"1 s"``, ``"0.5m"``), the number alone and the unit the setting is
    read in — or, when the unit written is another (``"20 ms"`` for a time in s), that it must be converted,
    never converting it here (a guess at what "t" or "ms" meant would be silent); else ""."""
    try:
        float(text)
        return f" (write {text.strip()}, without quotes)"
    except ValueError:
        pass
    comma = _DECIMAL_COMMA.fullmatch(text)  # "0,6" (a European spreadsheet's friction) said "must be a number"
    if comma and (len(comma.group(2)) != 3 or comma.group(1).lstrip("+-") == "0"):  # "1,500" may be 1500
        return f" (write {comma.group(1)}.{comma.group(2)}: the decimal separator is a point)"
    percent = _PERCENT.fullmatch(text)  # "--scale 50%": a factor of no unit, 0.5
    if percent and unit == "":
        return f" (write {float(percent.group(1)) / 100:g}: a percentage is written as a fraction)"
    found = _NUMBER_AND_UNIT.fullmatch(text)
    if found is None or _NOT_A_UNIT.fullmatch(text):
        return ""
    if not (_UNITLESS if unit == "" else _UNIT).fullmatch(found.group(2)):  # "12abc", "5x" for a length
        return ""
    number, written = found.groups()
    if unit is None:  # a setting of no known unit (a sample of an inline record): the number alone
        return f' (write {number}, without "{written}", in SI units)'
    if unit == "":
        return f' (write {number}, without "{written}": this setting has no unit)'
    if same_unit(written, unit):
        return f" (write {number}, in {unit}, without the unit)"
    spaced = number + ("" if written.startswith("°") else " ") + written  # "20ms": convert 20 ms; "90°" stays
    return f" (it is read in {unit}: convert {spaced} to {unit} and write the number alone)"


def number_problem(
    value, *, integer=False, gt=None, ge=None, lt=None, le=None, allow_inf=False, unit: str | None = None
) -> str | None:
    """What is wrong with ``value`` as a (finite) number within the given bounds, or None.

    ``integer``: it must be an int. ``allow_inf``: +inf passes (before the bounds are checked). ``unit``:
    the unit the setting is read in (:data:`SETTING_UNITS`; "" for none), named when ``value`` is a string
    of a number and a unit (``"1 s"``); None when not known.
    """
    if isinstance(value, str):  # density = "2500" said "must be a number", which "2500" reads as
        return f"must be {'an integer' if integer else 'a number'}, not a string{_string_hint(value, unit)}"
    if integer and not is_integer(value):
        return "must be an integer"
    if not is_real(value):
        return "must be a number"
    try:
        x = value if integer else float(value)
    except OverflowError:  # an int of 400 digits (TOML and JSON read any size): "int too large to convert"
        return "must be a finite number"
    if not integer and (math.isnan(x) or (math.isinf(x) and not (allow_inf and x > 0))):
        return "must be a finite number"
    if gt is not None and not x > gt:
        return f"must be > {_bound(gt)}"
    if ge is not None and not x >= ge:
        return f"must be >= {_bound(ge)}"
    if lt is not None and not x < lt:
        return f"must be < {_bound(lt)}"
    if le is not None and not x <= le:
        return f"must be <= {_bound(le)}"
    return None


def check_positive(label: str, **values) -> None:
    """Raise a one-line GeometryError unless every value is a finite number > 0."""
    for key, value in values.items():
        problem = number_problem(value, gt=0.0, unit=SETTING_UNITS.get(key))
        if problem is not None:
            what = problem.removeprefix("must be ") if isinstance(value, str) else "a positive number"
            raise GeometryError(f"{label}: {key} must be {what}, got {shown(value)}", keys=(key,))


MATERIAL_RANGE = {"density": (1e-3, 1e5, "kg/m³"), "thickness": (1e-6, 1e3, "m")}
"""Sensible density and out-of-plane thickness: outside, a likely typo (the densest element is 22 590 kg/m³).
The dynamics does not depend on them (rigid blocks: masses cancel), but at 1e300 the engine divided by
zero ("internal error") and at 1e-300 a resting wall was reported collapsed at its first step."""


def check_material(label: str, **values) -> None:
    """:func:`check_positive`, then each of ``density`` / ``thickness`` within ``MATERIAL_RANGE``."""
    check_positive(label, **values)
    for key, value in values.items():
        lo, hi, unit = MATERIAL_RANGE[key]
        if not lo <= value <= hi:
            raise GeometryError(
                f"{label}: {key} {_g(value)} {unit} is absurd (a likely typo: {lo:g} to {hi:g} {unit})", keys=(key,)
            )


DIMENSION_RANGE = (1e-3, 1e3)
"""Sensible builder dimensions, m (block sizes, span, ring, pier, depths): outside, a likely typo or other
units. ``--block-height 1e5`` built a 600 km wall and ``--block-length 1e-9`` a wall of 1 nm blocks, both run
without a word (the area bounds of :mod:`geometry_library.checks` are per block and far looser)."""


def check_dimensions(label: str, **values) -> None:
    """:func:`check_positive`, then each value within ``DIMENSION_RANGE``."""
    check_positive(label, **values)
    lo, hi = DIMENSION_RANGE
    for key, value in values.items():
        if not lo <= value <= hi:
            raise GeometryError(
                f"{label}: {key} {_g(value)} m is absurd (a likely typo: {lo:g} to {hi:g} m)", keys=(key,)
            )


MAX_BLOCKS = 100_000
"""Most blocks a builder makes: more is a likely typo (``--blocks 100000000`` used to build for minutes
and fill the memory before anything was said). The largest benchmark wall has 3996 blocks."""


def check_block_total(label: str, total: int, what: str = "", bound: bool = False, keys: tuple[str, ...] = ()) -> None:
    """Raise a one-line GeometryError when ``what`` (the options, for the message; ``keys``, their names)
    makes more than :data:`MAX_BLOCKS` blocks (``bound``: ``total`` is an upper bound of the count)."""
    if total > MAX_BLOCKS:
        makes = f"{what} makes up to " if bound else f"{what} makes " if what else ""
        raise GeometryError(f"{label}: {makes}{total} blocks, more than {MAX_BLOCKS} (a likely typo)", keys=keys)


def check_count(label: str, minimum: int = 1, **values) -> None:
    """Raise a one-line GeometryError unless every value is an integer ≥ ``minimum``."""
    for key, value in values.items():
        if number_problem(value, integer=True, ge=minimum) is not None:
            raise GeometryError(f"{label}: {key} must be an integer ≥ {minimum}, got {value!r}", keys=(key,))


MAX_CARRIED = 1e6
"""The most mass a block may carry (``Block.carried_mass``), in times its own: a fill 20 m deep over a 0.2 m
voussoir is 80 times. Beyond, a likely typo: a 1 m block carrying 1e300 kg ran and was reported "collapsed at
t = 0.001 s", and ``limit`` said "no collapse: unbounded"."""


def check_carried(label: str, block, own_mass: float, centroid) -> None:
    """Raise a one-line GeometryError unless ``block``'s carried mass is at most :data:`MAX_CARRIED` times
    ``own_mass`` (kg) and lumped within ``DIMENSION_RANGE[1]`` of its ``centroid`` (a fill column stands over
    its block: ``carried_at`` at 1e9 m lumped a mass a million km away, tipping the block, without a word)."""
    mass, at = block.carried_mass, block.carried_at
    if number_problem(mass, ge=0.0) is not None or not mass <= MAX_CARRIED * own_mass:
        raise GeometryError(
            f"{label}: carried_mass {_g(mass)} kg is absurd (a likely typo: at most {MAX_CARRIED:g} times the "
            f"block's own {own_mass:.4g} kg)",
            keys=("carried_mass",),
        )
    if mass == 0.0:
        return
    if at is None:
        raise GeometryError(
            f"{label}: carried_mass {_g(mass)} kg without carried_at (where it rides)", keys=("carried_at",)
        )
    reach = math.hypot(float(at[0]) - float(centroid[0]), float(at[1]) - float(centroid[1]))
    if not reach <= DIMENSION_RANGE[1]:
        raise GeometryError(
            f"{label}: carried_at ({_g(at[0])}, {_g(at[1])}) m is {reach:.3g} m from the block's centroid, absurd "
            f"(a likely typo: a carried fill rides within {DIMENSION_RANGE[1]:g} m of its block)",
            keys=("carried_at",),
        )
