"""What the user sees in the terminal: a rich progress bar during a run and a summary table after it, the
tables of ``masonry check`` and ``masonry inspect``."""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from contextlib import contextmanager

from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table
from rich.text import Text

SLOW_START = (  # said "compiles the numba kernels": words a class new to Python's tools did not know
    "starting: building the model; a first run (or the first after an update) also translates the solver "
    "to machine code (numba), about 20 s of CPU, once: later runs of a small structure start in about a second"
)


@contextmanager
def slow_start_notice(after: float = 5.0, stream=None):
    """On a terminal, say why nothing shows when setting a run up takes more than ``after`` s. A first run
    compiled the kernels for ~30 s of CPU (2026-11-27; ~20 s since 2026-11-28): 15 s with no line at all,
    then a progress bar at step 0 for 15 s more, and a user new to it took the command for hung (README,
    Quick start). A warm start takes 0.6 s for 4000 blocks, 3.8 s for 20 000 (2026-11-28). Not on a pipe or
    a file: logs and tests keep their lines."""
    stream = sys.stderr if stream is None else stream
    if not stream.isatty():
        yield
        return

    def notice():
        stream.write(SLOW_START + "\n")
        stream.flush()

    timer = threading.Timer(after, notice)
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()


@contextmanager
def progress_bar(console: Console, n_steps: int):
    """Yield an ``on_progress(sim, stats)`` callback drawing steps/s, simulated time and NLGS sweeps; from a
    notebook's cell a line at each tenth of the run instead (:mod:`masonrycli.outputs.cell_output`: the
    notebook stored every redraw of the bar)."""
    from masonrycli.outputs.cell_output import StepLines, notebook_cell

    if console.is_terminal and notebook_cell():
        yield StepLines(console, n_steps)
        return
    progress = Progress(
        TextColumn("[bold]simulating"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total} steps"),
        TextColumn("t = {task.fields[t]:.3f} s"),
        TextColumn("{task.fields[rate]:.0f} steps/s"),
        TextColumn("NLGS {task.fields[iters]} sweeps"),
        TimeRemainingColumn(),
        console=console,
        transient=False,
        disable=not console.is_terminal,
    )
    task = progress.add_task("run", total=n_steps, t=0.0, rate=0.0, iters=0)
    start = time.perf_counter()

    def on_progress(sim, stats):
        elapsed = time.perf_counter() - start
        progress.update(
            task,
            completed=sim.state.step,
            t=sim.state.time,
            rate=sim.state.step / elapsed if elapsed > 0 else 0.0,
            iters=stats.iterations,
        )

    progress.start()
    try:
        yield on_progress
    finally:
        # its last refresh, with the terminal gone (SIGHUP: an SSH session dropped) fails; the run's files do
        # not depend on it (it made the run "failed" where it was interrupted)
        with contextlib.suppress(OSError):
            progress.stop()


SOLVER_NOTES = {
    "nlgs-accel": "Gauss–Seidel with momentum; plain: --solver nlgs",
    "nlgs-accel32": "Gauss–Seidel with momentum, first sweeps in float32; plain: --solver nlgs",
    "nlgs": "plain Gauss–Seidel, the reference",
}
"""What the summary says after a solver's name (masonrycli.scenario.scenario.SOLVERS)."""


def summary_table(result, recording: str | None, history: str | None, name: str = "") -> Table:
    """The end-of-run table: steps, contacts, solver and its effort, penetration, energy, outputs. Its title
    is the scenario's ``name`` and how the run ended ("wall — completed"; it said "masonry run" after a
    ``masonry simulate`` too)."""
    table = Table(title=f"{name or 'run'} — {result.status}", show_header=False, title_justify="left")
    table.add_column("quantity", style="bold")
    # a path longer than the column folds onto the next lines: it was cut to 'runs/course-2026/assignm…'
    table.add_column("value", overflow="fold")
    tally = result.tally
    table.add_row("steps", f"{result.steps} (t = {result.time:.4f} s)")
    table.add_row("run time", f"{result.wall_time:.2f} s ({result.steps / max(result.wall_time, 1e-9):.0f} steps/s)")
    if result.solver:
        note = SOLVER_NOTES.get(result.solver)
        table.add_row("solver", f"{result.solver} ({note})" if note else result.solver)
    if tally.steps:
        table.add_row("contacts per step", f"mean {tally.contacts_mean:.0f}, max {tally.contacts_max}")
        table.add_row("NLGS sweeps per step", f"mean {tally.sweeps_mean:.1f}, max {tally.sweeps_max}")
        table.add_row("steps at the sweep cap", f"{tally.capped} ({100.0 * tally.capped / tally.steps:.1f} %)")
        bad = result.unconverged
        table.add_row(
            "unconverged steps", Text(f"{bad} ({100.0 * bad / tally.steps:.1f} %)", style="bold red" if bad else "")
        )
        table.add_row("NLGS residual (m/s)", f"max {tally.residual_max:.2e}, last {tally.residual_last:.2e}")
    table.add_row("max penetration", f"{result.max_penetration:.3e} m")
    # its change said apart: a file read moved from a map grid stands hundreds of metres up, and its 2.475e+08 J →
    # 2.475e+08 J hid the 2 J its stones lost (the balance: support work = change + dissipated)
    change = result.energy_final - result.energy_initial
    table.add_row(
        "energy (kinetic + potential)",
        f"{result.energy_initial:.4g} J → {result.energy_final:.4g} J (change {change:+.4g} J)",
    )
    table.add_row("dissipated at contacts", _dissipated(result))
    table.add_row("work of the supports", f"{result.support_work:.4g} J")
    for key, value in result.extra.items():
        table.add_row(key, value)
    if result.message:
        table.add_row("note", result.message)
    if history:
        table.add_row("history", history)
    if recording:
        table.add_row("recording", recording)
    return table


