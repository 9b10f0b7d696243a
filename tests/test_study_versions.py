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
from masonrycli.study import versions
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


CHANGE_AFTER_IMPORT = """
import pathlib, sys
import masonrycli
import masonrycli.study.versions as versions
builder = pathlib.Path(sys.argv[1]) / "geometry_library" / "builders" / "wall.py"
builder.write_text(builder.read_text() + "\\n")  # after the import: this process runs the code it read before
print(versions.describe(versions.this_version()))
"""


def test_the_digest_is_of_the_source_the_process_imported(tmp_path):
    # A long-lived worker that had imported masonry before its checkout changed reported the new files'
    # digest (hashed when first asked) while running the old code: its rows were kept as this code's.
    for package in ("masonrycli", "geometry_library"):
        shutil.copytree(ROOT / package, tmp_path / package, ignore=shutil.ignore_patterns("__pycache__"))
    ours = describe(this_version())
    out = subprocess.run(
        [sys.executable, "-c", CHANGE_AFTER_IMPORT, str(tmp_path)],
        capture_output=True, text=True, env={"PYTHONPATH": str(tmp_path)}, cwd=tmp_path,
    )  # fmt: skip
    assert out.stdout.strip() == ours, out.stdout + out.stderr  # the code it loaded: ours
    fresh = _version_of(tmp_path)  # a process started after the change
    assert fresh != ours and fresh.startswith("masonry 0.1.0 (source ")


class _Client:
    """What check_workers asks of the study's client: the scheduler's address and its workers."""

    def scheduler_info(self):
        return {"address": "tcp://s:8786", "workers": {"tcp://a:1": {}, "tcp://b:2": {}}}


def _answering(answers):
    """``ask_workers`` with these answers (or this exception), checking what it was asked."""

    def ask_workers(address, function, timeout):
        assert address == "tcp://s:8786" and timeout == versions.PROBE_TIMEOUT
        assert function() == this_version()  # the probe, as run here
        if isinstance(answers, BaseException):
            raise answers
        return answers

    return ask_workers


def test_the_refusal_names_the_worker_and_both_versions(monkeypatch):
    ours = this_version()
    monkeypatch.setattr(versions, "ask_workers", _answering({"tcp://a:1": ours, "tcp://b:2": list(ours)}))
    check_workers(_Client(), "tcp://s:8786")  # all the same
    answers = {"tcp://a:1": ours, "tcp://b:2": ("0.0.9", "abc"), "tcp://c:3": (None, "ModuleNotFoundError: x")}
    monkeypatch.setattr(versions, "ask_workers", _answering(answers))
    with pytest.raises(InputError) as err:
        check_workers(_Client(), "tcp://s:8786")
    assert str(err.value) == (
        "--scheduler tcp://s:8786: worker tcp://b:2 (and 1 more of 3 workers) runs masonry 0.0.9 (source abc), "
        f"this command runs {describe(ours)}; install the same masonry on every worker"
    )
    monkeypatch.setattr(versions, "ask_workers", _answering({"tcp://a:1": OSError("gone")}))
    with pytest.raises(InputError, match=r"worker tcp://a:1 could not be asked \(OSError: gone\)"):
        check_workers(_Client(), "tcp://s:8786")

    monkeypatch.setattr(versions, "ask_workers", _answering(TimeoutError()))
    with pytest.raises(InputError) as err:  # Client.run waited as long as a worker took, without a word
        check_workers(_Client(), "tcp://s:8786")
    assert str(err.value) == (
        "--scheduler tcp://s:8786: the workers (2) did not all answer the masonry check within 60 s (a worker "
        "inside a long call answers when it ends); try again when they are free"
    )


def test_the_probe_reads_no_file(monkeypatch):
    """Every run carries its worker's answer: the source was hashed once, when masonry was imported."""
    import hashlib

    import masonrycli

    monkeypatch.setattr(hashlib, "sha256", lambda *a: pytest.fail("hashed again"))
    answers = [this_version() for _ in range(3)]
    assert answers == [(masonrycli.__version__, masonrycli.SOURCE_DIGEST)] * 3


