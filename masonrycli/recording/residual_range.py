"""The residual plot's y range (numpy only): from the steps' NLGS residuals as they are logged.

A record run converged its first steps far below the tolerance (1e-7.5 m/s under 1e-5): the plot spanned
2.5 decades for them, the rest of the run a flat line on the tolerance's. So the range runs from the
smallest residual but those more than a decade under the tolerance to the largest (at least the tolerance),
when at most 5 % of the steps lie that low; else the viewer fits the data.
"""

from __future__ import annotations

import numpy as np


class ResidualRange:
    """Counts the steps with a residual, those a decade under the tolerance, the largest residual and the
    smallest of the others; ``tolerance``: m/s (None or 0: no range is ever given)."""

    def __init__(self, tolerance: float | None) -> None:
        self.log10_tolerance = float(np.log10(tolerance)) if tolerance else np.nan
        self._steps, self._low, self._worst, self._best = 0, 0, 0.0, np.inf

    def add(self, residual: float) -> None:
        """One step's residual, m/s (not finite or not positive: not counted)."""
        r = float(residual)
        if not (np.isfinite(r) and r > 0):
            return
        low = bool(np.log10(r) < self.log10_tolerance - 1.0)
        self._steps += 1
        self._low += low
        self._worst = max(self._worst, r)
        self._best = self._best if low else min(self._best, r)

    def range(self) -> tuple[float, float] | None:
        """(low, high), log10 of m/s, with a 5 % margin each side; None: the viewer's fit (module doc)."""
        if not self._steps or not np.isfinite(self.log10_tolerance) or self._low > 0.05 * self._steps:
            return None
        if not np.isfinite(self._best):
            return None
        lo, hi = float(np.log10(self._best)), max(self.log10_tolerance, float(np.log10(self._worst)))
        margin = 0.05 * (hi - lo)
        return (lo - margin, hi + margin)
