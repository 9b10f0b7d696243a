"""Colour scales (numpy only): 256-entry lookup tables, scalar → packed RGBA, range rounding, labels.

Rerun has no colormap for geometry, so block fills are coloured here. Colours are packed ``uint32``
``0xRRGGBBAA`` (what Rerun's ``Rgba32`` takes without conversion).

- ``VIRIDIS`` (sequential) for fields that are >= 0 (deviatoric parts);
- ``COOLWARM`` (diverging, blue < 0 < red, light grey at 0) for signed fields (compression is
  negative, so compression is blue);
- ``BLUES`` (sequential, dark blue at the most negative end, near white at 0) for fields that are
  <= 0 (the spherical stress p: compression is blue, as on the diverging map);
- ``NAN_RGBA`` (mid grey) for a value that is NaN (a block with no triangle, no contact...);
- ``UNDER_RGBA`` (magenta) and ``OVER_RGBA`` (lime green) for values beyond the range's low / high end:
  colours far from every map's (CIE76 ΔE >= 45 from every entry of the three maps and the NaN grey), so one
  rule serves all fields and an out-of-range cell never passes for an end-of-range one. They were black and
  white: white is ΔE 3 from the top of ``BLUES`` (p = 0), so on the spherical-stress scale "above the range"
  read as "0 kPa". Not black (the compression glyphs are near black) nor the tension glyphs' darker magenta
  for "above" (a cell above the p range is in tension, where those glyphs are drawn).
"""

from __future__ import annotations

import math
from typing import Final

import numpy as np

LUT_SIZE: Final = 256

# Control points (position in [0, 1], R, G, B), interpolated linearly in RGB.
_VIRIDIS_STOPS: Final = (
    (0.000, 68, 1, 84),
    (0.125, 71, 44, 122),
    (0.250, 59, 82, 139),
    (0.375, 44, 114, 142),
    (0.500, 33, 145, 140),
    (0.625, 40, 174, 128),
    (0.750, 94, 201, 98),
    (0.875, 170, 220, 50),
    (1.000, 253, 231, 37),
)
_COOLWARM_STOPS: Final = (
    (0.000, 59, 76, 192),
    (0.250, 124, 159, 249),
    (0.500, 221, 221, 221),
    (0.750, 244, 154, 123),
    (1.000, 180, 4, 38),
)


_BLUES_STOPS: Final = (  # ColorBrewer "Blues", dark end first
    (0.000, 8, 48, 107),
    (0.250, 33, 113, 181),
    (0.500, 107, 174, 214),
    (0.750, 198, 219, 239),
    (1.000, 247, 251, 255),
)


def pack_rgba(rgb: np.ndarray, alpha: int = 255) -> np.ndarray:
    """(..., 3) uint8-range RGB -> (...,) uint32 packed 0xRRGGBBAA."""
    c = np.asarray(rgb, dtype=np.uint32)
    return (c[..., 0] << 24) | (c[..., 1] << 16) | (c[..., 2] << 8) | np.uint32(alpha)


def unpack_rgba(packed: np.ndarray) -> np.ndarray:
    """(...,) uint32 0xRRGGBBAA -> (..., 4) uint8 RGBA."""
    p = np.asarray(packed, dtype=np.uint32)
    return np.stack([(p >> s) & 0xFF for s in (24, 16, 8, 0)], axis=-1).astype(np.uint8)


def make_lut(stops: tuple[tuple[float, int, int, int], ...], size: int = LUT_SIZE) -> np.ndarray:
    """(size, 3) uint8 table interpolated linearly between the control points."""
    pos = np.array([s[0] for s in stops])
    rgb = np.array([s[1:] for s in stops], dtype=np.float64)
    x = np.linspace(0.0, 1.0, size)
    return np.round(np.stack([np.interp(x, pos, rgb[:, k]) for k in range(3)], axis=1)).astype(np.uint8)


def _shared(lut: np.ndarray) -> np.ndarray:
    # every field and recording maps through the same table: a write into it would recolour them all
    lut.setflags(write=False)
    return lut


VIRIDIS: Final = _shared(pack_rgba(make_lut(_VIRIDIS_STOPS)))
"""(256,) uint32: sequential, dark purple (low) to yellow (high)."""
COOLWARM: Final = _shared(pack_rgba(make_lut(_COOLWARM_STOPS)))
"""(256,) uint32: diverging, blue (low) - light grey (middle) - red (high)."""
BLUES: Final = _shared(pack_rgba(make_lut(_BLUES_STOPS)))
"""(256,) uint32: sequential, dark blue (low, most negative) to near white (high, zero)."""
NAN_RGBA: Final = int(pack_rgba(np.array([128, 128, 128])))
UNDER_RGBA: Final = int(pack_rgba(np.array([255, 0, 255])))
OVER_RGBA: Final = int(pack_rgba(np.array([0, 255, 0])))


