"""Arrays for ``send_columns``: CSR polygons posed per frame, ragged line strips as Arrow, the frame buffer.

Everything done per frame works on whole batches of frames at once (no Python loop over frames or
blocks); only :class:`Polygons`' index arrays are built with one loop over the polygons, once per
recording.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import rerun as rr

from masonrycli.recording._rerun_private import STRIP_TYPE, VEC2_TYPE


class Polygons:
    """Index arrays of a CSR polygon set: owner of each vertex, fan triangles, closed outlines."""

    def __init__(self, start: np.ndarray, local: np.ndarray) -> None:
        start = np.asarray(start, dtype=np.int64)
        self.local = np.asarray(local, dtype=np.float64).reshape(-1, 2)
        self.count = len(start) - 1
        n_vert = np.diff(start)
        self.owner = np.repeat(np.arange(self.count), n_vert)
        # Fan of each convex polygon: (s, s+k, s+k+1), k = 1 .. n-2.
        fans = [
            np.stack([np.full(n - 2, s), s + np.arange(1, n - 1), s + np.arange(2, n)], axis=1)
            for s, n in zip(start[:-1], n_vert)
        ]
        self.fan = np.concatenate(fans or [np.zeros((0, 3))]).astype(np.uint32)
        # Closed outline: the polygon's vertices, then its first vertex again.
        self.outline_index = np.concatenate(
            [np.r_[s : s + n, s] for s, n in zip(start[:-1], n_vert)] or [np.zeros(0)]
        ).astype(np.intp)
        self.outline_offsets = np.r_[0, np.cumsum(n_vert + 1)].astype(np.int32)

    def world(self, q: np.ndarray) -> np.ndarray:
        """(F, P, 3) poses -> (F, V, 2) world vertices x_b + R(θ_b) local."""
        # cos and sin once per polygon, then spread to its vertices (the same values, a quarter of the calls)
        c, s = np.cos(q[..., 2])[:, self.owner], np.sin(q[..., 2])[:, self.owner]
        x, y = q[..., 0][:, self.owner], q[..., 1][:, self.owner]
        lx, ly = self.local[:, 0], self.local[:, 1]
        return np.stack([x + c * lx - s * ly, y + s * lx + c * ly], axis=-1)

    def outlines(self, verts: np.ndarray) -> pa.Array:
        """(F, V, 2) world vertices -> F × count closed strips, one Arrow array."""
        n_frames, total = len(verts), len(self.outline_index)
        shift = (np.arange(n_frames, dtype=np.int64) * total)[:, None]
        offsets = np.r_[(self.outline_offsets[:-1][None, :] + shift).ravel(), n_frames * total]
        return strips(verts[:, self.outline_index].reshape(-1, 2), offsets)


def own_centroids(start: np.ndarray, local: np.ndarray) -> np.ndarray:
    """(N, 2) m: each polygon's own area centroid relative to its pose, which is a block's body centre and so
    not its centroid when it carries a fill (the fill's mass pulls it up). Exact 0 below 1 nm: a block that
    carries nothing keeps its recording as it was."""
    start = np.asarray(start, dtype=np.int64)
    owner = np.repeat(np.arange(len(start) - 1), np.diff(start))
    nxt = np.arange(len(local)) + 1
    nxt[start[1:] - 1] = start[:-1]  # each polygon's last vertex wraps to its first
    (x0, y0), (x1, y1) = np.asarray(local, np.float64).T, np.asarray(local, np.float64)[nxt].T
    cross = x0 * y1 - x1 * y0  # shoelace: A = Σ cross / 2, C = Σ (p + p') cross / (6 A)
    area = np.bincount(owner, cross, len(start) - 1) / 2.0
    sums = np.stack(
        [np.bincount(owner, (x0 + x1) * cross, len(area)), np.bincount(owner, (y0 + y1) * cross, len(area))]
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        centre = np.nan_to_num((sums / (6.0 * area)).T)
    centre[np.hypot(*centre.T) < 1e-9] = 0.0
    return centre


def posed_points(q: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """(F, N, 3) poses and (N, 2) points fixed to the bodies -> (F, N, 2) the points, m."""
    c, s = np.cos(q[..., 2]), np.sin(q[..., 2])
    return np.stack(
        [q[..., 0] + c * offset[:, 0] - s * offset[:, 1], q[..., 1] + s * offset[:, 0] + c * offset[:, 1]], -1
    )


def strips(points: np.ndarray, offsets: np.ndarray) -> pa.Array:
    """Ragged line strips as one Arrow array (the SDK would loop in Python): points (P, 2), offsets (n+1,)."""
    flat = pa.array(np.ascontiguousarray(points, dtype=np.float32).reshape(-1))
    values = pa.FixedSizeListArray.from_arrays(flat, type=VEC2_TYPE)
    return pa.ListArray.from_arrays(pa.array(offsets, type=pa.int32()), values, type=STRIP_TYPE)


def uniform_strips(points: np.ndarray) -> pa.Array:
    """(M, k, 2): M strips of k points."""
    return strips(points.reshape(-1, 2), np.arange(len(points) + 1, dtype=np.int32) * points.shape[1])


def z0(verts: np.ndarray) -> np.ndarray:
    """(..., 2) -> (n, 3) float32 with z = 0."""
    return np.pad(np.asarray(verts, dtype=np.float32).reshape(-1, 2), ((0, 0), (0, 1)))


partition_lengths = np.full  # (n_frames, instances per frame) -> partition lengths


class FrameBatch(dict):
    """name -> list of per-frame arrays since the last flush (a frame's own arrays: sinks.FrameSink)."""

    def add(self, name: str, value) -> None:
        self.setdefault(name, []).append(value)

    def stack(self, name: str) -> np.ndarray:
        return np.stack(self[name])

    def concat(self, name: str, empty_shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        """Ragged per-frame arrays -> (all rows, rows per frame)."""
        lengths = np.array([len(p) for p in self[name]], dtype=np.int64)
        return (np.concatenate(self[name]) if lengths.sum() else np.zeros(empty_shape)), lengths


def time_indexes(b: FrameBatch) -> list:
    """The ``step`` and ``sim_time`` columns of a batch (its "step" and "time" lists)."""
    return [
        rr.TimeColumn("step", sequence=np.asarray(b["step"], dtype=np.int64)),
        rr.TimeColumn("sim_time", duration=np.asarray(b["time"], dtype=np.float64)),
    ]
