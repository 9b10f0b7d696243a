"""Fill over a structure: the dead weight of soil up to a level, carried by the blocks beneath it.

A masonry bridge's fill is assessed, in Heyman's conservative way, as dead load only: its weight bears
vertically on the ring, it has no strength of its own and pushes nothing sideways. Each vertical column
of fill, from the structure's top surface up to the fill level, bears on the block whose upper boundary
is highest under it.

The top surface is piecewise linear, with breaks only at the blocks' vertices. Between two consecutive
vertex abscissae one block is topmost and its top edge is one straight line, so the fill over that piece
is a trapezoid (cut where the top rises above the level: a ring standing proud of a haunch fill):

    for each piece [a, b] of the top surface within [x_lo, x_hi]:
        block, y(x) = the topmost block at (a + b) / 2 and its top edge there
        clip [a, b] to where y(x) < level
        add the trapezoid (a, y(a)), (b, y(b)), (b, level), (a, level) to that block's fill

A block's fill is the sum of its trapezoids (area, centroid); where no block is under a piece (a gap
between piers), no fill is counted (it would fall through).

A fill traced as an outline (a surveyed bridge's: :func:`traced_fill_over`) is read the same way, from the top
surface of the blocks and the supports up to the outline's top, each column bearing on the body topmost under it;
its surface need not be level, and the columns over a support (the ground beyond an abutment) rest on it.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from shapely import unary_union
from shapely.geometry import Polygon

from .blocks import Block

FILL_DENSITY = 2000.0
"""kg/m³: a bridge's fill when none is given (granular fill weighs 18–22 kN/m³)."""


@dataclasses.dataclass(frozen=True, eq=False)
class Fill:
    """The fill over each block: ``area`` (N,) m² and ``centroid`` (N, 2) m (nan where the area is 0)."""

    area: np.ndarray
    centroid: np.ndarray


