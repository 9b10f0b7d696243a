"""Run a scenario with its outputs: output checks, history file, Rerun recording, progress bar, summary.

Before step 1 every output path is checked and its temporary file created (:mod:`masonrycli.outputs.files`),
and a run whose outputs would not fit on the disk is refused. The outputs are then closed whatever
happens — normal end, divergence, a signal, an engine error, a failed write — and each one that closed
is renamed into place, so what was computed is kept and a path never holds half a file.
"""

from __future__ import annotations

import contextlib
import ntpath
import os
import platform
import re
import shlex
import shutil
import sys
import warnings
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.text import Text

from masonrycli import SOURCE_DIGEST, __version__
from masonrycli.engine import compile_ahead
from masonrycli.errors import InputError
from masonrycli.interrupt import StopSignals
from masonrycli.outputs.files import (
    OutputFile,
    check_distinct,
    check_output,
    check_space,
    default_recording_path,
    open_part,
)
from masonrycli.outputs.history import History, HistoryFile, block_constants, result_values
from masonrycli.outputs.report import progress_bar, slow_start_notice, summary_table
from masonrycli.outputs.sinks import COMPLETED, FAILED
from masonrycli.run import RunResult, Simulation, simulate
from masonrycli.scenario.values import option_text
from masonrycli.source_digest import source_commit

HISTORY_BYTES_PER_BLOCK = 500
"""Upper estimate of one block's share of a history row (measured: 326 B for the walls, 420 B for an arch of
60 voussoirs, whose blocks have more joints)."""
HISTORY_STATIC_BYTES = 60_000
"""... and of what a history holds however short (names, joints, intensity measures, the run's result; its
``units`` table alone is 43 kB: 61 rows of two 89-character UTF-32 cells, measured 2026-11-29)."""
RECORDING_BYTES_PER_BLOCK = 500
"""Upper estimate of one block's share of a recorded frame (measured: 405 B for the walls)."""
FRAME_OVERHEAD_BYTES = 2000
RECORDING_STATIC_BYTES = 750_000
"""Upper estimate of what a recording holds however short: blueprint, legends, document, static geometry
(measured: 452 kB for the 51-block wall's 10 steps, 548 kB for the aqueduct's 2; without it a 0.1 s run
was let start on a disk it then filled, exit 4). Re-measured 2026-11-29 (c5b6ab5): 678 kB for the wall's 2
steps, 763 kB for the aqueduct's; the wall's 0.3 s at --record-every 100 wrote 815–835 kB against the 600 kB
constant's estimate of 813 kB (test_execute's size test failed in CI)."""
RECORDING_STATIC_BYTES_PER_BLOCK = 300
"""... and its share per block (measured: 703 kB for 1004 blocks and 2 steps, one frame of ~400 kB in it)."""
RECORDING_BYTES_PER_STEP = 200
"""Upper estimate of the per-step series (solver sweeps, residual, contacts: measured ~150 B a step for
the wall at --record-every 1000, 603 kB for 1000 steps)."""


@dataclass
class Outputs:
    """The run's output files, checked (see :func:`plan_outputs`); None where not written."""

    recording: OutputFile | None = None
    history: OutputFile | None = None

    def files(self) -> list[OutputFile]:
        return [o for o in (self.recording, self.history) if o is not None]


MAX_MAGNIFY = 1e6
"""Largest --magnify: beyond it a millimetre is drawn a kilometre long (1e300 overflowed the recording's
float32 coordinates to inf, with a RuntimeWarning)."""


def check_run(
    scenario, out: Path | None, history: Path | None, *, no_recording: bool, force: bool, magnify: float | None
) -> Outputs:
    """Everything checked before a run (what ``masonry check`` stops after): the time step against the
    supports' motions, ``--magnify``, then the outputs (:func:`plan_outputs`). Raises InputError."""
    from masonrycli.scenario.sampling import check_sampling

    check_sampling(scenario)
    check_magnify(magnify, no_recording)
    return plan_outputs(scenario, out, history, no_recording=no_recording, force=force)


