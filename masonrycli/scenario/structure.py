"""The structure of a scenario: blocks and supports from a builder spec or a geometry file, checked.

``build_structure`` checks TOML / command-line options against the builder's spec dataclass
(``geometry_library.builders.BUILDERS``) and builds it; ``read_geometry`` reads a GeoJSON or WKT file;
``structure_warnings`` runs ``geometry_library.assembly_checks.validate_assembly``. Problems raise a one-line
:class:`~masonrycli.errors.InputError`.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import os
import re
from pathlib import Path

from geometry_library.blocks import Assembly, GeometryError
from geometry_library.values import SETTING_UNITS, TypedNumber, number_problem
from masonrycli.errors import InputContext, InputError, not_a_file, one_line
from masonrycli.scenario.values import did_you_mean, field_error, option_text, quote_string

GEOMETRY_SUFFIXES = (".geojson", ".json", ".wkt")


def read_geometry(
    path: str,
    density: float,
    thickness: float,
    ctx: InputContext,
    where: str = "[structure]",
    notes=None,
    survey=None,
    reading: dict | None = None,
) -> Assembly:
    """Blocks and supports of a GeoJSON or WKT file (``geometry_library.io``), with ``density`` and
    ``thickness`` (the material's) as defaults. ``where`` is the table naming the file ("" when the file
    is the scenario itself: ``masonry run wall.geojson``). ``notes``: a list given receives the one-line
    warning of :func:`unread_properties_warning`, if any, and the reader's notes (a map grid's coordinates moved
    near the origin, ``survey``'s hulls and trims: :mod:`geometry_library.survey`). ``reading``: a dict given
    receives what the file was read as (``survey.reading_record``: the map shift, units, hulls, trims), which a
    run's parameters record."""
    from geometry_library import io as geo_io
    from geometry_library import wkt as geo_wkt
    from geometry_library.survey import Survey

    survey = Survey() if survey is None else survey  # the default reading too: a map grid's file is moved

    suffix = Path(path).suffix.lower()
    if suffix not in GEOMETRY_SUFFIXES:
        raise ctx.error(
            where,
            f"file = {quote_string(path)}: unknown geometry format (expected {', '.join(GEOMETRY_SUFFIXES)})",
        )
    if not os.path.isfile(path):
        missing = not_a_file(path)
        raise ctx.error(where, f"file = {quote_string(path)}: {missing}" if where else missing)
    unknown: dict = {}
    said: list[str] = []
    try:
        if suffix == ".wkt":
            assembly = geo_wkt.read_wkt(path, density=density, thickness=thickness, survey=survey, notes=said)
        else:
            assembly = geo_io.read_geojson(
                path, density=density, thickness=thickness, unknown=unknown, survey=survey, notes=said
            )
        if unknown and notes is not None:
            notes.append(unread_properties_warning(path, unknown, geo_io.GEOJSON_PROPERTIES))
        if notes is not None:
            notes.extend(said)
        if reading is not None:
            reading.update(survey.done)
        return assembly
    except (GeometryError, ValueError) as exc:
        msg = one_line(exc)
        if "not convex" in msg and not getattr(survey, "convex_hull", False):  # the option, or the scenario's key
            msg += HULL_HINT if not where else "; convex_hull = true (in [structure]) reads it as its convex hull"
        if not where and msg.startswith(f"{path}:"):  # the reader named the file already
            raise InputError(msg) from None
        raise ctx.error(where, msg) from None


SURVEY_FLAGS = {
    "units": "--units",
    "flip_y": "--flip-y",
    "convex_hull": "--convex-hull",
    "trim_overlaps": "--trim-overlaps",
}


def survey_keys(table: dict, ctx: InputContext):
    """The :class:`~geometry_library.survey.Survey` of a scenario file's ``[structure]`` keys beside ``file``
    (``units``, ``flip_y``, ``convex_hull``, ``trim_overlaps``: the command line's options, which read a file run
    as it is), the default one when none is given; a wrong value is refused naming its key."""
    from geometry_library.survey import Survey, unit_scale

    given = {k: table[k] for k in SURVEY_FLAGS if k in table}
    for key in ("flip_y", "convex_hull"):
        if key in given and not isinstance(given[key], bool):
            raise ctx.error("[structure]", f"{key} = {given[key]!r}: must be true or false")
    if "units" in given:
        given["units"] = str(given["units"]) if not isinstance(given["units"], bool) else ""
        if unit_scale(given["units"]) is None:
            raise ctx.error("[structure]", f"units = {table['units']!r}: must be m, cm, mm or metres per unit (0.002)")
    depth = given.get("trim_overlaps")
    if depth is not None and (isinstance(depth, bool) or not isinstance(depth, (int, float)) or not 0 < depth <= 0.1):
        raise ctx.error("[structure]", f"trim_overlaps = {depth!r}: must be a number in (0, 0.1] m (0.003: 3 mm)")
    return Survey(**given)


