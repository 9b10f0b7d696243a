"""``masonry sweep``: a study of one structure over a grid of parameters or a set of records, on Dask.

Thin: options -> :func:`~masonrycli.study.plan.plan_study` (every check, the base scenario and the
:class:`~masonrycli.study.study.StudyRequest`) -> run_study -> table, PNG, Rerun recording; messages and
exit codes. Registered on the app by :mod:`masonrycli.cli.app`.
"""

from __future__ import annotations

import contextlib
import signal
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from masonrycli.cli.option_values import choice_value, file_path_value, number_value, path_value, whole_value
from masonrycli.cli.options import (
    SETTLE,
    SURVEY,
    with_options,
)
from masonrycli.errors import EXIT_DIVERGED, EXIT_OUTPUT_FAILED, EXIT_ROWS_FAILED
from masonrycli.interrupt import FirstSignalStops, exit_code, signal_name
from masonrycli.outputs.files import OutputFile
from masonrycli.outputs.verdict import counted

if TYPE_CHECKING:
    from masonrycli.study.plan import StudyPlan


@with_options(SURVEY, SETTLE)
def sweep_command(
    target: Annotated[
        str,
        typer.Argument(
            help="wall, arch, aqueduct, a scenario file (TOML) or a GeoJSON / WKT geometry (--records shakes its one support or those marked driven).",
            metavar="TARGET",
        ),
    ],
    param: Annotated[
        list[str] | None,
        typer.Option(
            "--param",
            "-p",
            help="An axis: NAME=LO:HI:N, NAME=a,b,c or NAME=value. Names: amp, freq, phase (the sine of the "
            "moving supports; ground.amp for one), scale (records), pga_g (records scaled to peak at this PGA, in "
            "g), friction, duration, dt, builder options.",
        ),
    ] = None,
    records: Annotated[
        list[Path] | None,
        typer.Option(
            "--records",
            parser=path_value,
            help="Record files (PEER .AT2, ESM .ASC, K-NET .NS/.EW/.UD or CSV) or folders of them, repeatable: one axis 'record' over them.",
        ),
    ] = None,
    record_dt: Annotated[
        float | None,
        typer.Option(
            "--record-dt",
            parser=number_value,
            help="Seconds between the samples of the --records CSVs of one value per line (no time column); "
            "the other files keep their own times.",
        ),
    ] = None,
    baseline: Annotated[
        str | None,
        typer.Option(
            "--baseline",
            parser=choice_value,
            help="Drift correction of the --records of acceleration, as a scenario file's baseline: quadratic "
            "(default) or none (the samples as given).",
        ),
    ] = None,
    scale: Annotated[
        str | None, typer.Option("--scale", help="Record scale axis, e.g. 0.25:2:8 (= --param scale=...).")
    ] = None,
    find: Annotated[
        str | None,
        typer.Option(
            "--find",
            help="Bisect this parameter for the smallest value giving --outcome (the largest, when it comes below "
            "a value: at LO, not at HI).",
        ),
    ] = None,
    # None when not given: without --find they were ignored without a word (a grid ran instead)
    outcome: Annotated[
        str | None,
        typer.Option(
            "--outcome",
            parser=choice_value,
            help="What --find looks for: collapse, sliding, rocking or drift:X (default collapse).",
        ),
    ] = None,
    rtol: Annotated[
        float | None,
        typer.Option(
            "--rtol", parser=number_value, help="Relative width at which --find stops bisecting (default 0.005)."
        ),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out",
            "-o",
            parser=file_path_value,
            help="Results, .parquet or .csv (one row per run; default study-<scenario>.parquet).",
        ),
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option("--scheduler", help="Address of an existing Dask scheduler, tcp://HOST:8786.")
    ] = None,
    workers: Annotated[
        int | None,
        typer.Option(
            "--workers",
            parser=whole_value,
            help="Worker processes of the local cluster (default: one per core; never more than the runs; 0: no cluster).",
        ),
    ] = None,
    full_runs: Annotated[bool, typer.Option("--full-runs", help="Do not stop a run when it collapses.")] = False,
    duration: Annotated[
        float | None,
        typer.Option(
            parser=number_value,
            help="Simulated time of every run, s (default: the scenario file's; a built-in's 1-2 s, or over --records "
            "the longest record).",
        ),
    ] = None,
    dt: Annotated[float | None, typer.Option("--dt", parser=number_value, help="Time step, s.")] = None,
    im: Annotated[
        str,
        typer.Option(
            "--im", parser=choice_value, help="Intensity measure of the fragility curve: pga, pgv, arias, sa."
        ),
    ] = "pga",
    plot: Annotated[
        Path | None,
        typer.Option(
            "--plot",
            parser=file_path_value,
            help="PNG of the state map / fragility / thresholds (default: beside --out, .png).",
        ),
    ] = None,
    recording: Annotated[
        Path | None,
        typer.Option(
            "--recording", parser=file_path_value, help="Rerun recording of the study (default: beside --out, .rrd)."
        ),
    ] = None,
    no_recording: Annotated[
        bool, typer.Option("--no-recording", help="Write no Rerun recording of the study.")
    ] = False,
    histories: Annotated[
        Path | None,
        typer.Option(
            "--histories", parser=path_value, help="Folder for one history (.npz) per run, e.g. amp=0.5_freq=2.npz."
        ),
    ] = None,
    force: Annotated[
        bool,
        typer.Option(
            "--force", help="Replace existing output files (finished rows of the same study are still reused)."
        ),
    ] = False,
    **survey,
) -> None:
    """Run a structure over a grid of parameters or a set of records on Dask; one row per run.

    [bold]masonry sweep wall --param amp=0.1:1.0:10 --param freq=0.5:4:8 --out study.parquet[/bold]
    """
    from masonrycli.cli.app import console, err_console
    from masonrycli.study import store
    from masonrycli.study.plan import plan_study
    from masonrycli.study.study import run_study

    plan = plan_study(
        target,
        params=param,
        records=records,
        record_dt=record_dt,
        baseline=baseline,
        scale=scale,
        find=find,
        outcome=outcome,
        rtol=rtol,
        out=out,
        scheduler=scheduler,
        workers=workers,
        stop_at_collapse=not full_runs,
        duration=duration,
        dt=dt,
        im=im,
        plot=plot,
        recording=recording,
        no_recording=no_recording,
        histories=histories,
        force=force,
        survey={k: v for k, v in survey.items() if k != "settle"},
        settle=survey["settle"],
        warn=lambda line: err_console.print(f"warning: {line}", soft_wrap=True),
    )
    # SIGTERM (kill, a batch system's time limit) takes Ctrl-C's way out: the finished rows are written and
    # the cluster closed. Before, it killed the command outright: no table, and multiprocessing's
    # "leaked semaphore" warning on stderr.
    # The handler stays for the plot and the recording: a SIGTERM there killed the command outright (exit
    # -15, a hidden .s.png.<pid>.part left beside the table), and Ctrl-C there said "stopped before any
    # output was written" with the whole table written.
    # Only the first signal stops the study; later ones are acknowledged and ignored, as in a run's closing
    # phase (masonrycli.interrupt): a second Ctrl-C while the table was written cut it (only the journal
    # left, under "every finished row is in s.parquet"), and one after it killed the process (exit -2).
    out, result, written = plan.request.out, None, []
    previous = _identity(out)  # a table that --force would replace, left as it was by a stop before any row
    with FirstSignalStops() as signals:
        try:
            result = run_study(plan.base, plan.request, console)
            _report(console, result, plan, im, written, signals)
            for line in result.warnings:
                err_console.print(f"warning: {line}", soft_wrap=True)
            _exit_for_failed_rows(result, err_console)
        except (KeyboardInterrupt, Exception) as exc:
            if not isinstance(exc, KeyboardInterrupt) and not signals.raised():
                raise  # an error of its own (a rename that failed while a signal was held): said as such
            # An error after the first signal is the KeyboardInterrupt that its handler raised, replaced by the
            # code it landed in: numpy's structured comparison (np.unique in a block's polygon check) made it
            # "TypeError: Cannot compare structured arrays", a traceback and exit 1 (1 in ~100 Ctrl-Cs 0.7 s in).
            signum = signals.stopping()
            how = "" if signum == signal.SIGINT else f" ({signal_name(signum)})"
            if result is None and not (out.exists() or store.journal_path(out).exists()):
                # stopped before the table was opened (while a --scheduler was reached): there is no file
                said = "stopped before any row was finished; nothing was written"
            elif result is None and previous is not None and _identity(out) == previous:
                said = f"stopped before any row was finished; nothing was written ({out} is as it was)"
            elif result is None:
                said = f"every finished row is in {out}; run the same command again to resume"
            else:  # the study is complete: what is missing is a picture
                files = (plan.picture, plan.recording)
                missing = [str(f.path) for f in files if f is not None and f.path not in written]
                again = "with --force (no run is made again)" if written else "(no run is made again)"
                said = f"every row is in {out}, but not written: {', '.join(missing)}; run the same command {again}"
            with contextlib.suppress(OSError):  # the terminal is gone (SIGHUP): the exit code still says how
                err_console.print(f"interrupted{how}: {said}", soft_wrap=True)
            raise typer.Exit(exit_code(signum)) from None


