"""The magnified deformed shape: every block (and support) at x0 + m (x − x0), rotated by m θ; when every
support moves by one translation g (a shaken ground, both foundations shaken alike) the blocks' displacement
relative to it is magnified instead, on the ground where it is: x0 + g + m (x − x0 − g), supports at x0 + g.
The shaken wall's view magnified the ground's rigid travel: ``masonry simulate wall --amp 0.3 --duration 0.5``
(the ground travels 4.8 cm) was drawn × 2.5, wall and ground sliding 12 cm to and fro, its own largest
displacement (0.036 mm, the summary's, relative to the ground) not seen; now × 3000. The same reference as the
summary's "largest block displacement" and masonrycli.analysis.collapse.

Logged when the recorder closes: the default factor m (``masonrycli.analysis.joint_forces.magnification``) needs
the largest displacement of the run. Only outlines (line strips), the initial frame (t = 0), every
``MAGNIFIED_EVERY``-th computed frame and the last: the mechanism reads as well at half the frame rate, for
half the bytes.

Until then the poses wait on disk (:class:`PoseSpool`), not in memory: a run of a million frames would
otherwise hold them all (~0.8 kB a frame for the 51-block wall) until it ends. They wait as displacements from
the first frame, taken in float64 and only then rounded to float32: rounding the poses themselves cost each
coordinate up to half a float32 step of its size (0.24 µm at 4 m), which × 600 put the bridge's Magnified
tab 0.12 mm off its as-built outline at step 0. A displacement's rounding is relative to the displacement
(6e-8 of it), and the first frame's is exactly 0: the magnified shape starts on the outline as built.
"""

from __future__ import annotations

import os
import tempfile
from typing import Final

import numpy as np
import pyarrow as pa
import rerun as rr

from masonrycli.analysis.joint_forces import magnification
from masonrycli.recording.arrays import FrameBatch, Polygons, partition_lengths, time_indexes
from masonrycli.recording.layout import MAGNIFIED, MAGNIFIED_FILL

MAGNIFIED_EVERY: Final = 2


class PoseSpool:
    """Every frame's (step, time, block_q − block_q0, support_q − support_q0), float32 displacements from the
    first frame's poses (module doc; taken in float64 by the caller), appended to an anonymous temporary file
    in ``folder`` (the output's: the same disk): ``tempfile.TemporaryFile`` has no name on Linux (O_TMPFILE;
    elsewhere it is unlinked at once or on close), so nothing is left behind whatever ends the process —
    close, Ctrl-C, SIGTERM or SIGKILL. RAM held: the file object's write buffer, whatever the frame count."""

    def __init__(self, folder: str, n_blocks: int, n_supports: int) -> None:
        self.dtype = np.dtype(
            [("step", "<i8"), ("time", "<f8"), ("q", "<f4", (n_blocks, 3)), ("sq", "<f4", (n_supports, 3))]
        )
        self.count = 0
        self._file = tempfile.TemporaryFile(dir=folder, prefix=".masonry-poses-")

    def append(self, step: int, time_s: float, q: np.ndarray, sq: np.ndarray) -> None:
        """``q``, ``sq``: the displacements (float64) from the first frame's poses."""
        row = np.empty((), self.dtype)
        row["step"], row["time"], row["q"], row["sq"] = step, time_s, q, sq
        self._file.write(row.tobytes())
        self.count += 1

    def read(self, first: int, stop: int) -> np.ndarray:
        """Rows ``first`` to ``stop`` (excluded), a structured array in memory."""
        self._file.flush()
        size = self.dtype.itemsize
        data = os.pread(self._file.fileno(), (stop - first) * size, first * size)
        return np.frombuffer(data, self.dtype)

    def close(self) -> None:
        self._file.close()


def selected(count: int, first_step: int) -> tuple[int, int]:
    """(initial, n_mid) of the frames drawn among ``count``: the initial pose (step 0, as built) if it opens
    the run and is not its only frame, every ``MAGNIFIED_EVERY``-th computed frame before the last, the last."""
    initial = 1 if count > 1 and first_step == 0 else 0
    return initial, len(range(initial, count - 1, MAGNIFIED_EVERY))


def _chunks(spool: PoseSpool, batch_frames: int):
    """The drawn frames of ``spool``, ``batch_frames`` at a time, each chunk read from disk on its own."""
    n = spool.count
    if n == 0:
        return
    initial, n_mid = selected(n, int(spool.read(0, 1)["step"][0]))
    total = initial + n_mid + 1
    for start in range(0, total, batch_frames):
        k = np.arange(start, min(start + batch_frames, total))
        rows = np.where(k < initial, k, np.where(k < initial + n_mid, initial + MAGNIFIED_EVERY * (k - initial), n - 1))
        lo = int(rows[0])
        yield spool.read(lo, int(rows[-1]) + 1)[rows - lo]


