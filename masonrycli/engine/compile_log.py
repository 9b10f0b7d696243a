"""What numba compiles in a process, kernel by kernel, and the CPU each compilation takes
(benchmarks/bench_cold.py: where a first run's time goes).

numba signals each compilation of a signature with a "numba:compile" event (``numba.core.event``), nested
when typing a kernel compiles its callees. :func:`recorded_compiles` records, per compilation, the kernel,
the signature, the thread CPU time it took with and without its callees' compilations, and its depth
(0: a Python call compiled it; more: typing a kernel that calls it). Kernels loaded from the cache are not
compiled, so not recorded.
"""

from __future__ import annotations

import threading
import time
from contextlib import contextmanager
from typing import NamedTuple

import numba.core.event as ev


class Compilation(NamedTuple):
    kernel: str
    """module.qualname of the compiled function (numba's own library functions included)."""
    signature: str
    own_cpu: float
    """s of thread CPU time, the callees' compilations excluded."""
    cpu: float
    """s of thread CPU time, the callees' compilations included."""
    depth: int
    """0: compiled for a call from Python; n > 0: for a kernel being typed n levels up."""


def _name(dispatcher) -> str:
    f = getattr(dispatcher, "py_func", None)
    return repr(dispatcher) if f is None else f"{f.__module__}.{f.__qualname__}"


class _Listener(ev.Listener):
    def __init__(self, out: list[Compilation]):
        self.out = out
        self.stack: list[list] = []  # [kernel, signature, start, callees' CPU]

    def on_start(self, event):
        data = event.data
        self.stack.append([_name(data["dispatcher"]), str(data["args"]), time.thread_time(), 0.0])

    def on_end(self, event):
        kernel, signature, start, callees = self.stack.pop()
        spent = time.thread_time() - start
        if self.stack:
            self.stack[-1][3] += spent
        self.out.append(Compilation(kernel, signature, spent - callees, spent, len(self.stack)))


@contextmanager
def recorded_compiles():
    """Yield a list that fills with a :class:`Compilation` for each compilation inside the block."""
    out: list[Compilation] = []
    listener = _Listener(out)
    ev.register("numba:compile", listener)
    try:
        yield out
    finally:
        ev.unregister("numba:compile", listener)


class _Depth(ev.Listener):
    """How many compilations of this thread are under way (nested: a kernel's callees); ``on_event()`` at
    each start and end of one."""

    def __init__(self, on_event=None):
        self.thread = threading.get_ident()
        self.depth = 0
        self.on_event = on_event

    def on_start(self, event):
        if threading.get_ident() == self.thread:
            self.depth += 1
            if self.on_event is not None:
                self.on_event()

    def on_end(self, event):
        if threading.get_ident() == self.thread:
            self.depth = max(0, self.depth - 1)
            if self.on_event is not None:
                self.on_event()


@contextmanager
def watched_compiles(on_event=None):
    """Yield ``compiling()``: whether numba is compiling for this thread now (a step's first call of a
    kernel; a kernel loaded from the cache does not count). A stop signal cannot wait for a compilation to
    end (:mod:`masonrycli.interrupt`); other threads' compilations are theirs. ``on_event()`` is called at
    the start and the end of each compilation of this thread, from numba's Python code: an exception it
    raises stops the compilation (a signal handler's raise may land inside a ctypes callback instead, where
    Python drops it)."""
    listener = _Depth(on_event)
    ev.register("numba:compile", listener)
    try:
        yield lambda: listener.depth > 0
    finally:
        ev.unregister("numba:compile", listener)
