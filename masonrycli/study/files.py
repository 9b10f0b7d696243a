"""The files a study writes, under the policy of :mod:`masonrycli.outputs.files`, all checked before any run.

- The table (``--out``) is the study's state: an existing table whose rows are all of this study (same
  ``study`` fingerprint, points of this grid) is resumed — its rows are kept and the new ones added, so
  that is no overwrite. A table holding rows of another study or of points outside the grid (they would
  be lost), an empty or unreadable one, or a journal of such rows, is refused (exit 2) unless
  ``--force``, which replaces it; ``--force`` never drops a finished row of this study and grid.
- The plot (``--plot``), the recording (``--recording``) and the per-run histories (``--histories``)
  follow ``simulate``: an existing file is refused unless ``--force``. The histories checked are those
  of the runs still to make (for ``--find``, any value of the bisected parameter at an unfinished point).
- Every file is written as ``.NAME.<pid>.part`` and renamed into place when complete
  (:func:`masonrycli.outputs.files.written_whole`), so Ctrl-C, a killed process or a failed write leaves the
  previous file or a complete new one, never half a file.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from masonrycli.errors import InputError
from masonrycli.outputs.files import OutputFile, check_output, glob_escape, part_writer
from masonrycli.study import store
from masonrycli.study.task import history_name, made_by_study

_ANY = "FINDVALUE"
"""Stands for the bisected value in a history name (letters only: :func:`history_name` keeps it)."""


def check_picture(path: Path | None, option: str, suffix: str, force: bool) -> OutputFile | None:
    """The plot or the recording of a study, checked like ``simulate``'s outputs (None: not written)."""
    return None if path is None else check_output(path, option, suffix, force)


def open_table(
    out: Path, study_id: str, force: bool, names: list[str], points: list[dict], warn=None, row_study=None
) -> tuple[OutputFile, list]:
    """Check the table ``out`` for the study ``study_id`` over ``points`` (rows keyed by ``names``):
    ``(its OutputFile, the rows of this study already in it and its journal)``; a row whose ``study`` is
    ``row_study(row)`` is this study's too (a record set's row, by its own record). Raises
    :class:`InputError` for a table that is not this study's unless ``force`` (see the module docstring);
    with ``force``, says through ``warn`` whose rows it replaces."""
    suffix = out.suffix.lower()
    try:
        rows = store.read_rows(out)
    except InputError as exc:  # not a table (a file named like one, a cut or foreign one): --force replaces it
        if not force:
            raise InputError(f"--out {exc} (add --force to replace it)") from None
        rows = []
    keys = {store.row_key(p, names) for p in points}
    mine = (study_id,) if row_study is None else None
    ours = [r for r in rows if r.get("study") in (mine or (study_id, row_study(r))) and store.row_key(r, names) in keys]
    foreign = len(ours) < len(rows)  # another study's rows, or points not in this grid: they would be lost
    if foreign and force and warn is not None:
        warn(f"--out {out}: --force replaces {_whose([r for r in rows if r not in ours])}")
    if out.exists():
        table = check_output(out, "--out", suffix, force or (bool(ours) and not foreign))
        table.force = True  # checked: this study's own table, or --force
    else:
        if foreign and not force:
            journal = store.journal_path(out)
            raise InputError(f"--out {out}: {journal} holds rows of another study or grid (add --force to replace it)")
        table = check_output(out, "--out", suffix, force)
    return table, ours


def _whose(rows: list[dict]) -> str:
    """What the rows about to be dropped were: how many, over which parameters, of which study. --force
    replaced another study's table without a word of whose it was."""
    params = []
    for key in rows[0]:
        if key in ("state", "status") or key.endswith("_threshold"):
            break  # a row's parameters come first (study.py's columns)
        params.append(key)
    studies = sorted({str(r.get("study") or "?")[:12] for r in rows})
    over = f" over {', '.join(params)}" if params else ""
    plural = "s" if len(rows) != 1 else ""
    return f"{len(rows)} row{plural}{over} of study {', '.join(studies)} (not this study's rows or grid)"


def check_histories(
    folder: Path | None, points: list[dict], find: str | None, force: bool, study: tuple[str, ...] | None = None
) -> None:
    """Refuse (unless ``force``) the history files the runs of ``points`` would write in ``folder``
    that exist already, but for those an earlier run of the same ``study`` wrote (:func:`made_by_study`);
    with ``find`` the bisected value is unknown, so any value counts."""
    if folder is None:
        return
    if folder.exists() and not folder.is_dir():
        raise InputError(f"--histories {folder}: is not a folder")
    if not folder.exists() and folder.suffix.lower() == ".npz":  # it was made: a folder h.npz of amp=0.1.npz, …
        raise InputError(
            f"--histories {folder}: names the folder for one history per run (e.g. --histories histories), "
            "not a file: a name ending in .npz is a file's"
        )
    names = dict.fromkeys(history_name(p | {find: _ANY} if find else p) for p in points)
    for name in names:
        if find:
            taken = sorted(folder.glob(glob_escape(name).replace(_ANY, "*"))) if folder.is_dir() else []
            name = taken[0].name if taken else name.replace(_ANY, "0")
        made = made_by_study(folder / name, study)
        check_output(folder / name, "--histories", ".npz", force or made)  # the study makes the folder


def remove_abandoned_parts(folder: Path | None) -> None:
    """Remove the temporary files of histories whose writer is gone. A study stopped by Ctrl-C closes its
    LocalCluster, whose workers die inside the runs in flight: their ``.NAME.<pid>.part`` files (and a
    history's ``.rows`` folder) stayed in ``--histories``, as after a ``kill -9``. Local workers only: the pid
    of a remote worker says nothing here."""
    if folder is None or not folder.is_dir():
        return
    for part in [*folder.glob(".*.npz.*.part"), *folder.glob(".*.npz.*.part.rows")]:
        writer = part.with_name(part.name.removesuffix(".rows"))
        if part_writer(writer) is not None:  # a run still going (another study in the same folder)
            continue
        if part.is_dir():
            shutil.rmtree(part, ignore_errors=True)
        else:
            part.unlink(missing_ok=True)
