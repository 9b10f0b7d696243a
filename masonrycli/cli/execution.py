"""A run from the command line, start to exit code: its outputs checked, the scenario's caveats warned, the
run under the stop signals, its summary, and the exit code saying how it ended (run and simulate; check asks
only :func:`checked_outputs`)."""

from __future__ import annotations

import os

import typer

from geometry_library.blocks import GeometryError
from masonrycli.cli.messages import console, fail, say, warn
from masonrycli.errors import EXIT_DIVERGED, EXIT_INTERNAL, EXIT_OUTPUT_FAILED, InputError


def checked_outputs(scenario, opts: dict):
    """The outputs a run of ``scenario`` would write, checked (``opts``: the OUTPUT and FORCE options), as
    run, simulate and check all ask: :func:`masonrycli.output_plan.check_run`."""
    from masonrycli.output_plan import check_run

    return check_run(
        scenario,
        opts["out"],
        opts["history"],
        no_recording=opts["no_recording"],
        force=opts["force"],
        magnify=opts["magnify"],
    )


def execute_and_exit(scenario, opts: dict, hint=None) -> None:
    """Check the outputs (``opts``: the OUTPUT, FORCE and STOP options), run, print the summary; exit with
    the code of how the run ended. ``hint``: the line under the summary, given the time the run reached."""
    # the run's module (the engine, the outputs) loaded before the run's handlers: a signal while it loads is
    # "stopped before any output was written", not a traceback out of the handlers below
    from masonrycli.execute import execute
    from masonrycli.interrupt import StopSignals
    from masonrycli.scenario.caveats import scenario_warnings

    outputs = checked_outputs(scenario, opts)
    for warning in scenario_warnings(scenario):
        warn(warning)
    # The run's handlers stay installed through the summary: once execute() had put Python's back, a Ctrl-C
    # while the summary was printed said "Ctrl-C: stopped before any output was written" (exit 130) of a
    # run whose files had just been renamed into place, and a SIGTERM killed the process mid-table (-15).
    with StopSignals() as signals:
        _execute_and_report(execute, scenario, opts, hint, outputs, signals)


def _execute_and_report(execute, scenario, opts: dict, hint, outputs, signals) -> None:
    """:func:`execute_and_exit`'s run (``execute``: :func:`masonrycli.execute.execute`) and summary, under
    ``signals``."""
    from masonrycli.interrupt import StopRun, exit_code, signal_name
    from masonrycli.outputs.sinks import DIVERGED, FAILED, INTERRUPTED
    from masonrycli.run_summary import print_summary

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
