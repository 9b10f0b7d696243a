"""One task of a study: build the point's scenario, run it, return a small row.

:func:`run_task` is what a Dask worker executes; it never raises for a failed run (the row says
``status = "error"`` and why), so one bad point does not stop a study.
"""

from __future__ import annotations

import contextlib
import json
import math
import time
from pathlib import Path

import numpy as np

from masonrycli.records.intensity import INTENSITY_MEASURES

OUTCOMES = ("collapse", "sliding", "rocking")
"""Outcomes ``--find`` can bisect for, besides ``drift:X`` (peak top drift beyond X × the height)."""
RESULT_COLUMNS = (
    "state",
    "collapse_time",
    "energy_dissipated",
    *INTENSITY_MEASURES,
    "residual_drift",
    "peak_drift",
    "max_opening",
    "hinges",
    "slide_time",
    "rock_time",
    "status",
    "steps",
    "time",
    "wall_time",
    "cpu_time",
    "sweeps_mean",
    "capped_steps",
    "last_residual",
    "max_penetration",
    "error",
)
"""The columns every row has after its parameters (units in ``docs/sweep.md``)."""
REFUSED = "refused: "
"""How the error of a row whose point was refused begins (its parameters cannot run: refused again on a retry)."""


def run_task(
    base,
    params: dict,
    stop_at_collapse: bool = True,
    history_dir: str | None = None,
    force: bool = False,
    study: tuple[str, str, str] | None = None,
) -> dict:
    """Run the grid point ``params`` of ``base`` (:class:`~masonrycli.study.axes.StudyBase`): its row.

    With ``history_dir`` the run's history (:mod:`masonrycli.outputs.history`) is written there as
    :func:`history_name` of the point (on the worker's file system), under the policy of
    :mod:`masonrycli.outputs.files`: a temporary file renamed into place when complete, an existing file
    replaced only with ``force`` or when an earlier run of the same ``study`` (its fingerprint and its
    table) wrote it (:func:`made_by_study`; the study checked them all before the first run). The history
    names its study, its table, its point and the ``masonry sweep`` command (``study``'s third, if any).
    """
    from masonrycli.errors import InputError
    from masonrycli.execute import run_metadata
    from masonrycli.outputs.files import OutputFile, written_whole
    from masonrycli.outputs.history import HistoryFile, block_constants, result_values
    from masonrycli.run import Simulation, simulate
    from masonrycli.study.axes import apply_point

    # the CPU time of this thread, not of the process: a worker of two threads (`dask worker --nthreads 2`, one
    # process a machine by default) runs two tasks at once, and each row counted the other's CPU too
    start, cpu_start = time.perf_counter(), time.thread_time()
    row = dict(params)
    out_file = None  # the history's, with history_dir
    try:
        scenario = apply_point(base, params)
        sim = Simulation(scenario)
        with contextlib.ExitStack() as files:
            sinks = []
            if history_dir:
                path = Path(history_dir) / history_name(params)
                out_file = OutputFile(path, "--histories", force=force or made_by_study(path, study))
                part = files.enter_context(written_whole(out_file))
                sinks.append(HistoryFile(part, sim.model.block_name, sim.model.support_name))
                sinks[0].run_info = run_metadata(scenario, sim) | {"study_point": params}
                sinks[0].run_values |= block_constants(sim.model)
                if study:
                    sinks[0].run_info |= {"study": study[0], "study_table": study[1]}
                    sinks[0].run_info |= {"command": study[2]} if study[2:] and study[2] else {}
            result = simulate(scenario, sinks, sim=sim, stop_at_collapse=stop_at_collapse)
            if sinks:
                sinks[0].run_values |= {f"intensity_{k}": v for k, v in result.intensity.items()}
                sinks[0].run_values |= result_values(result.outcome, sim.monitor.height)
                sinks[0].close(status=result.status, note=result.message)
        if history_dir:  # written whole: what a killed writer of the same point left is of no one now
            remove_stale_parts(path)
    except InputError as exc:  # the point's parameters refused (a grid too large to check whole: study.py)
        return row | empty_result(f"{REFUSED}{exc}", time.perf_counter() - start)
    except Exception as exc:  # a failed task is reported in its row; the study goes on
        # an output's (outputs.files.written_whole): "OSError: [Errno 28] No space left on device" named no file
        said = f"cannot write {exc.output}: {exc.strerror or exc}" if getattr(exc, "output", None) else None
        return row | empty_result(said or f"{type(exc).__name__}: {exc}", time.perf_counter() - start)
    out = result.outcome
    tally = result.tally
    # a run that stopped early without raising (status "failed": an output's write failed mid-run;
    # "interrupted") did not finish: an error row like any failed task, counted and run again on resume
    failed = result.status not in ("completed", "diverged")
    row |= {
        "state": "" if failed else out["state"],
        "collapse_time": out["collapse_time"],
        "energy_dissipated": result.energy_dissipated,
    }
    row |= {name: result.intensity.get(name, math.nan) for name in INTENSITY_MEASURES}
    row |= {k: out[k] for k in ("residual_drift", "peak_drift", "max_opening", "hinges", "slide_time", "rock_time")}
    row |= {
        "status": "error" if failed else result.status,
        "steps": result.steps,
        "time": result.time,
        "wall_time": time.perf_counter() - start,
        "cpu_time": time.thread_time() - cpu_start,
        "sweeps_mean": tally.sweeps_mean,
        "capped_steps": tally.capped,
        "last_residual": tally.residual_last,
        "max_penetration": result.max_penetration,
        "error": f"{result.status}: {_written(result, out_file)}{result.message}"
        if failed
        else (result.message if result.status == "diverged" else ""),
    }
    return row


