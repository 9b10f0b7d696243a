"""The bad-input catalogue: every row is an input a user may give, the exit code and a fragment of the one
line the tool must print — a fragment that says *where* (file, table, key, option, line).

Files of a row are written to a fresh folder that is also the working directory; ``{d}`` in an argument
is that folder. Every row runs in-process (CliRunner) and stops before step 1, so the table is cheap.
"""

from __future__ import annotations

import os

import pytest
from bad_input_files import FILE_ROWS
from bad_input_geometry import GEOMETRY_ROWS
from bad_input_options import OPTION_ROWS
from bad_input_paths import PATH_ROWS
from typer.testing import CliRunner

from masonrycli.cli.app import app

# (id, files, argv, exit code, fragment of the one line)
CATALOGUE = FILE_ROWS + GEOMETRY_ROWS + OPTION_ROWS + PATH_ROWS


def write_files(folder, files: dict) -> None:
    for name, content in files.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, str) and content.startswith("@"):  # a symbolic link to another file
            os.symlink(folder / content[1:], path)
        elif isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)


def test_catalogue_is_large_enough():
    assert len(CATALOGUE) >= 60
    assert len({row[0] for row in CATALOGUE}) == len(CATALOGUE)


@pytest.mark.parametrize("name, files, argv, code, fragment", CATALOGUE, ids=[row[0] for row in CATALOGUE])
def test_bad_input(name, files, argv, code, fragment, tmp_path, monkeypatch):
    write_files(tmp_path, files)
    monkeypatch.chdir(tmp_path)
    before = sorted(p.name for p in tmp_path.rglob("*"))
    result = CliRunner().invoke(app, [a.format(d=tmp_path) for a in argv])
    assert result.exit_code == code, result.output
    assert "Traceback" not in result.output
    lines = [ln for ln in result.output.splitlines() if ln.strip()]
    assert len(lines) == 1, result.output
    assert lines[0].startswith("error: "), lines[0]
    assert fragment in lines[0], lines[0]
    assert sorted(p.name for p in tmp_path.rglob("*")) == before  # nothing written, not even a temporary file
