"""What a recording logs once (static): entity styles and names, the drawing plane, the colour bars.

The drawing plane: Rerun has no filled 2-D polygon, so fills are ``Mesh3D`` at z = 0 in the 3-D space
``structure``, seen in the 2-D views through the pinhole ``structure/plane``: a camera looking down from
``_CAMERA_HEIGHT`` with focal length equal to that height (1 image unit = 1 m, image v = world −y: y up
on screen). Lines, arrows and points live under ``structure/plane/xy``, mapped to image (x − x0, y0 − y).
The pinhole's resolution is the blocks' bounding box at the first frame (plus margins and the legend), so
the views open fitted. The camera must be far: 2-D content is drawn at a fixed depth that a closer mesh
would hide.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np
import rerun as rr

from masonrycli.colormap import COOLWARM, VIRIDIS, colorbar_mesh, tick_label
from masonrycli.recording.arrays import Polygons, z0
from masonrycli.recording.document import viewer_safe_text
from masonrycli.recording.layout import (
    BLOCKS,
    FIELDS,
    FORCES,
    HINGE_RGBA,
    HINGES,
    LEGEND_TEXT_RGBA,
    OUTLINE_RGBA,
    PLANE,
    SERIES,
    STRAIN_RATE_AXES,
    STRESS_AXES,
    SUPPORT_FILL,
    SUPPORT_FILL_RGBA,
    SUPPORT_LINE_RGBA,
    SUPPORT_OUTLINES,
    TRIANGULATION,
    TRIANGULATION_RGBA,
    XY,
    FieldSpec,
)

_CAMERA_HEIGHT: Final = 1.0e4  # m, drawing-plane camera above z = 0
_SUPPORT_MARGIN: Final = 0.15  # initial view: supports up to this × the structure's size beyond blocks


@dataclass(frozen=True)
class RecordingStatic:
    """Geometry and constants the recording needs once (CSR polygons as in docs/architecture.md)."""

    block_name: np.ndarray
    """(N,) str."""
    block_vert_start: np.ndarray
    """(N+1,) int64: block i's vertices are block_vert_local[start[i]:start[i+1]]."""
    block_vert_local: np.ndarray
    """(V, 2) m, counter-clockwise, relative to the block centroid at θ = 0."""
    support_name: np.ndarray
    """(S,) str."""
    support_vert_start: np.ndarray
    """(S+1,) int64."""
    support_vert_local: np.ndarray
    """(Vs, 2) m, relative to the support's initial centroid (its position in Frame.support_q)."""
    triangles: np.ndarray
    """(T, 3) int64 block indices of the centroid triangulation."""
    friction: float
    dt: float
    """s."""


def log_static(rec: rr.RecordingStream, st: RecordingStatic, blocks: Polygons, supports: Polygons) -> None:
    """Everything constant over the run: fill meshes' triangles, line styles, names, series names."""
    for f in FIELDS:
        rec.log(f.fill, rr.Mesh3D.from_fields(triangle_indices=blocks.fan), static=True)
    rec.log(
        SUPPORT_FILL,
        rr.Mesh3D.from_fields(triangle_indices=supports.fan, albedo_factor=SUPPORT_FILL_RGBA),
        static=True,
    )
    rec.log(
        BLOCKS,
        rr.LineStrips2D.from_fields(colors=OUTLINE_RGBA, radii=-0.75, draw_order=30.0),
        rr.AnyValues(name=[viewer_safe_text(str(n)) for n in st.block_name]),
        static=True,
    )
    names = [viewer_safe_text(str(n)) for n in st.support_name]
    rec.log(
        SUPPORT_OUTLINES,
        rr.LineStrips2D.from_fields(colors=SUPPORT_LINE_RGBA, radii=-0.75),
        rr.AnyValues(name=names),
        static=True,
    )
    rec.log(
        TRIANGULATION,
        rr.LineStrips2D.from_fields(colors=TRIANGULATION_RGBA, radii=-0.5, draw_order=31.0),
        static=True,
    )
    for path in (STRESS_AXES, STRAIN_RATE_AXES):
        rec.log(path, rr.LineStrips2D.from_fields(radii=-1.25, draw_order=40.0), static=True)
    rec.log(FORCES, rr.Arrows2D.from_fields(radii=-1.25, draw_order=50.0), static=True)
    rec.log(HINGES, rr.Points2D.from_fields(radii=-4.0, colors=HINGE_RGBA, draw_order=60.0), static=True)
    series_names = {
        "energy": ["kinetic", "potential change", "dissipated", "support work"],
        "max_displacement": ["max block displacement"],
        "support_velocity": [f"{n} v{c}" for n in names for c in "xy"],
        "support_displacement": [f"{n} u{c}" for n in names for c in "xy"],
        "iterations": ["NLGS iterations"],
        "residual": ["NLGS residual"],
        "contacts": ["contacts"],
    }
    for key, path in SERIES.items():
        rec.log(path, rr.SeriesLines(names=series_names[key]), static=True)


