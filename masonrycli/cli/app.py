"""The ``masonry`` command line. Thin: options → Scenario → execute; errors → one line, exit code 2."""

from __future__ import annotations

import inspect
import os
import sys
from pathlib import Path
from typing import Annotated

import typer

from geometry_library.blocks import GeometryError
from masonrycli import __version__
from masonrycli.cli.messages import OneLineUsageErrors, console, err_console, fail, say, user_errors, warn
from masonrycli.cli.options import (
    ANY_STRUCTURE,
    AQUEDUCT,
    ARCH,
    BLOCK_MATERIAL,
    FORCE,
    FRICTION,
    GEO_OUT,
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
    checked_outputs,
    choice_value,
    file_defaults,
    with_options,
)
from masonrycli.errors import EXIT_DIVERGED, EXIT_INTERNAL, EXIT_OUTPUT_FAILED, InputError


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
build_app = typer.Typer(no_args_is_help=True, help="Build a structure and write it as GeoJSON.")
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


# -- shared options -------------------------------------------------------------------------------
# Each group maps a parameter name to its option; ``with_options`` adds groups to a command, so the
# commands that share them declare each option once.


def _execute(scenario, opts: dict, hint=None) -> None:
    """Check the outputs (``opts``: the OUTPUT, FORCE and STOP options), run, print the summary; exit with
    the code of how the run ended. ``hint``: the line under the summary, given the time the run reached."""
    from masonrycli.interrupt import StopSignals
    from masonrycli.scenario.caveats import scenario_warnings

    outputs = checked_outputs(scenario, opts)
    for warning in scenario_warnings(scenario):
        warn(warning)
    # The run's handlers stay installed through the summary: once execute() had put Python's back, a Ctrl-C
    # while the summary was printed said "Ctrl-C: stopped before any output was written" (exit 130) of a
    # run whose files had just been renamed into place, and a SIGTERM killed the process mid-table (-15).
    with StopSignals() as signals:
        _execute_and_report(scenario, opts, hint, outputs, signals)


def _execute_and_report(scenario, opts: dict, hint, outputs, signals) -> None:
    """:func:`_execute`'s run and summary, under ``signals``."""
    from masonrycli.execute import execute, print_summary
    from masonrycli.interrupt import StopRun, exit_code, signal_name
    from masonrycli.outputs.sinks import DIVERGED, FAILED, INTERRUPTED

    try:
        outcome = execute(
            scenario,
            outputs,
            console=console,
            stop_at_collapse=opts["stop_at_collapse"],
            magnify=opts["magnify"],
            signals=signals,
        )
    except StopRun as stop:
        fail(f"{signal_name(stop.signum)} before the first step: nothing was written", exit_code(stop.signum))
    except (InputError, GeometryError):
        raise
    except Exception as exc:  # an engine bug: say so in one line, keep what was computed
        if os.environ.get("MASONRY_DEBUG"):
            raise
        say(
            "internal error",
            "bold red",
            f"{type(exc).__name__}: {exc} — the recording and history hold every frame computed before it"
            " (MASONRY_DEBUG=1 shows the traceback)",
        )
        raise typer.Exit(EXIT_INTERNAL) from None
    result = outcome.result
    try:
        print_summary(console, outcome, scenario, hint(result.time) if hint is not None and result is not None else "")
        for error in outcome.errors:
            say("error", "bold red", f"cannot write {error}")
        if signals.signum is not None and (outcome.signum is None or result.status != INTERRUPTED):
            # it came once the last step was over
            say(
                "note",
                "yellow",
                f"{signal_name(signals.signum)} after the last step: the run {result.status} and its files are whole",
            )
    except OSError:  # the terminal is gone (SIGHUP: the files are closed, whole): the exit code still says how
        if signals.signum is None:
            raise
    if outcome.errors or result.status == FAILED:
        raise typer.Exit(EXIT_OUTPUT_FAILED)
    if signals.signum is not None:
        raise typer.Exit(exit_code(signals.signum))
    if result.status == DIVERGED:
        raise typer.Exit(EXIT_DIVERGED)


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
    _execute(scenario, outputs, lambda reached: paper_instant_hint(name, scenario.run, supports, reached))


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


# a str, checked by builtin.target_scenario as sweep's and limit's targets are: click's Path said of an
# unreadable file "Invalid value for 'SCENARIO.toml': path 's.toml' is not readable", and made "" the folder "."
ScenarioFile = Annotated[
    str, typer.Argument(help="Scenario file (TOML), or a GeoJSON / WKT geometry.", metavar="SCENARIO.toml")
]


RUN_FROM_FILE, FRICTION_FROM_FILE = file_defaults(RUN), file_defaults(FRICTION)  # run's: the file's values


