"""``api.simulate(progress=True)`` (masonrycli/outputs/live_line.py): in a notebook, one display under the cell
updated in place — first why a first run waits, then the step, last how it ended — and nothing on stdout or
stderr; in a script, stderr's start and end lines off a terminal. Before, a run in Jupyter showed nothing
(the API's console is quiet) for the ~20 s a first run compiles, and ``progress=`` was refused."""

from __future__ import annotations

import io
import re
import sys
import warnings

import pytest

from masonrycli import api
from masonrycli.outputs import live_line


class FakeDisplay:
    """What a notebook's display would show, update by update."""

    def __init__(self):
        self.shown = []

    def show(self, text: str, final: bool = False) -> None:
        self.shown.append(text)


def test_a_notebook_gets_one_line_updated_in_place(monkeypatch, capsys):
    display = FakeDisplay()
    monkeypatch.setattr(live_line, "in_notebook", lambda: True)
    monkeypatch.setattr(live_line, "_NotebookLine", lambda: display)
    monkeypatch.setattr(live_line, "EVERY", 0.0)  # every progress call shown (every 10 steps)
    run = api.simulate("wall", blocks=12, amp=0.5, duration=0.05, progress=True)
    assert capsys.readouterr() == ("", "")  # no stream text: the display alone
    first, *steps, last = display.shown
    run_of = re.escape("wall (blocks=12, amp=0.5, duration=0.05)")  # which run of a loop: the options given
    assert first == f"wall (blocks=12, amp=0.5, duration=0.05): {live_line.STARTING}"
    said = [int(m.group(1)) for text in steps if (m := re.match(rf"{run_of}: step (\d+) of 50, t = ", text))]
    assert said == list(range(10, 51, 10))  # the run's steps, in order, as the run reached them
    assert re.fullmatch(rf"{run_of}: completed, {run.outcome['state']}, 50 steps to t = 0.05 s in \d+\.\d s", last)


def test_off_a_terminal_a_script_gets_its_start_and_end(monkeypatch, capsys):
    monkeypatch.setattr(live_line, "in_notebook", lambda: False)
    api.simulate("wall", blocks=12, duration=0.02, progress=True)
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert out == "" and len(lines) == 2 and lines[0].startswith("wall (blocks=12, duration=0.02): starting")
    assert lines[1].startswith("wall (blocks=12, duration=0.02): completed")


def test_without_progress_nothing_is_shown(monkeypatch, capsys):
    monkeypatch.setattr(live_line, "in_notebook", lambda: pytest.fail("asked for no progress: no line made"))
    api.simulate("wall", blocks=12, duration=0.02)
    assert capsys.readouterr() == ("", "")


def test_a_run_that_raises_ends_its_line_saying_so(monkeypatch):
    # the display kept 'starting: building the model …' under the cell's traceback, as if the run still went on
    display = FakeDisplay()
    monkeypatch.setattr(live_line, "in_notebook", lambda: True)
    monkeypatch.setattr(live_line, "_NotebookLine", lambda: display)

    def broken(scenario):
        raise RuntimeError("the engine failed\nsecond line")

    monkeypatch.setattr("masonrycli.execute.Simulation", broken)
    with pytest.raises(RuntimeError, match="the engine failed"):
        api.simulate("wall", blocks=12, duration=0.02, progress=True)
    assert display.shown[-1] == "wall (blocks=12, duration=0.02): stopped: RuntimeError: the engine failed"


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_a_warning_during_the_run_starts_a_line_of_its_own_on_a_terminal(monkeypatch):
    # the first unconverged step's warning, said as it happens, was written at the end of the progress line
    # ('… ~20 s, once)/tmp/x.py:2: RuntimeWarning: step 1 …')
    terminal = _Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    monkeypatch.setattr(live_line, "in_notebook", lambda: False)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        # Python's own showing, on stderr (pytest's keeps a list)
        warnings.showwarning = lambda m, c, f, n, file=None, line=None: sys.stderr.write(
            warnings.formatwarning(m, c, f, n, line)
        )
        api.simulate("wall", blocks=12, duration=0.02, max_iterations=2, progress=True)
    text = terminal.getvalue()
    said = [m.start() for m in re.finditer(r"\S+:\d+: RuntimeWarning: ", text)]
    assert len(said) == 2 and all(text[at - 1] == "\n" for at in said), text
