"""What a study asks the cluster to run next: a grid (every point once) or threshold searches.

A driver hands out points (``start``), takes each finished row back (``feed``, which may hand out more
points) and finally gives the study's rows (``rows``). The runner (:mod:`masonrycli.study.runner`) does
the Dask side and knows nothing of grids or bisection; the drivers know nothing of Dask.

Threshold search (``--find amp``): for every point of the other axes, the values of the ``amp`` axis
(``amp=LO:HI:N``) are run first, all at once; they bracket the threshold, which is then bisected until the
bracket is narrower than ``rtol`` × its larger end in size (its upper end, for a positive axis). The threshold reported is the middle of the final bracket
(so it is within rtol / 2 of every value in the bracket). Which way the outcome goes is read from the ends
of the range:

* not at LO (or at both ends or neither): it comes *above* a value (``--find amp --outcome collapse``). The
  bracket is the smallest value producing the outcome and the value below it; ``holds = "above"``.
* at LO and not at HI: it comes *below* a value (``--find friction --outcome sliding``: a block slides at
  low friction). The same bracket mirrored: the largest value producing it and the value above it;
  ``holds = "below"``.

A point where no value produces the outcome, or LO already does and so does HI, has no threshold in the
range: NaN, ``holds`` empty, and the note says which (``<find>_hi`` is LO when LO already produces it: the
threshold curve marks the point there).

Bisection assumes the outcome, once reached, stays reached further on (above the threshold, or below it).
When the runs of a point show otherwise — the wall at 2 Hz collapses at 1.25 m/s and stands at 1.5 m/s —
the threshold is one of several: the row's note and a warning line (:attr:`FindDriver.warnings`) name the
two values, a run reaching the outcome and one beyond it that does not.
"""

from __future__ import annotations

import math

from masonrycli.study.axes import Axis, grid
from masonrycli.study.store import row_key
from masonrycli.study.task import reached


class GridDriver:
    """Every point of the grid once; ``done`` rows (resume) are not run again."""

    def __init__(self, axes: list[Axis], done: dict):
        self.names = [a.name for a in axes]
        self.points = grid(axes)
        self._rows = {
            row_key(p, self.names): done[row_key(p, self.names)] for p in self.points if row_key(p, self.names) in done
        }
        self.skipped = len(self._rows)
        self.total = len(self.points)
        self.finished: list[dict] = []
        """Rows finished since the caller last emptied this list (to journal them at once)."""

    def start(self) -> list[dict]:
        return [p for p in self.points if row_key(p, self.names) not in self._rows]

    def feed(self, params: dict, row: dict) -> list[dict]:
        self._rows[row_key(params, self.names)] = row
        self.finished.append(row)
        return []

    def rows(self) -> list[dict]:
        """Finished rows in grid order (first axis slowest)."""
        return [self._rows[k] for k in (row_key(p, self.names) for p in self.points) if k in self._rows]


class _Search:
    """The bracket of one threshold search."""

    def __init__(self, values: tuple):
        self.values = tuple(sorted(values))
        self.results: dict[float, bool] = {}
        self.lo = self.hi = math.nan
        self.evaluations = 0
        self.wall_time = 0.0
        self.error = ""
        self.note = ""
        self.holds = ""
        """"above": the outcome holds at values above the threshold, "below": below it, "": none found."""


