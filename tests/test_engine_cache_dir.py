"""engine._jit: where the compiled kernels are cached when the install cannot be written (a venv of root's
used by another user, a Docker image built as root and run as a user). The folders a user may not write
are simulated in a child process by refusing numba's own writability test there (``tempfile.TemporaryFile``
in that folder), so the tests run the same as root or not."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from masonrycli.engine import _jit

_REFUSE = """
import json, os, sys, tempfile
blocked = json.loads(sys.argv[1])
real = tempfile.TemporaryFile
def refusing(*args, dir=None, **kwargs):
    if dir is not None and any(os.path.abspath(dir).startswith(b) for b in blocked):
        raise PermissionError(13, "Permission denied", dir)
    return real(*args, dir=dir, **kwargs)
tempfile.TemporaryFile = refusing
"""

_RUN = """
from masonrycli.engine import compile_ahead, joints
value = joints._nan_max(1.0, 2.0)  # compiled (its twin), so cached if there is a cache
cache = joints._nan_max._python_twin._cache
out = {"cache_dir": cache.cache_path, "value": value}
out["locator"] = type(cache._impl.locator).__name__ if cache.cache_path else None
"""


def _run(tmp_path, blocked: list[str], more: str = "") -> dict:
    env = dict(os.environ, HOME=str(tmp_path / "home"), XDG_CACHE_HOME=str(tmp_path / "home" / ".cache"))
    env["TMPDIR"] = str(tmp_path / "tmp")
    env.pop("NUMBA_CACHE_DIR", None)
    (tmp_path / "tmp").mkdir()
    code = _REFUSE + _RUN + more + "print(json.dumps(out))\n"
    done = subprocess.run([sys.executable, "-c", code, json.dumps(blocked)], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr  # before: RuntimeError: cannot cache function …: no locator available
    return json.loads(done.stdout)


def _engine_pycache() -> str:
    return os.path.join(os.path.dirname(os.path.abspath(_jit.__file__)), "__pycache__")


def test_a_read_only_install_caches_in_the_users_folder_with_the_engine_stamp(tmp_path):
    out = _run(tmp_path, [_engine_pycache()])
    user_wide = str(tmp_path / "home" / ".cache" / "numba")
    assert out["cache_dir"].startswith(user_wide + os.sep)
    # numba's own user-wide locator stamps a kernel with its own file only: an upgrade of a callee in
    # place would load stale machine code; the engine's locator stamps it with every module it draws from
    assert out["locator"] == "_EngineCache"
    assert out["value"] == 2.0
    assert any(name.startswith("joints._nan_max") for name in os.listdir(out["cache_dir"]))


def test_no_writable_home_caches_in_the_users_own_temporary_folder(tmp_path):
    out = _run(tmp_path, [_engine_pycache(), str(tmp_path / "home")])
    own = tmp_path / "tmp" / f"masonry-numba-{os.geteuid()}"
    assert out["cache_dir"].startswith(str(own) + os.sep) and out["locator"] == "_EngineCache"
    assert own.stat().st_mode & 0o777 == 0o700
    assert any(name.startswith("joints._nan_max") for name in os.listdir(out["cache_dir"]))


def test_nothing_writable_runs_uncached_and_says_so(tmp_path):
    more = 'out["note"], out["child"] = compile_ahead.no_cache_note(), compile_ahead.needed()\n'
    out = _run(tmp_path, [_engine_pycache(), str(tmp_path)], more)
    assert out["cache_dir"] is None and out["value"] == 2.0
    assert out["note"].startswith("note: no folder for the compiled numba kernels can be written (")
    assert "every run compiles them again" in out["note"] and "NUMBA_CACHE_DIR" in out["note"]
    assert out["child"] is False  # the compile-ahead child would compile into nothing


def test_a_temporary_folder_another_may_write_into_is_refused(tmp_path):
    # numba's index is a pickle: a folder someone else can write into could hand this user their code
    shared = tmp_path / "masonry-numba-shared"
    shared.mkdir()
    shared.chmod(0o777)
    assert not _jit._own_folder(str(shared))
    shared.chmod(0o700)
    assert _jit._own_folder(str(shared))
    link = tmp_path / "link"
    link.symlink_to(shared)
    assert not _jit._own_folder(str(link))


def test_numba_cache_dir_comes_first_and_the_sources_next(monkeypatch, tmp_path):
    monkeypatch.setattr(_jit.config, "CACHE_DIR", str(tmp_path / "nc"))
    first, second, *_ = _jit.candidates()
    assert first.startswith(str(tmp_path / "nc") + os.sep) and second == _engine_pycache()
    assert _jit.cache_dir() == first
    monkeypatch.setattr(_jit.config, "CACHE_DIR", "")
    assert _jit.candidates()[0] == _engine_pycache()
