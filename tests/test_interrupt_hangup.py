"""SIGHUP: the terminal closing under a run (an SSH session dropped) leaves its history and recording whole,
exit 129; a run started under ``nohup`` goes on; the acknowledgement of a repeat never raises where the
terminal is gone."""

from __future__ import annotations

import contextlib
import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from test_interrupt import default_signals, frames_in_recording, wait_for_frames


def _history_frames(npz: Path):
    """Once the run's history under way at ``npz`` holds 3 frames (the 248-block wall's)."""

    def ready() -> bool:
        rows = list(npz.parent.glob(f".{npz.name}.*.part.rows/block_q.raw"))
        return bool(rows) and rows[0].stat().st_size >= 248 * 3 * 8 * 3

    return ready


def _hang_up(argv: list[str], cwd: Path, ready, seconds: float = 120) -> int:
    """Run masonry on a terminal of its own (a pty) and close the terminal once ``ready()``, as an SSH session
    that drops: the kernel sends SIGHUP, and every later write to the terminal fails. The exit code."""
    import pty

    pid, fd = pty.fork()
    if pid == 0:  # the child: exec at once
        default_signals()
        os.chdir(cwd)
        os.environ["RERUN_ANALYTICS"] = "0"
        os.execv(sys.executable, [sys.executable, "-m", "masonrycli", *argv])
    deadline = time.monotonic() + seconds
    try:
        while time.monotonic() < deadline:
            if ready():
                break
            with contextlib.suppress(OSError):  # keep the terminal's buffer drained
                while select.select([fd], [], [], 0.05)[0]:
                    os.read(fd, 65536)
    finally:
        os.close(fd)  # the terminal goes away
    _, status = os.waitpid(pid, 0)
    return os.waitstatus_to_exitcode(status)


@pytest.mark.slow
def test_a_closed_terminal_leaves_history_and_recording(tmp_path):
    """An SSH session dropped in the middle of a run: SIGHUP killed it (exit -1), leaving only .part files;
    its progress bar and summary then write to a terminal that is gone."""
    rrd, npz = tmp_path / "w.rrd", tmp_path / "w.npz"
    argv = ["simulate", "wall", "--blocks", "248", "--duration", "20", "--out", str(rrd), "--history", str(npz)]
    assert _hang_up(argv, tmp_path, _history_frames(npz)) == 129
    h = np.load(npz)
    assert str(h["status"]) == "interrupted" and 0 < h["time"][-1] < 20
    assert frames_in_recording(rrd) == len(h["time"]) >= 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["w.npz", "w.rrd"]


@pytest.mark.slow
def test_nohup_keeps_the_run_going(tmp_path):
    """Started with SIGHUP ignored (``nohup``), a run is not stopped by it: the user asked for that."""
    rrd, npz = tmp_path / "w.rrd", tmp_path / "w.npz"
    argv = ["simulate", "wall", "--blocks", "248", "--duration", "2", "--out", str(rrd), "--history", str(npz)]
    proc = subprocess.Popen(
        [sys.executable, "-m", "masonrycli", *argv],
        env=dict(os.environ, RERUN_ANALYTICS="0"),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN),
    )
    wait_for_frames(proc, tmp_path)
    proc.send_signal(signal.SIGHUP)
    out, _ = proc.communicate(timeout=300)
    assert proc.returncode == 0, out
    assert str(np.load(npz)["status"]) == "completed"


def test_a_repeat_acknowledged_where_stderr_is_gone_raises_nothing(monkeypatch):
    # on a closed terminal the acknowledgement's write fails; raised in a handler, that error would land in
    # the code closing the files
    import masonrycli.interrupt as interrupt

    def gone(fd, data):
        raise OSError(5, "Input/output error")

    monkeypatch.setattr(interrupt.os, "write", gone)
    interrupt.already_stopping(signal.SIGHUP)