def check_magnify(magnify: float | None, no_recording: bool) -> None:
    if magnify is not None and not 1.0 <= magnify <= MAX_MAGNIFY:
        raise InputError(f"--magnify {option_text(magnify)}: must be between 1 and {MAX_MAGNIFY:g}")
    if magnify is not None and no_recording:  # it was ignored, as --out was: nothing draws the shape
        raise InputError(
            f"--magnify {option_text(magnify)} with --no-recording: choose one (it draws in the recording)"
        )


def plan_outputs(scenario, out: Path | None, history: Path | None, *, no_recording: bool, force: bool) -> Outputs:
    """Check the output paths and the free space before anything is computed (raises InputError)."""
    if no_recording and out is not None:  # it was ignored: the recording asked for was silently not written
        raise InputError(f"--out {out} with --no-recording: choose one")
    rec = None
    if not no_recording:
        if out is None:
            # checked as --out is: a file named "recordings" here gave "internal error: NotADirectoryError"
            path = default_recording_path(scenario.name)
            try:
                rec = check_output(path, "--out", ".rrd", False, default_name=True)
            except InputError as exc:
                problem = str(exc).removeprefix(f"--out {path}: ")
                raise InputError(
                    f"the default recording {path}: {problem} (give --out R.rrd, or --no-recording)"
                ) from None
        else:
            rec = check_output(out, "--out", ".rrd", force)
    hist = check_output(history, "--history", ".npz", force) if history is not None else None
    check_distinct(rec, hist)
    check_space([(o, size) for o, size in zip((rec, hist), output_sizes(scenario)) if o is not None])
    return Outputs(rec, hist)


def output_sizes(scenario) -> tuple[int, int]:
    """Upper estimates of the recording's and the history's sizes, bytes (what check_space compares)."""
    steps, n = scenario.run.n_steps, scenario.assembly.block_count
    frames = steps // scenario.run.record_every + 2
    recording = (
        RECORDING_STATIC_BYTES
        + RECORDING_STATIC_BYTES_PER_BLOCK * n
        + RECORDING_BYTES_PER_STEP * steps
        + frames * (RECORDING_BYTES_PER_BLOCK * n + FRAME_OVERHEAD_BYTES)
    )
    return recording, HISTORY_STATIC_BYTES + frames * (HISTORY_BYTES_PER_BLOCK * n + FRAME_OVERHEAD_BYTES)


@dataclass
class Outcome:
    """What :func:`execute` did: the run's result, the signal that stopped it, the outputs' fates."""

    result: RunResult
    signum: int | None = None
    written: list[OutputFile] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)
    """One line per output that could not be written: "--history h.npz: No space left on device"."""
    history: History | None = None
    """The history kept in memory (``execute(keep_history=True)``: the Python API), closed: the arrays the
    ``--history`` file holds."""


def _one_or_range(values: list[float], default: float) -> float | list[float]:
    """The blocks' one value, or [least, greatest] when they differ; ``default`` for no block."""
    if not values:
        return float(default)
    lo, hi = float(min(values)), float(max(values))
    return lo if lo == hi else [lo, hi]


