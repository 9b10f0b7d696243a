"""The lengths fixed once per run so they compare across time: the joint resultants' scale (m per N) and the
principal-axis glyphs' scales (field unit per glyph half-length).

The joint-resultant scale draws the 95th percentile resultant of the first frame with a loaded joint
``RESULTANT_LENGTH`` block heights long; each glyph scale is the (nice-rounded) 98th percentile of |λ| of
the first batch with data. The colour ranges are not among them: they follow the data
(``colour_range.RangeTracker``).
"""

from __future__ import annotations

import numpy as np

from masonrycli.recording.arrays import FrameBatch
from masonrycli.recording.colormap import nice_ceil, robust_max_abs
from masonrycli.recording.layout import AXES, RESULTANT_LENGTH, RESULTANT_PERCENTILE, ROBUST_PERCENTILE


def fix_scales(
    force_scale: float | None,
    axis_scale: dict[str, float],
    tensors: dict[str, np.ndarray],
    b: FrameBatch,
    block_height: float,
) -> tuple[float | None, bool]:
    """Fix the scales not fixed yet from batch ``b`` (its ``tensors``) if it has data: ``axis_scale`` is
    completed in place; returns the force scale (m per N, None while no joint was loaded) and whether any
    scale was fixed now."""
    fixed = False
    if force_scale is None:
        forces, lengths = b.concat("joint_force", (0, 2))
        loaded = np.nonzero(lengths)[0]
        if loaded.size:  # the first frame with a loaded joint
            start = int(lengths[: loaded[0]].sum())
            first = forces[start : start + lengths[loaded[0]]]
            m = nice_ceil(float(np.percentile(np.hypot(first[:, 0], first[:, 1]), RESULTANT_PERCENTILE)))
            if m > 0.0:
                force_scale, fixed = RESULTANT_LENGTH * block_height / m, True
    for name, (values_key, _) in AXES.items():
        m = nice_ceil(robust_max_abs(tensors[values_key], ROBUST_PERCENTILE))
        if name not in axis_scale and m > 0.0:
            axis_scale[name], fixed = m, True
    return force_scale, fixed
