"""The entry point (masonrycli/__main__.py): a signal while Python loads the command line is one line."""

from __future__ import annotations

import pytest


def test_ctrl_c_while_masonry_starts_is_one_line_and_exit_130(monkeypatch, capsys):
    # a Ctrl-C in the first half second (Python importing typer, rich, numpy) printed a KeyboardInterrupt
    # traceback: the entry point imports the command line inside its own try
    import importlib.abc
    import sys

    from masonrycli.__main__ import main

    class Interrupted(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name == "masonrycli.cli":
                raise KeyboardInterrupt

    monkeypatch.delitem(sys.modules, "masonrycli.cli")
    monkeypatch.setattr(sys, "meta_path", [Interrupted(), *sys.meta_path])
    with pytest.raises(SystemExit) as exc:
        main()
    assert exc.value.code == 130
    assert capsys.readouterr().err == "error: Ctrl-C while masonry was starting: nothing was run\n"
