"""``masonry check``: what ``run`` (a file) or ``simulate`` (a built-in name) would run, with the same
options, summarised and checked; nothing computed or written. Registered on the app by :mod:`masonrycli.cli.app`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from masonrycli.cli.execution import checked_outputs
from masonrycli.cli.messages import console, warn
from masonrycli.cli.options import (
    ANY_STRUCTURE,
    BLOCK_MATERIAL,
    BUILT_IN_LOADING,
    FORCE,
    FRICTION,
    OUTPUT,
    RECORD,
    RUN,
    SETTLE,
    STOP,
    STRUCTURE_OPTIONS,
    SURVEY,
    file_defaults,
    with_options,
)
from masonrycli.errors import InputError

BUILT_IN_ONLY = {**ANY_STRUCTURE, **BUILT_IN_LOADING, **BLOCK_MATERIAL}
"""The options that shape a built-in structure and its loading (``simulate NAME``'s); a file gives its own."""


def material_hint(given) -> str:
    """What a refused --density / --thickness on a file is said with: where a file's stones get theirs (WKT has no
    column for it: a researcher with a 2300 kg/m³ survey found no way in)."""
    if not {"density", "thickness"} & set(given):
        return ""
    return (
        "; its stones' density and thickness: the file's density / thickness columns (GeoJSON), or a scenario file "
        "naming it ([structure] file = …) with [material] density / thickness (masonry docs scenario-format)"
    )


def _flags(names) -> str:
    return ", ".join(f"--{name.replace('_', '-')}" for name in names)


def _scenario(target: str, opts: dict):
    """The scenario ``run TARGET`` (a file) or ``simulate TARGET`` (a built-in name) would run with ``opts``
    (taken out of ``opts``): the built-in's structure, loading and material options refused for a file, and
    another built-in's structure options for a built-in, in one line."""
    from masonrycli.records.pga import with_pga
    from masonrycli.scenario.builtin import builtin
    from masonrycli.scenario.structure import survey_of
    from masonrycli.scenario.target import file_scenario, is_built_in

    shaping = {name: value for name in BUILT_IN_ONLY if (value := opts.pop(name)) is not None}
    pga = opts.pop("pga")  # the record's scale, found once the scenario is built (records/pga.py)
    settings = {name: opts.pop(name) for group in (RECORD, RUN, FRICTION) for name in group if name != "pga"}
    survey = {name: opts.pop(name) for name in SURVEY}  # how a geometry file is read: refused for a built-in
    if (settle := opts.pop("settle")) is not None:  # run's --settle runs the engine: here only its value is checked
        from masonrycli.settle import check_settle

        check_settle(settle)
    if not is_built_in(target):
        if shaping:
            raise InputError(
                f"{_flags(shaping)}: shape a built-in structure (masonry check wall|arch|aqueduct …); {target} is "
                f"a file, which gives its own geometry and loading{material_hint(shaping)}"
            )
        return with_pga(file_scenario(target, survey=survey, **settings), pga, settings["scale"])
    survey_of(survey, target)
    allowed = {*STRUCTURE_OPTIONS[target], *BUILT_IN_LOADING, *BLOCK_MATERIAL}
    foreign = [name for name in shaping if name not in allowed]
    if foreign:  # simulate NAME does not take them ("No such option"): the same run cannot be checked
        raise InputError(f"{_flags(foreign[:1])}: not an option of the {target} (masonry simulate {target} --help)")
    return with_pga(builtin(target, **shaping, **settings), pga, settings["scale"])


FILE_OR_BUILT_IN = "the scenario file's or the built-in's value"  # the run options' default: "the file's" was half
RUN_FROM_EITHER, FRICTION_FROM_EITHER = file_defaults(RUN, FILE_OR_BUILT_IN), file_defaults(FRICTION, FILE_OR_BUILT_IN)


@with_options(RUN_FROM_EITHER, STOP, FRICTION_FROM_EITHER, OUTPUT, FORCE, RECORD, BUILT_IN_ONLY, SURVEY, SETTLE)
def check_command(
    target: Annotated[
        str,
        typer.Argument(
            help="Scenario file (TOML), or a GeoJSON / WKT geometry, as run takes it; or wall, arch or aqueduct, "
            "as simulate takes it (with its structure and loading options).",
            metavar="SCENARIO|wall|arch|aqueduct",
        ),
    ],
    **opts,
) -> None:
    """Validate what `masonry run` (a file) or `masonry simulate NAME` (a built-in) would run, with the same
    arguments, and print a summary (blocks, supports, mass, bounding box, steps, the loading, outputs); nothing
    is computed or written."""
    from masonrycli.outputs.report import check_table
    from masonrycli.records.intensity import describe, loading_intensity
    from masonrycli.scenario.caveats import scenario_warnings
    from masonrycli.scenario.scenario import scenario_summary

    scenario = _scenario(target, opts)
    outputs = checked_outputs(scenario, opts)
    measured = loading_intensity(scenario)
    # "intensity", no longer than the other labels: a wider label column re-wrapped every loading line
    ground = None if measured is None else ("intensity", f"{measured[0]}: {describe(measured[1])}")
    console.print(check_table(str(Path(target)), scenario_summary(scenario), outputs.files(), ground))
    for warning in scenario_warnings(scenario):
        warn(warning)
