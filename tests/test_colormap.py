"""masonrycli.colormap: lookup tables, NaN colour, nice ceilings and robust maxima."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli import colormap as cm


def test_colormap_lookup():
    lut = cm.VIRIDIS
    assert len(lut) == 256 and lut.dtype == np.uint32
    colors = cm.map_scalars(np.array([-1.0, 0.0, 0.5, 1.0, 2.0, np.nan]), 0.0, 1.0, lut)
    assert list(colors[[0, 1, 3, 4]]) == [lut[0], lut[0], lut[-1], lut[-1]]
    assert colors[2] in (lut[127], lut[128]) and colors[5] == cm.NAN_RGBA
    np.testing.assert_array_equal(cm.unpack_rgba(cm.COOLWARM[[0, -1]])[:, :3], [[59, 76, 192], [180, 4, 38]])
    assert cm.unpack_rgba(cm.COOLWARM[128])[0] == pytest.approx(221, abs=2)  # light grey at zero


def test_nice_ceil_and_robust_max():
    values = (0.0, 0.9, 1.0, 1.2, 2.7, 7.0, 1.1e5)
    assert [cm.nice_ceil(x) for x in values] == [0.0, 1.0, 1.0, 1.5, 3.0, 8.0, 1.5e5]
    assert cm.robust_max_abs(np.array([np.nan, -3.0, 1.0]), 100) == 3.0
    assert cm.robust_max_abs(np.array([np.nan])) == 0.0