def _identity(path: Path) -> tuple | None:
    """Which file is at ``path`` (device, inode, size, modification time), None if none: a table written
    anew is renamed onto the path, so a changed identity means it was replaced."""
    try:
        st = path.stat()
    except OSError:
        return None
    return st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns


def _exit_for_failed_rows(result, err_console) -> None:
    """Exit 5 when rows failed, else 3 when runs diverged (as ``masonry simulate``), each with one line:
    a script saw exit 0 under "2 failed" (histories on a full disk). A collapse is an outcome, not this."""
    from masonrycli.study.task import REFUSED

    total = counted(len(result.rows), "row")
    diverged = sum(1 for r in result.rows if r.get("status") == "diverged")
    refused = [r for r in result.rows if r.get("status") == "error" and str(r.get("error")).startswith(REFUSED)]
    # The plot and the recording are written whole however many rows failed, so the same command again is
    # refused ("--out's plot s.png: the file exists"): --force replaces them and reuses every finished row.
    if refused:  # a retry refuses them again: "run the same command again to retry them" sent the user round
        first = str(refused[0]["error"]).removeprefix(REFUSED)
        err_console.print(
            f"error: {len(refused)} of {total} refused their parameters ({first}{'; …' if len(refused) > 1 else ''}): "
            f"the same command refuses {'it' if len(refused) == 1 else 'them'} again; a grid without "
            f"{'it' if len(refused) == 1 else 'them'}, with --force, reuses the finished rows (every reason is in the "
            f"error column in {result.out})",
            soft_wrap=True,
        )
    if result.failed > len(refused):
        err_console.print(
            f"error: {result.failed - len(refused)} of {total} failed (the reason is in their error column in "
            f"{result.out}); run the same command again with --force to retry them (it reuses the finished rows, "
            "and replaces the plot and the recording)",
            soft_wrap=True,
        )
    if diverged:
        err_console.print(
            f"error: {diverged} of {total} diverged (their error column in {result.out} says when); "
            "a smaller dt (--dt, or --param dt=...) may follow them",
            soft_wrap=True,
        )
    if result.failed or diverged:
        raise typer.Exit(EXIT_ROWS_FAILED if result.failed else EXIT_DIVERGED)


