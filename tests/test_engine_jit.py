"""engine._jit: a kernel's cache is stamped with every engine module it draws compiled code from; a kernel
only kernels call in a run has no Python entry, and a call from Python runs its twin instead of crashing;
numba's option values are replaced by the same dict."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from masonrycli.engine import _jit, broadphase, contact_key, fused, joints, narrowphase, watch


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


def test_a_kernel_only_kernel_called_from_python_runs_its_twin_instead_of_crashing():
    # Without the twin numba jumps to the null entry point of the missing wrapper: a segmentation fault,
    # so the calls run in a child process, whose exit code tells the two apart.
    code = (
        "import math\n"
        "from masonrycli.engine import joints\n"
        "print(joints._nan_max(1.0, 2.0), joints._nan_max(3.0, -1.0), math.isnan(joints._nan_max(math.nan, 0.0)))\n"
        "print(sorted(joints._nan_max.overloads), sorted(joints._nan_max._python_twin.overloads))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    values, compiled = done.stdout.splitlines()
    assert values == "2.0 3.0 True"
    assert compiled == "[] [(float64, float64)]"  # the twin compiled, the kernel itself not at all
    assert isinstance(joints._nan_max, _jit._KernelOnly)
    assert joints._nan_max.targetoptions["no_cpython_wrapper"] is True


def test_kernels_calling_kernel_only_kernels_still_run():
    # collide_polygons calls the kernel_only _collide_pair (its twin), which calls the kernel_only
    # contact_key._end_label and _make_key: a unit square resting on a wider one touches it at its two
    # bottom corners.
    assert isinstance(narrowphase._collide_pair, _jit._KernelOnly)
    assert isinstance(contact_key._end_label, _jit._KernelOnly)
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    ground = np.array([[-1.0, -1.0], [2.0, -1.0], [2.0, 0.0], [-1.0, 0.0]])
    point, normal, gap, _ = narrowphase.collide_polygons(ground, square, 1e-3)
    assert sorted(point[:, 0].tolist()) == pytest.approx([0.0, 1.0])
    assert normal.tolist() == [[0.0, 1.0], [0.0, 1.0]]
    assert gap.tolist() == [0.0, 0.0]
