"""The workers of an existing cluster run this masonry: its version and a digest of its source.

A study's rows are one table only if every run was made by the same code: runs are bit-identical by
design, a resumed study reuses finished rows, and a grid is read across. On a ``LocalCluster`` that holds
(its workers are started from this interpreter); on a cluster given by ``--scheduler`` the workers were
installed by someone else, perhaps with another masonry release, another checkout, or none. Before this
check a worker with another masonry wrote its rows into the study without a word, and a worker without
one failed every run (an error row each, "No module named 'masonrycli'").

What is compared: ``masonrycli.__version__`` and a SHA-256 of the source of ``masonrycli`` and
``geometry_library`` (every ``.py`` file, with its path inside the package), as the process imports them:
two checkouts of one release differ in their source, and that is what decides the numbers.

The probe is run on every worker with ``Client.run``. It is built inside :func:`_make_probe`, so
cloudpickle sends its code by value (a module-level function would be sent as a reference to
``masonrycli.study.versions``, which a worker without masonry, or with an older one, cannot import);
it imports only the standard library before it looks for masonry. The same probe describes this
process, so both sides are measured the same way.
"""

from __future__ import annotations

from masonrycli.errors import InputError


def _make_probe():
    """The probe: a function of no arguments returning ``(version, source digest)``, or ``(None, why)``
    when masonry cannot be imported. Nested so that it travels by value (module doc)."""

    def probe():
        import hashlib
        import importlib
        import os

        try:
            packages = [importlib.import_module(name) for name in ("masonrycli", "geometry_library")]
        except Exception as exc:  # noqa: BLE001 - any failure to import is "no usable masonry"
            return None, f"{type(exc).__name__}: {exc}"
        digest = hashlib.sha256()
        for package in packages:
            root = os.path.dirname(os.path.abspath(package.__file__))
            sources = []
            for folder, subfolders, names in os.walk(root):  # lazily, so the pruning below takes effect
                subfolders[:] = [d for d in subfolders if d != "__pycache__"]
                sources += [os.path.relpath(os.path.join(folder, n), root) for n in names if n.endswith(".py")]
            for relative in sorted(sources):  # one order on every machine, whatever the file system's
                digest.update(f"{package.__name__}/{relative}".encode() + b"\0")
                with open(os.path.join(root, relative), "rb") as fh:
                    digest.update(fh.read())
        return str(getattr(packages[0], "__version__", "unknown")), digest.hexdigest()[:12]

    return probe


def this_version() -> tuple[str | None, str]:
    """``(version, source digest)`` of the masonry this process runs."""
    return _make_probe()()


def describe(found) -> str:
    """``masonry 0.1.0 (source 3f2a9c1b7d0e)``, or why there is none."""
    version, source = found
    return f"masonry {version} (source {source})" if version is not None else f"no masonry ({source})"


def check_workers(client, scheduler: str) -> None:
    """Refuse (one-line :class:`InputError`) a cluster with a worker whose masonry differs from this
    process's, naming the worker and both versions. Workers that join later are not checked."""
    ours = this_version()
    found = client.run(_make_probe(), on_error="return")  # {worker address: result or exception}
    wrong = {}
    for worker, theirs in sorted(found.items()):
        if isinstance(theirs, BaseException):
            wrong[worker] = f"could not be asked ({type(theirs).__name__}: {theirs})"
        elif tuple(theirs) != ours:
            wrong[worker] = "runs " + describe(theirs)
    if wrong:
        worker, what = next(iter(wrong.items()))
        more = f" (and {len(wrong) - 1} more of {len(found)} workers)" if len(wrong) > 1 else ""
        raise InputError(
            f"--scheduler {scheduler}: worker {worker}{more} {what}, this command runs {describe(ours)}; "
            "install the same masonry on every worker"
        )
