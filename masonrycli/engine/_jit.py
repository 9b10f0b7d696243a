"""The one place where the engine's numba compilation flags are set.

Every kernel of ``masonrycli.engine`` is decorated with :data:`njit` (never ``numba.njit`` directly), so
that changing a flag changes it everywhere.

- ``cache=True``: compiled machine code is cached (next to the sources, ``__pycache__``, unless that
  folder cannot be written: "Where" below), so a second start does not recompile.
- ``no_cfunc_wrapper``: numba otherwise builds, optimises and compiles with every kernel a C-callable
  wrapper, used only when a kernel is passed as a first-class function value, which the engine never
  does: ~0.02 s of CPU a kernel, 5 % of a first run's compilation.
- :func:`kernel_only` for a kernel that a run calls only from kernels (Python calls it in tests and tools
  at most): ``no_cpython_wrapper`` as well, no CPython wrapper (argument unboxing, result boxing) built,
  optimised and compiled with it. The wrapper's cost grows with the arguments: 0.28 s of
  ``momentum._momentum_sweeps``'s 1.0 s (12 arguments, one omitted). numba would jump to a null entry
  point on a call from Python (a segmentation fault); the dispatcher's class is swapped for one whose
  Python call compiles a twin instead, the same function under another name (its own cache files) with
  a wrapper, and runs it: the tests call the same code, and a run that called it from Python would
  compile it twice, not crash. The kernels that call it link its code as before: the same results, bit
  for bit (the golden histories). numba compiles a library function (``np.empty``,
  ``max`` of two floats) once per set of caller flags, so one such call in a kernel_only kernel compiles
  it once more (~0.03 s): a kernel whose wrapper is cheap stays :data:`njit`.
- no ``fastmath``: it allows reassociation and contraction, which change results in the last bits from
  one build or machine to the next. The engine promises bit-identical output for the same input, and
  the contact geometry relies on exact comparisons (ties between faces, points on clipping planes).
- no ``parallel``: threads would make the order of floating-point reductions, hence the results,
  depend on scheduling.
- kernels allocate as ``np.empty(shape, np.float64)`` (the dtype positional) and fill the array if it
  must start at a value: numba compiles a copy of ``np.empty`` for each way of calling it (keyword or
  positional dtype, an omitted one, ``np.zeros`` and ``np.full`` calling it their own way), ~0.04 s each;
  22 were compiled for a first run, 6 are now.
- ``@njit(inline="always")`` for a kernel that one kernel calls and a run never calls from Python (the
  fused steps' stages, the tensor stages of ``_stress_step``, the sweep's reordering): numba then types
  it inside its caller and compiles no kernel of its own, whose fixed cost is ~0.1 s. A kernel called
  from Python in a run, or from several kernels, stays its own (inlined, it would be compiled once more
  for each caller). The detection stages gained nothing inlined into ``_detect``: its cost is LLVM
  optimising the same code, once for ``_detect`` and once more for ``fused._before_solve``.
- SLP vectorisation on (numba's default is off): LLVM packs the same operation on neighbouring scalars
  (the x and y of an impulse, the two bodies of a contact) into one vector instruction. Each lane is the
  same IEEE operation as before and, without fastmath, nothing is reassociated or contracted, so the
  results are bit-identical; the NLGS sweep takes ~4 % less time per contact·sweep. numba reads the
  setting whenever it compiles, so it holds for every kernel compiled in the process (the engine is
  numba's only user).

The cache of a kernel is stamped with the source of its module **and of every engine module that module
imports from**, transitively (:func:`source_files`). A cached kernel holds the machine code of the
kernels it calls: ``fused._before_solve`` that of detection, integration and warm start, ``watch._watch``
that of ``nlgs._relative_velocity``, ``warmstart`` the packed columns of ``nlgs``. numba alone stamps a
kernel with its own file only, so an edit of a callee in another file would leave its callers' cached
code stale.

Where: one folder for the whole engine, chosen at import (:func:`cache_dir`): ``NUMBA_CACHE_DIR`` when set
and writable, else ``__pycache__`` beside the sources, else numba's user-wide folder (``~/.cache/numba``),
else the user's own folder in the temporary folder (``/tmp/masonry-numba-<uid>``, 0700, refused if another
user owns it or may write into it), else none: kernels are compiled in every run, uncached, and a run says
so (:data:`NO_CACHE_NOTE`). A read-only install (a venv of root's used by another user, a Docker image
built as root and run as a user) thus caches in the user's folder, stamped as above, and that folder is
first given what the install's own ``__pycache__`` holds (:func:`seed`: a cache filled when the image was
built serves its users; not with ``NUMBA_CACHE_DIR``, which a cold-start benchmark sets empty). Before, a kernel whose
``__pycache__`` could not be written was left to numba's own locators: its user-wide cache was stamped
with the kernel's own file only (an upgrade of a callee in place then loaded stale code), and with no
writable home (``nobody``, a container's user) every engine import ended in numba's ``RuntimeError: cannot
cache function …: no locator available``.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import re
import shutil
import stat
import tempfile
import types

import numba
from numba.core import caching, config
from numba.core.registry import CPUDispatcher
from numba.misc.appdirs import AppDirs

config.SLP_VECTORIZE = 1  # module doc
__all__ = ["kernel_only", "njit"]


class _KernelOnly(CPUDispatcher):
    """A :func:`kernel_only` kernel: compiled without a Python entry. A call from Python (tests, tools)
    runs its twin, the same function compiled by :data:`njit` with a Python entry, instead of jumping to
    the kernel's null entry point (a segmentation fault)."""

    def __call__(self, *args, **kwargs):
        twin = self.__dict__.get("_python_twin")
        if twin is None:
            f = self.py_func
            copy = types.FunctionType(f.__code__, f.__globals__, f.__name__, f.__defaults__, f.__closure__)
            copy.__qualname__ = f.__qualname__ + PYTHON_TWIN  # its own cache files: it has a Python entry
            copy.__module__ = f.__module__
            twin = self._python_twin = njit(copy)
        return twin(*args, **kwargs)


