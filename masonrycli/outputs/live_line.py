"""``api.simulate(progress=True)``: a run's progress as one line that changes in place.

In a Jupyter notebook the line is a display of its own under the cell, updated (IPython's ``display_id``), so
the cell's output holds one line however long the run: the command line's rich bar there showed nothing
(the API's console is quiet) and a ``print("\\r…")`` of every update stays in the saved notebook as text.
Elsewhere (a script, a terminal) it is stderr's last line, rewritten with ``\\r`` on a terminal, and said
only when the run starts and ends on a pipe or a log file.

The line first says why nothing moves yet (a first run spends ~20 s translating the solver to machine code:
in a notebook that was a cell busy without a word), then the step, the simulated time, the rate and the
sweeps, at most every ``every`` seconds, and last how the run ended.
"""

from __future__ import annotations

import sys
import time

EVERY = 0.25
"""s between two updates of the line (a notebook's display is a message to the browser: not every 10 steps)."""

STARTING = "starting: building the model (a first run also translates the solver to machine code, ~20 s, once)"


def in_notebook() -> bool:
    """True inside a Jupyter kernel (IPython with a kernel), where a display can be updated in place."""
    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None and hasattr(ipython, "get_ipython") else None
    return getattr(shell, "kernel", None) is not None


class _NotebookLine:
    """A display under the cell, replaced at each update."""

    def __init__(self):
        from IPython.display import display

        self.handle = None
        self.display = display

    def show(self, text: str, final: bool = False) -> None:
        data = {"text/plain": text}
        if self.handle is None:
            self.handle = self.display(data, raw=True, display_id=True)
        else:
            self.handle.update(data, raw=True)


class _StreamLine:
    """stderr's last line: rewritten on a terminal; on a pipe or a file, the first and the last only."""

    def __init__(self, stream):
        self.stream = stream
        self.tty = stream.isatty()
        self.said = False
        self.open = False  # a terminal's line written without its end

    def show(self, text: str, final: bool = False) -> None:
        if self.tty:
            self.stream.write("\r\x1b[2K" + text + ("\n" if final else ""))
            self.open = not final
        elif final or not self.said:
            self.stream.write(text + "\n")
        self.said = True
        self.stream.flush()

    def end_line(self) -> None:
        """End the line where it is, so that what the stream says next (a warning) starts a line of its own."""
        if self.open:
            self.stream.write("\n")
            self.stream.flush()
            self.open = False


class LiveLine:
    """The progress of a run of ``name`` over ``n_steps`` steps (``start``, ``on_progress(sim, stats)`` as
    :func:`masonrycli.run.simulate` calls it, ``end``), shown by ``line`` (default: the notebook's display in
    a kernel, else stderr)."""

    def __init__(self, name: str, line=None, every: float | None = None, clock=time.perf_counter):
        self.name = name
        self.line = line if line is not None else (_NotebookLine() if in_notebook() else _StreamLine(sys.stderr))
        self.every = EVERY if every is None else every
        self.clock = clock
        self.started = self.last = self.first = None

    def start(self) -> None:
        self.started = self.clock()
        self.line.show(f"{self.name}: {STARTING}")

    def on_progress(self, sim, stats) -> None:
        now = self.clock()
        if self.last is not None and now - self.last < self.every:
            return
        if self.last is None:  # the first step is done: compiling is over, the rate counts from here
            self.first = (now, sim.state.step)
        self.last = now
        step, n = sim.state.step, sim.model.n_steps
        seconds, done = now - self.first[0], step - self.first[1]
        rate = f", {done / seconds:.0f} steps/s" if seconds > 0 and done > 0 else ""
        self.line.show(f"{self.name}: step {step} of {n}, t = {sim.state.time:.3f} s{rate}, {stats.iterations} sweeps")

    def end(self, status: str, steps: int, t: float, state: str = "") -> None:
        """The last line: how the run ended (and the structure's ``state``), its steps and time."""
        took = self.clock() - self.started
        ended = f"{status}, {state}" if state else status
        self.line.show(f"{self.name}: {ended}, {steps} steps to t = {t:g} s in {took:.1f} s", final=True)

    def under(self, showwarning):
        """``showwarning`` ending the line first: a warning said during the run (its first unconverged step) was
        written at the end of the terminal's line, after 'starting: …'. The next update starts a new line."""

        def show(*args, **kwargs):
            getattr(self.line, "end_line", lambda: None)()  # a notebook's display is not the warnings' stream
            showwarning(*args, **kwargs)

        return show

    def stopped(self, why: str) -> None:
        """The last line of a run that raised before it ended (``why``), in place of the line it had reached."""
        self.line.show(f"{self.name}: {why}", final=True)
