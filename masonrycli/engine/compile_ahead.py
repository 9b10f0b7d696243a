"""A first run compiles on two cores: a second process compiles the kernels a run needs late.

With an empty numba cache the quick start (``masonry simulate wall --freq 2 --amp 1``) spends ~20 s of
CPU compiling, one kernel after the other, in the order the run first calls them (benchmarks/README.md,
"Cold start"). About half of it is kernels a run calls only once the first stage's float32 sweeps have
compiled (``lane_sweeps32``, the largest): the float64 sweeps that finish a step, the body-order stage,
the joint and tensor kernels of a recorded frame. :func:`ahead` starts a child process that compiles
those (:data:`KERNELS`, in the order the run needs them) into the same cache while the run compiles the
others; the run then loads them from the cache instead of compiling them. When the child is late for a
kernel the run compiles it too (the same machine code, so results are bit-identical either way).

The child is started only when it can help: at least two CPUs for this process, and a cache that lacks
a current entry for one of :data:`EVERY_RUN` (a warm start reads a few small index files, nothing more);
never when no folder can hold the cache (``engine._jit``, "Where": a read-only install with no writable
home or temporary folder), where what it compiled would be lost.
It runs in its own session (a Ctrl-C at the terminal is the run's to handle), stops when its parent
is gone, and is stopped when the run ends. numba writes each cache file under a temporary name and
renames it, so a stopped child leaves no half-written entry.

A study does the same: on ``--workers 0`` around its runs (:func:`ahead`), on a cluster of two workers or
more (a LocalCluster, or ``--scheduler``'s workers of one host) as the last worker's first task
(:func:`on_cluster`), while the other workers start the runs.

    python -m masonrycli.engine.compile_ahead     # what the child runs (exit 0 whatever happens)
"""

from __future__ import annotations

import contextlib
import importlib
import os
import subprocess
import sys

ENGINE = "masonrycli.engine"

EVERY_RUN: tuple[tuple[str, str], ...] = (
    # (module.kernel, signature as numba types: f8 float64, i8 int64, i4 int32, i1 int8, b1 bool;
    #  f8[:, ::1] a C-contiguous 2-D array), in the order a recorded run first calls them. A test checks
    #  that a run calls each with exactly this signature (tests/test_engine_compile_ahead.py).
    (
        "lane_sweeps._lane_sweeps",
        "(i4[:, ::1], f8[:, ::1], i8, f8, f8, i8, f8[:, ::1], f8[:, ::1], i1[::1], i8, f8, i8, f8,)",
    ),
    (
        "power._contact_power",
        "(i4[:, ::1], f8[:, ::1], f8[:, ::1], i8, f8[:, ::1], f8[:, ::1], b1[::1], i8, f8, f8[:, ::1], f8[:, ::1],)",
    ),
    (
        "fused._after_solve",
        "(f8[:, ::1], f8[:, ::1], f8[:, ::1], f8, f8, i8, i8[::1], f8[:, ::1], f8[::1], i8, i8[::1], f8[:, ::1],)",
    ),
    ("tensor_kernels._strain_step", "(i8, f8[:, ::1], f8[:, ::1], i8[:, ::1], f8[::1], f8, f8[:, :, :, ::1],)"),
    (
        "watch._watch",
        "(f8[:, ::1], f8[:, ::1], f8[:, ::1], f8[::1], i8, i8[::1], i4[:, ::1], f8[:, ::1], i1[::1], i8,)",
    ),
    ("power._tangential_velocity", "(i4[:, ::1], f8[:, ::1], i8, f8[:, ::1], f8[::1],)"),
    ("joints._contact_states", "(i1[::1], f8[::1], f8[:, ::1], f8, f8, i1[::1], f8[::1],)"),
    ("joints._hinged", "(f8[::1], i8[::1], i8[::1], i8, i8[:, ::1], f8[::1], f8, f8, f8, b1[::1],)"),
    (
        "tensor_kernels._stress_step",
        "(i8, f8[:, ::1], f8[:, ::1], f8[:, ::1], f8[::1], i8[:, ::1], i4[:, ::1], f8[:, ::1], f8[:, ::1],"
        " f8[:, :, :, ::1], f8[::1],)",
    ),
    ("joints._hinge_contacts", "(i8[::1], b1[::1], i8, i8[:, ::1], f8[::1], b1[::1],)"),
)
"""Kernels every recorded run calls after the first stage's float32 sweeps."""

STALLED: tuple[tuple[str, str], ...] = (
    (
        "bodies._body_order_sweeps",
        "(i4[:, ::1], f8[:, ::1], i8, f8, f8, i8, f8[:, ::1], f8[:, ::1], i1[::1], i8, i8, f8, i8, f8, f8, i8,"
        " f8[::1], f8[::1], f8[:, ::1], f8[:, ::1],)",
    ),
)
"""The body-order stage, which a run calls when a step stalls (the quick start's does, ~2 s of compilation)."""

