"""The digest of masonry's source this process loaded: a SHA-256 of every ``.py`` file of ``masonrycli`` and
``geometry_library`` (with its path inside the package), taken once, when ``masonrycli`` is imported.

The workers' masonry check (:mod:`masonrycli.study.versions`) compares the command's digest with each
worker's. Taken when first asked, it described the files on disk then, not the code the process ran: a
long-lived worker that had imported masonry before its checkout changed (a ``git pull``, an edit) reported
the new files' digest while running the old code, and its rows were kept as this code's. Taken at import,
it describes the files as the process read them; a process started after the change reports the new one.

Not seen: a change between ``masonrycli``'s import and the first import of one of its modules (they are
imported as needed: the engine when a run starts) — a process started from a checkout in the middle of
a change. Hashing takes about 9 ms (99 files, 0.8 MB), once per process.

:func:`source_digest` is made by a factory so that cloudpickle sends it by value: the workers' probe
carries it to a worker whose masonry predates :data:`masonrycli.SOURCE_DIGEST`, and describes that
masonry by its files the same way. Standard library only, and it finds ``geometry_library`` without
importing it (shapely: a tenth of a second more on every ``import masonrycli``).
"""

from __future__ import annotations


def _make_source_digest():
    """``source_digest``, nested so that it travels by value (module doc)."""

    def source_digest(packages=("masonrycli", "geometry_library")) -> str:
        """12 hex digits of the SHA-256 of the packages' ``.py`` files as they are on disk now."""
        import hashlib
        import importlib.util
        import os

        digest = hashlib.sha256()
        for name in packages:
            spec = importlib.util.find_spec(name)
            if spec is None or spec.origin is None:  # not installed: the probe's import says so
                digest.update(f"{name}: missing".encode() + b"\0")
                continue
            root = os.path.dirname(os.path.abspath(spec.origin))
            sources = []
            for folder, subfolders, names in os.walk(root):  # lazily, so the pruning below takes effect
                subfolders[:] = [d for d in subfolders if d != "__pycache__"]
                # regular files only: an editor's lock file (Emacs: ".#cli.py", a symbolic link to nothing)
                # made open() raise inside "import masonrycli", and every command ended in a traceback
                paths = [os.path.join(folder, n) for n in names if n.endswith(".py")]
                sources += [os.path.relpath(p, root) for p in paths if os.path.isfile(p)]
            for relative in sorted(sources):  # one order on every machine, whatever the file system's
                try:
                    with open(os.path.join(root, relative), "rb") as fh:
                        content = fh.read()
                except FileNotFoundError:  # gone since the walk (a save in progress): as if never listed
                    continue
                digest.update(f"{name}/{relative}".encode() + b"\0")
                digest.update(content)
        return digest.hexdigest()[:12]

    return source_digest


source_digest = _make_source_digest()


def source_commit() -> str:
    """The git commit of the checkout masonry was imported from (``f935f83``, ``f935f83+changes`` when its
    files differ from the commit), or ``"not a git checkout"`` (a wheel): what a recording or a history
    names as the code that made it, beside :data:`masonrycli.SOURCE_DIGEST`. Asked once a run (~5 ms)."""
    import os
    import subprocess

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

    def git(*args: str) -> str:
        done = subprocess.run(["git", "-C", root, *args], capture_output=True, text=True, timeout=10, check=True)
        return done.stdout.strip()

    try:
        # A wheel in a virtual environment inside some other repository (a user's project) would
        # otherwise be named by that repository's commit: only a checkout whose top is masonry's counts.
        if os.path.realpath(git("rev-parse", "--show-toplevel")) != os.path.realpath(root):
            return "not a git checkout"
        commit = git("rev-parse", "--short=7", "HEAD")
        changed = git("status", "--porcelain", "--untracked-files=no", "--", "masonrycli", "geometry_library")
    except (OSError, subprocess.SubprocessError):  # no git, not a checkout, or git too slow
        return "not a git checkout"
    return commit + ("+changes" if changed else "")
