"""Scenario files in TOML: the reader (format: ``docs/scenario-format.md``) and the writer. The document is
read here (its top-level keys, [run], [material], [structure]); its [[block]] and [[support]] tables and their
motions: :mod:`masonrycli.scenario.toml_bodies`.

``load_scenario`` / ``loads_scenario`` read a scenario file; every problem with it raises
:class:`masonrycli.errors.InputError` with a one-line message naming the file and the key, e.g.
``wall.toml: [run] dt = -0.001: must be > 0``.

``dump_scenario`` writes one back. tomllib only reads TOML; this small writer emits exactly the subset the
scenario format uses, with floats spelled by ``repr`` so that a reload gives bit-identical vertices.
"""

from __future__ import annotations

import dataclasses
import os
import tomllib
from pathlib import Path

import numpy as np

from geometry_library.blocks import Assembly
from masonrycli.errors import (
    NOT_A_FILE,
    InputContext,
    InputError,
    input_path,
    not_utf8,
    one_line,
    special_file,
)
from masonrycli.scenario.caveats import idle_driven_supports
from masonrycli.scenario.motion import Fixed, Motion
from masonrycli.scenario.scenario import Material, RunConfig, Scenario
from masonrycli.scenario.structure import (
    SURVEY_FLAGS,
    build_structure,
    check_finite_tree,
    read_geometry,
    structure_warnings,
    survey_keys,
)
from masonrycli.scenario.toml_bodies import SUPPORT_KEYS, check_name, locator, parse_block, parse_motion, parse_support
from masonrycli.scenario.toml_lines import key_line, with_line
from masonrycli.scenario.toml_syntax import hint as syntax_hint
from masonrycli.scenario.values import (
    format_value,
    lower_words,
    quote_key,
    quote_string,
    unknown_key,
)

TOP_LEVEL_KEYS = ("name", "run", "material", "structure", "block", "support")
BUILDER_SUPPORT_KEYS = ("name", "motion")

# --------------------------------------------------------------------------------------------------
# reading


def load_scenario(path) -> Scenario:
    """Read a TOML scenario file (format: ``docs/scenario-format.md``).

    Relative record ``file`` paths are resolved against the scenario file's folder.
    Raises :class:`InputError` (one line naming the file and the key) on any problem.
    """
    fname = os.fspath(path)
    if special_file(fname):
        raise InputError(f"{fname}: cannot read scenario: {NOT_A_FILE}")
    try:
        raw = Path(fname).read_bytes()
    except IsADirectoryError:
        raise InputError(f"{fname}: cannot read scenario: is a directory") from None
    except OSError as exc:
        raise InputError(one_line(f"{fname}: cannot read scenario: {exc.strerror or exc}")) from None
    try:
        text = raw.decode("utf-8-sig")  # tolerate the byte-order mark some Windows editors add
    except UnicodeDecodeError as exc:
        raise not_utf8(fname, raw, exc) from None
    if "\x00" in text:  # valid UTF-8 all the same: UTF-16 saved without its byte-order mark, or not text
        raise not_utf8(fname, raw)
    base_dir = os.path.dirname(os.path.abspath(fname))
    return loads_scenario(text, source=fname, base_dir=base_dir, default_name=Path(fname).stem)


def loads_scenario(
    text: str, source: str = "<string>", base_dir: str | os.PathLike = ".", default_name: str = "scenario"
) -> Scenario:
    """Parse scenario TOML ``text``. ``source`` names it in error messages; ``base_dir`` resolves
    relative record files."""
    ctx = InputContext(os.fspath(source), os.path.abspath(os.fspath(base_dir)))
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        fix = syntax_hint(text, str(exc))
        raise ctx.error("", f"TOML syntax error: {exc}" + (f"; {fix}" if fix else "")) from None
    except RecursionError:  # thousands of nested [[[…]]]: tomllib recurses (a traceback, exit 1)
        raise ctx.error("", "TOML nested too deeply (arrays or inline tables within each other)") from None
    try:
        return _parse_document(doc, ctx, default_name)
    except InputError as exc:  # the line of the key it names, where the text shows it unambiguously
        message = with_line(str(exc), ctx.fname, text)
        keys = getattr(exc, "structure_keys", ())  # a builder's check: 'builder "arch": ring_thickness 0 m …'
        if message == str(exc) and len(keys) == 1 and (line := key_line(text, ("structure",), keys[0])):
            message = f"{ctx.fname}:{line}: {message[len(ctx.fname) + 2 :]}"
        raise InputError(message) from None


