"""The TARGET of run / check, sweep and limit: the same bad target gets the same one line and exit code 2
from every command (they said "no such scenario file", "no such scenario or geometry file" and "cannot
read scenario: No such file or directory" of one missing file; limit called a folder missing)."""

from __future__ import annotations

import os

import pytest

from masonrycli.errors import NOT_A_FILE

from cli_helpers import invoke

COMMANDS = (("run",), ("check",), ("sweep", "--param", "amp=1", "--workers", "0"), ("limit",))
BUILT_INS = "(built-in structures: wall, arch, aqueduct)"

# (target, the one line every command prints)
BAD_TARGETS = [
    ("nosuch.toml", f"nosuch.toml: no such scenario or geometry file {BUILT_INS}"),
    ("nosuch.geojson", f"nosuch.geojson: no such scenario or geometry file {BUILT_INS}"),
    ("nosuch", f"nosuch: no such scenario or geometry file {BUILT_INS}"),
    ("wal", "wal: no such scenario or geometry file (did you mean wall?)"),
    ("Arch", "Arch: no such scenario or geometry file (did you mean arch?)"),
    ("aqeduct", "aqeduct: no such scenario or geometry file (did you mean aqueduct?)"),
    ("wal.toml", f"wal.toml: no such scenario or geometry file {BUILT_INS}"),  # a file name: no built-in meant
    ("folder", "folder: is a directory, not a scenario or geometry file"),
    ("folder.geojson", "folder.geojson: is a directory, not a scenario or geometry file"),
    ("/dev/null", f"/dev/null: {NOT_A_FILE}"),
    ("", "the structure argument is empty (''): give wall, arch, aqueduct or a scenario file"),
    ("locked.toml", "locked.toml: cannot read file: Permission denied"),
    (
        "notes.txt",
        'notes.txt:1: unknown key "a" (expected one of: name, run, material, structure, block, support)'
        " (read as a scenario TOML: a geometry file's name ends in .geojson, .json, .wkt)",
    ),
]


@pytest.fixture
def here(tmp_path, monkeypatch):
    """A working folder with a folder, a folder named like a geometry file, an unreadable scenario and a
    TOML file under an unknown extension."""
    (tmp_path / "folder").mkdir()
    (tmp_path / "folder.geojson").mkdir()
    (tmp_path / "notes.txt").write_text("a = 1\n")
    locked = tmp_path / "locked.toml"
    locked.write_text("[run]\n")
    locked.chmod(0)
    if os.access(locked, os.R_OK):  # root reads it anyway: refuse it as the kernel refuses anyone else
        real_open = open

        def refusing_open(file, *args, **kwargs):
            if os.fspath(file) == "locked.toml":
                raise PermissionError(13, "Permission denied", "locked.toml")
            return real_open(file, *args, **kwargs)

        monkeypatch.setattr("masonrycli.scenario.target.open", refusing_open, raising=False)
    monkeypatch.chdir(tmp_path)
    yield tmp_path
    locked.chmod(0o644)


@pytest.mark.parametrize(("target", "message"), BAD_TARGETS, ids=[t or "empty" for t, _ in BAD_TARGETS])
def test_a_bad_target_gets_the_same_line_from_every_command(target, message, here):
    before = sorted(here.rglob("*"))
    said = {}
    for command, *options in COMMANDS:
        result = invoke(command, target, *options)
        lines = [ln for ln in result.output.splitlines() if ln.strip()]
        assert result.exit_code == 2 and len(lines) == 1, (command, result.output)
        said[command] = lines[0]
    assert set(said.values()) == {f"error: {message}"}, said
    assert sorted(here.rglob("*")) == before  # nothing written


def test_a_folder_named_as_a_built_in_is_no_target(here):
    """A folder ``wall/`` (of recordings, say) left the name to the built-in for sweep only: limit called it
    "no such scenario or geometry file", run "cannot read scenario: is a directory"."""
    (here / "wall").mkdir()
    result = invoke("run", "wall")
    assert result.exit_code == 2
    assert (
        result.output.strip() == "error: wall: not a file; the built-in structures are run with `masonry simulate wall`"
    )
    result = invoke("limit", "wall", "--json")
    assert result.exit_code == 0 and '"scenario": "wall"' in result.output, result.output
