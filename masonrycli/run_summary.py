"""What the command line says when a run ends (:mod:`masonrycli.execute` ran it): the summary table, the warning of
the steps that ended unconverged (the Python API warns the same text), the line that opens the recording."""

from __future__ import annotations

from typing import TYPE_CHECKING

from rich.console import Console
from rich.text import Text

from masonrycli.outputs.report import summary_table
from masonrycli.viewer_command import open_command

if TYPE_CHECKING:
    from masonrycli.execute import Outcome

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


def first_unconverged_warning(step: int, time: float, residual: float, run) -> str:
    """What the Python API warns as the first step of ``run`` (a RunConfig) ends unconverged, during the run:
    the step, its residual and the tolerance (the end's :func:`unconverged_warning` counts them all)."""
    ratio = residual / run.tolerance if residual == residual else float("nan")
    times = f"{ratio:.2g}" if ratio < 10 else f"{ratio:.0f}"
    return (
        f"step {step} (t = {time:g} s) ended unconverged: contact-law residual {residual:.3g} m/s, {times}× "
        f"--tolerance {run.tolerance:g} m/s; the run goes on, and its end says how many steps did"
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
