"""Scenarios: what to simulate (structure, material, support motions) and how (time stepping, solver).

A :class:`Scenario` is built either from a TOML scenario file (:func:`load_scenario`, format in
``docs/scenario-format.md``) or from a named builder of ``geometry_library.builders``
(:func:`scenario_from_builder`, used by ``masonry simulate wall ...``). :func:`masonrycli.scenario_toml.dump_scenario` writes the
TOML back (explicit blocks), :func:`scenario_summary` gives the numbers ``masonry check`` prints.

Every problem with the input raises :class:`masonrycli.errors.InputError` with a one-line message naming
the file and the key, e.g. ``wall.toml: [run] dt = -0.001: must be > 0``.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from geometry_library.blocks import Assembly, Block, GeometryError, Support
from masonrycli.errors import InputError
from masonrycli.motion import MOTION_KINDS, Fixed, Motion
from masonrycli.records import load_record_csv
from masonrycli.values import check_real, check_vector, field_error, format_value, is_real, quote_string

MAX_DURATION = 1e5
"""s — longer runs are refused as a likely typo."""
MAX_STEPS = 10**9
MAX_COUNT = 10**9

TOP_LEVEL_KEYS = ("name", "run", "material", "structure", "block", "support")
BLOCK_KEYS = ("name", "polygon", "density", "thickness", "velocity")
SUPPORT_KEYS = ("name", "polygon", "motion")
BUILDER_SUPPORT_KEYS = ("name", "motion")

ALL_MOTION_KEYS = tuple(dict.fromkeys(k for cls in MOTION_KINDS.values() for k in cls.TOML_KEYS))


# --------------------------------------------------------------------------------------------------
# configuration dataclasses


def _check_int(key: str, value, *, ge: int, le: int = MAX_COUNT) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise field_error(key, value, "must be an integer")
    v = int(value)
    if v < ge:
        raise field_error(key, value, f"must be >= {ge}")
    if v > le:
        raise field_error(key, value, f"must be <= {le}")
    return v


@dataclass(frozen=True)
class RunConfig:
    """Time stepping and solver settings.

    duration : s, simulated time (0 < duration <= 1e5).
    dt : s, time step (0 < dt <= duration).
    theta : Moreau–Jean θ, in [0.5, 1].
    gravity : (gx, gy) m/s², a vector (tilt it for tilting tests).
    tolerance : NLGS convergence tolerance (relative quadratic norm of the impulse change), in (0, 1).
    max_iterations : NLGS sweep cap per step, >= 1.
    record_every : record one frame every this many steps, >= 1.
    alert_distance : m, contacts with a gap below this are kept, > 0.
    """

    duration: float = 1.0
    dt: float = 1e-3
    theta: float = 0.5
    gravity: tuple[float, float] = (0.0, -9.81)
    tolerance: float = 1.666e-4
    max_iterations: int = 1000
    record_every: int = 10
    alert_distance: float = 1e-3

    def __post_init__(self):
        put = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        put("duration", check_real("duration", self.duration, gt=0.0, le=MAX_DURATION))
        put("dt", check_real("dt", self.dt, gt=0.0))
        if self.dt > self.duration:
            raise field_error("dt", self.dt, f"must be <= duration ({format_value(self.duration)})")
        if self.duration / self.dt > MAX_STEPS:
            raise field_error(
                "dt",
                self.dt,
                f"gives {self.duration / self.dt:.3g} steps for duration "
                f"{format_value(self.duration)} (at most {MAX_STEPS:.0e})",
            )
        put("theta", check_real("theta", self.theta, ge=0.5, le=1.0))
        put("gravity", check_vector("gravity", self.gravity))
        put("tolerance", check_real("tolerance", self.tolerance, gt=0.0, lt=1.0))
        put("max_iterations", _check_int("max_iterations", self.max_iterations, ge=1))
        put("record_every", _check_int("record_every", self.record_every, ge=1))
        put("alert_distance", check_real("alert_distance", self.alert_distance, gt=0.0))

    @property
    def n_steps(self) -> int:
        """Number of time steps, round(duration / dt)."""
        return max(1, round(self.duration / self.dt))


@dataclass(frozen=True)
class Material:
    """Defaults for every block, and the friction of every contact.

    density : kg/m³, > 0.  thickness : m, out of plane, > 0.  friction : Coulomb μ, >= 0.
    """

    density: float = 2500.0
    thickness: float = 1.0
    friction: float = 0.6

    def __post_init__(self):
        object.__setattr__(self, "density", check_real("density", self.density, gt=0.0))
        object.__setattr__(self, "thickness", check_real("thickness", self.thickness, gt=0.0))
        object.__setattr__(self, "friction", check_real("friction", self.friction, ge=0.0))


@dataclass(frozen=True, eq=False)
class Scenario:
    """Everything one run needs.

    name : label of the run (recording names, summaries).
    run : :class:`RunConfig`.  material : :class:`Material`.
    assembly : blocks and supports (``geometry_library.blocks.Assembly``).
    motions : one :class:`~masonrycli.motion.Motion` per support, in ``assembly.supports`` order.
    source : scenario file path, or ``"builder:<name>"``.
    structure : ``{"builder": name, **options}`` for builder scenarios, else ``{}``.
    warnings : non-fatal remarks from ``geometry_library.checks.validate_assembly``.

    Each support's ``role`` is made consistent with its motion (``"driven"`` unless the motion is fixed).
    """

    name: str
    run: RunConfig
    material: Material
    assembly: Assembly
    motions: tuple[Motion, ...]
    source: str = ""
    structure: dict = field(default_factory=dict)
    warnings: tuple[str, ...] = ()

    def __post_init__(self):
        motions = tuple(self.motions)
        object.__setattr__(self, "motions", motions)
        object.__setattr__(self, "warnings", tuple(self.warnings))
        if len(motions) != self.assembly.support_count:
            raise InputError(
                f"scenario {self.name!r}: {len(motions)} motions for {self.assembly.support_count} supports "
                "(one motion per support, same order)"
            )
        if not all(isinstance(m, Motion) for m in motions):
            raise InputError(f"scenario {self.name!r}: motions must be Motion objects")
        if any(s.role != m.role for s, m in zip(self.assembly.supports, motions)):
            supports = tuple(
                s if s.role == m.role else dataclasses.replace(s, role=m.role)
                for s, m in zip(self.assembly.supports, motions)
            )
            object.__setattr__(self, "assembly", Assembly(blocks=self.assembly.blocks, supports=supports))

    @property
    def block_count(self) -> int:
        return self.assembly.block_count

    @property
    def support_count(self) -> int:
        return self.assembly.support_count

    @property
    def friction(self) -> float:
        return self.material.friction


# --------------------------------------------------------------------------------------------------
# loading


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _unknown_key(key, known) -> str:
    close = difflib.get_close_matches(str(key), list(known), n=1)
    hint = f' (did you mean "{close[0]}"?)' if close else f" (expected one of: {', '.join(known)})"
    return f"unknown key {quote_string(str(key))}{hint}"


def _check_name(key: str, value) -> str:
    if not isinstance(value, str):
        raise field_error(key, value, "must be a string")
    if not value.strip():
        raise field_error(key, value, "must not be empty")
    if any(ord(c) < 0x20 or ord(c) == 0x7F for c in value):
        raise field_error(key, value, "must not contain control characters")
    return value


def _check_finite_tree(key: str, value):
    """Reject NaN/inf anywhere inside a TOML value (builder options)."""
    if isinstance(value, float) and not math.isfinite(value):
        raise field_error(key, value, "must be a finite number")
    if isinstance(value, list):
        for i, v in enumerate(value):
            _check_finite_tree(f"{key}[{i}]", v)
    if isinstance(value, dict):
        for k, v in value.items():
            _check_finite_tree(f"{key}.{k}", v)


def _freeze(value):
    """TOML lists -> tuples (recursively), for builder options."""
    if isinstance(value, list):
        return tuple(_freeze(v) for v in value)
    if isinstance(value, dict):
        return {k: _freeze(v) for k, v in value.items()}
    return value


class _Ctx:
    """Where we are in the file, for error messages."""

    def __init__(self, fname: str, base_dir: str):
        self.fname = fname
        self.base_dir = base_dir

    def error(self, where: str, message: str) -> InputError:
        where = f"{where} " if where else ""
        return InputError(_one_line(f"{self.fname}: {where}{message}"))


def load_scenario(path) -> Scenario:
    """Read a TOML scenario file (format: ``docs/scenario-format.md``).

    Relative record ``file`` paths are resolved against the scenario file's folder.
    Raises :class:`InputError` (one line naming the file and the key) on any problem.
    """
    fname = os.fspath(path)
    try:
        raw = Path(fname).read_bytes()
    except IsADirectoryError:
        raise InputError(f"{fname}: cannot read scenario: is a directory") from None
    except OSError as exc:
        raise InputError(_one_line(f"{fname}: cannot read scenario: {exc.strerror or exc}")) from None
    try:
        text = raw.decode("utf-8-sig")  # tolerate the byte-order mark some Windows editors add
    except UnicodeDecodeError as exc:
        raise InputError(f"{fname}: not a UTF-8 text file (byte {exc.start})") from None
    base_dir = os.path.dirname(os.path.abspath(fname))
    return loads_scenario(text, source=fname, base_dir=base_dir, default_name=Path(fname).stem)


def loads_scenario(
    text: str, source: str = "<string>", base_dir: str | os.PathLike = ".", default_name: str = "scenario"
) -> Scenario:
    """Parse scenario TOML ``text``. ``source`` names it in error messages; ``base_dir`` resolves
    relative record files."""
    ctx = _Ctx(os.fspath(source), os.path.abspath(os.fspath(base_dir)))
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ctx.error("", f"TOML syntax error: {exc}") from None
    return _parse_document(doc, ctx, default_name)


def _table(doc: dict, key: str, ctx: _Ctx) -> dict:
    value = doc.get(key, {})
    if not isinstance(value, dict):
        raise ctx.error("", f"{key} = {format_value(value)[:40]}: must be a table [{key}]")
    return value


def _array_of_tables(doc: dict, key: str, ctx: _Ctx) -> list:
    value = doc.get(key, [])
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise ctx.error("", f"{key}: must be an array of tables [[{key}]]")
    return value


def _config(cls, table: dict, ctx: _Ctx, section: str):
    names = [f.name for f in dataclasses.fields(cls)]
    for key in table:
        if key not in names:
            raise ctx.error(f"[{section}]", _unknown_key(key, names))
    try:
        return cls(**table)
    except InputError as exc:
        raise ctx.error(f"[{section}]", str(exc)) from None


def _parse_document(doc: dict, ctx: _Ctx, default_name: str) -> Scenario:
    for key in doc:
        if key not in TOP_LEVEL_KEYS:
            raise ctx.error("", _unknown_key(key, TOP_LEVEL_KEYS))
    try:
        name = _check_name("name", doc["name"]) if "name" in doc else default_name
    except InputError as exc:
        raise ctx.error("", str(exc)) from None
    run = _config(RunConfig, _table(doc, "run", ctx), ctx, "run")
    material = _config(Material, _table(doc, "material", ctx), ctx, "material")
    block_tables = _array_of_tables(doc, "block", ctx)
    support_tables = _array_of_tables(doc, "support", ctx)

    if "structure" in doc:
        structure = _table(doc, "structure", ctx)
        if block_tables:
            raise ctx.error(
                _locator("block", 1, block_tables[0], "block-1"),
                "not allowed together with a [structure] builder or file (use either explicit blocks or a [structure])",
            )
        if "file" in structure:
            extra = [k for k in structure if k != "file"]
            if extra:
                raise ctx.error(
                    "[structure]",
                    f"{extra[0]}: not allowed with file = ... (a geometry file brings its own blocks and supports)",
                )
            file = structure["file"]
            if not isinstance(file, str):
                raise ctx.error("[structure]", f"file = {format_value(file)[:40]}: must be a string")
            path = os.path.abspath(os.path.join(ctx.base_dir, file))
            assembly = _read_geometry(path, material, ctx)
            what = f"file {quote_string(file)}"
            structure_info = {"file": path}
        else:
            if "builder" not in structure:
                raise ctx.error("[structure]", 'builder: missing (e.g. builder = "wall", or file = "my-wall.geojson")')
            builder = structure["builder"]
            if not isinstance(builder, str):
                raise ctx.error("[structure]", f"builder = {format_value(builder)[:40]}: must be a string")
            options = {k: v for k, v in structure.items() if k != "builder"}
            for key, value in options.items():
                try:
                    _check_finite_tree(key, value)
                except InputError as exc:
                    raise ctx.error("[structure]", str(exc)) from None
            try:
                assembly = _call_builder(builder, options, material)
            except InputError as exc:
                raise ctx.error("[structure]", str(exc)) from None
            structure_info = {"builder": builder, **options}
            what = f'builder "{builder}"'
        motions_by_support = {}
        known = [s.name for s in assembly.supports]
        for i, table in enumerate(support_tables, start=1):
            loc = _locator("support", i, table, None)
            for key in table:
                if key not in BUILDER_SUPPORT_KEYS:
                    if key in SUPPORT_KEYS:
                        raise ctx.error(
                            loc,
                            f"{key}: not allowed with a [structure] "
                            f"({what} makes the supports; give only name and motion)",
                        )
                    raise ctx.error(loc, _unknown_key(key, BUILDER_SUPPORT_KEYS))
            if "name" not in table:
                raise ctx.error(loc, f"name: missing ({what} supports: {', '.join(known)})")
            sname = table["name"]
            if sname not in known:
                raise ctx.error(
                    loc,
                    f"name = {format_value(sname)[:40]}: no such support in {what} "
                    f"(supports: {', '.join(known) or 'none'})",
                )
            if sname in motions_by_support:
                raise ctx.error(loc, f"name = {quote_string(sname)}: support given twice")
            motions_by_support[sname] = _parse_motion(table.get("motion"), ctx, loc)
        motions = tuple(motions_by_support.get(s.name, Fixed()) for s in assembly.supports)
    else:
        blocks = []
        names: dict[str, str] = {}
        for i, table in enumerate(block_tables, start=1):
            blocks.append(_parse_block(i, table, material, ctx, names))
        if not blocks:
            raise ctx.error("", "no blocks: add [[block]] tables or a [structure] builder")
        supports, motions_list = [], []
        for i, table in enumerate(support_tables, start=1):
            support, motion = _parse_support(i, table, ctx, names)
            supports.append(support)
            motions_list.append(motion)
        assembly = Assembly(blocks=tuple(blocks), supports=tuple(supports))
        motions = tuple(motions_list)
        structure_info = {}

    warnings = _validate(assembly, ctx)
    return Scenario(
        name=name,
        run=run,
        material=material,
        assembly=assembly,
        motions=motions,
        source=ctx.fname,
        structure=structure_info,
        warnings=warnings,
    )


GEOMETRY_SUFFIXES = (".geojson", ".json", ".wkt")


def _read_geometry(path: str, material: Material, ctx: _Ctx) -> Assembly:
    """Blocks and supports of a GeoJSON or WKT file (``geometry_library.io``), with the material's
    density and thickness as defaults."""
    from geometry_library import io as geo_io

    suffix = Path(path).suffix.lower()
    if suffix not in GEOMETRY_SUFFIXES:
        raise ctx.error(
            "[structure]",
            f"file = {quote_string(path)}: unknown geometry format (expected {', '.join(GEOMETRY_SUFFIXES)})",
        )
    if not os.path.isfile(path):
        raise ctx.error("[structure]", f"file = {quote_string(path)}: no such file")
    reader = geo_io.read_wkt if suffix == ".wkt" else geo_io.read_geojson
    try:
        return reader(path, density=material.density, thickness=material.thickness)
    except (GeometryError, ValueError) as exc:
        raise ctx.error("[structure]", _one_line(exc)) from None


def scenario_from_geometry_file(path) -> Scenario:
    """A scenario with default run and material settings for a GeoJSON / WKT file: every support fixed.

    ``masonry run my-wall.geojson`` uses it; for motions or other settings, write a scenario file with
    ``[structure] file = "my-wall.geojson"``.
    """
    path = os.fspath(path)
    ctx = _Ctx(path, os.path.dirname(os.path.abspath(path)))
    material = Material()
    assembly = _read_geometry(os.path.abspath(path), material, ctx)
    warnings = _validate(assembly, ctx)
    return Scenario(
        name=Path(path).stem,
        run=RunConfig(),
        material=material,
        assembly=assembly,
        motions=tuple(Fixed() for _ in assembly.supports),
        source=path,
        structure={"file": os.path.abspath(path)},
        warnings=warnings,
    )


def _locator(section: str, index: int, table: dict, default_name: str | None) -> str:
    name = table.get("name", default_name)
    if isinstance(name, str) and name and not any(ord(c) < 0x20 for c in name):
        return f"[[{section}]] #{index} ({quote_string(name)}):"
    return f"[[{section}]] #{index}:"


def _check_polygon(value) -> list[tuple[float, float]]:
    if not isinstance(value, list) or not all(isinstance(v, list) for v in value):
        raise field_error("polygon", value, "must be a list of [x, y] vertices")
    coords = [check_vector(f"polygon[{j}]", v) for j, v in enumerate(value)]
    if len(coords) < 3:
        raise field_error("polygon", value, f"needs at least 3 vertices, got {len(coords)}")
    return coords


def _polygon(coords, index: int, name: str, kind: str, ctx: _Ctx, loc: str):
    """geometry_library's normalised convex polygon; its GeometryError becomes an InputError at ``loc``.

    ``index`` is 0-based (geometry_library's convention); the body label geometry_library puts in front
    of its message is replaced by our ``[[block]] #i ("name"):`` locator.
    """
    from geometry_library import checks

    try:
        return checks.polygon_from_coords(coords, index, name, kind)
    except GeometryError as exc:
        msg = str(exc).removeprefix(f"{checks.body_label(index, name, kind)}: ")
        raise ctx.error(loc, msg) from None


def _check_unique(name: str, loc: str, names: dict, ctx: _Ctx):
    if name in names:
        raise ctx.error(loc, f"name = {quote_string(name)}: already used by {names[name]} (names must be unique)")
    names[name] = loc.rstrip(":")


def _parse_block(i: int, table: dict, material: Material, ctx: _Ctx, names: dict) -> Block:
    default_name = f"block-{i}"
    loc = _locator("block", i, table, default_name)
    for key in table:
        if key not in BLOCK_KEYS:
            raise ctx.error(loc, _unknown_key(key, BLOCK_KEYS))
    try:
        name = _check_name("name", table.get("name", default_name))
        if "polygon" not in table:
            raise InputError("polygon: missing (e.g. polygon = [[0.0, 0.0], [0.4, 0.0], [0.4, 0.2], [0.0, 0.2]])")
        coords = _check_polygon(table["polygon"])
        density = check_real("density", table.get("density", material.density), gt=0.0)
        thickness = check_real("thickness", table.get("thickness", material.thickness), gt=0.0)
        velocity = check_vector("velocity", table.get("velocity", (0.0, 0.0, 0.0)), size=3)
    except InputError as exc:
        raise ctx.error(loc, str(exc)) from None
    _check_unique(name, loc, names, ctx)
    polygon = _polygon(coords, i - 1, name, "block", ctx, loc)
    return Block(polygon=polygon, name=name, density=density, thickness=thickness, velocity=velocity)


def _parse_support(i: int, table: dict, ctx: _Ctx, names: dict) -> tuple[Support, Motion]:
    default_name = f"support-{i}"
    loc = _locator("support", i, table, default_name)
    for key in table:
        if key not in SUPPORT_KEYS:
            raise ctx.error(loc, _unknown_key(key, SUPPORT_KEYS))
    try:
        name = _check_name("name", table.get("name", default_name))
        if "polygon" not in table:
            raise InputError("polygon: missing (e.g. polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]])")
        coords = _check_polygon(table["polygon"])
    except InputError as exc:
        raise ctx.error(loc, str(exc)) from None
    _check_unique(name, loc, names, ctx)
    polygon = _polygon(coords, i - 1, name, "support", ctx, loc)
    motion = _parse_motion(table.get("motion"), ctx, loc)
    return Support(polygon=polygon, name=name, role=motion.role), motion


def _parse_motion(table, ctx: _Ctx, loc: str) -> Motion:
    """A ``motion = {...}`` table -> Motion (None -> fixed)."""
    if table is None:
        return Fixed()
    if not isinstance(table, dict):
        raise ctx.error(
            loc,
            f"motion = {format_value(table)[:40]}: must be a table, e.g. "
            'motion = { kind = "sine", amplitude = 1.0, frequency = 2.0 }',
        )
    for key in table:
        if key not in ALL_MOTION_KEYS:
            raise ctx.error(loc, "motion: " + _unknown_key(key, ALL_MOTION_KEYS))
    if "kind" not in table:
        raise ctx.error(loc, f"motion.kind: missing (one of {', '.join(MOTION_KINDS)})")
    kind = table["kind"]
    if not isinstance(kind, str) or kind not in MOTION_KINDS:
        raise ctx.error(
            loc,
            f"motion.kind = {format_value(kind)[:40]}: unknown motion kind (expected one of {', '.join(MOTION_KINDS)})",
        )
    cls = MOTION_KINDS[kind]
    allowed = cls.TOML_KEYS
    for key in table:
        if key not in allowed:
            raise ctx.error(loc, f'motion.{key}: not used by kind "{kind}" (its keys: {", ".join(allowed)})')
    for key in cls.TOML_REQUIRED:
        if key not in table:
            raise ctx.error(loc, f'motion.{key}: missing (required for kind "{kind}")')

    args = {k: v for k, v in table.items() if k not in ("kind", "file", "time", "value")}
    if kind == "record":
        args.update(_record_data(table, ctx, loc))
    try:
        return cls(**args)
    except InputError as exc:
        raise ctx.error(loc, f"motion.{exc}") from None


def _record_data(table: dict, ctx: _Ctx, loc: str) -> dict:
    has_file = "file" in table
    has_inline = "time" in table or "value" in table
    if has_file and has_inline:
        raise ctx.error(loc, "motion.file: give either file or inline time and value, not both")
    if has_file:
        file = table["file"]
        if not isinstance(file, str) or not file:
            raise ctx.error(loc, f"motion.file = {format_value(file)[:40]}: must be a file name")
        resolved = os.path.abspath(os.path.join(ctx.base_dir, file))
        if not os.path.isfile(resolved):
            raise ctx.error(loc, f"motion.file = {quote_string(file)}: no such file (looked for {resolved})")
        try:
            time, value = load_record_csv(resolved, display=file)
        except InputError as exc:
            raise ctx.error(loc, f"motion.file: {exc}") from None
        if value.ndim == 2 and "direction" in table:
            raise ctx.error(loc, f"motion.direction: not used by a 3-column record ({file} gives x and y)")
        return {
            "time": tuple(time.tolist()),
            "value": tuple(value.tolist()) if value.ndim == 1 else tuple(map(tuple, value.tolist())),
            "source": resolved,
        }
    for key in ("time", "value"):
        if key not in table:
            raise ctx.error(loc, f'motion.{key}: missing (kind "record" needs file, or time and value)')
        if not isinstance(table[key], list):
            raise ctx.error(loc, f"motion.{key} = {format_value(table[key])[:40]}: must be an array")
    value = table["value"]
    if value and all(isinstance(v, list) for v in value) and "direction" in table:
        raise ctx.error(loc, "motion.direction: not used by a vector record (value holds [x, y] pairs)")
    return {"time": table["time"], "value": value}


def _validate(assembly: Assembly, ctx: _Ctx) -> tuple[str, ...]:
    from geometry_library.checks import validate_assembly

    try:
        warnings = validate_assembly(assembly)
    except GeometryError as exc:
        raise ctx.error("", str(exc)) from None
    return tuple(_one_line(w) for w in (warnings or ()))


# --------------------------------------------------------------------------------------------------
# builders


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
    if expected == "number":
        if not is_real(value):
            raise field_error(key, value, "must be a number")
        return float(value)
    if expected == "int" and (isinstance(value, bool) or not isinstance(value, int)):
        raise field_error(key, value, "must be an integer")
    if expected == "bool" and not isinstance(value, bool):
        raise field_error(key, value, "must be true or false")
    if expected == "str" and not isinstance(value, str):
        raise field_error(key, value, "must be a string")
    return value


def _call_builder(builder: str, options: dict, material: Material) -> Assembly:
    """``BUILDERS[builder](**options).build()``; errors become InputError ``key = value: problem``."""
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
        kwargs[key] = _check_option_type(key, _freeze(value), params[key])
    for key in ("density", "thickness"):
        if key in params and key not in kwargs:
            kwargs[key] = getattr(material, key)
    try:
        assembly = spec_cls(**kwargs).build()
    except ValueError as exc:  # GeometryError, InputError, bad values; a TypeError is a bug: not hidden
        raise InputError(f'builder "{builder}": {_one_line(exc)}') from None
    if not isinstance(assembly, Assembly):
        raise InputError(f'builder "{builder}" returned {type(assembly).__name__}, not an Assembly')
    return assembly


def scenario_from_builder(
    builder: str, options: dict, run: RunConfig, material: Material, motions_by_support: dict[str, Motion]
) -> Scenario:
    """A scenario from ``geometry_library.builders.BUILDERS[builder](**options).build()``.

    ``material.density`` / ``material.thickness`` are passed to the builder unless ``options`` sets
    them. ``motions_by_support`` maps support names to motions; supports not named are fixed; a name the
    builder does not make is an error. Raises :class:`InputError` (``builder "wall": ...``).
    """
    where = f'builder "{builder}":'
    options = dict(options)
    for key, value in options.items():
        try:
            _check_finite_tree(key, value)
        except InputError as exc:
            raise InputError(f"{where} {exc}") from None
    try:
        assembly = _call_builder(builder, options, material)
    except InputError as exc:
        msg = str(exc)
        raise InputError(msg if msg.startswith(f'builder "{builder}"') else f"{where} {msg}") from None
    known = [s.name for s in assembly.supports]
    for name, motion in motions_by_support.items():
        if name not in known:
            raise InputError(
                f"{where} no support named {quote_string(str(name))} (supports: {', '.join(known) or 'none'})"
            )
        if not isinstance(motion, Motion):
            raise InputError(f"{where} motion of support {quote_string(name)} must be a Motion")
    motions = tuple(motions_by_support.get(s.name, Fixed()) for s in assembly.supports)
    warnings = _validate(assembly, _Ctx(f'builder "{builder}"', "."))
    return Scenario(
        name=builder,
        run=run,
        material=material,
        assembly=assembly,
        motions=motions,
        source=f"builder:{builder}",
        structure={"builder": builder, **options},
        warnings=warnings,
    )


# --------------------------------------------------------------------------------------------------
# summary


def _block_mass(block: Block) -> float:
    from geometry_library.mass import mass_properties

    return float(mass_properties(block.vertices, block.density, block.thickness).mass)


def scenario_summary(scenario: Scenario) -> dict:
    """Numbers for ``masonry check``: counts, total mass (kg), bounding box (m), run settings, warnings."""
    asm = scenario.assembly
    masses = [_block_mass(b) for b in asm.blocks]
    return {
        "name": scenario.name,
        "source": scenario.source,
        "structure": dict(scenario.structure),
        "blocks": asm.block_count,
        "supports": asm.support_count,
        "support_motions": [
            {"name": s.name, "role": s.role, "motion": m.describe()} for s, m in zip(asm.supports, scenario.motions)
        ],
        "total_mass": float(sum(masses)),
        "total_area": float(sum(float(b.polygon.area) for b in asm.blocks)),
        "bounding_box": tuple(float(x) for x in asm.bounds()),
        "friction": scenario.material.friction,
        "duration": scenario.run.duration,
        "dt": scenario.run.dt,
        "n_steps": scenario.run.n_steps,
        "theta": scenario.run.theta,
        "record_every": scenario.run.record_every,
        "warnings": list(scenario.warnings),
    }