class FindDriver:
    """Bisect ``find`` for the threshold of ``outcome`` at every point of the other axes: the smallest value
    producing it, or the largest when it comes below a value (module doc)."""

    def __init__(self, axes: list[Axis], find: str, outcome: str, rtol: float, done: dict):
        self.find, self.outcome, self.rtol = find, outcome, rtol
        found = [a for a in axes if a.name == find]
        self.values = found[0].values
        self.others = [a for a in axes if a.name != find]
        self.names = [a.name for a in self.others]
        self.points = grid(self.others)
        self.searches = {row_key(p, self.names): _Search(self.values) for p in self.points}
        self._rows = {k: _resumed(done[k], find) for k in self.searches if k in done and not _stale(done[k])}
        self.skipped = len(self._rows)
        self.total = len(self.points)
        self.finished: list[dict] = []
        self.warnings: list[str] = []
        """One line per point whose runs show the outcome is not monotone in ``find`` (module doc)."""

    def start(self) -> list[dict]:
        return [
            p | {self.find: v} for p in self.points if row_key(p, self.names) not in self._rows for v in self.values
        ]

    def feed(self, params: dict, row: dict) -> list[dict]:
        key = row_key(params, self.names)
        search = self.searches[key]
        search.evaluations += 1
        search.wall_time += row.get("wall_time", 0.0) or 0.0
        if row["status"] == "error":
            search.error = search.error or row["error"]
        else:
            search.results[params[self.find]] = reached(row, self.outcome)
        if math.isnan(search.hi) and search.evaluations < len(search.values):  # initial values pending
            return []
        point = {n: params[n] for n in self.names}
        if search.error:
            return self._finish(key, point, search)
        if math.isnan(search.hi):  # the initial values are all in: bracket the threshold
            if not self._bracket(search):
                return self._finish(key, point, search)
        else:
            value = params[self.find]
            # the end of the bracket on the outcome's side moves: hi above (the outcome holds above), lo below
            if search.results[value] == (search.holds == "above"):
                search.hi = value
            else:
                search.lo = value
        # × the larger end in size: "× hi" never held for a bracket below 0 (amp=-1:-0.1:3 ran for ever)
        middle = 0.5 * (search.lo + search.hi)
        if (
            search.hi - search.lo <= self.rtol * max(abs(search.lo), abs(search.hi))
            or not search.lo < middle < search.hi
        ):
            return self._finish(key, point, search)  # the second: a bracket around 0 ends where float64 does
        return [point | {self.find: middle}]

    def _bracket(self, search: _Search) -> bool:
        """Bracket the threshold from the initial values (module doc); False, with a note, when the range
        holds none."""
        values, results, find = search.values, search.results, self.find
        yes = [v for v in values if results[v]]
        if not yes:
            search.note = f"no {self.outcome} up to {find} = {values[-1]:g}"
            return False
        if results[values[0]] and not results[values[-1]]:  # it comes below a value: the mirrored bracket
            last = yes[-1]
            search.lo, search.hi = last, min(v for v in values if v > last)
            search.holds = "below"
            return True
        first = yes[0]
        below = [v for v in values if v < first]
        if not below:  # at LO, and at HI too
            search.hi = first  # the lowest value producing it (the threshold curve's mark), lo stays NaN
            search.note = f"{self.outcome} already at {find} = {first:g}"
            no = [v for v in values if not results[v]]
            if no:
                search.note += (
                    f", not at {find} = {no[0]:g}, again at {find} = {values[-1]:g}: it comes and goes over the "
                    "range (a grid shows where it holds)"
                )
            return False
        search.lo, search.hi = below[-1], first
        search.holds = "above"
        return True

    def _finish(self, key, point: dict, search: _Search) -> list[dict]:
        threshold = 0.5 * (search.lo + search.hi)
        pair = _not_monotone(search.results, search.holds == "below")
        if pair is not None:
            find, outcome = self.find, self.outcome
            seen = f"{outcome} at {find} = {pair[0]:g}, not at {find} = {pair[1]:g}"
            if search.holds:  # a bracketed threshold; the note of one not found says it comes and goes
                search.note = f"not monotone: {seen}"
            at = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in point.items())
            found = f"the threshold {threshold:g} is one of several" if math.isfinite(threshold) else "no threshold"
            self.warnings.append(
                f"--find {find}{f' ({at})' if at else ''}: {seen}: not monotone in {find}, so {found} — a grid "
                "over the range shows where it holds"
            )
        self._rows[key] = point | {
            f"{self.find}_threshold": threshold,
            f"{self.find}_lo": search.lo,
            f"{self.find}_hi": search.hi,
            "holds": search.holds if math.isfinite(threshold) else "",
            "outcome": self.outcome,
            "evaluations": search.evaluations,
            "status": "error" if search.error else "completed",
            "wall_time": search.wall_time,
            "note": search.note,
            "error": search.error,
        }
        self.finished.append(self._rows[key])
        return []

    def rows(self) -> list[dict]:
        return [self._rows[k] for k in (row_key(p, self.names) for p in self.points) if k in self._rows]


def _not_monotone(results: dict[float, bool], below: bool) -> tuple[float, float] | None:
    """``(reached, not reached)``: two values of a search's runs that bisection's assumption rules out — the
    outcome reached at one and not at a value beyond it (above it; below it when the outcome comes ``below``
    a value), the run beyond as far out as any and the one reaching it the nearest to it; None if none."""
    order = sorted(results, reverse=below)  # the outcome's side last
    for k in range(len(order) - 1, 0, -1):
        beyond = order[k]
        if not results[beyond]:
            reaching = [v for v in order[:k] if results[v]]
            if reaching:
                return reaching[-1], beyond
    return None


def _stale(row: dict) -> bool:
    """A row of a search made before ``holds``: an outcome coming below a value was reported with no threshold
    (its note said "it comes below a value here"); it is searched again."""
    return "it comes below a value here" in str(row.get("note") or "")


def _resumed(row: dict, find: str) -> dict:
    """A finished row as resumed: one written before ``holds`` existed found its threshold upwards."""
    if not row.get("holds"):
        threshold = row.get(f"{find}_threshold")
        row = row | {"holds": "above" if isinstance(threshold, (int, float)) and math.isfinite(threshold) else ""}
    return row