def map_scalars(values: np.ndarray, lo: float, hi: float, lut: np.ndarray, nan_rgba: int = NAN_RGBA) -> np.ndarray:
    """Colours of ``values`` (any shape) on ``[lo, hi]`` (clipped): same shape, uint32 packed.

    ``lo`` maps to ``lut[0]``, ``hi`` to ``lut[-1]``; NaN maps to ``nan_rgba``.
    """
    v = np.asarray(values, dtype=np.float64)
    span = hi - lo if hi > lo else 1.0
    t = (v - lo) * ((len(lut) - 1) / span)
    finite = np.isfinite(t)
    idx = np.clip(np.where(finite, t, 0.0), 0, len(lut) - 1)
    out = lut[np.rint(idx).astype(np.intp)]
    if not finite.all():
        out = np.where(finite, out, np.uint32(nan_rgba))
    return out


def map_positions(position: np.ndarray, lut: np.ndarray) -> np.ndarray:
    """Colours of colour-map positions (0 = ``lut[0]`` … 1 = ``lut[-1]``, e.g. ``ColourRange.position``):
    ``UNDER_RGBA`` below 0, ``OVER_RGBA`` above 1, ``NAN_RGBA`` for NaN; same shape, uint32 packed."""
    t = np.asarray(position, dtype=np.float64)
    finite = np.isfinite(t)
    idx = np.rint(np.clip(np.where(finite, t, 0.0), 0.0, 1.0) * (len(lut) - 1)).astype(np.intp)
    out = lut[idx]
    out = np.where(finite & (t < 0.0), np.uint32(UNDER_RGBA), out)
    out = np.where(finite & (t > 1.0), np.uint32(OVER_RGBA), out)
    return np.where(finite, out, np.uint32(NAN_RGBA))


def robust_max_abs(values: np.ndarray, percentile: float = 99.0) -> float:
    """``percentile`` of |values| over the finite entries (0.0 when there are none)."""
    a = np.abs(np.asarray(values, dtype=np.float64).ravel())
    a = a[np.isfinite(a)]
    if a.size == 0:
        return 0.0
    return float(np.percentile(a, percentile))


def nice_ceil(x: float) -> float:
    """Smallest of (1, 1.5, 2, 2.5, 3, 4, 5, 6, 8) × 10^k that is >= x > 0; 0.0 for x <= 0 or not finite."""
    if not (x > 0.0 and math.isfinite(x)):
        return 0.0
    e = math.floor(math.log10(x))
    for m in (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0):
        v = m * 10.0**e
        if v >= x * (1.0 - 1e-12):
            return v
    return 10.0 ** (e + 1)


def tick_label(value: float, unit: str, span: float, signed: bool) -> str:
    """Legend label: 3 significant digits, explicit sign on a signed scale, Pa with a prefix from ``span``."""
    scale, prefix = 1.0, ""
    if unit == "Pa":
        prefixes = ((1e9, "G"), (1e6, "M"), (1e3, "k"))
        scale, prefix = next(((s, p) for s, p in prefixes if span >= s), (1.0, ""))
    x = value / scale
    text = f"{x:+.3g}" if signed and x != 0 else f"{x:.3g}"
    return f"{text} {prefix}{unit}".strip()


def colorbar_mesh(box: tuple[float, float, float, float], lut: np.ndarray, segments: int = 32):
    """A vertical colour bar filling ``box`` = (x0, y0, x1, y1), ``lut[0]`` at the bottom.

    Returns vertices (2 (segments+1), 2), triangles (2 segments, 3) uint32 and per-vertex colours.
    """
    x0, y0, x1, y1 = box
    verts = np.zeros((segments + 1, 2, 2))
    verts[:, :, 0] = x0, x1
    verts[:, :, 1] = np.linspace(y0, y1, segments + 1)[:, None]
    colors = np.repeat(lut[np.rint(np.linspace(0, len(lut) - 1, segments + 1)).astype(int)], 2)
    j = 2 * np.arange(segments)
    tri = np.concatenate([np.stack([j, j + 1, j + 3], 1), np.stack([j, j + 3, j + 2], 1)]).astype(np.uint32)
    return verts.reshape(-1, 2), tri, colors
