"""The residual plot's y range (numpy only): from the steps' NLGS residuals as they are logged.

A record run converged its first steps far below the tolerance (1e-7.5 m/s under 1e-5): the plot spanned
2.5 decades for them, the rest of the run a flat line on the tolerance's. So the range runs from the
smallest residual but those more than a decade under the tolerance to the largest (at least the tolerance),
when at most 5 % of the steps lie that low, with margins and room for the legend (``plot_range``); else the
viewer fits the data.
"""

from __future__ import annotations

import numpy as np

from masonrycli.recording.plot_range import plot_range

CHUNK = 1024
"""Residuals kept before they are counted, all at once (ResidualRange.add)."""


class ResidualRange:
    """Counts the steps with a residual, those a decade under the tolerance, the largest residual and the
    smallest of the others; ``tolerance``: m/s (None or 0: no range is ever given).

    The residuals are counted CHUNK at a time, by array operations: one step's by numpy scalar calls
    (np.isfinite, np.log10) took 14 ms of a recorded second of the 248-block wall (1000 steps), 1 % of its run.
    np.log10 gives an array's elements as it gives each alone (numpy's one loop: tested); math.log10 does not
    (another log10, other last bits, and a residual at a decade's edge counted otherwise)."""

    def __init__(self, tolerance: float | None) -> None:
        self.log10_tolerance = float(np.log10(tolerance)) if tolerance else np.nan
        self._steps, self._low, self._worst, self._best = 0, 0, 0.0, np.inf
        self._kept = np.empty(CHUNK)
        self._count = 0

    def add(self, residual: float) -> None:
        """One step's residual, m/s (not finite or not positive: not counted)."""
        self._kept[self._count] = residual
        self._count += 1
        if self._count == CHUNK:
            self._fold()

    def _fold(self) -> None:
        """Count the residuals kept: finite and positive ones; low ones (log10 a decade under the tolerance's)."""
        r = self._kept[: self._count]
        self._count = 0
        r = r[np.isfinite(r) & (r > 0)]
        if not r.size:
            return
        low = np.log10(r) < self.log10_tolerance - 1.0
        self._steps += int(r.size)
        self._low += int(low.sum())
        self._worst = max(self._worst, float(r.max()))
        if not low.all():
            self._best = min(self._best, float(r[~low].min()))

    def range(self, rows: int = 2) -> tuple[float, float] | None:
        """(low, high), log10 of m/s, with a margin above the lines and, under them, room for the legend's
        ``rows`` (``plot_range``); None: the viewer's fit (module doc)."""
        self._fold()
        if not self._steps or not np.isfinite(self.log10_tolerance) or self._low > 0.05 * self._steps:
            return None
        if not np.isfinite(self._best):
            return None
        lo, hi = float(np.log10(self._best)), max(self.log10_tolerance, float(np.log10(self._worst)))
        # the tolerance's line lay on the top edge, under the frame, and the legend (bottom left) over the
        # lowest residuals of the run's first steps, with a 5 % margin each side
        return plot_range(lo, hi, rows, with_zero=False)
