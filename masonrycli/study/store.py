"""The results of a study on disk: one row per run, ``.parquet`` or ``.csv`` (the extension chooses).

Finished rows are never lost: each row is appended to a journal (``<out>.journal.jsonl``, one JSON
object per line, flushed) the moment it arrives; the table itself is rewritten whole (temporary file,
then rename: :mod:`masonrycli.outputs.files`) at the end of the study and when it is interrupted, after which
the journal goes. Which existing table may be rewritten: :mod:`masonrycli.study.files`.
Re-running the same study reads both and skips the rows already finished (resume). Rows carry a
``study`` column, a fingerprint of everything but the grid, so a different study never reuses them.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
from pathlib import Path

from masonrycli.errors import InputError
from masonrycli.outputs.files import OutputFile, check_folder, written_whole

SUFFIXES = (".parquet", ".csv")
TEXT_COLUMNS = frozenset(
    {"study", "source", "command", "state", "status", "error", "note", "outcome", "holds", "record"}
)
"""CSV columns read back as text even when they look like numbers (a fingerprint "1234e5...")."""


def check_out(path: Path) -> Path:
    if path.suffix.lower() not in SUFFIXES:
        raise InputError(f"--out {path}: a study is written as .parquet or .csv")
    if path.exists() and path.is_dir():
        raise InputError(f"--out {path}: is a directory")
    check_folder(path, f"--out {path}")  # first: "--out's plot t.sh/s.png: t.sh is not a folder" named the plot
    return path


def fingerprint(*parts) -> str:
    """12 hex digits of SHA-1 over the ``repr`` of ``parts`` (the study's base and settings)."""
    return hashlib.sha1(repr(parts).encode()).hexdigest()[:12]


def journal_path(out: Path) -> Path:
    return out.with_name(out.name + ".journal.jsonl")


def read_rows(out: Path) -> list[dict]:
    """Rows already written for ``out``: the table, then the journal (a later row replaces an earlier
    one with the same key)."""
    rows = []
    if out.exists():
        rows += _read_table(out)
    journal = journal_path(out)
    if journal.exists():
        with open(journal) as fh:
            for line in fh:
                try:
                    rows.append(json.loads(line))
                except json.JSONDecodeError:  # a line cut by a hard kill: that row was not finished
                    continue
    return rows


def _read_table(path: Path) -> list[dict]:
    try:
        if path.suffix.lower() == ".parquet":
            import pyarrow.parquet as pq

            return pq.read_table(path).to_pylist()
        with open(path, newline="") as fh:
            return [{k: v if k in TEXT_COLUMNS else _parse(v) for k, v in row.items()} for row in csv.DictReader(fh)]
    except Exception as exc:  # a corrupt or foreign file: say which, do not guess
        raise InputError(f"{path}: cannot read the existing study ({type(exc).__name__}: {exc})") from None


def _parse(text: str):
    for convert in (int, float):
        try:
            return convert(text)
        except ValueError:
            pass
    return text


class Journal:
    """Append-only record of finished rows (one JSON line each, flushed to the OS at once)."""

    def __init__(self, out: Path):
        self.path = journal_path(out)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._fh = open(self.path, "a")
        except OSError as exc:  # said "error: /proc/s.csv.journal.jsonl: No such file ...": no option named
            raise InputError(f"--out {out}: cannot write its journal {self.path.name}: {exc.strerror or exc}") from None

    def append(self, row: dict) -> None:
        self._fh.write(json.dumps(row, default=_plain) + "\n")
        self._fh.flush()

    def close(self) -> None:
        self._fh.close()


def _plain(value):
    # numpy scalars in a row (a worker's int64, float64) -> Python numbers
    return value.item() if hasattr(value, "item") else str(value)


def write_rows(out: OutputFile, rows: list[dict], columns: list[str]) -> Path:
    """Write ``rows`` (every key of ``columns``, in that order) to ``out`` whole (temporary file renamed
    into place, :func:`masonrycli.outputs.files.written_whole`), then drop the journal; returns where it went."""
    table = [{c: _plain(r.get(c)) if hasattr(r.get(c), "item") else r.get(c) for c in columns} for r in rows]
    journal = journal_path(out.path)
    with written_whole(out) as part:
        if out.path.suffix.lower() == ".parquet":
            import pyarrow as pa
            import pyarrow.parquet as pq

            pq.write_table(pa.Table.from_pylist(table), part)
        else:
            with open(part, "w", newline="") as fh:
                writer = csv.DictWriter(fh, fieldnames=columns)
                writer.writeheader()
                writer.writerows({c: _csv_value(r[c]) for c in columns} for r in table)
    journal.unlink(missing_ok=True)
    return out.path


def _csv_value(value):
    # repr keeps every bit of a float, so a resumed study finds its points again
    if isinstance(value, float):
        return "nan" if math.isnan(value) else repr(value)
    return "" if value is None else value


def row_key(row: dict, names: list[str]) -> tuple:
    """The identity of a row within a study: its parameter values, in axis order."""
    return tuple(_key_value(row.get(n)) for n in names)


def _key_value(value):
    if isinstance(value, float) and value.is_integer():
        return int(value)
    return value
