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

from dataclasses import dataclass, field
from typing import Final

import numpy as np
import pyarrow as pa
import rerun as rr

from masonrycli.recording.arrays import Polygons, uniform_strips, z0
from masonrycli.recording.colormap import BLUES, COOLWARM, OVER_RGBA, UNDER_RGBA, VIRIDIS, colorbar_mesh
from masonrycli.recording.document import viewer_safe_text
from masonrycli.recording.layout import (
    BLOCKS,
    CENTROID_RADIUS,
    CENTROID_RGBA,
    FILL,
    FORCES,
    HINGE_RADIUS,
    HINGE_RGBA,
    HINGES,
    LEGEND_TEXT_RGBA,
    MAGNIFIED,
    MAGNIFIED_RGBA,
    PLANE,
    SERIES,
    STRESS_AXES,
    SUPPORT_FILL,
    SUPPORT_FILL_RGBA,
    SUPPORT_LINE_RGBA,
    SUPPORT_OUTLINES,
    TRIANGULATION,
    TRIANGULATION_RGBA,
    UNDEFORMED,
    UNDEFORMED_RGBA,
    XY,
    FieldSpec,
)
from masonrycli.recording.series import support_series_colours

_CAMERA_HEIGHT: Final = 1.0e4  # m, drawing-plane camera above z = 0
_SUPPORT_MARGIN: Final = 0.15  # initial view: supports up to this × the structure's size beyond blocks
_MIN_BAR_RATIO: Final = 12.0  # colour bar height / width at least (the paper's structures: 15 to 30)


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
    """(T, 3) int64 block indices of the cells' triangles (each drawn once)."""
    friction: float
    dt: float
    """s."""
    fill_block: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    """(P,) int64: the block carrying each column of fill (``carried_fill``; none without a fill)."""
    fill_vert_start: np.ndarray = field(default_factory=lambda: np.zeros(1, np.int64))
    """(P+1,) int64."""
    fill_vert_local: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    """(Vf, 2) m, relative to the carrying block's centre (as block_vert_local)."""
    fill_load_n: float = 0.0
    """N: the weight the blocks carry (for their thickness), said in the legend."""


