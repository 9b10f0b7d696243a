"""A study whose command is killed outright (``kill -9``, the out-of-memory killer): its finished rows are in the
journal beside the table, ``masonry inspect`` of the table says so, and the same command resumes from them."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from masonrycli.study.store import read_rows

from cli_helpers import words
from sweep_helpers import invoke

pytestmark = pytest.mark.slow  # a study run as its own process, killed and resumed
ROOT = Path(__file__).resolve().parent.parent
ENV = os.environ | {"RERUN_ANALYTICS": "0", "PYTHONUNBUFFERED": "1", "PYTHONPATH": str(ROOT)}


def _journal(out: Path) -> int:
    path = out.with_name(out.name + ".journal.jsonl")
    return sum(1 for ln in path.read_text().splitlines() if ln.endswith("}")) if path.exists() else 0


def _run_until(sweep, out: Path, rows: int, sig, tmp_path: Path) -> int:
    """Start ``sweep``, wait for ``rows`` finished rows in the journal, send ``sig`` to its session; its exit code."""
    proc = subprocess.Popen(sweep, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=ENV, cwd=tmp_path,
                            start_new_session=True)  # fmt: skip
    try:
        end = time.monotonic() + 240
        while _journal(out) < rows:
            assert proc.poll() is None and time.monotonic() < end, "the study ended before its rows"
            time.sleep(0.05)
        os.killpg(proc.pid, sig)
        return proc.wait(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


def test_inspect_names_the_rows_of_a_killed_study_and_the_command_resumes_them(tmp_path):
    out = tmp_path / "s.csv"
    sweep = [sys.executable, "-m", "masonrycli", "sweep", "wall", "--param", "blocks=12", "--duration", "5"]
    sweep += ["--param", "amp=0.1:0.25:6", "--workers", "0", "--no-recording", "--out", str(out)]
    assert _run_until(sweep, out, 1, signal.SIGKILL, tmp_path) == -signal.SIGKILL
    # no table: 'inspect s.csv' said "s.csv: no such file", as if the runs were lost
    waiting = _journal(out)
    result = invoke("inspect", out)
    assert result.exit_code == 2 and words(result.output) == (
        f"error: {out}: not written yet — {waiting} row{'s' if waiting > 1 else ''} finished, in s.csv.journal.jsonl "
        "(a study still running, or killed before it wrote its table): the same masonry sweep command writes it and "
        "runs the rest"
    )
    # a table of the rows at a Ctrl-C, then rows since it in the journal, killed again: inspect counts both
    assert _run_until(sweep, out, waiting + 1, signal.SIGINT, tmp_path) == 130
    kept = len(read_rows(out))
    assert kept > waiting and not out.with_name("s.csv.journal.jsonl").exists()
    assert _run_until(sweep, out, 1, signal.SIGKILL, tmp_path) == -signal.SIGKILL
    more = _journal(out)
    said = words(invoke("inspect", out).output.replace("│", " "))
    assert f"rows {kept} (" in said
    assert (
        f"journal {more} row{'s' if more > 1 else ''} finished since this table was written, in s.csv.journal" in said
    )
    # the same command: the table of the six rows, the finished ones not run again
    done = subprocess.run(sweep, capture_output=True, text=True, env=ENV, cwd=tmp_path, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    now = 6 - kept - more
    assert f"({now} run{'s' if now != 1 else ''} now, {kept + more} rows already there" in words(done.stdout)
    rows = read_rows(out)
    assert [r["amp"] for r in rows] == [0.1, 0.13, 0.16, 0.19, 0.22, 0.25] and {r["status"] for r in rows} == {
        "completed"
    }
