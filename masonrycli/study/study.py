"""A study from start to finish: resume, run on the cluster, keep every row, fit, summarise.

:func:`run_study` is what ``masonry sweep`` does once :mod:`masonrycli.study.plan` has checked its
options; the outputs around it (terminal table, PNG, Rerun recording) are made by
:mod:`masonrycli.cli.sweep`; which files may be written: :mod:`masonrycli.study.files`.
"""

from __future__ import annotations

import dataclasses
import hashlib
import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from rich.console import Console

from masonrycli.errors import InputError
from masonrycli.outputs.verdict import counted
from masonrycli.study import files, store
from masonrycli.study.axes import Axis, StudyBase, apply_point, check_axes, check_find, grid
from masonrycli.study.drivers import FindDriver, GridDriver
from masonrycli.study.progress import StudyProgress
from masonrycli.study.task import RESULT_COLUMNS
from masonrycli.study.versions import WorkerMismatch, this_version


@dataclass(frozen=True)
class StudyRequest:
    """What to run: the axes, an optional threshold search, where the rows go and on what cluster."""

    axes: list[Axis]
    out: Path
    find: str | None = None
    outcome: str = "collapse"
    rtol: float = 0.005
    scheduler: str | None = None
    workers: int | None = None
    stop_at_collapse: bool = True
    histories: Path | None = None
    """Folder for one history file per run (written by the workers), or None."""
    force: bool = False
    """Replace existing files (``--force``; see :mod:`masonrycli.study.files`)."""
    warnings: tuple[str, ...] = ()
    """Lines for the user once every check has passed, before the first run (a warning printed earlier
    came out beside the one-line error of a bad request)."""
    warn: Callable[[str], None] | None = None
    """Where ``warnings`` go (the command line's stderr)."""
    command: str = ""
    """The ``masonry sweep …`` line that asked for the study ("" from elsewhere): each history names it."""


@dataclass(frozen=True)
class StudyResult:
    """The study's rows (grid order) and columns; rows found done, runs made now, failed rows, seconds."""

    rows: list[dict]
    columns: list[str]
    skipped: int
    ran: int
    wall_time: float
    failed: int = 0
    out: Path | None = None
    """Where the table went."""
    warnings: tuple[str, ...] = ()
    """Lines for the user once the table is shown (a search whose runs are not monotone: drivers.py)."""


MAX_CHECKED_VALUES = 1000
"""Values of one axis checked one by one before the study (beyond it, only the axis' ends)."""
MAX_CHECKED_POINTS = 1000
"""A grid of at most this many points is checked whole before the study (0.2 ms a point, 8 ms where a
builder option rebuilds the 51-block wall: less than a tenth of the point's run)."""


def points_to_check(axes: list[Axis]) -> list[dict]:
    """Grid points to try before the study: every one of a grid of at most ``MAX_CHECKED_POINTS``; of a
    larger one its first and last, and the first point with each value of each axis of at most
    ``MAX_CHECKED_VALUES`` values. Only the ends were tried: a bad value inside an axis (friction = -1 of
    0.5,-1,0.6; dt = 0.003 of 0.002:0.004:3, which does not divide the duration) ran into an error row and
    the study said "3 rows … 1 failed". A bad combination of good values (freq=3 with dt=0.2: 3 Hz
    aliased at 2.5 Hz) did too, "run the same command again to retry them", refused again each time."""
    if math.prod(len(a.values) for a in axes) <= MAX_CHECKED_POINTS:
        return grid(axes)
    first = {a.name: a.values[0] for a in axes}
    points = [first, {a.name: a.values[-1] for a in axes}]
    for axis in axes:
        if len(axis.values) <= MAX_CHECKED_VALUES:
            points += [first | {axis.name: value} for value in axis.values[1:-1]]
    return points


def _samples_digest(record) -> str:
    """SHA-1 of a record's sample times and values, and of how they are read."""
    digest = hashlib.sha1(np.asarray(record.time, dtype=np.float64).tobytes())
    digest.update(np.asarray(record.value, dtype=np.float64).tobytes())
    digest.update(repr((record.quantity, record.direction, record.window, record.baseline)).encode())
    return digest.hexdigest()