def _dissipated(result) -> str:
    """The energy dissipated at the contacts; a negative value at round-off of the run's energies is said to
    be one: a column at rest printed "-6.394e-14 J", a dissipation below zero, which contacts cannot make."""
    d = result.energy_dissipated
    scale = max(abs(result.energy_initial), abs(result.energy_final), abs(result.support_work))
    if d < 0.0 and -d <= 1e-9 * scale:
        return f"0 J (round-off: {d:.1e} J)"
    return f"{d:.4g} J"


def _two_columns(title: str) -> Table:
    table = Table(title=title, show_header=False, title_justify="left")
    table.add_column("", style="bold")
    table.add_column("", overflow="fold")  # a long path or command whole, folded, not cut with '…'
    return table


def check_table(scenario_file: str, info: dict, output_files, ground: tuple[str, str] | None = None) -> Table:
    """``masonry check``'s table: ``info`` of :func:`masonrycli.scenario.scenario.scenario_summary`, the files a run
    would write (:class:`masonrycli.outputs.files.OutputFile`); ``ground``: the row the run's summary gives the
    ground motion as applied, (label, text), or None."""
    table = _two_columns(f"{scenario_file} — valid")
    xmin, ymin, xmax, ymax = info["bounding_box"]
    table.add_row("scenario", str(info["name"]))
    table.add_row("blocks", str(info["blocks"]))
    table.add_row("supports", str(info["supports"]))
    table.add_row("total mass", f"{info['total_mass']:.6g} kg")
    if info.get("fill_mass"):  # dead load riding on the blocks (an arch's --fill-to), not in the blocks' mass
        table.add_row("fill", f"{info['fill_mass']:.6g} kg carried by the blocks under it (dead load only)")
    table.add_row("bounding box", f"x {xmin:.4g} … {xmax:.4g} m, y {ymin:.4g} … {ymax:.4g} m")
    table.add_row("friction", f"{info['friction']:g}")
    table.add_row(
        "time", f"{info['duration']:g} s in {info['n_steps']} steps of {info['dt']:g} s, θ = {info['theta']:g}"
    )
    # the loading, as run will apply it (a --record and its --scale included): it was not shown at all
    driven = [f"{m['name']}: {m['motion']}" for m in info["support_motions"] if m["role"] != "fixed"]
    table.add_row("loading", "\n".join(driven) or "none (every support fixed)")
    if ground is not None:  # its PGA: a --scale read as a PGA in g, or a sine's 1.28 g, seen before it runs
        table.add_row(*ground)
    for out_file in output_files:
        table.add_row("recording" if out_file.option == "--out" else "history", str(out_file.path))
    return table


def recording_table(recording: str, info: dict) -> Table:
    """``masonry inspect``'s table: ``info`` of :func:`masonrycli.recording.inspect_recording` but its
    metadata (printed below the table)."""
    table = _two_columns(recording)
    for key, value in info.items():
        if key == "metadata":
            continue
        if key in ("steps", "time_span") and isinstance(value, (list, tuple)) and len(value) == 2:
            value = f"{value[0]} … {value[1]}" + (" s" if key == "time_span" else "")
        elif value is None:  # a study's or a mechanism's recording has no sim_time ("None" before)
            value = "—"
        elif isinstance(value, (list, tuple)):
            value = "\n".join(map(str, value))
        table.add_row(key, str(value))
    return table


def history_tables(history: str, info: dict) -> tuple[Table, list[str]]:
    """``masonry inspect H.npz``: a table of the run (:func:`masonrycli.outputs.inspect_history.run_rows`, as a
    recording's rows), then one line per array (name, shape, dtype, unit / meaning) in aligned columns — a
    line each, never wrapped into a box (a table of 49 arrays cut names and folded meanings over 3-5
    lines at 80 columns), so ``masonry inspect H.npz | grep stress`` finds an array."""
    from masonrycli.outputs.inspect_history import array_rows, run_rows

    table = _two_columns(f"{history} — run history")
    for label, value in run_rows(info):
        table.add_row(label, value)
    rows = [("array", "shape", "dtype", "unit / meaning (T frames, N blocks, S supports, J joints)")]
    rows += array_rows(info)
    widths = [max(len(row[i]) for row in rows) for i in range(3)]
    lines = ["  ".join([*(cell.ljust(w) for cell, w in zip(row[:3], widths)), row[3]]) for row in rows]
    return table, lines


def columns_lines(title: str, rows: list[tuple[str, str]], lines: list[tuple[str, str]], *heads: str):
    """``(table, lines)``: a two-column table of ``rows`` under ``title``, then one aligned line per ``(name,
    meaning)`` of ``lines`` under ``heads`` (``masonry inspect S.csv``: as a history's arrays, a line each,
    never wrapped: grep-able)."""
    table = _two_columns(title)
    for label, value in rows:
        table.add_row(label, value)
    width = max(len(n) for n, _ in [heads, *lines])
    return table, [f"{n.ljust(width)}  {m}" for n, m in [heads, *lines]]
