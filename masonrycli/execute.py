"""Run a scenario with its outputs: output checks, history file, Rerun recording, progress bar, summary.

Before step 1 every output path is checked and its temporary file created (:mod:`masonrycli.outputs.files`),
and a run whose outputs would not fit on the disk is refused. The outputs are then closed whatever
happens — normal end, divergence, a signal, an engine error, a failed write — and each one that closed
is renamed into place, so what was computed is kept and a path never holds half a file.
"""

from __future__ import annotations

import contextlib
import platform
import shlex
import sys
import warnings
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

import numpy as np
from rich.console import Console

from masonrycli import SOURCE_DIGEST, __version__
from masonrycli.engine import compile_ahead
from masonrycli.engine.compile_log import watched_compiles
from masonrycli.errors import InputError
from masonrycli.interrupt import StopSignals
from masonrycli.output_plan import Outputs
from masonrycli.outputs.files import OutputFile, open_part
from masonrycli.outputs.history import History, HistoryFile, block_constants, result_values
from masonrycli.outputs.report import progress_bar, slow_start_notice
from masonrycli.outputs.sinks import COMPLETED, FAILED
from masonrycli.run import RunResult, Simulation, simulate
from masonrycli.source_digest import source_commit


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
    with (
        StopSignals() if signals is None else contextlib.nullcontext(signals) as signals,
        compile_ahead.ahead(),
        contextlib.ExitStack() as watch,
    ):
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
            # a signal during a step's numba compilation stops the run at once, not minutes later (interrupt.py)
            compiling = watch.enter_context(watched_compiles(signals.compile_event))
            signals.stepping(compiling)
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