def prepare(base: StudyBase, request: StudyRequest) -> tuple[str, dict[str, str]]:
    """Check the request against the base (a bad axis fails here, before any cluster starts) and return
    the study's fingerprint, and that of each record of a ``--records`` set: the study of its rows alone.

    A row of a record set is of this study when its ``study`` is either: the fingerprint over every record
    (the rows of tables written before), or its own record's. Adding a record to the set (a fragility study
    grows as records are downloaded) changed the one fingerprint, and every finished row was "another
    study's": refused, or run again with --force."""
    from masonrycli.scenario.toml_file import dump_scenario

    check_axes(request.axes)
    check_find(request.axes, request.find)
    for point in points_to_check(request.axes):
        apply_point(base, point)  # raises InputError for an unknown or impossible parameter
    # a record by its samples, not its path and length: one corrected since (same file, same sample count)
    # kept its rows ("0 runs now, 1 row already there", the old pgv)
    records = {name: (r.source, r.scale, _samples_digest(r)) for name, r in base.records.items()}
    settings = (request.find, request.outcome if request.find else None, request.rtol if request.find else None)
    if base.settle is not None:  # the scenario is as drawn: each variant's runs start settled (tables before: no key)
        settings = (*settings, ("settle", base.settle))
    dumped = dump_scenario(base.scenario, inline_records=True)
    by_record = {
        name: store.fingerprint(dumped, {name: r}, settings, request.stop_at_collapse) for name, r in records.items()
    }
    return store.fingerprint(dumped, records, settings, request.stop_at_collapse), by_record


def run_study(base: StudyBase, request: StudyRequest, console: Console) -> StudyResult:
    """Run every row of the study not already in ``request.out``; write the table (also on Ctrl-C).
    On Dask, Dask's own log lines go to ``<out>.dask.log``, and one line says so (:mod:`masonrycli.study.dask_log`)."""
    if request.workers == 0:  # no Dask
        return _run_study(base, request, console)
    from masonrycli.study.dask_log import DaskLog, log_path

    result = None
    with DaskLog(log_path(request.out)) as log:
        try:
            result = _run_study(base, request, console)
        finally:  # stopped (Ctrl-C, a lost scheduler) as well: the line comes before the stop's
            said = log.said()
            if said is not None and result is None and request.warn is not None:
                request.warn(said)
    if said is not None:  # shown once the table is
        result = dataclasses.replace(result, warnings=(*result.warnings, said))
    return result