def _at_zero(rows: list[dict], im: str) -> str:
    """The runs the fit leaves out, at an IM of 0 (--scale 0:6:3): "1 of 4 runs collapsed" of 6 rows."""
    zero = sum(1 for r in rows if not (isinstance(r.get(im), (int, float)) and r[im] > 0))
    return f"; {counted(zero, 'run')} at {im} = 0 left out" if zero else ""


def _collapsed_line(group) -> str | None:
    """How many runs of a fragility curve collapsed at each level (``friction = 0.5: collapsed per pga_g (g):
    0.2 0/7, …, 1.6 4/7``): the paper's table, shown by the PNG's diamonds only; None without levels."""
    from masonrycli.study.curves import UNITS, collapsed_per_level

    found = collapsed_per_level(group.rows)
    if found is None:
        return None
    by, levels = found
    unit = UNITS.get(by)
    head = f"collapsed per {by}" + (f" ({unit})" if unit else "")
    counts = ", ".join(f"{level:g} {fell}/{runs}" for level, fell, runs in levels)
    return f"{group.label + ': ' if group.label else ''}{head}: {counts}"


def _no_fit(rows: list[dict], axes) -> str:
    """Why a record study has no fragility curve, and what gives one: 'no fit (every run collapsed, or none
    did)' left the user to count which, and which way to move the scales."""
    fell = sum(r.get("state") == "collapsed" for r in rows)
    names = [a.name for a in axes]
    by = "--param pga_g" if "pga_g" in names else "--scale"  # the axis that scales the records
    scaled = by != "--scale" or "scale" in names
    if len(rows) < 2:
        return f"fragility: no fit ({counted(len(rows), 'run')}; a fit needs at least 2)"
    if fell == 0:
        more = f"larger {by} values reach it" if scaled else "a --scale range reaches it"
        return f"fragility: no fit — none of the {len(rows)} runs collapsed ({more})"
    less = f"smaller {by} values find where it stands" if scaled else "a --scale range finds where it stands"
    return f"fragility: no fit — all {len(rows)} runs collapsed ({less})"