def send_magnified(
    rec: rr.RecordingStream,
    blocks: Polygons,
    supports: Polygons,
    poses: PoseSpool,
    ref: tuple[np.ndarray, np.ndarray],
    magnify: float | None,
    size: float,
    batch_frames: int,
    fill=None,
) -> tuple[float, np.ndarray]:
    """Send the magnified outlines of the frames in ``poses`` (displacements) about ``ref`` (the first block_q,
    support_q);
    returns the factor used (``magnify``, or the default for ``size`` m) and the extent drawn (xmin, ymin,
    xmax, ymax), m: the blocks' above the supports' lowest point (one fallen below it is left out), the supports' in y only (a wide ground is shown only a little beyond the
    blocks: ``static_content.log_plane``), for the view to hold it (the arch's right foundation, settled
    1 cm in 1 s and drawn x 25, touched the view's bottom edge). ``fill``: a bridge's ``CarriedFill``, its columns'
    outlines posed on the magnified blocks."""
    ref_q, ref_sq = ref
    rigid = _supports_move_together(poses, ref_sq, size, batch_frames)
    if magnify is None:  # one pass over the file: the displacement of largest norm, as a (1, 2) array
        largest, norm2 = np.zeros((0, 2)), -1.0
        for chunk in _chunks(poses, batch_frames):
            g = _ground_shift(chunk, rigid)
            d = (chunk["q"].astype(np.float64)[..., :2] - g[:, None, :2]).reshape(-1, 2)
            if d.size and (d2 := (d**2).sum(axis=1)).max() > norm2:  # sqrt is monotonic: the same maximum
                k = int(np.argmax(d2))
                largest, norm2 = d[k : k + 1], float(d2[k])
        m = magnification(largest, size)
    else:
        m = float(magnify)
    extent = np.array([np.inf, np.inf, -np.inf, -np.inf])
    for chunk in _chunks(poses, batch_frames):
        dq, dsq = chunk["q"].astype(np.float64), chunk["sq"].astype(np.float64)  # displacements
        batch = FrameBatch(step=chunk["step"].tolist(), time=chunk["time"].tolist())
        n_frames = len(chunk)
        back = (m - 1.0) * _ground_shift(chunk, rigid)[:, None, :]  # the ground's travel, not magnified
        magnified = ref_q + (m * dq - back)  # step 0: ref_q + 0, the outline as built to the bit
        verts = blocks.world(magnified)
        if fill is not None:
            fill.send_outlines(rec, time_indexes(batch), magnified, MAGNIFIED_FILL)
        sets = [blocks.outlines(verts)]
        count, held = blocks.count, verts.reshape(-1, 2)
        if supports.count:
            sverts = supports.world(ref_sq + (m * dsq - back))
            sets.append(supports.outlines(sverts))
            extent[1], extent[3] = (
                min(extent[1], float(sverts[..., 1].min())),
                max(extent[3], float(sverts[..., 1].max())),
            )
            count += supports.count
            # a block fallen off its supports (below the lowest one's bottom, in free fall) is not held in the
            # view: a wall whose end blocks fell off its shaken ground ('masonry simulate wall --amp 3 --freq
            # 0.8 --duration 3') was framed down to their last pose, metres under the ground, the structure
            # and its colour bar squeezed into the top third of the panel
            held = verts[verts[..., 1] >= sverts[..., 1].min(axis=1)[:, None]]
        if held.size:
            lo, hi = held.min(axis=0), held.max(axis=0)
            extent = np.r_[np.minimum(extent[:2], lo), np.maximum(extent[2:], hi)]
        # frame by frame: that frame's blocks, then its supports
        strips = [arr.slice(k * (len(arr) // n_frames), len(arr) // n_frames) for k in range(n_frames) for arr in sets]
        rec.send_columns(
            MAGNIFIED,
            indexes=time_indexes(batch),
            columns=rr.LineStrips2D.columns(strips=pa.concat_arrays(strips)).partition(
                partition_lengths(n_frames, count)
            ),
        )
    return m, extent


def _supports_move_together(poses: PoseSpool, ref_sq: np.ndarray, size: float, batch_frames: int) -> bool:
    """Whether every support moves by one translation at every drawn frame (a settling foundation beside a
    fixed one does not: the structure's displacement is then drawn as it is)."""
    if ref_sq.shape[0] == 0:
        return False
    atol = 1e-6 * max(1.0, size, float(np.abs(ref_sq[:, :2]).max()))  # as when the spool held float32 poses
    for chunk in _chunks(poses, batch_frames):
        d = chunk["sq"].astype(np.float64)[..., :2]  # displacements
        if not np.allclose(d, d[:, :1, :], rtol=0.0, atol=atol):
            return False
    return True


def _ground_shift(chunk: np.ndarray, rigid: bool) -> np.ndarray:
    """(frames, 3): the supports' common translation at each frame of ``chunk`` (x, y, 0), zeros unless ``rigid``."""
    shift = np.zeros((len(chunk), 3))
    if rigid:
        shift[:, :2] = chunk["sq"].astype(np.float64)[:, 0, :2]  # the first support's displacement
    return shift