def _run_study(base: StudyBase, request: StudyRequest, console: Console) -> StudyResult:
    from masonrycli.engine import compile_ahead
    from masonrycli.study.runner import SchedulerLost, open_cluster, run_on_cluster, run_serially

    study_id, by_record = prepare(base, request)

    def row_study(row: dict) -> str:  # the fingerprint a new row is written with: its record's, in a set
        return by_record.get(row.get("record"), study_id)

    names = [a.name for a in request.axes if a.name != request.find]  # a row's key
    points = grid([a for a in request.axes if a.name != request.find])
    table, ours = files.open_table(request.out, study_id, request.force, names, points, request.warn, row_study)
    # run again: error rows, and "failed" ones (tables written before those became error rows)
    done = {store.row_key(r, names): r for r in ours if r.get("status") not in ("error", "failed")}
    if request.find:
        driver = FindDriver(request.axes, request.find, request.outcome, request.rtol, done)
        columns = names + [f"{request.find}_{s}" for s in ("threshold", "lo", "hi")]
        columns += ["holds", "outcome", "evaluations", "status", "wall_time", "note", "error", "study", "source"]
        columns += ["command"]
    else:
        driver = GridDriver(request.axes, done)
        columns = names + list(RESULT_COLUMNS) + ["study", "source", "command"]
    # Each row names the masonry source that made it (every run's is the command's: versions.py). The
    # fingerprint is of the study's inputs, not of the code: resumed after an upgrade, a table mixed rows of
    # two solvers without a word.
    source = this_version()[1]
    other = [r for r in done.values() if r.get("source") != source]
    # whose histories may be replaced (study/task.py), and the command each names (`masonry report` says it)
    study = (study_id, str(request.out.resolve()), request.command)
    files.check_histories(request.histories, driver.start(), request.find, request.force, study)
    unknown = [r for r in other if not r.get("source")]
    if len(other) > len(unknown) and request.warn is not None:
        made = sorted({str(r["source"]) for r in other if r.get("source")})
        was = "was" if len(other) - len(unknown) == 1 else "were"
        request.warn(
            f"{counted(len(other) - len(unknown), 'row')} of {request.out} {was} made by another masonry (source "
            f"{', '.join(made[:3])}; this one is {source}): kept, not run again — remove them (or the file) to run "
            "them with this one"
        )
    if unknown and request.warn is not None:
        request.warn(
            f"{counted(len(unknown), 'row')} of {request.out} {'does' if len(unknown) == 1 else 'do'} not say which masonry "
            "made them (written before rows named their source): kept, not run again"
        )
    for line in request.warnings if request.warn is not None else ():
        request.warn(line)
    start = time.perf_counter()
    # The cluster first: a --scheduler that cannot be reached is bad input, refused before any file is
    # written (it left a header-only table, which the corrected command then refused as existing).
    # no more local workers than the runs that can go at once (the grid's, a search's initial values)
    runs = len(driver.start())
    client, cluster = open_cluster(request.scheduler, request.workers, runs) if request.workers != 0 else (None, None)
    try:
        if request.histories is not None:  # before the journal: a folder that cannot be made is bad input
            try:  # (it left a header-only table and "error: /proc/x: No such file or directory")
                request.histories.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise InputError(f"--histories {request.histories}: cannot make the folder ({exc.strerror})") from None
        journal = store.Journal(request.out)
    except BaseException:
        _close(client, cluster)
        raise
    progress = StudyProgress(console, driver.total, driver.skipped)  # a bar, or lines off a terminal
    counts: dict[str, int] = {}
    ran = 0

    def on_row(params: dict, row: dict) -> None:
        # every finished row of the study goes to the journal at once (a threshold row when its bisection ends)
        nonlocal ran
        ran += 1
        label = row.get("state") or "failed"
        counts[label] = counts.get(label, 0) + 1
        for finished in driver.finished:
            finished["study"] = row_study(finished)
            finished["source"] = source
            # the line that made the row, as its history keeps it: a column, which every CSV reader takes (a
            # "# command" line above the header broke csv.DictReader and pandas; the table has no other place)
            finished["command"] = request.command
            journal.append(finished)
            progress.advance()
        driver.finished.clear()
        progress.states(
            f"{ran} run{'' if ran == 1 else 's'}: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
        )

    try:
        histories = None
        if request.histories is not None:
            histories = str(request.histories.resolve())
        task_args = (request.stop_at_collapse, histories, request.force, study)
        with progress:
            if client is None:
                with compile_ahead.ahead():  # a first study on one core compiles on two (engine/compile_ahead.py)
                    run_serially(base, driver, on_row, *task_args)
            else:
                where = f"--scheduler {request.scheduler}" if request.scheduler else "the local cluster"
                ahead = compile_ahead.on_cluster(client, external=cluster is None)  # held to the end
                run_on_cluster(
                    client, base, driver, on_row, *task_args, warn=request.warn, where=where, cluster=cluster
                )
                del ahead
    except (WorkerMismatch, SchedulerLost) as exc:  # the rows before it are kept (written below), resumable
        where = f"--scheduler {request.scheduler}" if request.scheduler else "the local cluster"
        once = "every worker runs this masonry" if isinstance(exc, WorkerMismatch) else "the scheduler is back"
        if driver.rows():
            kept = f"every finished row is in {request.out} (the same command resumes the study once {once})"
        else:  # it said "every finished row is in s.csv", and there was no s.csv (a scheduler lost before the first row)
            kept = f"no row was finished, nothing was written (the same command runs the study once {once})"
        raise InputError(f"{where}: {exc}; {kept}") from None
    finally:
        journal.close()
        rows = driver.rows()
        for r in rows:
            r.setdefault("study", row_study(r))
            r.setdefault("source", "")  # a row of a table written before rows named their source: unknown
            r.setdefault("command", "")  # or their command
        if rows:
            store.write_rows(table, rows, columns)
        else:  # stopped before any row: a header-only table held nothing, yet the same command refused it;
            # and the table --force would replace (another study's) became an empty one, lost for nothing
            store.journal_path(request.out).unlink(missing_ok=True)
        _close(client, cluster)
        if request.scheduler is None:  # its workers are gone: what they left half-written is of no one
            files.remove_abandoned_parts(request.histories)
    failed = sum(1 for r in rows if r.get("status") == "error")
    found = tuple(getattr(driver, "warnings", ()))
    return StudyResult(rows, columns, driver.skipped, ran, time.perf_counter() - start, failed, table.path, found)


def _close(client, cluster) -> None:
    # Stopped with thousands of tasks still queued, the LocalCluster's scheduler (in this process) logged
    # "CRITICAL - Closed comm ... while trying to write" and a traceback, up to dozens of times, for its
    # messages to the client being closed: teardown noise under the one-line "interrupted" message.
    logging.disable(logging.CRITICAL)
    try:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    finally:
        logging.disable(logging.NOTSET)
