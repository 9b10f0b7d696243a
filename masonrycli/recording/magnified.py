"""The magnified deformed shape: every block (and support) at x0 + m (x − x0), rotated by m θ.

Logged when the recorder closes: the default factor m (``masonrycli.joint_forces.magnification``) needs
the largest displacement of the run. Only outlines (line strips), the initial frame (t = 0), every
``MAGNIFIED_EVERY``-th computed frame and the last: the mechanism reads as well at half the frame rate, for
half the bytes.
"""

from __future__ import annotations

from typing import Final

import numpy as np
import pyarrow as pa
import rerun as rr

from masonrycli.joint_forces import magnification
from masonrycli.recording.arrays import FrameBatch, Polygons, partition_lengths, time_indexes
from masonrycli.recording.layout import MAGNIFIED

MAGNIFIED_EVERY: Final = 2


def send_magnified(
    rec: rr.RecordingStream,
    blocks: Polygons,
    supports: Polygons,
    poses: list[tuple[int, float, np.ndarray, np.ndarray]],
    ref: tuple[np.ndarray, np.ndarray],
    magnify: float | None,
    size: float,
    batch_frames: int,
) -> float:
    """Send the magnified outlines of ``poses`` (step, time, block_q, support_q per frame) about ``ref``
    (the first block_q, support_q); returns the factor used (``magnify``, or the default for ``size`` m)."""
    ref_q, ref_sq = ref
    # the initial pose (step 0, as built), then every other computed frame as before it was recorded
    initial = 1 if len(poses) > 1 and poses[0][0] == 0 else 0
    poses = poses[:initial] + poses[initial:-1][::MAGNIFIED_EVERY] + poses[-1:]
    q = np.stack([p[2] for p in poses]).astype(np.float64)
    sq = np.stack([p[3] for p in poses]).astype(np.float64)
    m = magnification(q[..., :2] - ref_q[None, :, :2], size) if magnify is None else float(magnify)
    for start in range(0, len(q), batch_frames):
        part = slice(start, start + batch_frames)
        batch = FrameBatch(step=[p[0] for p in poses[part]], time=[p[1] for p in poses[part]])
        n_frames = len(batch["step"])
        sets = [blocks.outlines(blocks.world(ref_q + m * (q[part] - ref_q)))]
        count = blocks.count
        if supports.count:
            sets.append(supports.outlines(supports.world(ref_sq + m * (sq[part] - ref_sq))))
            count += supports.count
        # frame by frame: that frame's blocks, then its supports
        strips = [arr.slice(k * (len(arr) // n_frames), len(arr) // n_frames) for k in range(n_frames) for arr in sets]
        rec.send_columns(
            MAGNIFIED,
            indexes=time_indexes(batch),
            columns=rr.LineStrips2D.columns(strips=pa.concat_arrays(strips)).partition(
                partition_lengths(n_frames, count)
            ),
        )
    return m