def run_metadata(scenario, sim: Simulation) -> dict:
    """Scenario and parameters for the recording's metadata document (its Parameters table, a history's ``run``);
    ``sim``: the :class:`Simulation`, or only its Model (``masonry limit --out``: the same table, no time loop)."""
    run, mat = scenario.run, scenario.material
    model = getattr(sim, "model", sim)
    return {
        "scenario": scenario.name,
        "source": scenario.source,
        "structure": dict(scenario.structure),
        "blocks": model.block_count,
        # a carried fill, said in the parameters (only when there is one); a built-in's is also drawn
        **({"fill_mass_kg": fill} if (fill := float(model.block_carried_mass.sum())) > 0.0 else {}),
        # how its file was read (map shift, units, hulls, trims) and settled: the view shows only the result
        **({"reading": dict(scenario.reading)} if scenario.reading else {}),
        "supports": {s.name: m.describe() for s, m in zip(scenario.assembly.supports, scenario.motions)},
        "baseline_corrections": {
            s.name: m.baseline_correction
            for s, m in zip(scenario.assembly.supports, scenario.motions)
            if m.kind == "record"
        },
        "duration_s": run.duration,
        "dt_s": run.dt,
        "theta": run.theta,
        "gravity_m_s2": list(run.gravity),
        "nlgs_tolerance": run.tolerance,
        "nlgs_max_iterations": run.max_iterations,
        "solver": run.solver,
        "record_every": run.record_every,
        "alert_distance_m": run.alert_distance,
        "friction": mat.friction,
        # the blocks' own (a file's per-stone density column; the report said the default 2500 of a 2300 survey)
        "density_kg_m3": _one_or_range([b.density for b in scenario.assembly.blocks], mat.density),
        "thickness_m": _one_or_range([b.thickness for b in scenario.assembly.blocks], mat.thickness),
        "masonry": __version__,
        "commit": source_commit(),
        "source_digest": SOURCE_DIGEST,
        "python": platform.python_version(),
        "numpy": np.__version__,
        # the run's own start, one for all its outputs (each sink asked the clock: a second apart at times)
        "started": getattr(sim, "started", None) or datetime.now().isoformat(timespec="seconds"),
    }


def recording_static(sim: Simulation, scenario=None):
    """Geometry the recorder logs once: block and support polygons, triangulation; the columns of a built-in
    bridge's fill (``scenario``'s, moved to their blocks' frames)."""
    from masonrycli.recording import RecordingStatic
    from masonrycli.scenario.fill import columns_on_blocks

    m = sim.model
    n = m.block_count
    start = m.body_vert_start
    cols = None if scenario is None else columns_on_blocks(scenario, m.body_q0[:n, :2])
    fill = {} if cols is None else dict(zip(("fill_block", "fill_vert_start", "fill_vert_local"), cols))
    return RecordingStatic(
        **fill,
        fill_load_n=float(m.block_carried_mass.sum() * np.hypot(*m.gravity)),
        block_name=np.asarray(m.block_name, dtype=str),
        block_vert_start=start[: n + 1].copy(),
        block_vert_local=m.vert_local[: start[n]].copy(),
        support_name=np.asarray(m.support_name, dtype=str),
        support_vert_start=start[n:] - start[n],
        support_vert_local=m.vert_local[start[n] :].copy(),
        triangles=np.unique(np.sort(sim.triangles, axis=1), axis=0),  # each drawn once (fans share them)
        friction=m.friction,
        dt=m.dt,
    )