@pytest.mark.slow
def test_a_closed_terminal_keeps_a_study_s_finished_rows(tmp_path):
    """A study on a LocalCluster whose terminal closes: the finished rows written (the workers ignore SIGHUP, as
    Ctrl-C, so no run is counted as a failure for it), exit 129; the same command resumes."""
    from masonrycli.study import store

    out = tmp_path / "s.csv"
    argv = [
        "sweep",
        "wall",
        "-p",
        "amp=0.1:0.3:6",
        "-p",
        "freq=1,2",
        "--duration",
        "10",
        "--workers",
        "2",
        "--out",
        str(out),
    ]
    journal = store.journal_path(out)
    assert _hang_up(argv, tmp_path, lambda: journal.exists() and journal.stat().st_size > 0) == 129
    rows = store.read_rows(out)
    assert 1 <= len(rows) < 12 and all(r.get("state") in ("intact", "damaged", "collapsed") for r in rows)


def _appears(pattern_folder: Path, pattern: str, after: float = 0.0):
    """Once a file matching ``pattern`` is in ``pattern_folder``, and ``after`` seconds later."""
    seen: list[float] = []

    def ready() -> bool:
        if not seen and any(pattern_folder.glob(pattern)):
            seen.append(time.monotonic())
        return bool(seen) and time.monotonic() >= seen[0] + after

    return ready


@pytest.mark.slow
def test_a_closed_terminal_while_build_writes_leaves_the_file_whole(tmp_path):
    """The terminal closing while 'masonry build' writes a big GeoJSON: the file whole, exit 129. Before, the
    note saying so failed on the hung-up terminal (EIO) and the command exited 1."""
    import json

    argv = ["build", "wall", "--blocks", "20000", "--out", "w.geojson"]
    assert _hang_up(argv, tmp_path, _appears(tmp_path, ".w.geojson.*.part")) == 129
    assert len(json.loads((tmp_path / "w.geojson").read_text())["features"]) > 20000
    assert [p.name for p in tmp_path.iterdir()] == ["w.geojson"]


@pytest.mark.slow
@pytest.mark.parametrize(
    "pattern, after", [(".m.rrd.*.part", 0.0), ("m.rrd", 1.0)], ids=["writing-the-recording", "verify"]
)
def test_a_closed_terminal_stops_limit_with_its_recording_whole(tmp_path, pattern, after):
    """'masonry limit --verify --out' whose terminal closes while the recording is written or while --verify's
    engine runs: the recording whole, exit 129. Before, its 'interrupted: …' line failed on the hung-up
    terminal (EIO), and the error line for that failed too: exit 1."""
    argv = ["limit", "aqueduct", "--verify", "--out", "m.rrd"]
    assert _hang_up(argv, tmp_path, _appears(tmp_path, pattern, after)) == 129
    assert frames_in_recording(tmp_path / "m.rrd") >= 1
    assert [p.name for p in tmp_path.iterdir()] == ["m.rrd"]


def test_a_hung_up_terminal_is_replaced_by_dev_null_and_nothing_else(tmp_path):
    """In a child: stdout a pipe (kept), stderr a terminal whose master is closed (hung up: /dev/null after),
    stdin a live terminal (kept)."""
    import pty

    from masonrycli.interrupt import detach_hung_up_terminal

    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        code = 1
        try:
            live_master, live_slave = pty.openpty()
            dead_master, dead_slave = pty.openpty()
            os.dup2(live_slave, 0)
            os.dup2(write_end, 1)
            os.dup2(dead_slave, 2)
            os.close(dead_master)  # hung up: writes to fd 2 fail with EIO
            detach_hung_up_terminal()
            os.write(2, b"goes nowhere\n")
            os.write(1, b"kept\n")
            code = 0 if os.isatty(0) and os.path.samestat(os.fstat(2), os.stat(os.devnull)) else 3
        finally:
            os._exit(code)
    os.close(write_end)
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0
    assert os.read(read_end, 100) == b"kept\n"
    os.close(read_end)
