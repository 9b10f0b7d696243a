"""Spandrel walls: running-bond courses over an arch, cut along its extrados into convex blocks.

Algorithm
---------
The extrados region E is the convex polygon bounded by the extrados chain (the voussoirs' outer
chords) and the springing line. Courses are horizontal bands of height h from the springing line up
to a level top, spanning the width between the piers' outer faces; their vertical joints follow the
running bond (every l, shifted by l/2 on alternate courses).

1. **Cut.** Every slab (band ∩ between two joints) minus E gives the raw pieces. Their boundary
   follows the chain exactly (same vertex coordinates as the voussoirs), so walls and arch neither
   overlap nor leave a gap.
2. **Merge across joints.** While a raw piece is smaller than ``min_fraction`` of a full block
   (default 5 %), the vertical joint between it and its neighbour in the course (the one it shares
   the longer edge with) is removed — the piece becomes part of a longer block, as a mason would cut
   one stone instead of two. Removing a joint keeps the union a "band ∩ slab − E" piece.
3. **Split into convex blocks.** A piece is not convex where a chain vertex lies strictly inside
   its band (the extrados bulges into it). Each such reflex vertex is resolved by a straight cut
   from it to another vertex of the piece, or along a vertical, horizontal or radial ray; among the
   cuts that make that vertex convex, the one whose smaller side is largest is taken, recursively.
4. **Last slivers.** A block still below ``min_fraction`` is merged with a touching wall block if
   their union is convex. If none is, it is kept when thicker than ``hair`` (1 mm, measured as
   2·area/perimeter) and dropped otherwise (the gap it leaves is thinner than a hair).

The result depends only on the parameters (no randomness), is mirror-symmetric about the arch axis
when the bond is, and every block is a convex polygon.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import LineString, Polygon, box

from ..blocks import GeometryError
from ..checks import COLLINEAR_RTOL, _next, _remove_collinear, _turn_cross, is_convex, signed_area

DUST = 1e-10  # m², pieces below this are clipping noise


def _components(geom) -> list[Polygon]:
    """Polygons of a clipping result, dropping dust and lower-dimensional leftovers."""
    if geom.is_empty:
        return []
    parts = getattr(geom, "geoms", [geom])
    return [p for p in parts if isinstance(p, Polygon) and p.area > DUST]


def _ring(poly: Polygon) -> np.ndarray:
    """CCW exterior without repeat or collinear vertices."""
    xy = np.asarray(poly.exterior.coords)[:-1, :2]
    if signed_area(xy) < 0:
        xy = xy[::-1]
    return _remove_collinear(xy)


@dataclass(frozen=True)
class Limits:
    """Smallest acceptable block: ``area`` m² and ``thickness`` m (thickness = 2·area/perimeter,
    the inradius of a regular shape; a 0.30 × 0.20 block has 0.12 m, a 1 cm strip about 1 cm)."""

    area: float
    thickness: float

    def quality(self, xy: np.ndarray) -> float:
        """min(area / limit, thickness / limit) of a CCW ring: < 1 means a sliver."""
        area = signed_area(xy)
        perimeter = float(np.sum(np.hypot(*(_next(xy) - xy).T)))
        return min(area / self.area, 2.0 * area / perimeter / self.thickness)


def _shared_length(a: Polygon, b: Polygon) -> float:
    inter = shapely.intersection(a.boundary, b.boundary)
    return float(inter.length) if not inter.is_empty else 0.0


def _course_blocks(
    joints: list[float], y0: float, y1: float, region: Polygon, centre: np.ndarray, limits: Limits
) -> list[Polygon]:
    """Steps 1–3 for one course: cut, split into convex blocks, and drop vertical joints next to
    slivers (quality < 1) until none is left or no joint can help."""
    joints = list(joints)
    stuck: set[tuple[float, float]] = set()
    cache: dict[tuple[float, float], list[np.ndarray]] = {}
    while True:
        parts: list[tuple[int, np.ndarray]] = []
        for k, (a, b) in enumerate(zip(joints[:-1], joints[1:])):
            if (a, b) not in cache:
                cache[(a, b)] = [
                    r
                    for piece in _components(box(a, y0, b, y1).difference(region))
                    for r in convex_split(_ring(piece), centre, limits)[1]
                ]
            parts += [(k, r) for r in cache[(a, b)]]
        small = [
            (limits.quality(r), k, Polygon(r))
            for k, r in parts
            if limits.quality(r) < 1.0 and (joints[k], joints[k + 1]) not in stuck
        ]
        if not small:
            return [Polygon(r) for _, r in parts]
        _, k, piece = min(small, key=lambda t: (t[0], t[1]))
        options = []
        for side, j in ((-1, k), (1, k + 1)):
            if 0 < j < len(joints) - 1:
                line = LineString([(joints[j], y0), (joints[j], y1)])
                touch = float(shapely.intersection(piece.boundary, line).length)
                options.append((touch, -abs(piece.centroid.x - joints[j]), side, j))
        if not options or max(options)[0] <= 1e-9:
            stuck.add((joints[k], joints[k + 1]))
            continue
        del joints[max(options)[3]]


def _split_ring(xy: np.ndarray, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
    """Cut the ring along the diagonal i–j: (i … j) and (j … i), both inclusive."""
    n = len(xy)
    if j < i:
        i, j = j, i
    return xy[i : j + 1], np.concatenate([xy[j:], xy[: i + 1]])


def _ray_hit(xy: np.ndarray, i: int, d: np.ndarray) -> tuple[int, np.ndarray] | None:
    """First edge (index e: xy[e]→xy[e+1]) hit by the ray from vertex i along d, and the point."""
    n = len(xy)
    p = xy[i]
    best = None
    for e in range(n):
        if e == i or (e + 1) % n == i:
            continue
        a, b = xy[e], xy[(e + 1) % n]
        s = b - a
        den = d[0] * s[1] - d[1] * s[0]
        if abs(den) < 1e-15:
            continue
        w = a - p
        t = (w[0] * s[1] - w[1] * s[0]) / den
        u = (w[0] * d[1] - w[1] * d[0]) / den
        if t > 1e-12 and -1e-12 <= u <= 1 + 1e-12 and (best is None or t < best[0]):
            best = (t, e, p + t * d)
    return None if best is None else (best[1], best[2])


def _valid_cut(a: np.ndarray, b: np.ndarray, total: float) -> bool:
    area_a, area_b = signed_area(a), signed_area(b)
    if area_a <= DUST or area_b <= DUST or abs(area_a + area_b - total) > 1e-9 * total:
        # (a cut leaving the ring makes one side clockwise or self-intersecting)
        return False
    return Polygon(a).is_valid and Polygon(b).is_valid


def _reflex(xy: np.ndarray) -> np.ndarray:
    cross, scale = _turn_cross(xy)
    return np.flatnonzero(cross < -COLLINEAR_RTOL * scale)


def _cuts(xy: np.ndarray, i: int, centre: np.ndarray):
    """Every admissible cut from reflex vertex i: pairs of sub-rings leaving vertex i convex."""
    n = len(xy)
    total = signed_area(xy)
    candidates = [(xy, i, j) for j in range(n) if j not in (i, (i - 1) % n, (i + 1) % n)]
    radial = xy[i] - centre
    for d in ((0.0, 1.0), (0.0, -1.0), (1.0, 0.0), (-1.0, 0.0), tuple(radial / np.hypot(*radial))):
        hit = _ray_hit(xy, i, np.asarray(d))
        if hit is None:
            continue
        e, point = hit
        ext = np.insert(xy, e + 1, point, axis=0)
        candidates.append((ext, i + 1 if i > e else i, e + 1))
    for ring, ii, jj in candidates:
        a, b = _split_ring(ring, ii, jj)
        if not _valid_cut(a, b, total):
            continue
        # The cut vertex is the first/last vertex of the sub-rings; it must be convex in both.
        at_a, at_b = (0, len(b) - 1) if ii < jj else (len(a) - 1, 0)
        if at_a in _reflex(a).tolist() or at_b in _reflex(b).tolist():
            continue
        yield a, b


def convex_split(
    xy: np.ndarray, centre: np.ndarray, limits: Limits, depth: int = 0
) -> tuple[float, list[np.ndarray]]:
    """Step 3: split a CCW ring into convex rings by straight cuts from its reflex vertices.

    Returns (worst part quality, parts), choosing the cuts that maximise the worst quality
    (:meth:`Limits.quality`: area and thickness relative to the limits).

    Pseudo-code::

        if no reflex vertex: return area, [ring]
        v = first reflex vertex (every decomposition must cut at v)
        for each cut from v (to another vertex, or along a ray up / down / left / right / away
        from ``centre``) that stays inside the ring and leaves v convex on both sides:
            split both sides recursively; score = worst part quality
        return the best score (ties: fewer parts)
    """
    xy = _remove_collinear(xy)
    reflex = _reflex(xy)
    if reflex.size == 0:
        return limits.quality(xy), [xy]
    if depth > 8:
        raise GeometryError("spandrel: could not split a wall piece into convex blocks (builder bug)")
    best = None
    for a, b in _cuts(xy, int(reflex[0]), centre):
        sa, pa = convex_split(a, centre, limits, depth + 1)
        sb, pb = convex_split(b, centre, limits, depth + 1)
        key = (min(sa, sb), -(len(pa) + len(pb)))
        if best is None or key > best[0]:
            best = (key, pa + pb)
    if best is None:
        raise GeometryError("spandrel: could not split a wall piece into convex blocks (builder bug)")
    return best[0][0], best[1]


def spandrel_blocks(
    region: Polygon,
    centre: np.ndarray,
    x_min: float,
    x_max: float,
    y_base: float,
    courses: int,
    block_length: float,
    block_height: float,
    first_offset: bool = False,
    min_fraction: float = 0.05,
    min_thickness: float = 0.1,
    hair: float = 1e-3,
) -> list[tuple[int, Polygon]]:
    """Convex spandrel blocks as (course index from 0, polygon), bottom course first, left to right.

    Parameters
    ----------
    region : the extrados polygon E (area the wall must not enter), m.
    centre : (2,) arch centre, m — radial cuts point away from it.
    x_min, x_max : wall ends, m. y_base : bottom of the first course, m.
    courses : number of courses; the level top is at y_base + courses · block_height.
    block_length, block_height : full block size, m.
    first_offset : if True the first course's joints are shifted by half a block.
    min_fraction : pieces smaller than this fraction of a full block are slivers (see module doc).
    min_thickness : pieces thinner (2·area/perimeter) than this fraction of the block height are
        slivers too.
    hair : m — a sliver that cannot be merged is dropped only if thinner than this.
    """
    limits = Limits(min_fraction * block_length * block_height, min_thickness * block_height)
    half = 0.5 * block_length
    mid = 0.5 * (x_min + x_max)
    pieces: list[tuple[int, Polygon]] = []
    for c in range(courses):
        y0, y1 = y_base + c * block_height, y_base + (c + 1) * block_height
        shift = (c + int(first_offset)) % 2
        # Joints at mid + (2k + shift) · l/2: mirror-symmetric about the wall's axis.
        k_lo = math.floor((x_min - mid) / half) - 1
        k_hi = math.ceil((x_max - mid) / half) + 1
        inner = [
            mid + k * half
            for k in range(k_lo, k_hi + 1)
            if (k - shift) % 2 == 0 and x_min + 1e-9 < mid + k * half < x_max - 1e-9
        ]
        for poly in _course_blocks([x_min, *inner, x_max], y0, y1, region, centre, limits):
            pieces.append((c, poly))
    pieces = _merge_slivers(pieces, limits, hair)
    pieces.sort(key=lambda cp: (cp[0], cp[1].centroid.x))
    return pieces


def _merge_slivers(pieces: list[tuple[int, Polygon]], limits: Limits, hair: float):
    """Step 4: merge remaining slivers into a touching block when the union is convex."""
    pieces = list(pieces)
    kept: set[int] = set()  # ids of slivers we gave up on
    while True:
        small = [
            (q, k)
            for k, (c, p) in enumerate(pieces)
            if (q := limits.quality(_ring(p))) < 1.0 and id(p) not in kept
        ]
        if not small:
            return pieces
        _, k = min(small)
        c, p = pieces[k]
        options = []
        for m, (cm, q) in enumerate(pieces):
            if m == k or not p.intersects(q):
                continue
            shared = _shared_length(p, q)
            if shared <= 1e-9:
                continue
            union = shapely.union(p, q)
            if isinstance(union, Polygon) and not union.interiors and is_convex(_ring(union)):
                options.append((-shared, m, cm, union))
        if options:
            _, m, cm, union = min(options, key=lambda t: (t[0], t[1]))
            pieces[m] = (cm, Polygon(_ring(union)))
            del pieces[k]
        elif 2.0 * p.area / p.length < hair:
            del pieces[k]
        else:
            kept.add(id(p))