def log_plane(
    rec: rr.RecordingStream, blocks: Polygons, supports: Polygons, block_q: np.ndarray, support_q: np.ndarray
) -> tuple[float, float, float, float]:
    """Pinhole and y-up transform sized to the structure at the first frame; returns the legend box."""
    sup = supports.world(support_q[None])[0]
    blk = blocks.world(block_q[None])[0] if blocks.count else sup
    lo, hi = blk.min(axis=0), blk.max(axis=0)
    size = float(max(hi - lo)) or 1.0
    if len(sup):  # show the supports, but a wide ground only a little beyond the blocks
        lo = np.minimum(lo, np.maximum(sup.min(axis=0), lo - _SUPPORT_MARGIN * size))
        hi = np.maximum(hi, np.minimum(sup.max(axis=0), hi + _SUPPORT_MARGIN * size))
    pad, bar = 0.05 * size, 0.025 * size
    ya, yb = blk[:, 1].min(), blk[:, 1].max()
    room = 0.08 * (yb - ya)  # for the labels above and below the bar
    legend_box = (hi[0] + 2 * pad, ya + room, hi[0] + 2 * pad + bar, yb - room)
    x0, y0 = lo[0] - pad, hi[1] + pad
    resolution = [hi[0] + 3 * pad + bar + 0.12 * size - x0, y0 - lo[1] + pad]
    rec.log(
        PLANE,
        rr.Pinhole(focal_length=_CAMERA_HEIGHT, principal_point=[0.0, 0.0], resolution=resolution),
        rr.Transform3D(translation=[x0, y0, _CAMERA_HEIGHT], mat3x3=np.diag([1.0, -1.0, -1.0])),
        static=True,
    )
    rec.log(XY, rr.Transform3D(translation=[-x0, y0, 0.0], scale=[1.0, -1.0, 1.0]), static=True)
    return legend_box


def log_legend(
    rec: rr.RecordingStream,
    f: FieldSpec,
    field_range: tuple[float, float],
    legend_box: tuple[float, float, float, float],
) -> None:
    """Colour bar (a Mesh3D gradient beside the structure) and its labels, once the range is fixed."""
    (lo, hi), (xa, ya, xb, yb) = field_range, legend_box
    verts, tri, colors = colorbar_mesh(legend_box, COOLWARM if f.signed else VIRIDIS)
    bar = rr.Mesh3D(vertex_positions=z0(verts), triangle_indices=tri, vertex_colors=colors)
    rec.log(f.bar, bar, static=True)
    labels = [tick_label(v, f.unit, max(-lo, hi), f.signed) for v in (lo, 0.5 * (lo + hi), hi)]
    labels[-1] = f"{f.title}\n{labels[-1]}"
    xm, gap = 0.5 * (xa + xb), 0.04 * (yb - ya)
    pos = [[xm, ya - gap], [2 * xb - xa, 0.5 * (ya + yb)], [xm, yb + 2 * gap]]
    rec.log(
        f.labels,
        rr.Points2D(pos, labels=labels, radii=-0.5, show_labels=True, colors=LEGEND_TEXT_RGBA),
        static=True,
    )
