"""The entry point (masonrycli/__main__.py): a signal while Python loads the command line is one line."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest


def test_ctrl_c_while_masonry_starts_is_one_line_and_exit_130(monkeypatch, capsys):
    # a Ctrl-C in the first half second (Python importing typer, rich, numpy) printed a KeyboardInterrupt
    # traceback: the entry point imports the command line inside its own try
    import importlib.abc
    import sys

    from masonrycli.__main__ import main

    class Interrupted(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name == "masonrycli.cli.app":
                raise KeyboardInterrupt

    monkeypatch.delitem(sys.modules, "masonrycli.cli.app", raising=False)  # imported or not by earlier tests
    monkeypatch.setattr(sys, "meta_path", [Interrupted(), *sys.meta_path])
    with pytest.raises(SystemExit) as exc:
        main()
    assert exc.value.code == 130
    assert capsys.readouterr().err == "error: Ctrl-C while masonry was starting: nothing was run\n"


@pytest.mark.parametrize("args", [("simulate", "wall", "--duration", "0.01", "--no-recording"), ("docs", "collapse")])
def test_a_terminal_without_unicode_gets_question_marks_not_a_traceback(args, tmp_path):
    # PYTHONIOENCODING=cp1252 (a Windows console, or a redirect there): the summary's '→' raised
    # UnicodeEncodeError — a traceback and exit 1 after the run; `masonry docs collapse` (σ, ≤) the same
    env = dict(os.environ, PYTHONIOENCODING="cp1252", RERUN_ANALYTICS="0", COLUMNS="100")
    done = subprocess.run(
        [sys.executable, "-m", "masonrycli", *args], cwd=tmp_path, env=env, capture_output=True, timeout=300
    )
    assert done.returncode == 0, done.stderr.decode("cp1252")
    assert b"Traceback" not in done.stderr
    said = (done.stdout + done.stderr).decode("cp1252")
    assert "?" in said  # the characters cp1252 lacks, replaced
