"""engine._jit: a kernel's cache is stamped with every engine module it draws compiled code from."""

from __future__ import annotations

import os

from masonrycli.engine import _jit, broadphase, fused, watch


def _names(module) -> set[str]:
    return {os.path.basename(f) for f in _jit.source_files(module.__file__)}


def test_the_stamp_covers_the_modules_a_kernel_calls_into():
    # fused inlines detection, integration and warm start; warm start reads nlgs's packed columns.
    assert {"fused.py", "collision.py", "broadphase.py", "narrowphase.py", "contact_key.py"} <= _names(fused)
    assert {"integrate.py", "warmstart.py", "nlgs.py", "_jit.py"} <= _names(fused)
    assert {"nlgs.py", "watch.py"} <= _names(watch)
    assert _names(broadphase) == {"_arrays.py", "_jit.py", "broadphase.py"}  # nothing it does not use


def test_engine_kernels_use_the_engine_stamp(tmp_path, monkeypatch):
    locator = fused._before_solve._cache._impl.locator
    assert isinstance(locator, _jit._EngineSources)
    assert locator.get_source_stamp() == _jit._stamp(fused.__file__)
    # A change in a callee's file changes the caller's stamp (numba alone stamps the caller's own file).
    files = {os.path.basename(f): f for f in _jit.source_files(fused.__file__)}
    copy = tmp_path / "engine"
    copy.mkdir()
    for name, path in files.items():
        (copy / name).write_bytes(open(path, "rb").read())
    monkeypatch.setattr(_jit, "_ENGINE", str(copy))
    before = _jit._stamp.__wrapped__(str(copy / "fused.py"))
    with open(copy / "integrate.py", "a", encoding="utf-8") as f:
        f.write("\n# edited\n")
    _jit.source_files.cache_clear()
    assert _jit._stamp.__wrapped__(str(copy / "fused.py")) != before
    _jit.source_files.cache_clear()
