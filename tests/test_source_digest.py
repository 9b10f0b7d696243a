"""masonrycli.source_digest.source_commit: a checkout is named by its commit, anything else is not."""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
from pathlib import Path

import masonrycli.source_digest as source_digest


def _git(cwd: Path, *args: str) -> str:
    env_args = ["-c", "user.name=t", "-c", "user.email=t@t", "-c", "commit.gpgsign=false"]
    return subprocess.run(["git", *env_args, *args], cwd=cwd, check=True, capture_output=True, text=True).stdout


def _copy_at(root: Path):
    """The module copied to ROOT/masonrycli/source_digest.py and loaded from there: its checkout is ROOT."""
    package = root / "masonrycli"
    package.mkdir(parents=True)
    shutil.copy(source_digest.__file__, package / "source_digest.py")
    spec = importlib.util.spec_from_file_location("copied_source_digest", package / "source_digest.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_checkout_is_named_by_its_commit_and_its_changes(tmp_path):
    module = _copy_at(tmp_path)
    _git(tmp_path, "init", "-q")
    _git(tmp_path, "add", ".")
    _git(tmp_path, "commit", "-q", "-m", "one")
    head = _git(tmp_path, "rev-parse", "--short=7", "HEAD").strip()
    assert module.source_commit() == head
    (tmp_path / "masonrycli" / "source_digest.py").write_text("# edited\n")
    assert module.source_commit() == head + "+changes"


def test_an_install_inside_another_repository_is_not_named_by_that_repository(tmp_path):
    # a virtual environment inside a user's own project: site-packages lies in their git repository
    _git(tmp_path, "init", "-q")
    (tmp_path / "notes.txt").write_text("the user's project\n")
    _git(tmp_path, "add", ".")
    _git(tmp_path, "commit", "-q", "-m", "user")
    module = _copy_at(tmp_path / ".venv" / "lib" / "python3.11" / "site-packages")
    assert module.source_commit() == "not a git checkout"


def test_no_repository_at_all(tmp_path):
    assert _copy_at(tmp_path).source_commit() == "not a git checkout"