def survey_of(options: dict, target: str):
    """The :class:`geometry_library.survey.Survey` of the command line's options reading a geometry file
    (None when none is given); given for a target that is no GeoJSON / WKT file, they are refused."""
    from geometry_library.survey import UNITS, Survey, unit_scale

    given = {k: v for k, v in options.items() if v is not None and v is not False}
    if not given:
        return None
    flags = " and ".join(SURVEY_FLAGS[k] for k in given)
    if Path(target).suffix.lower() not in GEOMETRY_SUFFIXES:
        raise InputError(f"{flags}: read{'s' if len(given) == 1 else ''} a GeoJSON / WKT file; {target} is not one")
    if unit_scale(given.get("units", "m")) is None:
        raise InputError(
            f"--units {given['units']}: expected one of {', '.join(UNITS)} or metres per unit in (0, 1000] (a "
            "photograph's pixels of 2 mm: 0.002)"
        )
    depth = given.get("trim_overlaps")
    if depth is not None and not (math.isfinite(depth) and 0.0 < depth <= 0.1):
        raise InputError(
            f"--trim-overlaps {depth:g}: must be in (0, 0.1] m, the deepest overlap a tracing slip makes (0.003: 3 mm)"
        )
    return Survey(**given)


_MISPLACED = {  # a property read on the other role's bodies (geometry_library.io): why it was not read here
    "density": " (read on blocks only: a support has no mass)",
    "thickness": " (read on blocks only: a support has no mass)",
    "velocity": " (read on blocks only: a support moves by a scenario file's [[support]] motion)",
    "support_role": " (read on supports only)",
    "carried_mass": " (read on blocks only: a support carries nothing)",
    "carried_at": " (read on blocks only: a support carries nothing)",
}


def unread_properties_warning(path: str, unknown: dict, known) -> str:
    """One line for the GeoJSON properties the reader does not use (``unknown``: key → first body): a
    per-block ``friction`` or a misspelt ``densty`` was ignored without a word, the run using the defaults,
    and so was a support's ``velocity`` (a block's property: the support stayed fixed)."""
    items = []
    for key, first in unknown.items():
        hint = _MISPLACED.get(key) or did_you_mean(key, known)
        if ", fill " in first and key in _MISPLACED:  # a traced fill's: not a support's reason
            hint = " (a fill takes role, name and density only)"
        if not hint and str(key).lower() == "friction":  # one coefficient for every contact, not a block's
            hint = " (friction is the scenario file's [material] friction, one for every contact)"
        items.append(f"{quote_string(str(key))}{hint} first on {first}")
    return f"{path}: properties not used, ignored (used: {', '.join(known)}): {'; '.join(items)}"


TRIM_HINT = (
    "; a slip of the tracing? --trim-overlaps 0.003 cuts neighbours overlapping up to 3 mm where their outlines cross"
)
HULL_HINT = "; --convex-hull reads a slightly non-convex stone as its convex hull"


def structure_warnings(assembly: Assembly, ctx: InputContext, as_run: bool = False) -> tuple[str, ...]:
    """``validate_assembly``: its errors raised at ``ctx``, its warnings on one line each. ``as_run``: a
    geometry file run as it is, whose overlap is refused with the option that trims a tracing slip."""
    from geometry_library.assembly_checks import validate_assembly

    try:
        warnings = validate_assembly(assembly)
    except GeometryError as exc:
        hint = TRIM_HINT if as_run and " overlap by " in str(exc) else ""
        raise ctx.error("", str(exc) + hint) from None
    return tuple(one_line(w) for w in (warnings or ()))


def check_finite_tree(key: str, value):
    """Reject NaN/inf anywhere inside a TOML value (builder options)."""
    if isinstance(value, float) and not math.isfinite(value):
        raise field_error(key, value, "must be a finite number")
    if isinstance(value, list):
        for i, v in enumerate(value):
            check_finite_tree(f"{key}[{i}]", v)
    if isinstance(value, dict):
        for k, v in value.items():
            check_finite_tree(f"{key}.{k}", v)


def _freeze(value):
    """TOML lists -> tuples (recursively), for builder options."""
    if isinstance(value, list):
        return tuple(_freeze(v) for v in value)
    if isinstance(value, dict):
        return {k: _freeze(v) for k, v in value.items()}
    return value


_OPTION_TYPES = {  # spec field annotation (spaces removed) -> what a TOML / CLI value must be
    "float": "number",
    "float|None": "number",
    "int": "int",
    "int|None": "int",
    "bool": "bool",
    "str": "str",
}


def _check_option_type(key: str, value, spec_field: dataclasses.Field):
    """Light type check of a builder option against its spec field (the builder validates ranges itself)."""
    ann = spec_field.type if isinstance(spec_field.type, str) else spec_field.type.__name__
    ann = ann.replace(" ", "")
    if value is None and (spec_field.default is None or "None" in ann):
        return value  # programmatic callers may pass None where the builder accepts it
    expected = _OPTION_TYPES[ann]
    if expected in ("number", "int"):  # the wording of every numeric setting ('not a string' for "1.2")
        problem = number_problem(value, integer=expected == "int", allow_inf=True, unit=SETTING_UNITS.get(key))
        if problem is not None:
            raise field_error(key, value, problem)
        if expected == "number":  # an option's TypedNumber kept: the builder's message echoes it as typed
            return value if type(value) is TypedNumber else float(value)
        return value
    if expected == "bool" and not isinstance(value, bool):
        raise field_error(key, value, "must be true or false")
    if expected == "str" and not isinstance(value, str):
        raise field_error(key, value, "must be a string")
    return value