def history_name(params: dict) -> str:
    """``amp=0.5_freq=2.npz``: the file name of a point's history (characters unsafe in names -> "-"). Values
    to 15 significant digits: 6 (``:g``) gave two points of a fine search (``--rtol 1e-6``) one name, the later
    run's history replacing the earlier one; 15 still writes linspace's 0.30000000000000004 as 0.3."""
    text = "_".join(f"{k}={v:.15g}" if isinstance(v, float) else f"{k}={v}" for k, v in params.items())
    return "".join(c if c.isalnum() or c in "=._-" else "-" for c in text) + ".npz"


def remove_stale_parts(path: Path) -> None:
    """Remove the temporary files of ``path`` (a history this process has just written whole) that writers no
    longer running left: a worker killed inside a run leaves its ``.NAME.<pid>.part`` and the history's
    ``.rows`` folder (3 MB for 3 s of the 51-block wall, growing with the run), and the scheduler runs the
    point again elsewhere. The command removes those of its LocalCluster's workers at the end; on a
    ``--scheduler``'s workers, whose pids mean nothing to it, they stayed for good (walk-through 2026-11-29).
    A writer still running on this machine is left alone (another study writing the same folder)."""
    import shutil

    from masonrycli.outputs.files import glob_escape, part_writer

    for part in path.parent.glob(f".{glob_escape(path.name)}.*.part*"):
        writer = part.with_name(part.name.removesuffix(".rows"))
        if not writer.name.endswith(".part") or part_writer(writer) is not None:
            continue
        try:
            if part.is_dir():
                shutil.rmtree(part, ignore_errors=True)
            else:
                part.unlink(missing_ok=True)
        except OSError:  # another process removing it too, a read-only folder: left, as before
            pass


def made_by_study(path: Path, study: tuple[str, ...] | None) -> bool:
    """Whether ``path`` is a history that a run of ``study`` (its fingerprint, its table; not the command's
    words) wrote. A study
    stopped by Ctrl-C (or killed) leaves the histories of its runs in flight, which the workers finish,
    without their rows: the same command then refused to resume ("--histories …/amp=1.10909.npz: the file
    exists"). Such a file is made again and may be replaced; any other needs ``--force`` (the same study
    into another table too: that table's row is its history)."""
    if not study or not path.is_file():
        return False
    try:
        with np.load(path) as history:
            run = json.loads(str(history["run"]))
    except Exception:  # not a history
        return False
    return (run.get("study"), run.get("study_table")) == tuple(study)[:2]


def empty_result(error: str, wall_time: float) -> dict:
    """The result columns of a task that failed before or during its run."""
    row = {name: math.nan for name in RESULT_COLUMNS}
    row |= {"state": "", "status": "error", "steps": 0, "hinges": 0, "capped_steps": 0, "wall_time": wall_time}
    return row | {"error": " ".join(error.split())[:300]}


def reached(row: dict, outcome: str) -> bool:
    """Did the run of ``row`` produce ``outcome`` (collapse, sliding, rocking, or drift:X)?"""
    if outcome == "collapse":
        return row["state"] == "collapsed"
    if outcome == "sliding":
        return not np.isnan(row["slide_time"])
    if outcome == "rocking":
        return not np.isnan(row["rock_time"])
    return row["peak_drift"] > drift_limit(outcome)


def drift_limit(outcome: str) -> float:
    """X of ``drift:X``; raises ValueError otherwise."""
    name, _, value = outcome.partition(":")
    if name != "drift":
        raise ValueError(outcome)
    return float(value)


def check_outcome(outcome: str) -> str:
    from masonrycli.errors import InputError

    if outcome in OUTCOMES:
        return outcome
    try:
        limit = drift_limit(outcome)
    except ValueError:
        value = outcome.partition(":")[2].strip()
        percent = value.endswith("%") and value[:-1].strip()
        hint = ""
        try:  # "drift:5%": the ratio as a fraction, as --scale 50% is told
            hint = f" (write drift:{float(percent) / 100:g}: a percentage is written as a fraction)" if percent else ""
        except ValueError:
            pass
        raise InputError(
            f"--outcome {outcome}: expected collapse, sliding, rocking or drift:X (X a drift ratio, e.g. drift:0.01)"
            + hint
        ) from None
    if not (math.isfinite(limit) and limit > 0):
        raise InputError(f"--outcome {outcome}: the drift ratio must be > 0")
    if limit > 1:
        # "drift:50" (50 % meant) searched for a top drift of 50 × the height, which no run reaches (the wall
        # is collapsed at 0.25): "no drift:50 up to amp = 1" for every point
        raise InputError(
            f"--outcome {outcome}: a drift of {limit:g} × the height, beyond the height itself (a likely typo: "
            f"the ratio is a fraction, drift:{limit / 100:g} is {limit:g} %)"
        )
    return outcome


def _written(result, out) -> str:
    """``cannot write --histories h/amp=0.5.npz: `` when the run stopped because its history could not be
    written (the row said only "failed: stopped at t = 0.03 s (step 30): No space left on device")."""
    return f"cannot write {out.option} {out.path}: " if out and result.failed_sink is not None else ""
