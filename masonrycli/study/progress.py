"""How far a study has got: a bar on a terminal, and elsewhere (``nohup … > log``, a batch job, a pipe) a line
now and then, on stderr.

The bar is drawn only on a terminal; a study of 224 runs sent to a log file wrote nothing for its whole length
until the summary, so a user could not tell a study at 90 % from one stuck at its first run. Off a terminal a
line goes out at the first finished row, then each time another tenth of the rows to make has finished or a
minute has passed since the last line (checked as rows arrive), and at the last row:

    sweep: 45 of 224 rows (23 runs: damaged 5, intact 18), 1 min 12 s

On stderr, as the warnings: stdout keeps the results, which are printed once every file is written (a reader
of stdout that goes away, ``masonry sweep … | head -2``, must not stop the study), and a stderr that breaks
ends the lines, not the study.
"""

from __future__ import annotations

import math
import time

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from masonrycli.outputs.cell_output import notebook_cell

LINE_EVERY_FRACTION = 0.1
"""Of the rows to make (those not already in the table): a line each time this many more have finished."""
LINE_EVERY_S = 60.0
"""s: a line at the next finished row once this long has passed since the last one."""


class StudyProgress:
    """The study's progress, ``with``-entered around the runs; :meth:`advance` per finished row,
    :meth:`states` with the runs' states so far after each."""

    def __init__(self, console: Console, total: int, skipped: int) -> None:
        self.total, self.done, self.skipped = total, skipped, skipped
        self.terminal = console.is_terminal and not notebook_cell()  # a cell stored each redraw: lines there
        self.lines = None if self.terminal else Console(stderr=True, markup=False, highlight=False)
        self.bar = Progress(
            TextColumn("[bold]sweep"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("{task.fields[states]}"),
            TimeElapsedColumn(),
            console=console,
            disable=not self.terminal,
        )
        self.task = self.bar.add_task("rows", total=total, completed=skipped, states="")
        self.start = time.monotonic()
        self.last_line: tuple[int, float] | None = None  # (rows done, time) at the last line written

    def __enter__(self):
        self.bar.__enter__()
        return self

    def __exit__(self, *exc) -> None:
        self.bar.__exit__(*exc)

    def advance(self) -> None:
        self.done += 1
        self.bar.advance(self.task)

    def states(self, text: str) -> None:
        self.bar.update(self.task, states=text)
        if self.lines is None:
            return
        now = time.monotonic()
        step = max(1, math.ceil(LINE_EVERY_FRACTION * (self.total - self.skipped)))
        due = (
            self.last_line is None
            or self.done >= self.total
            or self.done - self.last_line[0] >= step
            or now - self.last_line[1] >= LINE_EVERY_S
        )
        if due and self.done > (self.last_line or (self.skipped, 0.0))[0]:
            self.last_line = (self.done, now)
            took = elapsed(now - self.start)
            try:
                self.lines.print(f"sweep: {self.done} of {self.total} rows ({text}), {took}", soft_wrap=True)
            except OSError:  # stderr gone (its reader closed): the study goes on without its lines
                self.lines = None


def elapsed(seconds: float) -> str:
    """``42 s``, ``1 min 12 s``, ``2 h 03 min``."""
    s = int(seconds)
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"
