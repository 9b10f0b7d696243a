"""A command run from a notebook's cell (``!masonry sweep …``): its progress as a few lines, not a bar.

IPython runs a ``!`` command on a pseudo-terminal, so the command sees a terminal and rich redraws its bar in
place with carriage returns, ten times a second; the notebook keeps every redraw as text in the saved ``.ipynb``
(a 4-row study of 2 s stored 33 redraws, a 1 s ``masonry simulate`` 39: nbclient + ipykernel 7.4, 2026-11-29),
thousands for a long study. There the commands print a line now and then instead, as off a terminal.
"""

from __future__ import annotations

import math
import os
import time

from rich.console import Console

LINES = 10
"""A run's progress in a notebook's cell: a line at each tenth of its steps."""


def notebook_cell() -> bool:
    """True when this process runs from a Jupyter kernel's cell: jupyter_client puts ``JPY_PARENT_PID`` in the
    kernel's environment, whence every command a cell starts inherits it (a terminal of JupyterLab does not:
    its shell is the server's child, not a kernel's)."""
    return bool(os.environ.get("JPY_PARENT_PID"))


class StepLines:
    """``on_progress(sim, stats)`` writing ``simulating: step 300 of 1000, t = 0.300 s, 686 steps/s`` to
    ``console`` at each tenth of the ``n_steps`` steps (at most :data:`LINES` lines)."""

    def __init__(self, console: Console, n_steps: int, clock=time.perf_counter):
        self.console, self.n_steps, self.clock = console, n_steps, clock
        self.start = clock()
        self.said = 0  # tenths said

    def __call__(self, sim, stats) -> None:
        step = sim.state.step
        reached = min(LINES, math.floor(LINES * step / max(self.n_steps, 1)))
        if reached <= self.said:
            return
        self.said = reached
        seconds = self.clock() - self.start
        rate = f", {step / seconds:.0f} steps/s" if seconds > 0 else ""
        self.console.print(
            f"simulating: step {step} of {self.n_steps}, t = {sim.state.time:.3f} s{rate}, {stats.iterations} sweeps",
            markup=False,
            highlight=False,
            soft_wrap=True,
        )
