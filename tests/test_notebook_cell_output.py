"""``!masonry sweep …`` and ``!masonry simulate …`` in a notebook's cell store a few progress lines in the
notebook, not every redraw of a bar (masonrycli/outputs/cell_output.py). IPython runs a ``!`` command on a
pseudo-terminal, so the commands drew their bars in place with carriage returns, and the notebook kept each
redraw: a 4-row study of 0.3 s runs stored 33, a 1 s simulate 39 (nbclient + ipykernel, before the fix)."""

from __future__ import annotations

import io
import re
import sys
from types import SimpleNamespace

import pytest
from rich.console import Console

from masonrycli.outputs.report import progress_bar
from masonrycli.study.progress import StudyProgress


def _terminal() -> tuple[Console, io.StringIO]:
    out = io.StringIO()
    return Console(file=out, force_terminal=True, width=100), out


def test_a_run_from_a_cell_says_a_line_at_each_tenth(monkeypatch):
    monkeypatch.setenv("JPY_PARENT_PID", "1234")
    console, out = _terminal()
    with progress_bar(console, 1000) as on_progress:
        for step in range(10, 1001, 10):  # as run.simulate calls it: every 10 steps
            on_progress(
                SimpleNamespace(state=SimpleNamespace(step=step, time=step * 1e-3)), SimpleNamespace(iterations=7)
            )
    lines = out.getvalue().splitlines()
    assert [int(re.match(r"simulating: step (\d+) of 1000, t = ", line).group(1)) for line in lines] == list(
        range(100, 1001, 100)
    )
    assert "\r" not in out.getvalue()


def test_a_study_from_a_cell_says_lines_not_a_bar(monkeypatch):
    monkeypatch.setenv("JPY_PARENT_PID", "1234")
    console, _ = _terminal()
    assert not StudyProgress(console, 4, 0).terminal  # the lines off a terminal, on stderr
    monkeypatch.delenv("JPY_PARENT_PID")
    assert StudyProgress(console, 4, 0).terminal  # a terminal's bar as before


def _stored_lines(cell) -> list[str]:
    """What a cell's stream outputs hold, one entry per line a reader of the .ipynb sees (a \\r starts one)."""
    text = "".join(output.get("text", "") for output in cell.outputs if output.output_type == "stream")
    text = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", text)  # colours and cursor moves
    return [line for line in re.split(r"\r\n|\r|\n", text) if line.strip()]


@pytest.mark.slow
def test_a_notebook_stores_a_few_progress_lines(tmp_path):
    import nbclient  # the test extra installs it and ipykernel (pyproject)
    import nbformat

    python = sys.executable
    cells = [
        f"!{python} -m masonrycli sweep wall --param freq=1,2,3,4 --duration 0.3 --workers 0 --out s.csv",
        f"!{python} -m masonrycli simulate wall --duration 1 --no-recording",
    ]
    notebook = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(c) for c in cells])
    client = nbclient.NotebookClient(notebook, timeout=600, resources={"metadata": {"path": str(tmp_path)}})
    client.execute()
    sweep, simulate = (_stored_lines(cell) for cell in notebook.cells)
    progress = [line for line in sweep if line.startswith("sweep")]
    assert 1 <= len(progress) <= 4, progress  # one per finished row at most (a tenth of 4 rows is one)
    assert progress[-1].startswith("sweep: 4 of 4 rows") and any("4 rows in s.csv" in line for line in sweep)
    steps = [line for line in simulate if line.startswith("simulating")]
    assert len(steps) == 10 and steps[-1].startswith("simulating: step 1000 of 1000"), steps
    assert any(line.startswith("wall — completed") for line in simulate)
