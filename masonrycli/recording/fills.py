"""What fills the drawing per batch: the blocks' mesh with one colour component per field, each field's
legend labels and colour range, the hover points and their values; the supports' fill and outlines."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import rerun as rr

from masonrycli.recording.arrays import Polygons, partition_lengths, z0
from masonrycli.recording.field_colours import FieldColours
from masonrycli.recording.layout import BLOCKS, COLOURED, FILL, HOVER_VALUES, SUPPORT_FILL, SUPPORT_OUTLINES
from masonrycli.recording.static_content import TICKS


def send_blocks(
    rec: rr.RecordingStream,
    idx: list,
    fill: Polygons,
    owner: np.ndarray,
    colours: FieldColours,
    label_anchors: np.ndarray,
    q: np.ndarray,
    tensors: dict[str, np.ndarray],
    initial: int = 0,
    at: np.ndarray | None = None,
    times: np.ndarray | None = None,
) -> None:
    """The fill (positions once, a colour component per field), legends, hover points and values of the
    frames ``q`` (F, N, 3); ``owner``: the block of each fill vertex; the ``initial`` first frames (the
    state as built) take the colour range of the frame after them; ``at`` (F, N, 2): the hover points (the
    blocks' own centroids; default their poses); ``times`` (F,) s: each frame's instant, in its colour bars'
    titles."""
    n_frames, n_blocks = len(q), q.shape[1]
    verts = fill.world(q)  # (F, V, 2)
    n_vert = verts.shape[1]
    per_vertex, per_block = partition_lengths(n_frames, n_vert), partition_lengths(n_frames, n_blocks)
    columns = [*rr.Mesh3D.columns(vertex_positions=z0(verts)).partition(per_vertex)]
    hover = [
        *rr.Points2D.columns(positions=(q[..., :2] if at is None else at).reshape(-1, 2).astype(np.float32)).partition(
            per_block
        )
    ]
    for f in COLOURED:  # the fields first: a square-root view takes its linear twin's ranges
        colors, labels, lo, hi = colours.colour(f, tensors[f.key], initial, times)
        archetype = f.colors.removesuffix(":colors")
        columns += rr.DynamicArchetype.columns(
            archetype, components={"colors": rr.components.ColorBatch(colors[:, owner].reshape(-1))}
        ).partition(per_vertex)
        # no point for an empty count ("0 below" is left out): an empty label still drew its box
        shown = np.array(labels, dtype=object).astype(bool).reshape(n_frames, TICKS + 3)
        rec.send_columns(
            f.labels,
            indexes=idx,
            columns=[
                # positions with the labels at every frame: a view pinned to an instant reads a time
                # range, which joins no static positions to temporal labels
                *rr.Points2D.columns(
                    positions=np.tile(label_anchors, (n_frames, 1))[shown.reshape(-1)],
                    labels=pa.array(labels, type=pa.utf8()).filter(shown.reshape(-1)),  # not a list: 2x faster
                ).partition(shown.sum(axis=1)),
                *rr.AnyValues.columns(range_lo=pa.array(lo), range_hi=pa.array(hi)),
            ],
        )
    rec.send_columns(FILL, indexes=idx, columns=columns)
    # pyarrow arrays: AnyValues.columns turns 1-D numpy arrays into Python lists of lists (slow).
    values = {
        name: pa.array(tensors[key].reshape(-1).astype(np.float32), type=pa.float32())
        for name, key in HOVER_VALUES.items()
    }
    rec.send_columns(BLOCKS, indexes=idx, columns=[*hover, *rr.AnyValues.columns(**values).partition(per_block)])


def send_supports(rec: rr.RecordingStream, idx: list, supports: Polygons, support_q: np.ndarray) -> None:
    """The supports' fill and outlines at the poses ``support_q`` (F, S, 3); nothing without a support."""
    n_frames = len(support_q)
    if supports.count:
        verts = supports.world(support_q)
        rec.send_columns(
            SUPPORT_FILL,
            indexes=idx,
            columns=rr.Mesh3D.columns(vertex_positions=z0(verts)).partition(
                partition_lengths(n_frames, verts.shape[1])
            ),
        )
        rec.send_columns(
            SUPPORT_OUTLINES,
            indexes=idx,
            columns=rr.LineStrips2D.columns(strips=supports.outlines(verts)).partition(
                partition_lengths(n_frames, supports.count)
            ),
        )