def _fit_line(group, im: str, axes) -> str:
    """The fragility line of one group of runs (``fragility.FitGroup``): its fit, or why there is none;
    prefixed by the group's values when the study has several (``friction = 0.5: fragility (pga): …``)."""
    from masonrycli.records.intensity import UNITS

    fit, rows, unit = group.fit, group.rows, UNITS[im]
    if fit is None:
        line = _no_fit(rows, axes)
    elif fit.separated is not None:
        stood, fell = fit.separated
        line = (
            f"fragility ({im}): not resolved — every collapse ({im} ≥ {fell:.4g} {unit}) is above every run "
            f"that stood (≤ {stood:.4g} {unit}): the median θ is anywhere between, the dispersion β → 0; more "
            f"records or scales are needed ({fit.collapsed} of {fit.runs} runs collapsed{_at_zero(rows, im)})"
        )
    elif fit.unbounded:
        line = (
            f"fragility ({im}): not resolved — the collapses do not come at larger {im} than the runs that "
            f"stood (the fit's dispersion β runs to its bound, {fit.dispersion:.3g}); more records or scales are "
            f"needed ({fit.collapsed} of {fit.runs} runs collapsed{_at_zero(rows, im)})"
        )
    else:
        line = (
            f"fragility ({im}): median θ = {fit.median:.4g} {unit}, dispersion β = {fit.dispersion:.3f} "
            f"({fit.collapsed} of {fit.runs} runs collapsed{_at_zero(rows, im)})"
        )
    return f"{group.label}: {line}" if group.label else line


