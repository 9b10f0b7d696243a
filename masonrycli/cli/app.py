"""The ``masonry`` command line. Thin: options → Scenario → execute; errors → one line, exit code 2."""

from __future__ import annotations

import inspect
import sys
from typing import Annotated

import typer

from masonrycli import __version__
from masonrycli.cli.build import build_app
from masonrycli.cli.execution import execute_and_exit
from masonrycli.cli.inspect_file import inspect_command
from masonrycli.cli.messages import OneLineUsageErrors, console, err_console, user_errors
from masonrycli.cli.option_values import choice_value
from masonrycli.cli.options import (
    ANY_STRUCTURE,
    AQUEDUCT,
    ARCH,
    BLOCK_MATERIAL,
    FORCE,
    FRICTION,
    OUTPUT,
    RECORD,
    RUN,
    SETTLE,
    SETTLED_LOADING,
    SIMULATE_SETTLE,
    STOP,
    SURVEY,
    WALL,
    WALL_LOADING,
    AtOption,
    DirectionOption,
    Friction,
    MechanismOutOption,
    MinThicknessOption,
    PointForceOption,
    SettleOption,
    SpreadOption,
    ThrustOption,
    VerifyOption,
    WorstOption,
    file_defaults,
    with_options,
)


class _InTheOrderUsersMeetThem(OneLineUsageErrors):
    """``masonry --help`` lists the commands in the order a user meets them — the quick start's ``simulate``
    first — instead of typer's (commands, then groups: ``simulate`` and ``build`` came last, under ``docs``)."""

    ORDER = ("simulate", "run", "check", "build", "inspect", "export", "report", "limit", "sweep", "docs")

    def list_commands(self, ctx) -> list[str]:
        rank = {name: k for k, name in enumerate(self.ORDER)}
        return sorted(super().list_commands(ctx), key=lambda name: rank.get(name, len(rank)))


app = typer.Typer(
    cls=_InTheOrderUsersMeetThem,
    rich_markup_mode="rich",
    no_args_is_help=True,
    add_completion=False,
    context_settings={"help_option_names": ["-h", "--help"]},  # "-h" said "No such option" (no short option uses it)
    help="Dynamic analysis of dry-stone masonry: rigid blocks, Coulomb friction, NSCD, "
    "the cell stress and strain tensors of Chetouane et al. (2003), Rerun recordings.",
)
simulate_app = typer.Typer(no_args_is_help=True, help="Build a structure, load it and record the run.")
app.add_typer(simulate_app, name="simulate")
app.add_typer(build_app, name="build")


def _version(value: bool) -> None:
    if value:
        console.print(f"masonry {__version__}")
        raise typer.Exit()


@app.callback()
def main_callback(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit.")
    ] = False,
) -> None:
    """masonry: rigid-block dynamics of dry-stone masonry."""


def _pop(opts: dict, *groups: dict) -> dict:
    """The options of ``groups`` taken out of ``opts``."""
    return {k: opts.pop(k) for group in groups for k in group}


# -- commands -------------------------------------------------------------------------------------


def _simulate(name: str, opts: dict) -> None:
    from masonrycli.records.pga import with_pga
    from masonrycli.scenario.builtin import builtin, paper_instant_hint
    from masonrycli.settle import settled_scenario

    outputs, settle, pga = _pop(opts, OUTPUT, FORCE, STOP), opts.pop("settle"), opts.pop("pga")
    scenario = with_pga(builtin(name, **opts), pga, opts["scale"])
    scenario = settled_scenario(scenario, settle)  # as run's _load: before the run, not part of it
    supports = {s.name: m.describe() for s, m in zip(scenario.assembly.supports, scenario.motions)}
    execute_and_exit(scenario, outputs, lambda reached: paper_instant_hint(name, scenario.run, supports, reached))


@simulate_app.command("wall")
@user_errors
@with_options(WALL, WALL_LOADING, RECORD, RUN, SIMULATE_SETTLE, STOP, FRICTION, BLOCK_MATERIAL, OUTPUT, FORCE)
def simulate_wall(**opts) -> None:
    """The paper's running-bond wall on a shaken ground (default 51 blocks, 1 m/s at 2 Hz for 1 s)."""
    _simulate("wall", opts)


@simulate_app.command("arch")
@user_errors
@with_options(ARCH, SETTLED_LOADING, RECORD, RUN, SIMULATE_SETTLE, STOP, FRICTION, BLOCK_MATERIAL, OUTPUT, FORCE)
def simulate_arch(**opts) -> None:
    """The paper's 98-block arch on two piers; default: right foundation settles at 1 cm/s for 5 s."""
    _simulate("arch", opts)


@simulate_app.command("aqueduct")
@user_errors
@with_options(AQUEDUCT, SETTLED_LOADING, RECORD, RUN, SIMULATE_SETTLE, STOP, FRICTION, BLOCK_MATERIAL, OUTPUT, FORCE)
def simulate_aqueduct(**opts) -> None:
    """A segment of the Arles aqueduct (98 arch + 248 wall blocks); default: settlement 1 cm/s for 5 s.

    Shake it instead with [bold]--settlement 0 --amp 1 --freq 2[/bold].
    """
    _simulate("aqueduct", opts)


# a str, checked by target.target_scenario as sweep's and limit's targets are: click's Path said of an
# unreadable file "Invalid value for 'SCENARIO.toml': path 's.toml' is not readable", and made "" the folder "."
ScenarioFile = Annotated[
    str, typer.Argument(help="Scenario file (TOML), or a GeoJSON / WKT geometry.", metavar="SCENARIO.toml")
]