def _load(scenario_file: str, opts: dict):
    """The scenario of a TOML, GeoJSON or WKT file with the command line's record and run options
    (taken out of ``opts``) applied."""
    from masonrycli.records.pga import with_pga
    from masonrycli.scenario.builtin import file_scenario
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
    _execute(scenario, opts)


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


def _write_assembly(builder: str, opts: dict) -> None:
    """Build, check and write the GeoJSON under a temporary name, renamed onto ``--out`` when complete."""
    from geometry_library.checks import validate_assembly
    from geometry_library.io import write_geojson
    from masonrycli.outputs.files import check_output, written_whole
    from masonrycli.scenario.builtin import build_assembly

    # .json too: `masonry run` reads a .json file as GeoJSON (GEOMETRY_SUFFIXES), build refused to write one
    target = check_output(opts.pop("out"), "--out", (".geojson", ".json"), opts.pop("force"))
    assembly = build_assembly(builder, **opts)
    for warning in validate_assembly(assembly):
        warn(warning)
    from masonrycli.interrupt import StopSignals, exit_code, signal_name

    out = target.path
    # A signal waits until the file is whole and said: a Ctrl-C just after the rename said "Ctrl-C: stopped
    # before any output was written" of the file written, a SIGTERM there killed the command (-15).
    with StopSignals() as signals:
        signals.closing()
        with written_whole(target) as part:
            write_geojson(assembly, part)
        console.print(
            f"{builder}: {assembly.block_count} block{'s' if assembly.block_count != 1 else ''} and "
            f"{assembly.support_count} support{'s' if assembly.support_count != 1 else ''} → {out}"
        )
    if signals.signum is not None:
        say("note", "yellow", f"{signal_name(signals.signum)} while {out} was written: it is whole")
        raise typer.Exit(exit_code(signals.signum))


@build_app.command("wall")
@user_errors
@with_options(GEO_OUT, WALL, BLOCK_MATERIAL, FORCE)
def build_wall_command(**opts) -> None:
    """A running-bond wall on its ground."""
    _write_assembly("wall", opts)


@build_app.command("arch")
@user_errors
@with_options(GEO_OUT, ARCH, BLOCK_MATERIAL, FORCE)
def build_arch_command(**opts) -> None:
    """A semicircular arch on two piers, each on its foundation; segmental with --rise below span / 2."""
    _write_assembly("arch", opts)


@build_app.command("aqueduct")
@user_errors
@with_options(GEO_OUT, AQUEDUCT, BLOCK_MATERIAL, FORCE)
def build_aqueduct_command(**opts) -> None:
    """The arch plus spandrel walls in running bond up to a level top."""
    _write_assembly("aqueduct", opts)


@app.command("inspect")
@user_errors
def inspect_command(
    recording: Annotated[
        Path, typer.Argument(help="Recording (.rrd), run history (.npz) or study table.", metavar="REC.rrd|H.npz|S.csv")
    ],
) -> None:
    """Summarise a recording (scenario, frames, time span, entities), a run history (its parameters,
    status, frames and each array's unit) or a study's table (its rows and each column's unit)."""
    from masonrycli.outputs.inspect_history import inspect_history, is_history
    from masonrycli.study.inspect_table import is_study_table, study_summary

    if recording.is_file() and recording.stat().st_size == 0:  # rerun's "file too small to be an RRD", a zip error
        raise InputError(f"{recording}: an empty file (0 bytes), not a recording or a history")
    if is_study_table(recording):
        from masonrycli.outputs.report import columns_lines

        table, lines = columns_lines(
            f"{recording} — study table", *study_summary(recording), "column", "unit / meaning"
        )
        console.print(table)
        for line in lines:
            console.print(line, soft_wrap=True)
        return
    if is_history(recording):
        from masonrycli.outputs.report import history_tables

        table, lines = history_tables(str(recording), inspect_history(recording))
        console.print(table)
        for line in lines:
            console.print(line, soft_wrap=True)
        return
    from masonrycli.outputs.report import recording_table
    from masonrycli.recording import inspect_recording, recording_path_problem

    problem = recording_path_problem(recording)
    if problem:
        raise InputError(problem)
    try:
        info = inspect_recording(recording)
    except ValueError as exc:  # the reader's own words: the file holds no complete recording
        raise InputError(f"{recording}: not a readable Rerun recording: {exc}") from None
    except Exception as exc:  # a corrupt or foreign file: say so in one line
        raise InputError(f"{recording}: not a readable Rerun recording ({type(exc).__name__}: {exc})") from None
    console.print(recording_table(str(recording), info))
    if info.get("metadata"):
        console.print(info["metadata"])
    if info["truncated"]:
        from masonrycli.outputs.files import part_writer

        pid = part_writer(recording)
        why = (
            f"a run still going (pid {pid}) writes it"
            if pid
            else "its writer did not finish: killed, or the disk was full"
        )
        warn(f"{recording}: truncated ({why}) — {info['frames']} frames up to its last complete chunk")


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