def _report(console, result, plan: StudyPlan, im: str, written: list, signals: FirstSignalStops) -> None:
    """The table on the terminal, the fit, the plot and the recording; ``written`` gets each file's path
    as it is renamed into place, a signal held between the two (:func:`_recorded`)."""
    from masonrycli.outputs.files import written_whole
    from masonrycli.records.intensity import UNITS
    from masonrycli.study.curves import searched_range
    from masonrycli.study.fragility import fit_by
    from masonrycli.study.plots import fragility_curve, state_map, threshold_curve
    from masonrycli.study.table import find_columns, grid_columns, study_table

    request, name, plot, recording = plan.request, plan.name, plan.picture, plan.recording
    rows, axes = result.rows, request.axes
    keys = [a.name for a in axes if a.name != request.find]  # what a row is keyed by
    names = [a.name for a in axes if a.name != request.find and len(a.values) > 1]
    # an axis of one value is said once under the table, not in a column a row: the wall's courses, length and
    # density took 3 of an 80-column terminal's 7 columns, and the pga and collapse columns were left out
    fixed = {a.name: a.values[0] for a in axes if a.name != request.find and len(a.values) == 1 and names}
    shown = [k for k in keys if k not in fixed]
    columns = find_columns(shown, request.find) if request.find else grid_columns(shown, im)
    fit, groups = None, []
    with written_whole(plot, around_commit=_recorded(signals, written, plot)) as part:
        if request.find:
            title = f"{name}: {request.outcome} threshold"
            searched = searched_range(request)
            threshold_curve(rows, request.find, names[0] if names else None, part, title, searched, tuple(names[1:]))
        elif "record" in [a.name for a in axes]:
            good = [r for r in rows if r.get("status") != "error"]
            # one curve per value of the other swept parameters: pooled, two frictions made one curve of neither
            groups = fit_by(good, im, [n for n in names if n not in ("record", "scale", "pga_g")])
            fit = groups[0].fit if len(groups) == 1 else None
            title = f"{name}: fragility ({len(good)} runs{f', {len(groups)} curves' if len(groups) > 1 else ''})"
            fragility_curve(good, im, fit, part, title, UNITS[im], groups)
        else:
            x, y = names[0] if names else axes[0].name, names[1] if len(names) > 1 else None
            state_map(rows, x, y, part, name, tuple(names[2:]))
    if recording is not None:
        from masonrycli.recording.study import record_study

        try:
            with written_whole(recording, around_commit=_recorded(signals, written, recording)) as part:
                record_study(part, name, rows, request, fit, im, plot.path, groups)
        except OSError as exc:  # a full disk: the table and plot are written, the recording is not (exit 4)
            from masonrycli.cli.messages import fail

            fail(f"cannot write {recording.option} {recording.path}: {exc.strerror or exc}", EXIT_OUTPUT_FAILED)
    # said once both are written: a reader of stdout that goes away (`masonry sweep … | head`) broke the pipe
    # at the first line after the table, and the plot and the recording were never written
    console.print(study_table(rows, columns, keys, console, result.out, fixed))
    # each on a line of its own however long its paths (soft_wrap): at a pipe's 80 columns, a notebook's capture or
    # a log, 'histories: … (…; as CSV: masonry export h --top)' broke its path and command over two lines
    console.print(
        f"{counted(len(rows), 'row')} in {result.out} ({counted(result.ran, 'run')} now, {counted(result.skipped, 'row')} already "
        f"there, {result.failed} failed) in {result.wall_time:.1f} s",
        soft_wrap=True,
    )
    for group in groups:
        console.print(_fit_line(group, im, request.axes))
        if (line := _collapsed_line(group)) is not None:
            console.print(line)
    console.print(f"plot: {plot.path}", soft_wrap=True)
    if request.histories is not None:  # the summary named the table, plot and recording, not the runs' histories
        # counted where this command runs (a remote cluster's workers write them where they run)
        found = sum(1 for _ in request.histories.glob("*.npz")) if request.histories.is_dir() else 0
        each = f"{found} {'history' if found == 1 else 'histories'}, one a run" if found else "one history a run"
        console.print(
            f"histories: {request.histories} ({each}; as CSV: masonry export {request.histories} --top)", soft_wrap=True
        )
    if recording is not None:
        # as masonry run says it: 'recording: s.rrd' left a first user to find out what opens a .rrd
        from rich.text import Text

        from masonrycli.viewer_command import open_command

        command = open_command(recording.path)
        console.print(
            Text.assemble("recording: ", str(recording.path), "  (open it: ", (command, "bold"), ")"), soft_wrap=True
        )


@contextlib.contextmanager
def _recorded(signals: FirstSignalStops, written: list, out: OutputFile):
    """Around a report file's rename: the file is added to ``written`` once in place, a signal held until
    then — one arriving between the rename and the record named the file "not written"."""
    with signals.held():
        yield
        written.append(out.path)