class BuilderError(InputError):
    """``builder "arch": <problem>``, with the builder options the problem is about (``keys``, maybe none),
    for a caller that names them as the user gave them (:func:`as_options`; a file adds its line)."""

    def __init__(self, builder: str, problem: str, keys: tuple[str, ...] = (), named: bool = True):
        super().__init__(f'builder "{builder}": {problem}' if named else problem)  # named: the builder's name first
        self.builder, self.problem, self.keys, self.named = builder, problem, tuple(keys), named

    def __reduce__(self):  # pickled with its fields (a sweep's worker sends it back): not as InputError(str)
        return BuilderError, (self.builder, self.problem, self.keys, self.named)


def as_options(exc: BuilderError, given: dict) -> InputError:
    """``exc`` naming the command-line options it is about, when ``given`` (builder option -> value, from the
    command line) holds them: ``--ring-thickness 0.0001 m is absurd (…)``, ``--blocks 0: must be a positive
    integer``, ``--courses and --length: …`` ('builder "arch": ring_thickness 0.0001 m …' named a key the user
    never typed). Else ``exc`` unchanged (a problem of no option, or of a default the user did not give)."""
    keys = [k for k in exc.keys if k in given]
    if not keys:
        return exc
    key = keys[0]
    flag = "--" + key.replace("_", "-")
    # a value's problem as the options' ("--courses 0: must be a positive integer"; it said "--courses must be a
    # positive integer, got 0", which the API spelled "courses= must be …")
    if len(keys) == 1 and (bad := re.fullmatch(rf"(?:[a-z]+: )?{key} (must be .+), got .+", exc.problem)):  # "arch: "
        return InputError(f"{flag} {option_text(given[key])}: {bad[1]}")
    if len(keys) == 1 and exc.problem.startswith(f"{key} ") and not exc.problem.startswith(f"{key} = "):
        return InputError(f"{flag} {_flags(exc, exc.problem[len(key) + 1 :])}")  # "ring_thickness 0.0001 m is absurd"
    flags = " and ".join("--" + k.replace("_", "-") for k in keys)
    return InputError(f"{flags}: {_flags(exc, exc.problem)}")


def _flags(exc: BuilderError, text: str) -> str:
    """``text`` with the builder's other option keys it names as options: '--fill-density without --fill-to or
    --fill-cover' (it said 'without fill_to or fill_cover', the file's keys, on the command line)."""
    from geometry_library.builders import BUILDERS

    names = {f.name for f in dataclasses.fields(BUILDERS[exc.builder])} if exc.builder in BUILDERS else set()
    return re.sub(r"\b[a-z]+(?:_[a-z]+)+\b", lambda m: "--" + m[0].replace("_", "-") if m[0] in names else m[0], text)


def build_structure(builder: str, options: dict, density: float, thickness: float) -> Assembly:
    """``BUILDERS[builder](**options).build()``; errors become InputError ``key = value: problem``.

    ``density`` and ``thickness`` (the material's) are passed to the builder unless ``options`` sets them.
    """
    from geometry_library.builders import BUILDERS

    if builder not in BUILDERS:
        raise field_error("builder", builder, f"unknown builder (expected one of {', '.join(sorted(BUILDERS))})")
    spec_cls = BUILDERS[builder]
    params = {f.name: f for f in dataclasses.fields(spec_cls)}
    kwargs = {}
    for key, value in options.items():
        if key not in params:
            close = difflib.get_close_matches(key, list(params), n=1)
            hint = f'did you mean "{close[0]}"?' if close else f"options: {', '.join(params) or 'none'}"
            raise InputError(f'unknown option {quote_string(key)} of builder "{builder}" ({hint})')
        try:
            kwargs[key] = _check_option_type(key, _freeze(value), params[key])
        except InputError as exc:
            raise BuilderError(builder, str(exc), (key,), named=False) from None  # "[structure] key = …" in a file
    for key, value in (("density", density), ("thickness", thickness)):
        if key in params and key not in kwargs:
            kwargs[key] = value
    try:
        assembly = spec_cls(**kwargs).build()
    except ValueError as exc:  # GeometryError, InputError, bad values; a TypeError is a bug: not hidden
        msg = one_line(exc)  # the builders' messages start with their name: not twice ('builder "wall": wall: …')
        msg = msg[len(builder) + 2 :] if msg.startswith(f"{builder}: ") else msg
        raise BuilderError(builder, msg, getattr(exc, "keys", ())) from None
    if not isinstance(assembly, Assembly):
        raise InputError(f'builder "{builder}" returned {type(assembly).__name__}, not an Assembly')
    return assembly
