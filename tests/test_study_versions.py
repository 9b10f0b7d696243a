"""What the workers' masonry check compares: the version and a digest of the source, the same for two
copies of one checkout wherever they lie, different for one changed byte. The check against real
workers (another masonry, none, the same) is in test_sweep_cluster.py."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from masonrycli.errors import InputError
from masonrycli.study.versions import check_workers, describe, this_version

ROOT = Path(__file__).resolve().parent.parent


def _version_of(copy: Path) -> str:
    code = "from masonrycli.study.versions import *; import masonrycli; print(masonrycli.__file__, describe(this_version()))"
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env={"PYTHONPATH": str(copy)}, cwd=copy
    )
    where, said = out.stdout.strip().split(" ", 1)
    assert where.startswith(str(copy)), out.stdout + out.stderr  # the copy is what ran
    return said


def test_the_digest_follows_the_source_not_where_it_lies(tmp_path):
    copies = []
    for name in ("a", "b"):
        for package in ("masonrycli", "geometry_library"):
            shutil.copytree(ROOT / package, tmp_path / name / package, ignore=shutil.ignore_patterns("__pycache__"))
        copies.append(tmp_path / name)
    ours = describe(this_version())
    assert _version_of(copies[0]) == _version_of(copies[1]) == ours
    builder = copies[1] / "geometry_library" / "builders" / "wall.py"
    builder.write_text(builder.read_text() + "\n")  # one byte more in a builder
    changed = _version_of(copies[1])
    assert changed != ours and changed.startswith("masonry 0.1.0 (source ")


class _Client:
    def __init__(self, answers):
        self.answers = answers

    def run(self, function, on_error):
        assert on_error == "return" and function() == this_version()  # the probe, as run here
        return self.answers


def test_the_refusal_names_the_worker_and_both_versions():
    ours = this_version()
    check_workers(_Client({"tcp://a:1": ours, "tcp://b:2": list(ours)}), "tcp://s:8786")  # all the same
    answers = {"tcp://a:1": ours, "tcp://b:2": ("0.0.9", "abc"), "tcp://c:3": (None, "ModuleNotFoundError: x")}
    with pytest.raises(InputError) as err:
        check_workers(_Client(answers), "tcp://s:8786")
    assert str(err.value) == (
        "--scheduler tcp://s:8786: worker tcp://b:2 (and 1 more of 3 workers) runs masonry 0.0.9 (source abc), "
        f"this command runs {describe(ours)}; install the same masonry on every worker"
    )
    with pytest.raises(InputError, match=r"worker tcp://a:1 could not be asked \(OSError: gone\)"):
        check_workers(_Client({"tcp://a:1": OSError("gone")}), "tcp://s:8786")
