"""The fill a bridge's blocks carry, drawn: each column of fill over its block, moving with it.

The fill is dead load only (``geometry_library.fill``): the engine and the limit analysis know it as a mass
riding on each block under it (``Block.carried_mass``). A view of the bare ring hid 421.6 kN/m of it, so
each column is drawn where its block carries it: a translucent sand mesh with a faint outline, placed by its
block's pose every frame (it is carried: when the ring deforms, its columns go with their voussoirs and may
overlap or part, as a fill with no strength of its own would not, which the legend says). The Magnified tab
outlines them on its magnified blocks (``magnified.send_magnified``): it showed the bare ring.

Columns arrive as plain arrays (``geometry_library.fill.FillColumns``: bottom points left to right, then the
level right to left), vertices relative to their block's body centre at θ = 0 as the blocks' own. Each
column is triangulated piece by piece (two triangles a trapezoid of the top surface), exact where a fan from
one corner would cross a peaked top.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np
import rerun as rr

from masonrycli.recording.arrays import Polygons, partition_lengths, z0
from masonrycli.recording.layout import CARRIED_FILL, MAGNIFIED_FILL

FILL_MESH, FILL_OUTLINES = CARRIED_FILL  # only in the recording of a structure that carries a fill
FILL_RGBA: Final = 0xD9C49A60  # sand, translucent: the fill is load, not masonry
FILL_LINE_RGBA: Final = 0x8C6E3CC0
FILL_LINE_POINTS: Final = 0.75  # ui points


@dataclass(frozen=True, eq=False)
class ColumnArrays:
    """The fill's columns as the recording takes them (``FillColumns`` moved to their blocks' frames)."""

    block: np.ndarray
    """(P,) int64: the block carrying column k."""
    start: np.ndarray
    """(P+1,) int64: column k's vertices are local[start[k]:start[k+1]]."""
    local: np.ndarray
    """(V, 2) m, relative to the block's body centre (its pose's x, y) at θ = 0."""


def no_columns() -> ColumnArrays:
    return ColumnArrays(np.zeros(0, np.int64), np.zeros(1, np.int64), np.zeros((0, 2)))


def strip_triangles(start: np.ndarray) -> np.ndarray:
    """(T, 3) uint32: each column's trapezoids, two triangles each (module docstring)."""
    out = []
    for s, k in zip(start[:-1], np.diff(start)):
        n = k // 2 - 1  # pieces: bottom points p_0 … p_n at s … s+n, t_i (above p_i) at s + k - 1 - i
        i = np.arange(n)
        top = s + k - 1 - i
        out += [np.stack([s + i, s + i + 1, top - 1], axis=1), np.stack([s + i, top - 1, top], axis=1)]
    return np.concatenate(out or [np.zeros((0, 3))]).astype(np.uint32)


class CarriedFill:
    """The columns of one recording: logged once (style, triangles), then posed per batch of frames."""

    def __init__(self, columns: ColumnArrays, copies: int = 1, blocks: int = 0) -> None:
        """``copies`` > 1 (the limit recording's structure as built and its mechanism copy): the columns again
        for each copy, copy c's on block ``c × blocks + block``."""
        start, local = np.asarray(columns.start, np.int64), np.asarray(columns.local, np.float64)
        self.count = (len(start) - 1) * copies
        starts = [start[:-1] + c * start[-1] for c in range(copies)] + [np.array([copies * start[-1]])]
        self.polygons = Polygons(np.concatenate(starts), np.tile(local, (copies, 1)))
        self.block = np.concatenate([columns.block + c * blocks for c in range(copies)])
        self.triangles = strip_triangles(np.concatenate(starts))

    def log_static(self, rec: rr.RecordingStream, magnified: bool = True) -> None:
        """Style and triangles; ``magnified``: the Magnified tab's outlines too (a run's, not limit's)."""
        if not self.count:
            return
        rec.log(FILL_MESH, rr.Mesh3D.from_fields(triangle_indices=self.triangles, albedo_factor=FILL_RGBA), static=True)
        style = rr.LineStrips2D.from_fields(colors=FILL_LINE_RGBA, radii=-FILL_LINE_POINTS, draw_order=20.0)
        rec.log(FILL_OUTLINES, style, static=True)
        if magnified:
            rec.log(MAGNIFIED_FILL, style, static=True)

    def send(self, rec: rr.RecordingStream, idx: list, q: np.ndarray) -> None:
        """The columns at the block poses ``q`` (F, N, 3) of the frames ``idx``."""
        if not self.count:
            return
        verts = self.polygons.world(q[:, self.block])  # (F, V, 2): column k posed as its block
        frames = len(q)
        rec.send_columns(
            FILL_MESH,
            indexes=idx,
            columns=rr.Mesh3D.columns(vertex_positions=z0(verts)).partition(partition_lengths(frames, verts.shape[1])),
        )
        self.send_outlines(rec, idx, q, FILL_OUTLINES, verts)

    def send_outlines(self, rec: rr.RecordingStream, idx: list, q: np.ndarray, path: str, verts=None) -> None:
        """The columns' outlines at the block poses ``q`` (F, N, 3) to ``path``: the Live view's, and the Magnified
        tab's (``magnified``: posed as its magnified blocks, the bare ring was drawn there)."""
        if not self.count:
            return
        verts = self.polygons.world(q[:, self.block]) if verts is None else verts
        rec.send_columns(
            path,
            indexes=idx,
            columns=rr.LineStrips2D.columns(strips=self.polygons.outlines(verts)).partition(
                partition_lengths(len(q), self.count)
            ),
        )


def magnified_fill_note(fill_load_n: float, drawn: bool) -> str:
    """The Magnified line's words on a carried fill ('' without one), ending that line: the tab shows the
    columns' outlines and the legend's Fill line, under it, was cut off the panel there."""
    if not fill_load_n:
        return ""
    load = f"dead load only, {fill_load_n / 1e3:.4g} kN"
    return (
        f"; sand outlines = the fill ({load}), each column on its magnified block"
        if drawn
        else (f"; the fill ({load}) is not drawn")
    )


def fill_legend(fill_load_n: float, thickness: float | None, drawn: bool) -> str:
    """The legend's line for a carried fill ('' without one); ``fill_load_n``: its weight, N, for the blocks'
    ``thickness`` (m; None: not known); ``drawn``: its columns are (a built-in bridge's, not a GeoJSON's)."""
    if not fill_load_n:
        return ""
    load = f"{fill_load_n / 1e3:.4g} kN"
    if thickness:
        load += f" ({fill_load_n / 1e3 / thickness:.4g} kN per metre of width)"
    where = (
        "drawn over the blocks that carry it, each column moving with its block"
        if drawn
        else "carried by the blocks under it, not drawn (the carried masses are not those of one fill up to one level)"
    )
    return f"\n- **Fill** (sand, translucent): dead load only, {load}, {where}."