def test_a_masonry_from_before_the_import_digest_is_described_by_its_files(monkeypatch):
    """A worker whose masonry has no SOURCE_DIGEST: the probe hashes its files, as that masonry did."""
    import masonrycli
    from masonrycli.source_digest import source_digest

    digest = masonrycli.SOURCE_DIGEST
    assert source_digest() == digest  # the files are those imported
    monkeypatch.delattr(masonrycli, "SOURCE_DIGEST")
    assert this_version() == (masonrycli.__version__, digest)


class _Opened:
    """Counts its unpickling (in this process)."""

    opened = 0

    def __reduce__(self):
        return (_Opened._open, ())

    @staticmethod
    def _open():
        _Opened.opened += 1
        return "the base"


def test_a_run_answers_with_its_masonry_and_runs_only_for_the_same(monkeypatch):
    """The task of a point: probe, then the run only if the worker's masonry is the driver's; its inputs are
    opened once per process and only then (a worker without masonry could not open them)."""
    import cloudpickle

    keep, run = versions.make_task()
    ours = this_version()
    # another masonry: the inputs are not even opened (these bytes are not a pickle), nothing runs
    assert run(("0.0.9", "abc"), b"not a pickle", {"amp": 0.3}) == (ours, "?", None)
    payload = keep(cloudpickle.dumps((lambda base, params, x: (base, params, x), _Opened())))
    _Opened.opened = 0
    for amp in (0.1, 0.2):
        assert run(ours, payload, {"amp": amp}, 7) == (ours, "?", ("the base", {"amp": amp}, 7))
    assert _Opened.opened == 1
    versions.check_result(ours, "tcp://w:1", {"amp": 0.1}, ours)
    with pytest.raises(versions.WorkerMismatch) as err:
        versions.check_result(("0.0.9", "abc"), "tcp://w:1", {"amp": 0.1, "record": "a.AT2"}, ours)
    assert str(err.value) == (
        f"worker tcp://w:1 runs masonry 0.0.9 (source abc), this command runs {describe(ours)}: its run of "
        "amp=0.1 record=a.AT2 is not kept and the study stops"
    )


def test_the_study_uses_only_distributed_s_public_api():
    # The check's deadline was Client.sync(client._run, ..., callback_timeout=): a private coroutine of
    # distributed, free to change in any release. No private attribute of a Dask object in masonrycli.
    import ast

    dask_objects = {"client", "cluster", "future", "scheduler", "worker"}
    private = []
    for path in sorted((ROOT / "masonrycli").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if (
                isinstance(node, ast.Attribute)
                and isinstance(node.value, ast.Name)
                and node.value.id in dask_objects
                and node.attr.startswith("_")
                and not node.attr.startswith("__")
            ):
                private.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.value.id}.{node.attr}")
    assert private == []


def test_the_digest_skips_what_is_not_a_source_file(tmp_path, monkeypatch):
    """An editor's lock file (Emacs: '.#cli.py', a symbolic link to nothing) beside the sources: open() of it
    raised FileNotFoundError inside 'import masonrycli', and every command ended in a traceback."""
    from masonrycli.source_digest import source_digest

    package = tmp_path / "digest_probe_pkg"
    package.mkdir()
    (package / "__init__.py").write_text("x = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    clean = source_digest(("digest_probe_pkg",))
    (package / ".#__init__.py").symlink_to(tmp_path / "user@host.1234")  # what Emacs leaves while editing
    assert source_digest(("digest_probe_pkg",)) == clean


def test_the_check_asks_at_the_address_the_command_was_given(monkeypatch):
    """A scheduler in a container or behind a tunnel reports an address of its own (tcp://172.17.0.2:8786)
    that this machine may not reach: the check connects where the study's client did (--scheduler)."""
    asked = []

    class Tunnelled:
        def scheduler_info(self):
            return {"address": "tcp://172.17.0.2:8786", "workers": {"tcp://a:1": {}}}

    def ask_workers(address, function, timeout):
        asked.append(address)
        return {"tcp://a:1": this_version()}

    monkeypatch.setattr(versions, "ask_workers", ask_workers)
    check_workers(Tunnelled(), "tcp://localhost:18786")
    assert asked == ["tcp://localhost:18786"]