RUN_FROM_FILE, FRICTION_FROM_FILE = file_defaults(RUN), file_defaults(FRICTION)  # run's: the file's values


def _load(scenario_file: str, opts: dict):
    """The scenario of a TOML, GeoJSON or WKT file with the command line's record and run options
    (taken out of ``opts``) applied."""
    from masonrycli.records.pga import with_pga
    from masonrycli.scenario.target import file_scenario
    from masonrycli.settle import settled_scenario

    settings = _pop(opts, RECORD, RUN, FRICTION)
    pga = settings.pop("pga")
    scenario = with_pga(file_scenario(scenario_file, survey=_pop(opts, SURVEY), **settings), pga, settings["scale"])
    return settled_scenario(scenario, opts.pop("settle"))  # the engine: before the run, not part of it


@app.command("run")
@user_errors
@with_options(RUN_FROM_FILE, STOP, FRICTION_FROM_FILE, OUTPUT, FORCE, RECORD, SURVEY, SETTLE)
def run_command(scenario_file: ScenarioFile, **opts) -> None:
    """Run any scenario file, or a GeoJSON / WKT geometry file (supports fixed, or shaken by --record: the one
    support, or those marked driven); options given here override the file's values."""
    scenario = _load(scenario_file, opts)
    execute_and_exit(scenario, opts)


def _register_sweep() -> None:
    # the sweep command lives in its own module (it is as long as a small CLI); registered here so
    # that `masonry --help` lists it with the others
    from masonrycli.cli.sweep import sweep_command

    app.command("sweep")(user_errors(sweep_command))


_register_sweep()


def _register_check() -> None:
    from masonrycli.cli.check import check_command

    app.command("check")(user_errors(check_command))


_register_check()


def _register_export() -> None:
    from masonrycli.cli.export import export_command
    from masonrycli.cli.report import report_command

    app.command("export")(user_errors(export_command))
    app.command("report")(user_errors(report_command))


_register_export()
app.command("inspect")(user_errors(inspect_command))


@app.command("limit")
@user_errors
@with_options(ANY_STRUCTURE, BLOCK_MATERIAL, SURVEY)
def limit_command(
    structure: Annotated[
        str,
        typer.Argument(
            help="wall, arch or aqueduct (built-in defaults), a scenario file (TOML) or a GeoJSON / WKT geometry.",
            metavar="SCENARIO|wall|arch|aqueduct",
        ),
    ],
    load: Annotated[
        str,
        typer.Option(
            parser=choice_value, help="horizontal (λ × weight), tilt (tilting table, tan ψ = λ) or point (on --block)."
        ),
    ] = "horizontal",
    block: Annotated[str | None, typer.Option(help="Block carrying the point load (λ × its weight).")] = None,
    at: AtOption = None,
    worst: WorstOption = False,
    point_force: PointForceOption = None,
    spread: SpreadOption = None,
    direction: DirectionOption = None,
    friction: Friction = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout, nothing else.")] = False,
    thrust: ThrustOption = False,
    settle: SettleOption = None,
    min_thickness: MinThicknessOption = False,
    verify: VerifyOption = False,
    out: MechanismOutOption = None,
    force: Annotated[bool, typer.Option("--force", help="Replace the --out file if it exists.")] = False,
    **structure_options,
) -> None:
    """The collapse load factor λ and mechanism of a block assembly (rigid-block limit analysis, one LP).

    A built-in takes the structure options of [bold]masonry build NAME[/bold]:
    [bold]masonry limit arch --span 4[/bold].
    """
    from masonrycli.limit.command import run_limit

    run_limit(
        structure,
        load=load,
        direction=direction,
        block=block,
        friction=friction,
        as_json=as_json,
        verify=verify,
        out=out,
        console=console,
        err_console=err_console,
        force=force,
        structure_options=structure_options,
        at=at,
        thrust=thrust,
        min_thickness=min_thickness,
        settle=settle,
        worst=worst,
        point_force=point_force,
        spread=spread,
    )


@app.command("docs")
@user_errors
def docs_command(
    topic: Annotated[str | None, typer.Argument(help="A page's topic; without one, the list of topics.")] = None,
    path: Annotated[bool, typer.Option("--path", help="Print the page's file name instead of the page.")] = False,
) -> None:
    """List the documentation's topics, or print one page (Markdown) or its file.

    The pages ship with masonry: an install without the clone has them too."""
    from masonrycli.cli import docs as user_docs

    if topic is None:
        for line in user_docs.listing():
            console.print(line, soft_wrap=True)
        return
    page = user_docs.find(topic)
    sys.stdout.write(f"{page.path}\n" if path else page.path.read_text(encoding="utf-8"))


def _one_line_summaries(*typer_apps: typer.Typer) -> None:
    # The command lists (masonry --help, masonry simulate --help) showed a docstring with its source line
    # breaks ("run history (the run's" / "parameters, …" on two lines) and run's and check's had a copy to
    # avoid it, which drifted (check's left out "the loading"): each command's summary is its docstring's
    # first paragraph on one line.
    for typer_app in typer_apps:
        for info in typer_app.registered_commands:
            if info.short_help is None:
                first = (inspect.getdoc(info.callback) or "").split("\n\n")[0]
                info.short_help = " ".join(first.split())


_one_line_summaries(app, simulate_app, build_app)


def main() -> None:
    app()


if __name__ == "__main__":
    sys.exit(main())