PYTHON_TWIN = "__python_twin"
"""Suffix of the qualified name of a kernel_only kernel's twin (in --kernels tables, the cache's files)."""


def kernel_only(func):
    """:data:`njit` for a kernel that kernels call, and Python only in tests and tools (module doc): no
    CPython wrapper; a Python call compiles and runs a twin that has one."""
    dispatcher = njit(func, no_cpython_wrapper=True)
    dispatcher.__class__ = _KernelOnly  # same layout: a Python call now goes to _KernelOnly.__call__
    return dispatcher


_ENGINE = os.path.dirname(os.path.abspath(__file__))
_IMPORT = re.compile(
    r"^\s*from\s+(?:masonrycli\.engine\.|\.)(\w+)\s+import"  # from .x import … / masonrycli.engine.x
    r"|^\s*from\s+(?:masonrycli\.engine|\.)\s+import\s+([\w, ]+)",  # from masonrycli.engine import x, y
    re.M,
)


@functools.cache
def source_files(path: str) -> tuple[str, ...]:
    """The engine module ``path`` and every engine module it imports from, transitively (sorted paths)."""
    seen: set[str] = set()
    todo = [os.path.abspath(path)]
    while todo:
        file = todo.pop()
        if file in seen or not os.path.isfile(file):
            continue
        seen.add(file)
        with open(file, encoding="utf-8") as f:
            text = f.read()
        for single, several in _IMPORT.findall(text):
            names = [single] if single else [n.strip() for n in several.split(",")]
            todo += [os.path.join(_ENGINE, f"{n}.py") for n in names if n]
    return tuple(sorted(seen))


@functools.cache
def _stamp(path: str) -> str:
    h = hashlib.sha256()
    for file in source_files(path):
        with open(file, "rb") as f:
            h.update(os.path.basename(file).encode() + b"\0" + f.read())
    return h.hexdigest()


class _EngineSources:
    """Locator mix-in: engine kernels only, stamped by :func:`_stamp` (module docstring)."""

    def get_source_stamp(self):
        return _stamp(self._py_file)

    @classmethod
    def from_function(cls, py_func, py_file):
        if os.path.dirname(os.path.abspath(py_file)) != _ENGINE:
            return None
        return super().from_function(py_func, py_file)


