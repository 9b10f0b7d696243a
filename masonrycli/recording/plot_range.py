"""A plot's y range (numpy only): a margin above and below its lines, and under them room for its legend.

The viewer fits a plot to its data: lines on its top and bottom edges, and its legend (bottom left) over
the lowest of them. The recording sets the range of the plots of several series instead (``series.RANGED``,
and the residual's, ``residual_range``), from the lowest and highest value the run logged.
"""

from __future__ import annotations

from typing import Final

import numpy as np

PLOT_PAD: Final = 0.08
"""Share of a plot's height left empty above and below its lines: a settling arch's supports (vx, vy = 0 and
vy = -0.01 m/s) drew lines on the plot's top and bottom edges, the viewer's fit to the data."""
LEGEND_ROW_SHARE: Final = 0.1
"""Share of a plot's height one legend row takes at 1920 x 1080 (~23 of the ~240 px of the support plots), kept
free of lines under them: the legend (bottom left) hid the start of a settling foundation's vy line."""


def plot_range(low: float, high: float, rows: int, *, with_zero: bool = True) -> tuple[float, float] | None:
    """A plot's y range for values from ``low`` to ``high`` (and 0 unless ``with_zero`` is False) and ``rows``
    series in its legend: PLOT_PAD above and below the lines, and under them room for the legend (its rows,
    at most 60 % of the plot). None when the values span nothing (a still support: the viewer's fit)."""
    if with_zero:
        low, high = min(low, 0.0), max(high, 0.0)
    if not np.isfinite(low) or not np.isfinite(high) or high - low <= 0.0:
        return None
    legend = min(0.6, LEGEND_ROW_SHARE * rows)
    height = (high - low) / (1.0 - 2.0 * PLOT_PAD - legend)
    return low - (PLOT_PAD + legend) * height, high + PLOT_PAD * height
