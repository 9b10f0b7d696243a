"""``masonry sweep --find`` against closed-form thresholds of a block on a sine-shaken ground.

Ground velocity A·sin(2πft), so the ground acceleration peaks at 2πfA (at t = 0 and t = 1/(2f) = 0.25 s,
inside the 0.3 s run). A block of width B and height
H with friction μ slides once 2πfA > μg (if μ < B/H) and rocks once 2πfA > g·B/H (if B/H < μ): upwards in
A, and downwards in μ — it slides iff μ < 2πfA/g.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

from masonrycli.cli.app import app

from cli_helpers import words

G, F = 9.81, 2.0
runner = CliRunner()

SCENARIO = """
[run]
duration = 0.3
dt = 1e-3
gravity = [0.0, -{g}]
[material]
friction = {mu}
[[block]]
polygon = [[{x0}, 0.0], [{x1}, 0.0], [{x1}, {h}], [{x0}, {h}]]
[[support]]
name = "ground"
polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]
motion = {{ kind = "sine", amplitude = {a}, frequency = {f} }}
"""


def block_file(tmp_path: Path, width: float, height: float, mu: float, amp: float = 0.1) -> Path:
    path = tmp_path / "block.toml"
    path.write_text(SCENARIO.format(g=G, mu=mu, x0=-width / 2, x1=width / 2, h=height, f=F, a=amp))
    return path


@pytest.mark.parametrize(
    "width, height, mu, outcome, closed_form",
    [
        (0.8, 0.4, 0.6, "sliding", 0.6 * G / (2 * math.pi * F)),  # B/H = 2: 0.4684 m/s
        (0.25, 1.0, 0.8, "rocking", G * 0.25 / (2 * math.pi * F)),  # B/H = 0.25: 0.1952 m/s
        # a small block: the solver's 1e-5 m/s turned it at 1.5e-4 rad/s at rest, past 1e-4 ("rocking already")
        (0.05, 0.2, 0.8, "rocking", G * 0.25 / (2 * math.pi * F)),
    ],
)
def test_find_reproduces_the_closed_form_threshold(tmp_path, width, height, mu, outcome, closed_form):
    out = tmp_path / "find.parquet"
    args = [str(block_file(tmp_path, width, height, mu)), "--param", "amp=0.05:1.0:3", "--find", "amp"]
    args += ["--outcome", outcome, "--workers", "0", "--out", str(out)]
    result = runner.invoke(app, ["sweep", *args], terminal_width=200)
    assert result.exit_code == 0, result.output
    rows = pq.read_table(out).to_pylist()
    assert len(rows) == 1 and rows[0]["status"] == "completed"
    found = rows[0]["amp_threshold"]
    assert found == pytest.approx(closed_form, rel=0.01)
    # nothing is detected below the closed form; just above it the motion is too small to be seen
    assert closed_form <= rows[0]["amp_hi"] and rows[0]["amp_lo"] < 1.005 * closed_form
    assert (rows[0]["amp_hi"] - rows[0]["amp_lo"]) <= 0.005 * rows[0]["amp_hi"]
    assert "amp_threshold" in result.output and (tmp_path / "find.png").stat().st_size > 0
    assert (tmp_path / "find.rrd").stat().st_size > 0  # the study recording, beside --out by default


def test_find_friction_finds_the_friction_below_which_the_block_slides(tmp_path):
    """``--find friction --outcome sliding``: the block slides at low friction, not at high; the search
    finds μ* = 2πfA/g (the peak ground acceleration over g) from below and says the outcome holds below it.
    B/H = 2 > μ over the whole range, so it slides rather than rocks. Before, the row said "sliding already
    at friction = 0.1, not at friction = 1: it comes below a value here", with no threshold."""
    amp = 0.3
    closed_form = 2 * math.pi * F * amp / G  # 0.3843
    out = tmp_path / "find.csv"
    args = [str(block_file(tmp_path, 0.8, 0.4, 0.6, amp)), "--param", "friction=0.1:1.0:3", "--find", "friction"]
    args += ["--outcome", "sliding", "--workers", "0", "--out", str(out), "--no-recording"]
    result = runner.invoke(app, ["sweep", *args], terminal_width=200)
    assert result.exit_code == 0, result.output
    with open(out, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 1 and rows[0]["status"] == "completed" and rows[0]["note"] == ""
    row = {k: float(rows[0][k]) for k in ("friction_threshold", "friction_lo", "friction_hi")}
    assert rows[0]["holds"] == "below"
    assert row["friction_threshold"] == pytest.approx(closed_form, rel=0.01)
    # nothing slides at or above the closed form; just below it the slip is too small to be seen
    assert row["friction_lo"] <= closed_form and row["friction_hi"] > 0.995 * closed_form
    assert (row["friction_hi"] - row["friction_lo"]) <= 0.005 * row["friction_hi"]
    # the terminal says which side too: the holds column and its legend
    line = next(line for line in result.output.splitlines() if f"{row['friction_threshold']:.4g}" in line)
    assert "below" in line and "holds: the outcome above / below the threshold" in words(result.output)


def test_find_says_in_one_line_when_its_runs_are_not_monotone(tmp_path, monkeypatch):
    # at 2 Hz the wall collapses at 1.25 m/s and stands at 1.5 m/s: --find amp gave a threshold as if it were
    # the only one. The runs here are real; which of them reach the outcome is set (as the wall's would be).
    from masonrycli.study import drivers

    monkeypatch.setattr(drivers, "reached", lambda row, outcome: 0.12 < row["amp"] < 0.22)
    out = tmp_path / "find.csv"
    args = [str(block_file(tmp_path, 0.8, 0.4, 0.6)), "--param", "amp=0.05:0.25:5", "--find", "amp"]
    args += ["--outcome", "sliding", "--workers", "0", "--out", str(out), "--no-recording"]
    result = runner.invoke(app, ["sweep", *args], terminal_width=200)
    assert result.exit_code == 0, result.output
    with open(out, newline="") as fh:
        (row,) = list(csv.DictReader(fh))
    assert row["note"] == "not monotone: sliding at amp = 0.2, not at amp = 0.25"
    said = [line for line in result.output.splitlines() if line.startswith("warning: --find")]
    assert said == [
        f"warning: --find amp: sliding at amp = 0.2, not at amp = 0.25: not monotone in amp, so the threshold "
        f"{float(row['amp_threshold']):g} is one of several — a grid over the range shows where it holds"
    ], result.output