def execute(
    scenario,
    outputs: Outputs,
    *,
    console: Console,
    stop_at_collapse: bool = False,
    magnify: float | None = None,
    signals: StopSignals | None = None,
    keep_history: bool = False,
    sinks_also=(),
    command: str | None = None,
    on_progress=None,
) -> Outcome:
    """Run ``scenario`` writing ``outputs``; ``stop_at_collapse`` ends the run when the structure
    collapses (:mod:`masonrycli.analysis.collapse`); ``magnify``: the recording's magnified-shape factor (None:
    chosen from the run). Signals: :mod:`masonrycli.interrupt` (a stop before step 1
    raises its ``StopRun`` after removing the temporary files); an engine error is re-raised after the
    outputs are closed with status "failed" and renamed into place. ``signals``: a :class:`StopSignals`
    the caller entered and keeps installed after the run (its closing phase lasting through the summary);
    by default one of the run's own. ``keep_history``: also keep the history in memory, as the ``--history``
    file would hold it (:attr:`Outcome.history`); ``sinks_also``: further frame sinks (the API's ``on_frame``),
    handed every frame after the outputs and closed by their owner. ``command``: what made the run, kept in its
    histories' ``run`` (the Python API's call); by default the ``masonry`` command line (:func:`command_line`).
    ``on_progress(sim, stats)``: the run's progress, in place of the console's bar (the API's live line)."""
    made_by = {"command": command} if command else command_line()
    with StopSignals() if signals is None else contextlib.nullcontext(signals) as signals, compile_ahead.ahead():
        sinks: dict[OutputFile, object] = {}
        if note := compile_ahead.no_cache_note():  # a read-only install and no writable home or /tmp
            print(note, file=sys.stderr)
        try:
            for out in outputs.files():
                open_part(out)
            with signals.setup_work():  # a Ctrl-C inside numba's compiler stops the run (interrupt.py)
                with slow_start_notice():  # a first run compiles the kernels here and in step 1
                    sim = Simulation(scenario)
            for out in outputs.files():
                try:
                    sinks[out] = _open_sink(out, outputs, scenario, sim, magnify, made_by)
                except OSError as exc:
                    raise InputError(f"{out.option} {out.path}: cannot write: {exc.strerror or exc}") from None
            kept = _history(History, scenario, sim, made_by) if keep_history else None
        except BaseException:
            for sink in sinks.values():
                _quietly_close(sink)
            for out in outputs.files():
                out.discard()
            raise
        status, note = FAILED, "the run stopped on an unexpected error"
        result = None
        try:
            signals.stepping()
            with progress_bar(console, sim.model.n_steps) as bar:
                result = simulate(
                    scenario,
                    [*sinks.values(), *([kept] if kept is not None else []), *sinks_also],
                    on_progress=on_progress or bar,
                    sim=sim,
                    stop=signals.requested,
                    stop_at_collapse=stop_at_collapse,
                )
            status, note = result.status, result.message
            for history in (sinks.get(outputs.history), kept):
                if history is not None:
                    history.run_values |= {f"intensity_{k}": v for k, v in result.intensity.items()}
                    history.run_values |= result_values(result.outcome, sim.monitor.height)
            recorder = sinks.get(outputs.recording) if outputs.recording is not None else None
            if recorder is not None:  # its closing document says what the summary does: state, peak drift, PGA
                recorder.metadata["result"] = dict(result.extra)
        finally:
            signals.closing()
            written, errors = _close_all(sinks, status, note, result)
            if kept is not None:  # as the file was closed: "failed" once an output failed
                kept.close(*((result.status, result.message) if result is not None else (status, note)))
    return Outcome(result, signals.signum, written, errors, kept)


def _open_sink(out: OutputFile, outputs: Outputs, scenario, sim: Simulation, magnify=None, made_by=None):
    """The history or the recorder writing ``out``'s temporary file; ``made_by``: the history's ``command``."""
    if out is outputs.history:
        return _history(HistoryFile, scenario, sim, made_by or {}, out.part)
    from masonrycli.recording import Recorder

    # the recording's Parameters name the command as the history does (a viewer of a colleague's run had no way to it)
    metadata = run_metadata(scenario, sim) | (made_by or {})
    return Recorder(out.part, recording_static(sim, scenario), metadata, magnify=magnify)


def command_line() -> dict:
    """``{"command": "masonry simulate wall --record site.AT2 …"}`` when the ``masonry`` command (its entry point,
    or ``python -m masonrycli``) runs this process, else ``{}`` (the Python API, a test's in-process runner): the
    history keeps how it was made, which ``masonry report`` puts first (an engineer's summary named no command)."""
    first = Path(sys.argv[0]) if sys.argv and sys.argv[0] else None
    ours = first is not None and (first.name == "masonry" or first.parts[-2:] == ("masonrycli", "__main__.py"))
    return {"command": shlex.join(["masonry", *sys.argv[1:]])} if ours else {}


