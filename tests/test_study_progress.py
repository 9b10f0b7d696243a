"""A study's progress off a terminal (``nohup masonry sweep … > log``): a line now and then, not silence."""

from __future__ import annotations

import re

from masonrycli.study import progress
from masonrycli.study.store import read_rows

from sweep_helpers import invoke

GRID = ("--param", "courses=4", "--param", "length=0.6", "--param", "amp=0.1:0.2:20", "--duration", 0.01)


def counts(output: str) -> list[tuple[int, int]]:
    return [(int(a), int(b)) for a, b in re.findall(r"^sweep: (\d+) of (\d+) rows \(", output, flags=re.M)]


def test_a_study_off_a_terminal_says_how_far_it_has_got(tmp_path):
    # the bar is drawn on a terminal only: a 224-run study sent to a log file wrote nothing until its summary
    out = tmp_path / "s.csv"
    result = invoke("sweep", "wall", *GRID, "--workers", 0, "--no-recording", "--out", out)
    assert result.exit_code == 0, result.output
    # the first row, then each 2 more (a tenth of 20), and the last
    assert counts(result.output) == [(1, 20), (3, 20), *[(n, 20) for n in range(5, 20, 2)], (20, 20)]
    assert re.search(r"^sweep: 1 of 20 rows \(1 run: intact 1\), \d+ s$", result.output, flags=re.M)
    assert len(read_rows(out)) == 20


def test_a_resumed_study_counts_the_rows_it_had_and_a_minute_brings_a_line(tmp_path, monkeypatch):
    out = tmp_path / "s.csv"
    result = invoke("sweep", "wall", *GRID, "--workers", 0, "--no-recording", "--out", out)
    assert result.exit_code == 0, result.output
    kept = tmp_path / "kept.csv"  # its header and first 12 rows, as a study stopped at its 12th leaves them
    kept.write_text("".join(out.read_text().splitlines(keepends=True)[:13]))
    assert len(read_rows(kept)) == 12
    monkeypatch.setattr(progress, "LINE_EVERY_S", 0.0)  # every row comes a minute after the last line
    result = invoke("sweep", "wall", *GRID, "--workers", 0, "--no-recording", "--out", kept)
    assert result.exit_code == 0, result.output
    assert counts(result.output) == [(n, 20) for n in range(13, 21)]
    assert len(read_rows(kept)) == 20


def test_elapsed_times_read_as_a_clock():
    assert [progress.elapsed(s) for s in (0.4, 59.9, 72, 3599, 7380)] == [
        "0 s",
        "59 s",
        "1 min 12 s",
        "59 min 59 s",
        "2 h 03 min",
    ]