def _misplaced(key: str) -> str:
    """A [run] or [material] setting written at the top, before any table (its header forgotten)."""
    for section, cls in (("run", RunConfig), ("material", Material)):
        if key in (f.name for f in dataclasses.fields(cls)):
            return f"unknown key {quote_string(key)} at the top of the file (a [{section}] setting: write it below a [{section}] line)"
    return ""


def _table(doc: dict, key: str, ctx: InputContext) -> dict:
    value = doc.get(key, {})
    if not isinstance(value, dict):
        raise ctx.error("", f"{key} = {format_value(value)[:40]}: must be a table [{key}]")
    return value


def _array_of_tables(doc: dict, key: str, ctx: InputContext) -> list:
    value = doc.get(key, [])
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise ctx.error("", f"{key}: must be an array of tables [[{key}]]")
    return value


def _config(cls, table: dict, ctx: InputContext, section: str):
    names = [f.name for f in dataclasses.fields(cls)]
    for key in table:
        if key not in names:
            raise ctx.error(f"[{section}]", unknown_key(key, names))
    table = lower_words(table)
    try:
        return cls(**table)
    except InputError as exc:
        raise ctx.error(f"[{section}]", str(exc)) from None


def _parse_document(doc: dict, ctx: InputContext, default_name: str) -> Scenario:
    if not doc:  # an empty file (saved before it was typed, or another file than the one written)
        raise ctx.error(
            "",
            "the file is empty (or only comments): a scenario needs [[block]] tables or a [structure] builder (masonry docs scenario-format)",
        )
    for key in doc:
        if key not in TOP_LEVEL_KEYS:
            raise ctx.error("", _misplaced(key) or unknown_key(key, TOP_LEVEL_KEYS))
    try:
        name = check_name("name", doc["name"]) if "name" in doc else default_name
    except InputError as exc:
        raise ctx.error("", str(exc)) from None
    run = _config(RunConfig, _table(doc, "run", ctx), ctx, "run")
    material = _config(Material, _table(doc, "material", ctx), ctx, "material")
    block_tables = _array_of_tables(doc, "block", ctx)
    support_tables = _array_of_tables(doc, "support", ctx)
    notes, reading = [], {}  # a geometry file's warnings (its properties not used); what it was read as

    if "structure" in doc:
        structure = _table(doc, "structure", ctx)
        if block_tables:
            raise ctx.error(
                locator("block", 1, block_tables[0], "block-1"),
                "not allowed together with a [structure] builder or file (use either explicit blocks or a [structure])",
            )
        if "file" in structure:
            extra = [k for k in structure if k != "file" and k not in SURVEY_FLAGS]  # how it is read: survey_keys
            if extra:
                raise ctx.error(
                    "[structure]",
                    f"{extra[0]}: not allowed with file = ... (a geometry file brings its own blocks and supports; "
                    f"how it is read: {', '.join(SURVEY_FLAGS)})",
                )
            file = structure["file"]
            if not isinstance(file, str):
                raise ctx.error("[structure]", f"file = {format_value(file)[:40]}: must be a string")
            path = input_path(ctx.base_dir, file)  # "~/w.geojson" too
            survey = survey_keys(structure, ctx)
            assembly = read_geometry(path, material.density, material.thickness, ctx, notes=notes, survey=survey)
            what = f"file {quote_string(file)}"
            structure_info, reading = {"file": path}, dict(survey.done)  # read_geometry filled it
        else:
            if "builder" not in structure:
                raise ctx.error("[structure]", 'builder: missing (e.g. builder = "wall", or file = "my-wall.geojson")')
            builder = structure["builder"]
            if not isinstance(builder, str):
                raise ctx.error("[structure]", f"builder = {format_value(builder)[:40]}: must be a string")
            options = {k: v for k, v in structure.items() if k != "builder"}
            for key, value in options.items():
                try:
                    check_finite_tree(key, value)
                except InputError as exc:
                    raise ctx.error("[structure]", str(exc)) from None
            try:
                assembly = build_structure(builder, options, material.density, material.thickness)
            except InputError as exc:
                error = ctx.error("[structure]", str(exc))
                error.structure_keys = getattr(exc, "keys", ())  # its line, if one key (loads_scenario)
                raise error from None
            structure_info = {"builder": builder, **options}
            what = f'builder "{builder}"'
        motions_by_support = {}
        known = [s.name for s in assembly.supports]
        for i, table in enumerate(support_tables, start=1):
            loc = locator("support", i, table, None)
            for key in table:
                if key not in BUILDER_SUPPORT_KEYS:
                    if key in SUPPORT_KEYS:
                        raise ctx.error(
                            loc,
                            f"{key}: not allowed with a [structure] "
                            f"({what} makes the supports; give only name and motion)",
                        )
                    raise ctx.error(loc, unknown_key(key, BUILDER_SUPPORT_KEYS))
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
            motions_by_support[sname] = parse_motion(table.get("motion"), ctx, loc)
        motions = tuple(motions_by_support.get(s.name, Fixed()) for s in assembly.supports)
        notes += idle_driven_supports(assembly, motions)
    else:
        blocks = []
        names: dict[str, str] = {}
        for i, table in enumerate(block_tables, start=1):
            blocks.append(parse_block(i, table, material, ctx, names))
        if not blocks:
            raise ctx.error("", "no blocks: add [[block]] tables or a [structure] builder")
        supports, motions_list = [], []
        for i, table in enumerate(support_tables, start=1):
            support, motion = parse_support(i, table, ctx, names)
            supports.append(support)
            motions_list.append(motion)
        assembly = Assembly(blocks=tuple(blocks), supports=tuple(supports))
        motions = tuple(motions_list)
        structure_info = {}
    warnings = (*notes, *structure_warnings(assembly, ctx))
    return Scenario(
        name=name,
        run=run,
        material=material,
        assembly=assembly,
        motions=motions,
        source=ctx.fname,
        structure=structure_info,
        warnings=warnings,
        reading=reading,
    )


