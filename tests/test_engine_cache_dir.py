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


def _run(tmp_path, blocked: list[str], more: str = "", numba_cache_dir: str | None = None) -> dict:
    env = dict(os.environ, HOME=str(tmp_path / "home"), XDG_CACHE_HOME=str(tmp_path / "home" / ".cache"))
    env["TMPDIR"] = str(tmp_path / "tmp")
    env.pop("NUMBA_CACHE_DIR", None)
    if numba_cache_dir:
        env["NUMBA_CACHE_DIR"] = numba_cache_dir
    (tmp_path / "tmp").mkdir(parents=True)
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


def test_a_read_only_install_s_own_cache_serves_its_user(tmp_path):
    # the install's __pycache__ filled as its owner runs it (a Docker image's build step), then read-only
    filled = tmp_path / "owner"
    filled.mkdir()
    assert _run(filled, [])["cache_dir"] == _engine_pycache()
    more = 'out["hits"] = sum(joints._nan_max._python_twin.stats.cache_hits.values())\n'
    out = _run(tmp_path / "user", [_engine_pycache()], more)
    assert out["cache_dir"].startswith(str(tmp_path / "user" / "home" / ".cache" / "numba") + os.sep)
    assert out["hits"] == 1  # loaded, not compiled again (before: 0, the user's empty cache)
    # an empty NUMBA_CACHE_DIR stays empty (benchmarks/bench_cold.py measures a first run so)
    cold = str(tmp_path / "cold")
    out = _run(tmp_path / "bench", [_engine_pycache()], more, numba_cache_dir=cold)
    assert out["cache_dir"].startswith(cold + os.sep) and out["hits"] == 0


def test_seed_copies_what_the_target_lacks_or_holds_older(tmp_path):
    source, target = tmp_path / "source", tmp_path / "target"
    source.mkdir()
    target.mkdir()
    for name, text in [("m.f-3.py311.nbi", "index"), ("m.f-3.py311.1.nbc", "one"), ("m.f-3.py311.2.nbc", "two")]:
        (source / name).write_text(text)
    (source / "m.f-30.py311.1.nbc").write_text("another kernel's data, without its index")
    assert _jit.seed(str(source), str(target)) == 1
    assert sorted(p.name for p in target.iterdir()) == ["m.f-3.py311.1.nbc", "m.f-3.py311.2.nbc", "m.f-3.py311.nbi"]
    assert (target / "m.f-3.py311.2.nbc").read_text() == "two"
    (target / "m.f-3.py311.nbi").write_text("the user's, newer")
    assert _jit.seed(str(source), str(target)) == 0  # not overwritten
    os.utime(source / "m.f-3.py311.nbi", (2e9, 2e9))  # the install's cache filled again, later
    assert _jit.seed(str(source), str(target)) == 1
    assert (target / "m.f-3.py311.nbi").read_text() == "index"
    assert _jit.seed(str(tmp_path / "none"), str(target)) == 0