def _history(kind, scenario, sim: Simulation, made_by: dict, *path):
    """A history (``kind``: :class:`HistoryFile` writing ``path``, or :class:`History` in memory) given what
    the rows do not hold: the run's parameters (and ``made_by``: the command that ran it) and the blocks'
    constants."""
    history = kind(*path, sim.model.block_name, sim.model.support_name)
    history.run_info = run_metadata(scenario, sim) | made_by
    history.run_values |= block_constants(sim.model)
    return history


def _quietly_close(sink) -> None:
    """Close a sink whose file is abandoned anyway: no error, no warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            sink.close(FAILED, "")
        except Exception:  # the caller removes the temporary file anyway
            pass


def _close_all(sinks: dict, status: str, note: str, result) -> tuple[list[OutputFile], list[str]]:
    """Close every sink (the recording first), rename each complete file into place; a file that cannot
    be finished is removed. Once one output failed, the run is "failed", not "completed", in the others
    and in ``result``."""
    written, errors = [], []
    for out, sink in sinks.items():
        if errors and status == COMPLETED:
            status, note = FAILED, f"output failed: {errors[0]}"
        try:
            if result is not None and sink is result.failed_sink:
                raise OSError(result.message)
            sink.close(status, note)
            out.commit()
            written.append(out)
        except Exception as exc:  # OSError: disk full, folder removed; anything else: said as it is
            cause = exc.strerror or str(exc) if isinstance(exc, OSError) else f"{type(exc).__name__}: {exc}"
            errors.append(f"{out.option} {out.path}: {cause}")
            _quietly_close(sink)
            out.discard()
    if errors and result is not None and result.status == COMPLETED:
        result.status, result.message = FAILED, f"output failed: {errors[0]}"
    return written, errors


_STALLED = {
    "nlgs": "no lower residual in 10 000 sweeps by faces",
    "nlgs-accel": "every method of the stalled-step round-robin gave up above it",
    "nlgs-accel32": "every method of the stalled-step round-robin gave up above it",
}
"""What a step that ends unconverged below the cap went through, by solver (engine/nlgs.py, stalled.py)."""


def unconverged_warning(unconverged: int, steps: int, capped: int, run, worst: tuple[float, int] | None = None) -> str:
    """The warning's text for ``unconverged`` of ``steps`` steps, ``capped`` of them at the sweep cap of
    ``run`` (a RunConfig); the rest stalled. It said "20 at the 2-sweep cap, the others stalled: every method
    … gave up" when there were no others. ``worst``: the largest residual (m/s) and its step (1-based), said
    with its time and its multiple of the tolerance, so that a user knows how far off and where to look."""
    stalled = unconverged - capped
    why = [f"{capped} at the {run.max_iterations}-sweep cap"] if capped else []
    if stalled:
        why.append(f"{'the other ' if capped else ''}{stalled} stalled: {_STALLED[run.solver]}")
    if worst is not None and worst[1] > 0 and worst[0] == worst[0]:  # not before a step, not NaN
        residual, step = worst
        ratio = residual / run.tolerance
        times = f"{ratio:.2g}" if ratio < 10 else f"{ratio:.0f}"  # 1.4×, 64×, 637× (not 6.4e+02×)
        why.append(f"the worst {residual:.3g} m/s ({times}× the tolerance) at t = {step * run.dt:g} s")
    advice = "Raise --max-iterations for capped steps, or check" if capped else "Check"
    return (
        f"{unconverged} of {steps} steps ended unconverged (contact-law residual above --tolerance "
        f"{run.tolerance:g} m/s; {', '.join(why)}); their impulses and motion are approximate. "
        f"{advice} the history's nlgs_residual."
    )


def result_warning(result, run) -> str | None:
    """The warning a run's ``result`` gets after its summary (``run``: its RunConfig): how many steps ended
    unconverged, or None when every step converged. The command line prints it; the Python API warns it."""
    if result is None or not result.unconverged:
        return None
    tally = result.tally
    worst = (tally.residual_max, tally.residual_max_step)
    return unconverged_warning(result.unconverged, result.steps, tally.capped, run, worst)


def print_summary(console: Console, outcome: Outcome, scenario, hint: str = "") -> None:
    """The summary table, the optional ``hint``, and last the command that opens the recording."""
    result = outcome.result
    paths = {o.option: str(o.path) for o in outcome.written}
    console.print(summary_table(result, paths.get("--out"), paths.get("--history"), scenario.name))
    if (text := result_warning(result, scenario.run)) is not None:
        console.print(Text.assemble(("warning: ", "bold red"), text), soft_wrap=True)
    if hint and "--out" in paths:
        console.print(hint, soft_wrap=True)
    if "--out" in paths:
        command = open_command(paths["--out"])
        console.print(Text.assemble("Open the recording:  ", (command, "bold")), soft_wrap=True)


def open_command(recording, *, windows: bool = os.name == "nt", environ=os.environ) -> str:
    """The line that opens ``recording`` in the viewer, quoted for this system's shell ("rerun my runs/w.rrd"
    opened "my" and "runs/w.rrd"). On Windows with double quotes, which cmd.exe and PowerShell both read
    (shlex's '…', taken for a backslash, so every default path 'recordings\\wall-….rrd', are no quotes to
    cmd.exe); a quoted viewer ("C:\\Users\\Ana Silva\\…\\rerun.exe") is a string to PowerShell, run only
    after its call operator &, which cmd.exe refuses: in PowerShell (:func:`in_powershell`) the line starts
    with "& ". An unquoted viewer needs no operator, so that line runs in either."""
    if not windows:
        return shlex.join([rerun_command(windows=windows), os.fspath(recording)])
    viewer, path = (_windows_word(text) for text in (rerun_command(windows=windows), os.fspath(recording)))
    call = "& " if viewer.startswith('"') and in_powershell(environ) else ""
    return f"{call}{viewer} {path}"


_PLAIN_WORD = re.compile(r"[\w.:\\/+=~-]+")
"""What cmd.exe and PowerShell both read as one literal word; anything else goes between double quotes
(a space, and the characters either shell gives a meaning outside quotes: ' & ( ) ; , @ { } ^ < > |)."""


def _windows_word(text: str) -> str:
    return text if _PLAIN_WORD.fullmatch(text) else f'"{text}"'


def in_powershell(environ=os.environ) -> bool:
    """Whether this process most likely runs in a PowerShell window: PowerShell (5.1 and 7) adds the user's
    own module folder (under %USERPROFILE%, Documents\\WindowsPowerShell\\Modules or
    Documents\\PowerShell\\Modules) to PSModulePath at start, which the machine's value, the one cmd.exe
    started from the Start menu gets, does not hold. A cmd.exe started from PowerShell inherits it: the
    line is then PowerShell's."""
    home = environ.get("USERPROFILE", "").rstrip("\\/")
    if not home:
        return False
    home = ntpath.normcase(home) + "\\"
    return any(ntpath.normcase(p).startswith(home) for p in environ.get("PSModulePath", "").split(";") if p)


def rerun_command(*, windows: bool = os.name == "nt") -> str:
    """How to start the viewer from here: ``rerun`` if it is on PATH, else the one beside this Python (on
    Windows ``Scripts\\rerun.exe``: a ``rerun`` there does not exist, and "rerun" alone is not found in a
    venv not activated), relative to the working folder when it is below it (``.venv/bin/rerun``)."""
    if shutil.which("rerun"):
        return "rerun"
    beside = Path(sys.executable).parent / ("rerun.exe" if windows else "rerun")
    if not beside.exists():
        return "rerun"
    try:
        below = os.path.relpath(beside)
    except ValueError:  # on another drive
        return str(beside)
    if below.startswith(os.pardir):
        return str(beside)
    return os.path.join(os.curdir, below) if windows or os.sep not in below else below  # PowerShell: .\x.exe
