"""Run a scenario with its outputs: history file, Rerun recording, progress bar and summary.

The outputs are closed whatever happens — normal end, divergence, an exception or Ctrl-C — so the
recording always has its footer and the history holds every frame computed.
"""

from __future__ import annotations

import platform
import shutil
import sys
from datetime import datetime
from pathlib import Path

import numpy as np
from rich.console import Console

from masonrycli import __version__
from masonrycli.history import History
from masonrycli.report import progress_bar, summary_table
from masonrycli.run import RunResult, Simulation, simulate

RECORDINGS_DIR = Path("recordings")


def default_recording_path(name: str) -> Path:
    """``recordings/<scenario>-<timestamp>.rrd`` relative to the working directory."""
    stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
    return RECORDINGS_DIR / f"{name}-{stamp}.rrd"


def run_metadata(scenario, sim: Simulation) -> dict:
    """Scenario and parameters for the recording's metadata document."""
    run, mat = scenario.run, scenario.material
    return {
        "scenario": scenario.name,
        "source": scenario.source,
        "structure": dict(scenario.structure),
        "blocks": sim.model.block_count,
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
        "record_every": run.record_every,
        "alert_distance_m": run.alert_distance,
        "friction": mat.friction,
        "density_kg_m3": mat.density,
        "thickness_m": mat.thickness,
        "masonry": __version__,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "started": datetime.now().isoformat(timespec="seconds"),
    }


def recording_static(sim: Simulation):
    """Geometry the recorder logs once: block and support polygons, triangulation."""
    from masonrycli.recording import RecordingStatic

    m = sim.model
    n = m.block_count
    start = m.body_vert_start
    return RecordingStatic(
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
    scenario, *, out: Path | None, history: Path | None, console: Console, stop_at_collapse: bool = False
) -> RunResult:
    """Run ``scenario``, writing the recording ``out`` and the history ``history`` (either may be None);
    ``stop_at_collapse`` ends the run when the structure collapses (:mod:`masonrycli.collapse`)."""
    sim = Simulation(scenario)
    sinks = []
    hist = None
    recorder = None
    if history is not None:
        hist = History(sim.model.block_name, sim.model.support_name)
        sinks.append(hist)
    if out is not None:
        from masonrycli.recording import Recorder

        out.parent.mkdir(parents=True, exist_ok=True)
        recorder = Recorder(out, recording_static(sim), run_metadata(scenario, sim))
        sinks.append(recorder)
    result = None
    status, note = "error", "the run stopped on an unexpected error"
    try:
        with progress_bar(console, sim.model.n_steps) as on_progress:
            result = simulate(scenario, sinks, on_progress=on_progress, sim=sim, stop_at_collapse=stop_at_collapse)
        if hist is not None:
            hist.run_values |= {f"intensity_{k}": v for k, v in result.intensity.items()}
        status, note = result.status, result.message
    except KeyboardInterrupt:
        status = "interrupted"
        note = f"interrupted at t = {sim.state.time:.4f} s (step {sim.state.step})"
        raise
    finally:
        if recorder is not None:
            recorder.close(status=status, note=note)
        if hist is not None:
            hist.write(history, status=status)
    return result


def print_summary(console: Console, result: RunResult, scenario, out: Path | None, history: Path | None) -> None:
    console.print(
        summary_table(result, scenario.run.max_iterations, str(out) if out else None, str(history) if history else None)
    )
    if out is not None:
        console.print(f"Open the recording:  [bold]{rerun_command()} {out}[/bold]", soft_wrap=True)


def rerun_command() -> str:
    """How to start the viewer from here: ``rerun`` if it is on PATH, else the one beside this Python."""
    if shutil.which("rerun"):
        return "rerun"
    beside = Path(sys.executable).parent / "rerun"
    return str(beside) if beside.exists() else "rerun"