def _edges(blocks) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(E, 2) start and end points and (E,) owner of every block edge."""
    starts, ends, owner = [], [], []
    for i, block in enumerate(blocks):
        xy = np.asarray(block.vertices, dtype=np.float64)
        starts.append(xy)
        ends.append(np.roll(xy, -1, axis=0))
        owner.append(np.full(len(xy), i))
    return np.concatenate(starts), np.concatenate(ends), np.concatenate(owner)


def _trapezoid(a: float, b: float, ya: float, yb: float, level: float) -> tuple[float, float, float]:
    """(area, first moment about y = 0 … as Σ x·A, Σ y·A) of {a ≤ x ≤ b, line(ya, yb) ≤ y ≤ level}, the line
    assumed below the level over [a, b] (a corner may touch it)."""
    ha, hb = level - ya, level - yb  # heights of the two vertical sides, ≥ 0
    width = b - a
    area = 0.5 * width * (ha + hb)
    if area <= 0.0:
        return 0.0, 0.0, 0.0
    # centroid of a trapezoid with parallel vertical sides: x from a by w (ha + 2 hb) / (3 (ha + hb));
    # y: the mean over the strip of the column's mid-height, weighted by its height
    cx = a + width * (ha + 2.0 * hb) / (3.0 * (ha + hb))
    # ∫ h(x) (level − h(x)/2) dx / ∫ h(x) dx with h linear: level − (ha² + ha hb + hb²) / (3 (ha + hb))
    cy = level - (ha * ha + ha * hb + hb * hb) / (3.0 * (ha + hb))
    return area, cx * area, cy * area


@dataclasses.dataclass(frozen=True, eq=False)
class TopPiece:
    """A piece [a, b] (m) of the blocks' top surface over which block ``block`` (index) is topmost, its top
    the straight line y(x) = y_a + slope (x − a)."""

    a: float
    b: float
    block: int
    y_a: float
    slope: float

    def y(self, x: float) -> float:
        return self.y_a + self.slope * (x - self.a)


def top_surface(blocks, x_lo: float, x_hi: float) -> list[TopPiece]:
    """The blocks' top surface between ``x_lo`` and ``x_hi`` (m), left to right (module docstring): one piece
    per stretch on one straight top edge of one block (consecutive stretches of the same edge merged); none
    where no block is."""
    p, q, owner = _edges(blocks)
    xs = np.unique(np.concatenate([p[:, 0], [x_lo, x_hi]]))
    xs = xs[(xs >= x_lo) & (xs <= x_hi)]
    lo, hi = np.minimum(p[:, 0], q[:, 0]), np.maximum(p[:, 0], q[:, 0])
    pieces: list[TopPiece] = []
    edge_of: list[int] = []
    for a, b in zip(xs[:-1], xs[1:]):
        mid = 0.5 * (a + b)
        spans = np.flatnonzero((lo < mid) & (mid < hi))  # no vertex lies strictly inside (a, b)
        if spans.size == 0:
            continue
        t = (mid - p[spans, 0]) / (q[spans, 0] - p[spans, 0])
        k = int(spans[int(np.argmax(p[spans, 1] + t * (q[spans, 1] - p[spans, 1])))])
        slope = float((q[k, 1] - p[k, 1]) / (q[k, 0] - p[k, 0]))
        if pieces and edge_of[-1] == k and pieces[-1].b == a:  # the same straight edge goes on
            pieces[-1] = dataclasses.replace(pieces[-1], b=float(b))
            continue
        pieces.append(TopPiece(float(a), float(b), int(owner[k]), float(p[k, 1] + slope * (a - p[k, 0])), slope))
        edge_of.append(k)
    return pieces


LEVEL_ROUNDING = 1e-9
"""A top within this × max(1 m, |level|) of the fill level is at the level: it carries no fill. A skewback whose
top is the level but for round-off (1.2999999999999994 against 1.3: the fill of 'masonry build arch --span 8
--rise 2 … --fill-to 0.3') carried 3e-12 kg, and a file of that bridge was no longer read as one fill."""


def _under_level(blocks, level: float, x_lo: float, x_hi: float, pieces: list[TopPiece] | None = None):
    """(block, a, b, y(a), y(b)) of each piece of the top surface below ``level``, left to right, clipped where
    the top crosses the level (module docstring); ``pieces``: ``top_surface(blocks, x_lo, x_hi)`` if known."""
    at_level = level - LEVEL_ROUNDING * max(1.0, abs(level))
    for piece in top_surface(blocks, x_lo, x_hi) if pieces is None else pieces:
        a, b = piece.a, piece.b
        ya, yb = piece.y(a), piece.y(b)
        if ya >= at_level and yb >= at_level:  # a top at the level but for round-off carries no fill
            continue
        if ya > level or yb > level:  # the top crosses the level inside: keep the part below it
            cross = a + (level - ya) / piece.slope
            a, b = (a, cross) if ya < level else (cross, b)
            ya, yb = min(piece.y(a), level), min(piece.y(b), level)
        yield piece.block, a, b, ya, yb


def fill_over(blocks, level: float, x_lo: float, x_hi: float, pieces: list[TopPiece] | None = None) -> Fill:
    """The fill up to ``level`` (m) over the blocks' top surface between ``x_lo`` and ``x_hi`` (m), per block
    (module docstring); ``pieces``: that top surface, if known."""
    sums = np.zeros((len(blocks), 3))
    for block, a, b, ya, yb in _under_level(blocks, level, x_lo, x_hi, pieces):
        sums[block] += _trapezoid(a, b, ya, yb, level)
    area = sums[:, 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        centroid = np.where(area[:, None] > 0.0, sums[:, 1:] / area[:, None], np.nan)
    return Fill(area=area, centroid=centroid)


@dataclasses.dataclass(frozen=True, eq=False)
class FillColumns:
    """The fill's columns as drawn: one polygon per run of the top surface that one block carries (one per
    block under the fill when, as over a ring, each block's top is one stretch). Polygon k belongs to block
    ``block[k]``; its vertices ``vertices[start[k]:start[k + 1]]`` (m, counter-clockwise) are the top surface
    left to right, p_0 … p_n, then the same abscissae on the level right to left, so that piece i of the
    column is the trapezoid p_i, p_i+1, t_i+1, t_i (t the points on the level): an exact triangulation
    where a fan would cross a peaked top."""

    block: np.ndarray
    """(P,) int64."""
    start: np.ndarray
    """(P+1,) int64."""
    vertices: np.ndarray
    """(V, 2) float64, m."""


def fill_columns(blocks, level: float, x_lo: float, x_hi: float) -> FillColumns:
    """The fill of :func:`fill_over` as polygons, per block (:class:`FillColumns`): the same pieces, each
    block's consecutive pieces joined into one column, so their areas sum to ``fill_over``'s."""
    runs: list[tuple[int, list[tuple[float, float]]]] = []  # (block, bottom points left to right)
    for block, a, b, ya, yb in _under_level(blocks, level, x_lo, x_hi):
        if runs and runs[-1][0] == block and runs[-1][1][-1][0] == a:  # the same block goes on
            runs[-1][1].append((b, yb))
        else:
            runs.append((block, [(a, ya), (b, yb)]))
    polygons = [np.array(bottom + [(x, level) for x, _ in reversed(bottom)]) for _, bottom in runs]
    sizes = np.array([len(p) for p in polygons], dtype=np.int64)
    return FillColumns(
        block=np.array([b for b, _ in runs], dtype=np.int64),
        start=np.r_[0, np.cumsum(sizes)].astype(np.int64),
        vertices=np.concatenate(polygons) if polygons else np.zeros((0, 2)),
    )


def with_fill(blocks, level: float, density: float, x_lo: float, x_hi: float) -> list[Block]:
    """``blocks`` each carrying the mass of its fill (:func:`fill_over`; density kg/m³ × area × the block's
    thickness) lumped at the fill's centroid, added to any mass it carried before."""
    return carry(blocks, fill_over(blocks, level, x_lo, x_hi), density)


LEVEL_TOLERANCE = 1e-6
"""A fill read back from its carried masses (:func:`level_from_carried`) is one when every block's fill
centroid lies within this × the structure's size (at least 1 m) of its ``carried_at``, every block's
mass over its fill's area and thickness within this fraction of one density, and a block carrying none has at
most this share of the fill's area over it (a sliver of its top)."""


def level_from_carried(blocks) -> tuple[float, float, float] | None:
    """(level, x_lo, x_hi), m, of the fill whose weight the blocks carry (``Block.carried_mass`` at
    ``carried_at``), when it is one: a fill of one density up to one level over the blocks' top surface
    between the structure's ends, as :func:`with_fill` lays it (a built-in bridge's written to GeoJSON or to
    a scenario file's [[block]] tables). None for any other set of carried masses: nothing says their outline.

        Y = Σ w_i y_i / Σ w_i, w_i = carried_mass_i / thickness_i  (∝ the fill's area over block i)
        g(level) = the centroid y of fill_over(level), strictly increasing in the level (each layer added
            lies above the fill under it), below Y at the highest carried_at (every column's centroid is
            under the level), above it at 2 Y − the lowest vertex (a column's centroid is at least halfway up)
        level = the root of g − Y (bisection to the last bit); then check every block, as LEVEL_TOLERANCE says
    """
    mass = np.array([b.carried_mass for b in blocks], dtype=np.float64)
    if not blocks or not (mass > 0.0).any():
        return None
    carrying = mass > 0.0
    at = np.array([b.carried_at if m > 0.0 else (np.nan, np.nan) for b, m in zip(blocks, mass)], dtype=np.float64)
    thickness = np.array([b.thickness for b in blocks], dtype=np.float64)
    weight = mass / thickness
    target = float(np.sum(weight[carrying] * at[carrying, 1]) / weight.sum())
    x_lo, x_hi = _extent(blocks)
    pieces = top_surface(blocks, x_lo, x_hi)
    bottom = min(float(np.asarray(b.vertices)[:, 1].min()) for b in blocks)

    def centre(level: float) -> float:
        fill = fill_over(blocks, level, x_lo, x_hi, pieces)
        area = fill.area.sum()
        return -np.inf if area <= 0.0 else float(np.nansum(fill.area * fill.centroid[:, 1]) / area)

    lo, hi = float(at[carrying, 1].max()), 2.0 * target - bottom
    if not lo < hi:
        return None
    for _ in range(200):  # halves the bracket until it holds no float between its ends
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:
            break
        lo, hi = (mid, hi) if centre(mid) < target else (lo, mid)
    level = 0.5 * (lo + hi)
    fill = fill_over(blocks, level, x_lo, x_hi, pieces)
    size = max(1.0, x_hi - x_lo, level - bottom)
    # a block carrying nothing may show a sliver of the top (a column ~1e-8 m² once --settle moved the stones by
    # microns: the traced bridge's fill was no longer drawn); one carrying mass must be under the fill
    sliver = (fill.area > 0.0) & ~carrying
    if (carrying & ~(fill.area > 0.0)).any() or (fill.area[sliver] > LEVEL_TOLERANCE * fill.area.sum()).any():
        return None
    if np.hypot(*(fill.centroid[carrying] - at[carrying]).T).max() > LEVEL_TOLERANCE * size:
        return None
    density = mass[carrying] / (fill.area[carrying] * thickness[carrying])
    if np.abs(density / np.median(density) - 1.0).max() > LEVEL_TOLERANCE:
        return None
    return level, x_lo, x_hi


def spread_load(blocks, x: float, level: float, angle_deg: float) -> list[tuple[int, float, float, float]]:
    """A load at abscissa ``x`` on the fill's surface (``level``, m), spread down through the fill at
    ``angle_deg`` from the vertical onto the blocks' top (a wheel's load through a bridge's fill): uniform
    over x − h … x + h, h = d tan(angle), d the fill's depth over the top at x. Returns (block index, x, y,
    share) of each piece of the top it covers: the resultant of its part, at the middle of the part (a
    uniform load on a straight edge), shares summing to 1 (less a part past the structure's ends). No depth (the top at or above the level): all at x.
    """
    pieces = top_surface(blocks, *_extent(blocks))
    under = [p for p in pieces if p.a <= x <= p.b]
    if not under:
        return []
    depth = level - max(p.y(x) for p in under)
    half = depth * np.tan(np.radians(angle_deg)) if depth > 0 else 0.0
    if half <= 0.0:
        piece = max(under, key=lambda p: p.y(x))
        return [(piece.block, x, piece.y(x), 1.0)]
    out = []
    for p in pieces:  # a part of the strip past the structure's ends bears on the ground there: not counted
        lo, hi = max(p.a, x - half), min(p.b, x + half)
        if hi > lo:
            mid = 0.5 * (lo + hi)
            out.append((p.block, mid, p.y(mid), (hi - lo) / (2.0 * half)))
    return out


def _extent(blocks) -> tuple[float, float]:
    xs = np.concatenate([np.asarray(b.vertices)[:, 0] for b in blocks])
    return float(xs.min()), float(xs.max())


@dataclasses.dataclass(frozen=True, eq=False)
class TracedFill:
    """A traced fill's outline read over the structure: ``fill`` per block (area m², centroid m), and the areas
    (m²) over a support (resting on it) and of the outline not above the bodies' top (drawn into the stones, or
    over no body: no column to bear on)."""

    fill: Fill
    on_supports: float
    not_above: float


def traced_fill_over(blocks, supports, outline: Polygon) -> TracedFill:
    """The fill of a traced ``outline`` (m), per block: from the top surface of the blocks and the supports up to
    the outline's top, each column on the body topmost under it (module docstring; supports carry nothing). The
    outline's top is the fill's surface and the fill reaches down to the stones (a tracing's lower edge along the
    extrados, a few mm off the stones' chords, leaves no void under it), so a level outline between the
    structure's ends is fill_over's fill to that level.

        shadow = the outline swept down (its union with each edge's quadrilateral down to below every body)
        for each piece [a, b] of the bodies' top surface under the outline (top_surface over blocks + supports):
            part = shadow ∩ {a ≤ x ≤ b, y ≥ the piece's top line}
            add its area and first moments to the piece's block, or to on_supports
    """
    bodies = [*blocks, *supports]
    x_lo, _, x_hi, y_hi = outline.bounds
    floor = min([outline.bounds[1], *(b.polygon.bounds[1] for b in bodies)]) - 1.0
    xy = np.asarray(outline.exterior.coords)
    sweeps = [Polygon([p, q, (q[0], floor), (p[0], floor)]) for p, q in zip(xy[:-1], xy[1:]) if p[0] != q[0]]
    shadow = unary_union([outline, *sweeps])
    sums = np.zeros((len(blocks), 3))
    on_supports = outline_above = 0.0
    for piece in top_surface(bodies, x_lo, x_hi) if bodies else []:
        a, b = piece.a, piece.b
        column = Polygon([(a, piece.y(a)), (b, piece.y(b)), (b, y_hi + 1.0), (a, y_hi + 1.0)])
        outline_above += outline.intersection(column).area
        part = shadow.intersection(column)
        if part.is_empty or part.area <= 0.0:
            continue
        if piece.block >= len(blocks):
            on_supports += part.area
            continue
        centre = part.centroid
        sums[piece.block] += (part.area, centre.x * part.area, centre.y * part.area)
    area = sums[:, 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        centroid = np.where(area[:, None] > 0.0, sums[:, 1:] / area[:, None], np.nan)
    return TracedFill(Fill(area=area, centroid=centroid), on_supports, max(0.0, outline.area - outline_above))


def carry(blocks, fill: Fill, density: float) -> list[Block]:
    """``blocks`` each carrying the mass of its ``fill`` (density kg/m³ × area × the block's thickness) at the
    fill's centroid, added to any mass it carried before."""
    out = []
    for block, area, centre in zip(blocks, fill.area, fill.centroid):
        if area <= 0.0:
            out.append(block)
            continue
        mass = density * area * block.thickness
        total = block.carried_mass + mass
        before = np.asarray(block.carried_at if block.carried_at is not None else centre, dtype=np.float64)
        at = (block.carried_mass * before + mass * centre) / total
        out.append(dataclasses.replace(block, carried_mass=float(total), carried_at=(float(at[0]), float(at[1]))))
    return out
