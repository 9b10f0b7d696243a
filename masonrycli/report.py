"""What the user sees in the terminal: a rich progress bar during a run and a summary table after it."""

from __future__ import annotations

import time
from contextlib import contextmanager

from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn
from rich.table import Table
from rich.text import Text


@contextmanager
def progress_bar(console: Console, n_steps: int):
    """Yield an ``on_progress(sim, stats)`` callback drawing steps/s, simulated time and NLGS sweeps."""
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

    with progress:
        yield on_progress


SOLVER_NOTES = {
    "nlgs-accel": "Gauss–Seidel with momentum; plain: --solver nlgs",
    "nlgs": "plain Gauss–Seidel, the reference",
}
"""What the summary says after a solver's name (masonrycli.scenario.SOLVERS)."""


def summary_table(result, recording: str | None, history: str | None) -> Table:
    """The end-of-run table: steps, contacts, solver and its effort, penetration, energy, outputs."""
    table = Table(title=f"masonry run — {result.status}", show_header=False, title_justify="left")
    table.add_column("quantity", style="bold")
    table.add_column("value")
    tally = result.tally
    table.add_row("steps", f"{result.steps} (t = {result.time:.4f} s)")
    table.add_row("wall time", f"{result.wall_time:.2f} s ({result.steps / max(result.wall_time, 1e-9):.0f} steps/s)")
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
    table.add_row("energy (kinetic + potential)", f"{result.energy_initial:.4g} J → {result.energy_final:.4g} J")
    table.add_row("dissipated at contacts", f"{result.energy_dissipated:.4g} J")
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
