"""``masonry inspect study.csv|study.parquet``: what a study's table holds, and each column's unit.

A study's table is numbers under short names (``pga``, ``residual_drift``, ``max_opening``) with no unit in
the file: opened in a spreadsheet, ``pga 1.70`` read as g as easily as m/s², and ``inspect`` refused the file
("a table (.csv), not a recording"). As for a history (``inspect H.npz``), it now prints a table of the study —
rows and their states, the swept parameters and their values, the study fingerprints and the masonry source
that made the rows — then one line per column: its name and unit / meaning (the units of docs/sweep.md, "Rows").
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

from masonrycli.errors import InputError
from masonrycli.outputs.verdict import counted
from masonrycli.records.intensity import UNITS as IM_UNITS
from masonrycli.study.curves import UNITS as PARAM_UNITS

COLUMN_UNITS = {
    "state": "collapsed, damaged or intact (masonry docs collapse)",
    "collapse_time": "s, when it collapsed (NaN if not)",
    "energy_dissipated": "J, at the contacts, the run's final value",
    "pga": f"{IM_UNITS['pga']}, peak ground acceleration as applied",
    "pgv": f"{IM_UNITS['pgv']}, peak ground velocity as applied",
    "arias": f"{IM_UNITS['arias']}, Arias intensity as applied",
    "d5_95": "s, significant duration D5-95",
    "sa": f"{IM_UNITS['sa']}, Sa(0.5 s, 5 %)",
    "residual_drift": "× height (0.01 = 1 %), top drift relative to the ground at the end",
    "peak_drift": "× height (0.01 = 1 %), the largest top drift",
    "max_opening": "m, largest joint opening at the end",
    "hinges": "hinged joints at the end",
    "slide_time": "s, first sliding contact (NaN if none; single blocks)",
    "rock_time": "s, first rocking block (NaN if none; single blocks)",
    "status": "completed, diverged or error",
    "steps": "time steps run",
    "time": "s, simulated time run",
    "wall_time": "s, of the task on its worker",
    "cpu_time": "s, CPU time of the thread that ran the task",
    "sweeps_mean": "mean NLGS sweeps a step",
    "capped_steps": "steps at the sweep cap",
    "last_residual": "m/s, the last step's residual (against the tolerance)",
    "max_penetration": "m, the largest penetration",
    "error": "why the task failed (empty if it did not)",
    "study": "fingerprint of the base scenario and settings",
    "source": "digest of the masonry source that made the row",
    "command": "the masonry sweep line that made the row (its histories name it too; empty: not recorded)",
    "holds": "above / below: the outcome holds above or below the threshold",
    "outcome": "what --find looked for",
    "evaluations": "runs the search made",
    "note": "why no threshold was found, or the two runs showing the outcome is not monotone",
}
"""Each column of a study's table after its parameters: unit, then meaning (docs/sweep.md, "Rows")."""
_SEARCH = ("_threshold", "_lo", "_hi")
SHOWN_VALUES = 8


def is_study_table(path) -> bool:
    """Whether ``path`` is named as a study's table (.csv or .parquet)."""
    return Path(path).suffix.lower() in (".csv", ".parquet")


def study_summary(path) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
    """``(rows of the study's table, (column, unit / meaning) a column)`` of the table at ``path``.
    Raises :class:`InputError` for a file that is no study's table (one line)."""
    from masonrycli.study.store import _read_table

    path = Path(path)
    waiting = _journal_rows(path)
    if not path.is_file() and waiting:  # killed (kill -9, out of memory) before it wrote its table: it said
        # "no such file", as if the finished runs were lost
        raise InputError(
            f"{path}: not written yet — {counted(waiting, 'row')} finished, in {path.name}.journal.jsonl (a study still "
            "running, or killed before it wrote its table): the same masonry sweep command writes it and runs the rest"
        )
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    rows = _read_table(path)
    columns = list(rows[0]) if rows else _header(path)
    if "study" not in columns or "status" not in columns:
        raise InputError(
            f"{path}: not a study's table (no study and status columns); inspect reads the .rrd recordings, the .npz "
            "histories and the tables of masonry sweep"
        )
    find, params = _params(columns)
    states = Counter(r.get("state") or "failed" for r in rows) if "state" in columns else Counter()
    if find:  # a search's rows: found or not
        states = Counter(
            "threshold found" if r.get(f"{find}_threshold") == r.get(f"{find}_threshold") else "none found"
            for r in rows
        )
    table = [
        (
            "rows",
            f"{len(rows)} ({', '.join(f'{n} {s}' for s, n in states.most_common())})" if rows else _none_yet(path),
        ),
        *((p, _values(rows, p) if rows else "no value yet") for p in params),
        *(
            [("study", _some(r.get("study") for r in rows)), ("masonry source", _some(r.get("source") for r in rows))]
            if rows
            else []
        ),
    ]
    if "command" in columns and rows:  # first, as inspect H.npz shows what made a history
        table.insert(0, ("command", _commands(rows)))
    if rows and waiting:  # a resumed study still running, or killed: the table is of its last stop
        more = f"{counted(waiting, 'row')} finished since this table was written, in {path.name}.journal.jsonl"
        table.insert(1, ("journal", f"{more} (the study still running, or killed: the same command adds them)"))
    if find:
        table.insert(1, ("search", f"--find {find}: {find}_threshold, {find}_lo, {find}_hi"))
    lines = []
    for c in columns:
        if c in params:
            unit = PARAM_UNITS.get(c.rpartition(".")[2])
            lines.append((c, f"{unit}, swept" if unit else "swept parameter"))
        elif find and c.startswith(find) and c.endswith(_SEARCH):
            unit = PARAM_UNITS.get(find.rpartition(".")[2])
            what = {"_threshold": "the threshold", "_lo": "the bracket's low end", "_hi": "the bracket's high end"}
            lines.append((c, (f"{unit}, " if unit else "") + what[c[len(find) :]]))
        else:
            lines.append((c, COLUMN_UNITS[c]))
    return table, lines


