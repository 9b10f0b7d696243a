"""A scenario file's bodies: its ``[[block]]`` and ``[[support]]`` tables read into Blocks and Supports (keys,
unique names, convex polygons, a block's initial velocity and carried fill), and a support's ``motion`` table
read into its Motion (``kind`` -> class: :data:`MOTION_KINDS`). Every problem is an InputError at the table's
locator (``[[block]] #2 ("b"):``); the document around them: :mod:`masonrycli.scenario.toml_file`."""

from __future__ import annotations

import math
import os
import warnings

from geometry_library.blocks import Block, GeometryError, Support, name_problem
from masonrycli.errors import InputContext, InputError, RecordWarning
from masonrycli.records.motion import Record, unused_baseline
from masonrycli.records.read import record_fields
from masonrycli.scenario.motion import Constant, Fixed, Motion, Ramp, Sine
from masonrycli.scenario.scenario import Material, block_speed_problem
from masonrycli.scenario.values import (
    check_real,
    check_vector,
    field_error,
    format_value,
    lower_words,
    quote_string,
    unknown_key,
)

BLOCK_KEYS = ("name", "polygon", "density", "thickness", "velocity", "carried_mass", "carried_at")
SUPPORT_KEYS = ("name", "polygon", "motion")

MOTION_KINDS: dict[str, type[Motion]] = {cls.kind: cls for cls in (Fixed, Constant, Sine, Ramp, Record)}
"""TOML ``kind`` -> motion class."""

ALL_MOTION_KEYS = tuple(dict.fromkeys(k for cls in MOTION_KINDS.values() for k in cls.TOML_KEYS))


def check_name(key: str, value) -> str:
    problem = name_problem(value)
    if problem is not None:
        raise field_error(key, value, problem)
    return value


def locator(section: str, index: int, table: dict, default_name: str | None) -> str:
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


def _polygon(coords, index: int, name: str, kind: str, ctx: InputContext, loc: str):
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


def _check_unique(name: str, loc: str, names: dict, ctx: InputContext):
    if name in names:
        raise ctx.error(loc, f"name = {quote_string(name)}: already used by {names[name]} (names must be unique)")
    names[name] = loc.rstrip(":")


def parse_block(i: int, table: dict, material: Material, ctx: InputContext, names: dict) -> Block:
    default_name = f"block-{i}"
    loc = locator("block", i, table, default_name)
    if unknown := [key for key in table if key not in BLOCK_KEYS]:
        raise ctx.error(loc, unknown_key(unknown[0], BLOCK_KEYS))
    try:
        name = check_name("name", table.get("name", default_name))
        if "polygon" not in table:
            raise InputError("polygon: missing (e.g. polygon = [[0.0, 0.0], [0.4, 0.0], [0.4, 0.2], [0.0, 0.2]])")
        coords = _check_polygon(table["polygon"])
        density = check_real("density", table.get("density", material.density), gt=0.0)
        thickness = check_real("thickness", table.get("thickness", material.thickness), gt=0.0)
        velocity = check_vector("velocity", table.get("velocity", (0.0, 0.0, 0.0)), size=3)
        carried = {}  # a fill's dead mass riding on the block (Block.carried_mass): both keys or neither
        if "carried_at" in table and "carried_mass" not in table:  # a point carrying nothing: it ran as no fill
            raise InputError("carried_at without carried_mass: give the mass it carries (kg), or leave carried_at out")
        if "carried_mass" in table or "carried_at" in table:
            carried["carried_mass"] = check_real("carried_mass", table.get("carried_mass", 0.0), ge=0.0)
            carried["carried_at"] = check_vector("carried_at", table.get("carried_at"))
    except InputError as exc:
        raise ctx.error(loc, str(exc)) from None
    _check_unique(name, loc, names, ctx)
    polygon = _polygon(coords, i - 1, name, "block", ctx, loc)
    block = Block(polygon=polygon, name=name, density=density, thickness=thickness, velocity=velocity, **carried)
    if problem := block_speed_problem(block):  # velocity = [1e9, 0, 0] ran and ended as exit 3, "diverged at step 1"
        raise ctx.error(loc, problem)
    return block


def parse_support(i: int, table: dict, ctx: InputContext, names: dict) -> tuple[Support, Motion]:
    default_name = f"support-{i}"
    loc = locator("support", i, table, default_name)
    for key in table:
        if key not in SUPPORT_KEYS:
            raise ctx.error(loc, unknown_key(key, SUPPORT_KEYS))
    try:
        name = check_name("name", table.get("name", default_name))
        if "polygon" not in table:
            raise InputError("polygon: missing (e.g. polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]])")
        coords = _check_polygon(table["polygon"])
    except InputError as exc:
        raise ctx.error(loc, str(exc)) from None
    _check_unique(name, loc, names, ctx)
    polygon = _polygon(coords, i - 1, name, "support", ctx, loc)
    motion = parse_motion(table.get("motion"), ctx, loc)
    return Support(polygon=polygon, name=name, role=motion.role), motion


def parse_motion(table, ctx: InputContext, loc: str) -> Motion:
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
            raise ctx.error(loc, "motion: " + unknown_key(key, ALL_MOTION_KEYS))
    if "kind" not in table:
        raise ctx.error(loc, f"motion.kind: missing (one of {', '.join(MOTION_KINDS)})")
    kind = table["kind"]
    if isinstance(kind, str):  # kind = "Sine" was "unknown motion kind (expected one of …, sine, …)"
        kind = kind.strip().lower()
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

    args = {k: v for k, v in lower_words(table).items() if k not in ("kind", "file", "vertical", "time", "value")}
    if kind == "record":
        try:
            args.update(record_fields(lower_words(table), ctx.base_dir))
        except InputError as exc:
            raise ctx.error(loc, str(exc)) from None
    try:
        motion = cls(**args)
    except InputError as exc:
        raise ctx.error(loc, f"motion.{exc}") from None
    if kind == "record" and "baseline" in table:  # a velocity record's is never applied: said (records/motion.py)
        name = os.path.basename(motion.source) if motion.source else "the inline record"
        try:
            said = unused_baseline(motion.baseline, {name: motion}, "baseline", f'baseline = "{motion.baseline}"')
        except InputError as exc:
            raise ctx.error(loc, f"motion.{exc}") from None
        for line in said:
            warnings.warn(RecordWarning(str(ctx.error(loc, f"motion.{line}"))), stacklevel=2)
    if kind == "sine" and motion.frequency == 0.0 and motion.amplitude and abs(math.sin(motion.phase)) < 1e-12:
        # it ran: amplitude · sin(0) = 0, the ground never moved ("intact"); --freq 0 --amp 1 was refused
        raise ctx.error(
            loc,
            f"motion.frequency = {format_value(table['frequency'])}: the velocity {motion.amplitude:g} m/s · "
            f"sin(2π·0·t + {motion.phase:g}) is 0, nothing moves (amplitude = 0 for no shaking; a steady velocity "
            'is kind = "constant")',
        )
    return motion
