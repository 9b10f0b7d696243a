"""Coordinates exported in float32 (GIS / CAD files: ~7 significant digits): how far the rounding may have
moved them, and the end of a refusal or warning that says so.

A float32 keeps 24 bits, so a coordinate x is rounded by at most 2⁻²⁴ |x|: 6e-8 m at 1 m, 6e-5 m at 1000 m,
6e-4 m at 10 km — coarse against the shape tolerances of :mod:`geometry_library.checks` far from the origin
(a local map grid). Only files whose every coordinate is a float32 value, one at least with the long tail
of a rounded decimal, count as such exports.
"""

from __future__ import annotations

import numpy as np

FLOAT32_RTOL = 2.0**-24
"""A float32 value x is rounded by at most this × |x|."""


def float32_resolution(xy: np.ndarray) -> float | None:
    """How far float32 rounding may have moved these coordinates, m (2⁻²⁴ × the largest |coordinate|), if
    every one is a float32 value and one at least shows the rounding (a float32 export); None if not.

    Short decimals that float32 holds exactly (5000.5, 0.25) are what a user typed, nothing was rounded:
    1 × 0.5 m blocks drawn at x = 5000 m were told to "export them in float64". A decimal float32 cannot
    hold comes back with a long tail (1000.3 → 1000.2999877929688): at least one coordinate of a real
    export has more significant digits than a float32 export prints (9)."""
    xy = np.asarray(xy, dtype=np.float64)
    if not xy.size or not np.array_equal(xy.astype(np.float32).astype(np.float64), xy):
        return None
    if all(_significant_digits(v) <= FLOAT32_DIGITS for v in np.unique(xy)):
        return None
    return FLOAT32_RTOL * float(np.abs(xy).max())


FLOAT32_DIGITS = 9
"""Significant decimal digits that always round-trip a float32 (FLT_DECIMAL_DIG)."""


def _significant_digits(value: float) -> int:
    """Significant digits of the shortest decimal that gives ``value`` back (5000.5 → 5, 0.25 → 2)."""
    text = np.format_float_scientific(value, unique=True, trim="-")
    return len(text.split("e")[0].replace("-", "").replace(".", ""))


def float32_hint(xy: np.ndarray, h: float, whose: str = "its") -> str:
    """The end of a refusal when float32 rounding is a tenth of the tolerance ``h`` or more (else "")."""
    resolution = float32_resolution(xy)
    if resolution is None or resolution < 0.1 * h:
        return ""
    far = resolution / FLOAT32_RTOL
    return (
        f"; {whose} coordinates are float32 values, exact only to ±{resolution:.2g} m this far ({far:,.0f} m) from "
        "the origin: shift them near the origin or export them in float64"
    )
