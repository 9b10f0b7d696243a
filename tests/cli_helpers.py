"""Driving the command line in tests: one CliRunner, invoke with any arguments, one-line error checks, words."""

from __future__ import annotations

import ctypes
import os
import time

from typer.testing import CliRunner

from masonrycli.cli.app import app

runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


def words(text: str) -> str:
    """``text`` with every run of whitespace one space: the console wraps a line where a path's length puts it."""
    return " ".join(text.split())


def assert_one_line_error(result, *fragments):
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    lines = [ln for ln in result.output.strip().splitlines() if ln.strip()]
    assert len(lines) == 1, result.output
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


def signal_inside_a_ctypes_callback(signum: int) -> None:
    """Send ``signum`` to this process from inside a ctypes callback, where numba's compiler calls back into
    Python (llvmlite's object cache) on a first run: an exception a handler raises there cannot leave the
    callback, and ctypes reports it as "Exception ignored …" and drops it."""

    def callback():
        os.kill(os.getpid(), signum)
        time.sleep(0.2)  # the handler runs here

    ctypes.CFUNCTYPE(None)(callback)()


def refusals_within(read, path, seconds: float = 10.0) -> list[str]:
    """The InputError messages of ``read(path)``, run in a thread so that a read that never ends (a named
    pipe, /dev/zero) fails the test after ``seconds`` instead of stopping the suite."""
    import threading

    from masonrycli.errors import InputError

    said = []

    def run():
        try:
            read(path)
        except InputError as exc:
            said.append(str(exc))

    reader = threading.Thread(target=run, daemon=True)
    reader.start()
    reader.join(seconds)
    assert not reader.is_alive(), f"reading {path} did not end"
    return said
