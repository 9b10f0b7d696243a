"""A record study's collapsed fraction per level, read back from its table: ``masonry inspect study.csv``.

A fragility study (``--records recs --param pga_g=0.25:2.5:10``, or ``--scale``) printed ``collapsed per pga_g
(g): 0.25 0/4, …, 2.5 3/4`` once, at its end; from the table on disk, later or after a resume, nothing gave it, and
the user counted rows in a spreadsheet. Here the same counts, one row a level, one column a value of the other
swept parameters (``friction`` 0.5, 0.6, …; the records are what each level's runs are over), with the fraction:

    collapsed / runs per pga_g (rows) and friction (columns)
    pga_g (g)        0.5        0.6
    0.25        0/4  0 %   0/4  0 %
    2.5        3/4  75 %  2/4  50 %

A run without a state (an error row: its run never ended) is no outcome: left out and counted under the table,
as the fragility fit leaves it out. The other outputs (the drifts, the intensity measures) are columns of the
table for pandas: docs/sweep.md "Reading a fragility study".
"""

from __future__ import annotations

from masonrycli.study.curves import UNITS, point_groups

LEVELS = ("pga_g", "scale")
"""The axes that scale a record set, in the order they are looked for (one study has one of them)."""


def collapsed_table(rows: list[dict], params: list[str]) -> tuple[str, list[str], list[list[str]], str] | None:
    """``(title, column heads, rows of cells, note)`` of the collapsed fraction per level of ``rows`` (a study's
    table, ``params`` its swept parameters), or None when it has no level axis. Columns: the level, then one per
    combination of the other swept parameters of more than one value, ``record`` aside."""
    by = next((p for p in LEVELS if p in params), None)
    if by is None or not rows:
        return None
    other = [p for p in params if p not in (by, "record") and len({r.get(p) for r in rows}) > 1]
    decided = [r for r in rows if r.get("state") in ("collapsed", "damaged", "intact")]
    groups = point_groups(decided, other)
    levels = sorted({r[by] for r in decided})
    cells = []
    for level in levels:
        line = [_number(level)]
        for _, members in groups:
            runs = [decided[i] for i in members if decided[i][by] == level]
            fell = sum(r["state"] == "collapsed" for r in runs)
            line.append(f"{fell}/{len(runs)}  {100 * fell / len(runs):.0f} %" if runs else "–")
        cells.append(line)
    unit = UNITS.get(by)
    title = f"collapsed / runs per {by}"
    labels = [label or "collapsed" for label, _ in groups]
    if len(other) == 1:  # "friction = 0.5" a column was cut to "friction =…" at 80 columns: named once, above
        unit_of = UNITS.get(other[0].rpartition(".")[2])
        title += f" (rows) and {other[0]}" + (f" ({unit_of})" if unit_of else "") + " (columns)"
        labels = [label.partition(" = ")[2] for label in labels]
    left = len(rows) - len(decided)
    note = f"{left} row{'' if left == 1 else 's'} without a state (error rows) left out" if left else ""
    return title, [f"{by}" + (f" ({unit})" if unit else ""), *labels], cells, note


def _number(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)
