"""masonrycli.recording.colormap: lookup tables, NaN colour, nice ceilings and robust maxima."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.recording import colormap as cm


def test_colormap_lookup():
    lut = cm.VIRIDIS
    assert len(lut) == 256 and lut.dtype == np.uint32
    colors = cm.map_scalars(np.array([-1.0, 0.0, 0.5, 1.0, 2.0, np.nan]), 0.0, 1.0, lut)
    assert list(colors[[0, 1, 3, 4]]) == [lut[0], lut[0], lut[-1], lut[-1]]
    assert colors[2] in (lut[127], lut[128]) and colors[5] == cm.NAN_RGBA
    np.testing.assert_array_equal(cm.unpack_rgba(cm.COOLWARM[[0, -1]])[:, :3], [[59, 76, 192], [180, 4, 38]])
    assert cm.unpack_rgba(cm.COOLWARM[128])[0] == pytest.approx(221, abs=2)  # light grey at zero


@pytest.mark.parametrize("name", ["VIRIDIS", "COOLWARM", "BLUES"])
def test_shared_tables_cannot_be_written(name):
    # one table colours every field of every recording: a caller's write would recolour the others
    lut = getattr(cm, name)
    with pytest.raises(ValueError, match="read-only"):
        lut[0] = 0


def test_nice_ceil_and_robust_max():
    values = (0.0, 0.9, 1.0, 1.2, 2.7, 7.0, 1.1e5)
    assert [cm.nice_ceil(x) for x in values] == [0.0, 1.0, 1.0, 1.5, 3.0, 8.0, 1.5e5]
    assert cm.robust_max_abs(np.array([np.nan, -3.0, 1.0]), 100) == 3.0
    assert cm.robust_max_abs(np.array([np.nan])) == 0.0


def cie_lab(rgb: np.ndarray) -> np.ndarray:
    """(..., 3) sRGB 0-255 -> CIE L*a*b* (D65), the textbook formulas."""
    c = np.asarray(rgb, dtype=np.float64) / 255.0
    c = np.where(c > 0.04045, ((c + 0.055) / 1.055) ** 2.4, c / 12.92)
    m = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]])
    xyz = c @ m.T / np.array([0.95047, 1.0, 1.08883])
    f = np.where(xyz > 0.008856, np.cbrt(xyz), 7.787 * xyz + 16.0 / 116.0)
    return np.stack([116.0 * f[..., 1] - 16.0, 500.0 * (f[..., 0] - f[..., 1]), 200.0 * (f[..., 1] - f[..., 2])], -1)


def min_distances(colour: int, scale: np.ndarray) -> tuple[float, float]:
    """Smallest CIE76 ΔE and RGB distance from packed ``colour`` to any packed colour of ``scale``."""
    a, b = cm.unpack_rgba(np.array([colour]))[:, :3], cm.unpack_rgba(scale)[:, :3]
    delta_e = np.linalg.norm(cie_lab(b) - cie_lab(a), axis=1).min()
    return float(delta_e), float(np.linalg.norm(b.astype(float) - a, axis=1).min())


def test_out_of_range_colours_are_on_no_scale():
    """Below / above the range must not pass for a colour of any field's scale (white above the range was
    ΔE 3 from the top of the spherical-stress scale, 0 kPa), nor for NaN grey, nor for each other."""
    every_scale = np.concatenate([cm.VIRIDIS, cm.COOLWARM, cm.BLUES, [cm.NAN_RGBA]]).astype(np.uint32)
    for colour in (cm.UNDER_RGBA, cm.OVER_RGBA):
        delta_e, rgb = min_distances(colour, every_scale)
        assert delta_e > 40.0 and rgb > 100.0, (hex(colour), delta_e, rgb)
    assert min_distances(cm.UNDER_RGBA, np.array([cm.OVER_RGBA], np.uint32))[0] > 40.0