# --------------------------------------------------------------------------------------------------
# writing


def _vertices(polygon_owner) -> list[list[float]]:
    return [[float(x), float(y)] for x, y in np.asarray(polygon_owner.vertices, dtype=np.float64)]


def _motion_lines(motion: Motion, inline_records: bool) -> list[str]:
    return [f"{quote_key(k)} = {format_value(v)}" for k, v in motion.toml_fields(inline_records).items()]


def dump_scenario(scenario: Scenario, *, inline_records: bool = False) -> str:
    """TOML text of ``scenario`` with explicit blocks and supports; ``loads_scenario`` of it gives back
    the same run, material, names, vertices (bit for bit), densities, thicknesses, velocities and motions.

    Record motions refer to their CSV by absolute path, or carry inline ``time``/``value`` arrays when
    ``inline_records`` is true or the record has no file. A builder scenario is written as its blocks
    (the builder and options are noted in a comment).
    """
    out = ["# masonry scenario (written by masonrycli.scenario.toml_file.dump_scenario)"]
    if scenario.structure:
        opts = ", ".join(
            f"{quote_key(str(k))} = {format_value(v)}" for k, v in scenario.structure.items() if k != "builder"
        )
        out.append(
            f"# generated by builder {quote_string(str(scenario.structure.get('builder')))}"
            + (f" with {opts}" if opts else "")
        )
    if scenario.source:
        out.append(f"# from {' '.join(str(scenario.source).split())}")
    out.append(f"name = {quote_string(scenario.name)}")
    out.append("")
    out.append("[run]")
    for f in dataclasses.fields(RunConfig):
        value = getattr(scenario.run, f.name)
        out.append(f"{f.name} = {format_value(list(value) if isinstance(value, tuple) else value)}")
    out.append("")
    out.append("[material]")
    for f in dataclasses.fields(Material):
        out.append(f"{f.name} = {format_value(getattr(scenario.material, f.name))}")
    mat = scenario.material
    for block in scenario.assembly.blocks:
        out += ["", "[[block]]", f"name = {quote_string(block.name)}", f"polygon = {format_value(_vertices(block))}"]
        if float(block.density) != mat.density:
            out.append(f"density = {format_value(float(block.density))}")
        if float(block.thickness) != mat.thickness:
            out.append(f"thickness = {format_value(float(block.thickness))}")
        velocity = [float(v) for v in block.velocity]
        if any(v != 0.0 for v in velocity):
            out.append(f"velocity = {format_value(velocity)}")
        if block.carried_mass > 0.0:
            out.append(f"carried_mass = {format_value(float(block.carried_mass))}")
            out.append(f"carried_at = {format_value([float(x) for x in block.carried_at])}")
    for support, motion in zip(scenario.assembly.supports, scenario.motions):
        out += [
            "",
            "[[support]]",
            f"name = {quote_string(support.name)}",
            f"polygon = {format_value(_vertices(support))}",
        ]
        if motion.kind != "fixed":
            out.append("[support.motion]")
            out += _motion_lines(motion, inline_records)
    out.append("")
    return "\n".join(out)