def log_static(rec: rr.RecordingStream, st: RecordingStatic, blocks: Polygons, supports: Polygons) -> None:
    """Everything constant over the run: the fill mesh's triangles, line styles, names, series names."""
    rec.log(FILL, rr.Mesh3D.from_fields(triangle_indices=blocks.fan), static=True)
    rec.log(
        SUPPORT_FILL,
        rr.Mesh3D.from_fields(triangle_indices=supports.fan, albedo_factor=SUPPORT_FILL_RGBA),
        static=True,
    )
    # A small dark dot at each block's centroid carrying its name and values (the hover target; the
    # legend says so). They were 0.15 block sizes wide "in the block's colour, so they do not show": rerun
    # shades points as spheres and ignores their alpha over a mesh, so they showed as grey rings.
    rec.log(
        BLOCKS,
        rr.Points2D.from_fields(radii=CENTROID_RADIUS, colors=CENTROID_RGBA, draw_order=5.0),
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
    rec.log(STRESS_AXES, rr.LineStrips2D.from_fields(radii=-LINE_POINTS[STRESS_AXES][0], draw_order=40.0), static=True)
    rec.log(FORCES, rr.Arrows2D.from_fields(radii=-LINE_POINTS[FORCES][0], draw_order=50.0), static=True)
    rec.log(HINGES, rr.Points2D.from_fields(radii=HINGE_RADIUS, colors=HINGE_RGBA, draw_order=60.0), static=True)
    magnified = rr.LineStrips2D.from_fields(colors=MAGNIFIED_RGBA, radii=-LINE_POINTS[MAGNIFIED][0], draw_order=30.0)
    rec.log(MAGNIFIED, magnified, static=True)
    series_names = {
        "energy_kinetic": ["kinetic"],
        "energy_large": ["support work", "dissipated (cumulated)", "potential change"],
        "energy_balance": ["log10 |kinetic + potential change + dissipated − support work| ÷ largest term"],
        "max_displacement": ["max block displacement, relative to a shaken ground"],
        "support_velocity": [f"{n} v{c}" for n in names for c in "xy"],
        "support_displacement": [f"{n} u{c}" for n in names for c in "xy"],
        "iterations": ["NLGS sweeps"],
        "residual": ["log10 NLGS residual", "log10 tolerance"],
        "contacts": ["contacts"],
    }
    colours = support_series_colours(len(names))  # the same component, the same colour in both plots
    for key, path in SERIES.items():
        lines = [viewer_safe_text(n) for n in series_names[key]]
        if key in ("support_velocity", "support_displacement") and lines:
            rec.log(path, rr.SeriesLines(names=lines, colors=colours), static=True)
        else:
            rec.log(path, rr.SeriesLines(names=lines), static=True)


def log_initial_shape(
    rec: rr.RecordingStream,
    blocks: Polygons,
    triangles: np.ndarray,
    block_q: np.ndarray,
    support_q: np.ndarray,
    supports: Polygons,
    centroids: np.ndarray | None = None,
) -> None:
    """The as-built outlines (the magnified view's ghost) and the cells' triangles as built, between the blocks'
    ``centroids`` (N, 2) m (None: their poses' x, y), their own, as the cells are (analysis.tensors)."""
    verts = blocks.world(block_q[None])
    ghost = [blocks.outlines(verts)]
    if supports.count:
        ghost.append(supports.outlines(supports.world(support_q[None])))
    rec.log(
        UNDEFORMED,
        rr.LineStrips2D(pa.concat_arrays(ghost), colors=UNDEFORMED_RGBA, radii=-0.75, draw_order=20.0),
        static=True,
    )
    points = block_q[:, :2] if centroids is None else np.asarray(centroids, dtype=np.float64)
    closed = points[np.asarray(triangles, dtype=np.intp).reshape(-1, 3)[:, [0, 1, 2, 0]]]
    rec.log(
        TRIANGULATION,
        rr.LineStrips2D(uniform_strips(closed), colors=TRIANGULATION_RGBA, radii=-0.5, draw_order=31.0),
        static=True,
    )


def inset_local(start: np.ndarray, local: np.ndarray, distance: float) -> np.ndarray:
    """(V, 2) the convex polygons' local vertices moved inwards by ``distance`` (at most a quarter of each
    polygon's smaller side): adjacent fills then leave a dark line along every joint, so no outline has
    to be logged per frame. Each vertex moves along its corner's bisector by distance / sin(half angle).
    """
    start = np.asarray(start, dtype=np.int64)
    local = np.asarray(local, dtype=np.float64).reshape(-1, 2)
    if local.size == 0:
        return local.copy()
    n_vert = np.diff(start)
    owner = np.repeat(np.arange(len(n_vert)), n_vert)
    pos = np.arange(len(local)) - start[owner]
    nxt = start[owner] + (pos + 1) % n_vert[owner]
    prv = start[owner] + (pos - 1) % n_vert[owner]
    first = start[:-1]
    size = np.maximum.reduceat(local, first) - np.minimum.reduceat(local, first)
    d = np.minimum(distance, 0.25 * size.min(axis=1))[owner]

    def inward(a, b):  # unit normal of edge a → b pointing into a counter-clockwise polygon
        e = b - a
        n = np.stack([-e[:, 1], e[:, 0]], axis=1)
        return n / np.linalg.norm(n, axis=1, keepdims=True)

    n1, n2 = inward(local[prv], local), inward(local, local[nxt])
    bis = n1 + n2
    return local + bis * (d / (1.0 + np.einsum("ij,ij->i", n1, n2)))[:, None]


def log_plane(
    rec: rr.RecordingStream,
    blocks: Polygons,
    supports: Polygons,
    block_q: np.ndarray,
    support_q: np.ndarray,
    content: np.ndarray | None = None,
    block_side: float | None = None,
    shape: np.ndarray | None = None,
) -> tuple[tuple[float, float, float, float], float, tuple[tuple[float, float], tuple[float, float]]]:
    """Pinhole and y-up transform sized to the structure at the first frame; returns the legend box, the
    structure's size (m) and, for the tab without a colour bar nor arrows (the magnified shape's), the part
    of the view that holds the structure and ``shape`` (xmin, ymin, xmax, ymax, m: what that tab draws),
    as image ranges (u0, u1), (v0, v1). ``content``: (xmin, ymin, xmax, ymax), m, of what the run drew (the blocks'
    x reach, the joint arrows; the recorder's close): the view widens to hold it and the legend box stands
    right of it (a wall shaken right covered the bar, one falling left left the view, and a 64-course wall's
    toe arrows ran off the bottom: 'masonry simulate wall --courses 64 --length 4.5', 70 frames of 100).
    ``block_side``: a median block's smaller side (m); given, the centroid dots are sized to the blocks as
    drawn in this view, and the hinge dots (:func:`centroid_radius`, :func:`hinge_radius`)."""
    sup = supports.world(support_q[None])[0]
    blk = blocks.world(block_q[None])[0] if blocks.count else sup
    size = float(max(blk.max(axis=0) - blk.min(axis=0))) or 1.0
    lo, hi = _held(blk, sup, size, content)
    # the bar's width: 2.5 % of the structure's size, or of the box the view holds when what the run drew widens
    # it beyond the supports' margin: a collapse strewn along its ground ('masonry simulate wall --amp 3 --freq
    # 0.8 --duration 3') drew a bar 7 px wide at close, its tick labels (3 widths right of it) over it
    pad, bar = 0.05 * size, 0.025 * max(size, float(max(hi - lo)) / (1.0 + 2.0 * _SUPPORT_MARGIN))
    ya, yb = blk[:, 1].min(), blk[:, 1].max()
    room = 0.12 * (yb - ya)  # for the title above the bar and the over / under labels
    # a low structure got a bar as short as itself: an 8-course wall 37.5 m long ('simulate wall
    # --courses 8 --length 37.5') drew a square bar 1.2 m high whose five tick labels, title and count
    # overlapped in a smear. The bar is at least _MIN_BAR_RATIO times as high as it is wide (its labels
    # ~60 px apart), standing on the same base and rising above the structure, the view made taller to hold
    # it and its title (at 0.14 of the bar's height above it)
    span = max(yb - ya - 2 * room, _MIN_BAR_RATIO * bar)
    hi[1] = max(hi[1], ya + room + span + 0.14 * span + bar)
    x0, y0 = lo[0] - pad, hi[1] + pad
    height, t = y0 - lo[1] + pad, 1.02 * _TITLE_HALF_PX

    def resolution_for(gap: float) -> list[float]:
        # room for half the bar's title right of the bar's centre as drawn at first open: the view's right
        # margin m >= T / px_per_m - c, px_per_m = min(Pw / (w0 + m), Ph / height), solved for m (2 % spare)
        w0, c = hi[0] + gap + pad + bar - x0, pad + 0.5 * bar
        right = max(0.2 * size, t * height / _PANEL_PX[1] - c, (t * w0 / _PANEL_PX[0] - c) / (1.0 - t / _PANEL_PX[0]))
        return [w0 + right, height]

    # and left of it, clear of the blocks and supports as built at the title's height: the aqueduct's title
    # ("Volumetric strain rate, t = 5.000 s", centred on a bar 2 pads right of its foundation) covered the
    # wall's top right blocks. A wider gap widens the view (fewer px a metre): a few rounds of gap = what
    # reaches the title's height + T / px_per_m - bar / 2 settle (T < Pw / 9)
    title_y = ya + room + 1.14 * span  # legend_positions' title anchor
    parts = [_boxes(p, v) for p, v in ((blocks, blk), (supports, sup)) if p.count]
    low, high, right_end = (np.concatenate(c) for c in zip(*parts)) if parts else (np.zeros(0),) * 3
    gap = 2 * pad
    for _ in range(8):
        resolution = resolution_for(gap)
        px_per_m = min(_PANEL_PX[0] / resolution[0], _PANEL_PX[1] / resolution[1])
        band = _TITLE_BAND_PX / px_per_m
        beside = (high >= title_y - band) & (low <= title_y + band)
        if not beside.any():
            break
        need = float(right_end[beside].max()) + (t + _TITLE_SPARE_PX) / px_per_m - 0.5 * bar - hi[0]
        if gap >= need:
            break
        gap = need
    resolution = resolution_for(gap)
    legend_box = (hi[0] + gap, ya + room, hi[0] + gap + bar, ya + room + span)
    rec.log(
        PLANE,
        rr.Pinhole(focal_length=_CAMERA_HEIGHT, principal_point=[0.0, 0.0], resolution=resolution),
        rr.Transform3D(translation=[x0, y0, _CAMERA_HEIGHT], mat3x3=np.diag([1.0, -1.0, -1.0])),
        static=True,
    )
    rec.log(XY, rr.Transform3D(translation=[-x0, y0, 0.0], scale=[1.0, -1.0, 1.0]), static=True)
    if block_side is not None:
        rec.log(BLOCKS, rr.Points2D.from_fields(radii=centroid_radius(resolution, block_side)), static=True)
        rec.log(HINGES, rr.Points2D.from_fields(radii=hinge_radius(resolution, block_side)), static=True)
        for path, (points, share) in LINE_POINTS.items():
            radius = centroid_radius(resolution, block_side, points, share)
            style = (
                rr.Arrows2D.from_fields(radii=radius) if path == FORCES else rr.LineStrips2D.from_fields(radii=radius)
            )
            rec.log(path, style, static=True)
    slo, shi = _held(blk, sup, size, shape)  # a 64-course wall's Magnified tab kept room for the toe arrows
    return legend_box, size, ((slo[0] - pad - x0, shi[0] + pad - x0), (y0 - shi[1] - pad, y0 - slo[1] + pad))


def legend_move(old: tuple[float, float, float, float], new: tuple[float, float, float, float]) -> rr.Transform3D:
    """The transform (on the colour bars' and their labels' parents) that takes what was drawn in legend box
    ``old`` (the first frame's, ``log_plane``) to box ``new`` (the view at close): moved and stretched, the
    labels' anchors (``legend_positions``) with it, so the ticks keep their distance to the bar."""
    kx, ky = (new[2] - new[0]) / (old[2] - old[0]), (new[3] - new[1]) / (old[3] - old[1])
    return rr.Transform3D(translation=[new[0] - kx * old[0], new[1] - ky * old[1], 0.0], scale=[kx, ky, 1.0])


CONTENT_REACH: Final = 2.0
"""× the structure's size: how far beyond the structure as built a view widens for what the run drew (the blocks'
reach, the joint arrows, the magnified shape). A wall toppled flat lies within its height of its base, and a
magnified shape drawn ×40 on a lab wall reached 1.8 × its size above it; blocks that fell off the supports' edge
fall on with nothing under them ('masonry run aqueduct.geojson --record quake.AT2 --pga 0.3 --duration 8': collapsed at 3 s, 5 s of
free fall after, ~120 m) and made the view so tall that the 7 m aqueduct was a dot at its top."""


def _held(blk: np.ndarray, sup: np.ndarray, size: float, content: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi), m: the box a view holds: the blocks, ``content`` (xmin, ymin, xmax, ymax) and the supports,
    but a wide ground only a little beyond the blocks."""
    lo, hi = blk.min(axis=0), blk.max(axis=0)
    if content is not None:  # within CONTENT_REACH of the structure: a toppled wall, not a block falling for ever
        reach = CONTENT_REACH * size
        lo = np.minimum(lo, np.maximum(content[:2], lo - reach))
        hi = np.maximum(hi, np.minimum(content[2:], hi + reach))
    if len(sup):
        lo = np.minimum(lo, np.maximum(sup.min(axis=0), lo - _SUPPORT_MARGIN * size))
        hi = np.maximum(hi, np.minimum(sup.max(axis=0), hi + _SUPPORT_MARGIN * size))
    return lo, hi


LINE_POINTS: Final = {FORCES: (1.5, 0.125), STRESS_AXES: (1.25, 0.1), MAGNIFIED: (1.0, 0.1)}
"""Radius (ui points) of the lines drawn over the blocks, and the share of a median block's smaller side they
keep to when that is smaller at first open (:func:`centroid_radius`): on an 8-course wall 37.5 m long ('masonry
simulate wall --courses 8 --length 37.5', 5.6 px high blocks) the joint arrows 3 px thick (1.5 points) and
the glyphs hid every colour under orange and green."""
_PANEL_PX: Final = (1150.0, 840.0)  # the structure panel of a 1920 x 1080 window (docs' screenshots)
_TITLE_HALF_PX: Final = 125.0
"""Half the widest colour-bar title at 1920 x 1080, px ("Deviatoric cumulated strain, t = 10.000 s": ~5.7 px a
character, its box's padding): the title is centred on the bar and says the frame's time; on a wide view (a
collapsed wall strewn along its ground, 'masonry simulate wall --amp 3 --freq 0.8 --duration 3') the 0.2 x
the structure's size right of the ticks left ~80 px, and "Spherical stress p, t = 3.000 s" lost its end."""


_TITLE_SPARE_PX: Final = 8.0
"""px kept between the structure and the left end of a colour-bar title (``log_plane``)."""
_TITLE_BAND_PX: Final = 14.0
"""Half the height of a colour-bar title's box and a spare, px: the blocks within it are beside the title."""


def _boxes(polygons: Polygons, verts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each polygon's lowest y, highest y and rightmost x (m) from its world vertices ``verts`` (V, 2)."""
    first = np.flatnonzero(np.r_[True, polygons.owner[1:] != polygons.owner[:-1]])
    y, x = verts[:, 1], verts[:, 0]
    return np.minimum.reduceat(y, first), np.maximum.reduceat(y, first), np.maximum.reduceat(x, first)


def centroid_radius(resolution, block_side: float, points: float = -CENTROID_RADIUS, share: float = 0.125) -> float:
    """A dot's radius: -``points`` (ui points, negative: the same size at every zoom), unless a dot that size
    would be more than 2 ``share`` of a median block's smaller side wide as drawn at first open
    (``resolution``: the view's extent, m, fitted to the structure panel); then ``share`` of that side, in
    metres (positive): as small at first open, and it grows with the blocks when the user zooms in.

    The centroid dots (2.5 points, an eighth of the side): 5 px wide on the 4-5 px high blocks of an
    8-course wall 37.5 m long and on the 11 px ones of a 64-course wall, they darkened every colour map. The
    hinges (:func:`hinge_radius`)."""
    px_per_m = min(_PANEL_PX[0] / float(resolution[0]), _PANEL_PX[1] / float(resolution[1]))
    if share * block_side * px_per_m >= points:
        return -points
    return share * block_side


def hinge_radius(resolution, block_side: float) -> float:
    """The hinge dots' radius: 4 ui points, or a quarter of a median block's smaller side when such a dot
    would be wider than half the side at first open (:func:`centroid_radius`). On the 64-course wall
    ('masonry simulate wall --courses 64 --length 4.5') 729 hinges 8 px wide on 9 px high blocks covered
    the Sliding and Opening tabs in yellow, the colour of a sliding ratio of 1 there."""
    return centroid_radius(resolution, block_side, -HINGE_RADIUS, 0.25)


LUTS: Final = {"signed": COOLWARM, "negative": BLUES, "positive": VIRIDIS}
TICKS: Final = 5


def legend_positions(legend_box: tuple[float, float, float, float]) -> np.ndarray:
    """(TICKS + 3, 2) label anchors: the ticks right of the bar (bottom up), the title above it, the
    below / above counts left of the end caps.

    A label is centred on its anchor and about 50-80 px wide whatever the zoom; the bar is about 20 px
    wide (its width w is 2.5 % of the structure's size, which the view fits). Ticks 3 w right of the bar
    clear it (at 0.6 w they hid its right half), and the counts left of the caps clear the top and bottom
    ticks (beside them, "1 above" covered "+0.4 1/s")."""
    xa, ya, xb, yb = legend_box
    h, w = yb - ya, xb - xa
    ticks = np.stack([np.full(TICKS, xb + 3.0 * w), np.linspace(ya, yb, TICKS)], axis=1)
    title = [[0.5 * (xa + xb), yb + 0.14 * h]]
    caps = [[xa - 2.0 * w, ya - 0.04 * h], [xa - 2.0 * w, yb + 0.04 * h]]
    return np.concatenate([ticks, title, caps])


def log_legend(rec: rr.RecordingStream, f: FieldSpec, legend_box: tuple[float, float, float, float]) -> None:
    """Colour bar (a Mesh3D gradient beside the structure) with end caps in the below / above colours,
    and the static style of its labels (the labels themselves change with the range, per frame)."""
    xa, ya, xb, yb = legend_box
    verts, tri, colors = colorbar_mesh(legend_box, LUTS[f.kind])
    cap = 0.04 * (yb - ya)
    xm = 0.5 * (xa + xb)
    cap_verts = np.array(
        [
            [xa, ya - 0.01 * cap],
            [xb, ya - 0.01 * cap],
            [xm, ya - cap],
            [xa, yb + 0.01 * cap],
            [xb, yb + 0.01 * cap],
            [xm, yb + cap],
        ]
    )
    k = len(verts)
    bar = rr.Mesh3D(
        vertex_positions=z0(np.concatenate([verts, cap_verts])),
        triangle_indices=np.concatenate([tri, np.array([[k, k + 2, k + 1], [k + 3, k + 4, k + 5]], np.uint32)]),
        vertex_colors=np.concatenate([colors, np.repeat(np.array([UNDER_RGBA, OVER_RGBA], np.uint32), 3)]),
    )
    rec.log(f.bar, bar, static=True)
    # radius 0: the labels alone (at -0.5 ui points a white speck showed beside each label)
    rec.log(f.labels, rr.Points2D.from_fields(radii=0.0, show_labels=True, colors=LEGEND_TEXT_RGBA), static=True)