class _EngineCache(_EngineSources, caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
    """In :data:`CACHE_DIR` (one folder for the whole engine, chosen at import)."""

    def __init__(self, py_func, py_file):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno

    def get_cache_path(self):
        return CACHE_DIR

    @classmethod
    def from_function(cls, py_func, py_file):
        return super().from_function(py_func, py_file) if CACHE_DIR else None


def _writable(path: str) -> bool:
    """Whether ``path`` is (or can be made) a folder this process writes into: numba's own test."""
    try:
        os.makedirs(path, exist_ok=True)
        tempfile.TemporaryFile(dir=path).close()
    except OSError:
        return False
    return True


def _own_folder(path: str) -> bool:
    """Whether ``path`` is a folder (not a link) of this user that no one else may write into, made so if it
    is not there. A shared temporary folder: another user could otherwise put a cache there first, and
    numba's index is a pickle, run as it is read."""
    try:
        os.makedirs(path, mode=0o700, exist_ok=True)
        st = os.lstat(path)
    except OSError:
        return False
    return stat.S_ISDIR(st.st_mode) and st.st_uid == os.geteuid() and not st.st_mode & 0o022


def candidates() -> list[str]:
    """Where the engine's cache may go, in order: ``NUMBA_CACHE_DIR`` when set, next to the sources
    (``__pycache__``), numba's user-wide folder (``~/.cache/numba``), then a folder of this user in the
    temporary folder (``/tmp/masonry-numba-1000``). The first three are numba's own order and folders."""
    sub = caching._CacheLocator.get_suitable_cache_subpath(os.path.join(_ENGINE, "_jit.py"))  # engine_<sha1>
    found = [os.path.join(config.CACHE_DIR, sub)] if config.CACHE_DIR else []
    found.append(os.path.join(_ENGINE, "__pycache__"))
    found.append(os.path.join(AppDirs(appname="numba", appauthor=False).user_cache_dir, sub))
    uid = os.geteuid() if hasattr(os, "geteuid") else os.getpid()
    found.append(os.path.join(tempfile.gettempdir(), f"masonry-numba-{uid}", sub))
    return found


def cache_dir() -> str | None:
    """The first of :func:`candidates` this process can write into, or None (module doc, "Where")."""
    *usual, temporary = candidates()
    for path in usual:
        if _writable(path):
            return path
    return temporary if _own_folder(os.path.dirname(temporary)) and _writable(temporary) else None


def seed(source: str, target: str) -> int:
    """Copy into ``target`` each kernel's cache files (its index ``*.nbi`` and the data ``*.N.nbc`` it names)
    that ``source`` holds newer or ``target`` lacks; the number of kernels copied. A read-only install whose
    ``__pycache__`` was filled when it was made (a Docker image's build step running masonry as root) thus
    serves its user's cache, which started empty and compiled everything again (18.6 s of CPU). Data first,
    the index last, each under a temporary name renamed into place (as numba writes them): a process
    reading the target meanwhile (the compile-ahead child seeds it too) sees an old entry or a whole one. An
    entry stamped for other sources reads as empty there, as it did here; nothing is copied on error."""
    try:
        names = os.listdir(source)
        have = {n: os.stat(os.path.join(target, n)).st_mtime for n in os.listdir(target) if n.endswith(".nbi")}
    except OSError:
        return 0
    copied = 0
    for index in sorted(n for n in names if n.endswith(".nbi")):
        base, part = index[: -len(".nbi")], None
        try:
            if index in have and os.stat(os.path.join(source, index)).st_mtime <= have[index]:
                continue
            data = [
                n for n in names if n.startswith(base + ".") and n.endswith(".nbc") and n[len(base) + 1 : -4].isdigit()
            ]
            for name in [*data, index]:
                part = os.path.join(target, f".{name}.{os.getpid()}.part")
                shutil.copyfile(os.path.join(source, name), part)
                os.replace(part, os.path.join(target, name))
        except OSError:
            with contextlib.suppress(OSError, TypeError):  # TypeError: no part yet
                os.unlink(part)
            continue
        copied += 1
    return copied


CACHE_DIR = cache_dir()
"""The folder of the engine's compiled kernels, None when no folder can be written (then none is cached)."""

if CACHE_DIR is not None and not config.CACHE_DIR and CACHE_DIR != os.path.join(_ENGINE, "__pycache__"):
    seed(os.path.join(_ENGINE, "__pycache__"), CACHE_DIR)  # a read-only install's own cache, if it has one

NO_CACHE_NOTE = (
    "note: no folder for the compiled numba kernels can be written ({}): every run compiles them again "
    "(about 20 s of CPU); set NUMBA_CACHE_DIR to a writable folder to keep them"
)
"""Said at the start of a run when :data:`CACHE_DIR` is None (formatted with the folders tried)."""

njit = functools.partial(numba.njit, cache=CACHE_DIR is not None, no_cfunc_wrapper=True)
"""``numba.njit`` with the engine's flags. Use as ``@njit`` or ``@njit(...)``."""

# numba ≥ 0.60 names it CacheImpl, earlier _CacheImpl; the first locator that accepts a function is used.
_CACHE_IMPL = getattr(caching, "CacheImpl", None) or caching._CacheImpl
_CACHE_IMPL._locator_classes[:0] = [_EngineCache]