KERNELS = EVERY_RUN + STALLED
"""What the child compiles, in this order."""


def dispatcher(name: str):
    """The numba dispatcher of ``module.kernel`` in the engine."""
    module, kernel = name.split(".")
    return getattr(importlib.import_module(f"{ENGINE}.{module}"), kernel)


def signature(text: str) -> tuple:
    """The tuple of numba types written in ``text`` (:data:`KERNELS`' notation)."""
    import numba.types

    return eval(text, {"__builtins__": {}}, vars(numba.types))  # noqa: S307 - our own constant strings


def _cached(name: str) -> bool:
    """Whether the cache holds an entry of ``name`` for its current source (numba's index reader: an
    index stamped with another source reads as empty). Anything unexpected reads as cached: then no
    child is started and the run compiles as it would without this module."""
    try:
        return bool(dispatcher(name)._cache._cache_file._load_index())
    except Exception:  # noqa: BLE001 - a numba without these internals: do nothing
        return True


def _cpus() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def no_cache_note() -> str | None:
    """The line a run says when no folder can hold the compiled kernels (engine._jit, "Where"), else None."""
    from masonrycli.engine import _jit

    if _jit.CACHE_DIR is not None:
        return None
    return _jit.NO_CACHE_NOTE.format(", ".join(_jit.candidates()))


def needed() -> bool:
    """Whether a child would help: two CPUs or more, JIT on, a cache, and a kernel of :data:`EVERY_RUN` not cached.
    :data:`STALLED` does not count: a run that never stalls would otherwise start a child every time."""
    from numba.core import config

    from masonrycli.engine import _jit

    if _cpus() < 2 or config.DISABLE_JIT or os.environ.get("MASONRY_COMPILE_AHEAD", "1") == "0":
        return False
    if _jit.CACHE_DIR is None:  # nowhere to put what it compiles
        return False
    return not all(_cached(name) for name, _ in EVERY_RUN)


@contextlib.contextmanager
def ahead():
    """Within the block, a child process compiles :data:`KERNELS` when :func:`needed`; stopped (and
    reaped) at the end of the block, whether the run finished, failed or was interrupted."""
    child = None
    if sys.executable and needed():
        with contextlib.suppress(OSError):
            child = subprocess.Popen(
                [sys.executable, "-m", __name__, str(os.getpid())],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                start_new_session=True,
            )
    try:
        yield child
    finally:
        if child is not None:
            child.kill()  # what it finished is in the cache; the kernel it was compiling is dropped
            child.wait()


def compile_all(parent: int | None = None) -> int:
    """Compile (or load from the cache) every kernel of :data:`KERNELS` in order; stop early when the
    process ``parent`` is gone. Returns how many were done."""
    done = 0
    for name, text in KERNELS:
        if parent is not None and os.getppid() != parent:
            break
        dispatcher(name).compile(signature(text))
        done += 1
    return done


def compile_quietly() -> int:
    """:func:`compile_all`, any error swallowed (-1): a helper never reports, the runs compile what it missed."""
    try:
        return compile_all()
    except Exception:  # noqa: BLE001
        return -1


def compile_if_needed() -> int:
    """:func:`compile_quietly` where :func:`needed` says so, in the worker's own process (0 when not): an
    external cluster's workers have their own cache, which the study's process cannot see."""
    try:
        return compile_quietly() if needed() else 0
    except Exception:  # noqa: BLE001
        return -1


def on_cluster(client, external: bool = False):
    """The same on a study's cluster: when the cluster has two workers or more that share a cache, the last
    of them compiles :data:`KERNELS` as its first task while the others start the runs, which then load them.
    Returns the task's future (hold it until the study ends: a released future is cancelled), or None.

    A LocalCluster's workers share this process's cache, so :func:`needed` is asked here. An external
    cluster's (``--scheduler``) are asked on the worker itself (:func:`compile_if_needed`), among the workers
    of the host that has the most (those of one host share a cache, as a study's ``dask worker --nworkers N``
    do): without it, N workers of an empty cache each compiled every kernel, one after the other."""
    if not external and not needed():
        return None
    try:
        workers = client.scheduler_info()["workers"]
    except Exception:  # noqa: BLE001 - a helper never fails the study: its runs compile what they need
        return None
    hosts: dict = {}
    for address, info in workers.items():
        hosts.setdefault(info.get("host") if external else None, []).append(address)
    group = sorted(max(hosts.values(), key=len, default=[]))
    if len(group) < 2:
        return None
    task = compile_if_needed if external else compile_quietly
    return client.submit(task, workers=group[-1:], allow_other_workers=False, pure=False)


def main(argv: list[str]) -> None:
    parent = int(argv[0]) if argv else None
    with contextlib.suppress(BaseException):  # a helper: it never reports, the run compiles what it misses
        compile_all(parent)


if __name__ == "__main__":
    main(sys.argv[1:])