def level_table(path):
    """The collapsed fraction per level of a record study's table at ``path`` (:func:`masonrycli.study.levels.
    collapsed_table`: title, heads, cells, note), or None (no level axis, a search's table, no row)."""
    from masonrycli.study.levels import collapsed_table
    from masonrycli.study.store import _read_table

    rows = _read_table(Path(path))
    find, params = _params(list(rows[0]) if rows else [])
    return None if find else collapsed_table(rows, params)


def _params(columns: list[str]) -> tuple[str | None, list[str]]:
    """``(the --find parameter or None, the swept parameters)`` of a table's ``columns``."""
    find = next((c[: -len("_threshold")] for c in columns if c.endswith("_threshold")), None)
    return find, [
        c for c in columns if c not in COLUMN_UNITS and not (find and c.startswith(find) and c.endswith(_SEARCH))
    ]


def _commands(rows: list[dict]) -> str:
    """The lines that made ``rows``, each once in the rows' order (a resume's after the first run's), one a line,
    and how many rows say none (written before rows named their command, or by a study run from elsewhere)."""
    made = [str(r.get("command") or "") for r in rows]
    lines = [c for c in dict.fromkeys(made) if c]
    unknown = made.count("")
    if unknown:
        lines.append(f"{counted(unknown, 'row')}: not recorded" if lines else "not recorded")
    return "\n".join(lines)


def _header(path: Path) -> list[str]:
    """The column names of a table with no row (its header alone; a .parquet file's schema)."""
    import csv

    try:
        if path.suffix.lower() == ".parquet":
            import pyarrow.parquet as pq

            return list(pq.read_schema(path).names)
        with open(path, newline="") as fh:
            return next(csv.reader(fh), [])
    except Exception:  # _read_table read it: a header it cannot give is no study's
        return []


def _journal_rows(path: Path) -> int:
    """Finished rows in the journal beside the table ``path`` (whole lines: a kill -9 may cut the last)."""
    from masonrycli.study.store import journal_path

    journal = journal_path(path)
    if not journal.is_file():
        return 0
    with open(journal, errors="replace") as fh:
        return sum(1 for line in fh if line.rstrip().endswith("}"))


def _none_yet(path: Path) -> str:
    """The rows line of a study's table with its header and no row: ``inspect`` said "not a study's table (no
    study and status columns)" of it, though its header has both. masonry sweep writes the table whole when the
    study ends or is stopped, with every finished row, and none when stopped before its first (a header-only
    table comes from elsewhere: a spreadsheet's rows deleted, a filter that kept none); finished rows wait in
    the journal beside it meanwhile."""
    from masonrycli.study.store import journal_path

    journal = journal_path(path)
    waiting = ""
    if journal.is_file():
        with open(journal, errors="replace") as fh:
            n = sum(1 for line in fh if line.strip())
        waiting = f"; {n} finished row{'s' if n != 1 else ''} wait in {journal.name}, written here when the study ends"
    return (
        "0 — no rows yet: masonry sweep writes its rows here when the study ends or is stopped (Ctrl-C), each "
        f"finished row kept in the journal {journal.name} meanwhile{waiting}"
    )


def _some(values) -> str:
    """The distinct ``values``, the first 3 and a count."""
    found = sorted({str(v) for v in values})
    return ", ".join(found[:3]) + (f", … ({len(found)})" if len(found) > 3 else "")


def _values(rows: list[dict], name: str) -> str:
    """The distinct values of parameter ``name``, in order, the first ``SHOWN_VALUES`` and a count."""
    values = sorted(
        {r.get(name) for r in rows}, key=lambda v: (isinstance(v, str), v if not isinstance(v, str) else 0, str(v))
    )
    shown = [f"{v:g}" if isinstance(v, float) else str(v) for v in values[:SHOWN_VALUES]]
    more = f", … ({len(values)} values)" if len(values) > SHOWN_VALUES else ""
    unit = PARAM_UNITS.get(name.rpartition(".")[2])
    return ", ".join(shown) + more + (f" {unit}" if unit else "")
