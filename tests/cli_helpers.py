"""Driving the command line in tests: one CliRunner, invoke with any arguments, one-line error checks, words."""

from __future__ import annotations

from typer.testing import CliRunner

from masonrycli.cli import app

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
