"""Spandrel walls: running-bond courses over an arch, cut along its extrados into convex blocks.

Algorithm
---------
The extrados region E is the convex polygon bounded by the extrados chain (the voussoirs' outer
chords) and the springing line. Courses are horizontal bands of height h from the springing line up
to a level top, spanning the width between the piers' outer faces; their vertical joints follow the
running bond (every l, shifted by l/2 on alternate courses, mirror-symmetric about the arch axis).

A block is a *sliver* when its area is below ``min_fraction`` of a full block (default 5 %) or its
thickness 2·area/perimeter is below ``min_thickness`` × h (default 0.15 × 0.20 = 3 cm); its
quality is min(area / limit, thickness / limit), < 1 for a sliver.

1. **Cut.** Every slab (band ∩ between two vertical joints) minus E gives the raw pieces. Their
   boundary follows the chain exactly (the voussoirs' own vertex coordinates), so the wall and the
   arch neither overlap nor leave a gap.
2. **Split into convex blocks.** A piece is not convex where a chain vertex lies strictly inside its
   band (the extrados bulges into it). Each such reflex vertex is resolved by a straight cut from
   it to another vertex of the piece, or along a ray (vertical, horizontal, radial — continuing the
   voussoir joint —, extending an edge, or bisecting the vertex); the decomposition whose worst
   block has the best quality is kept (exhaustive search up to 2 reflex vertices, greedy beyond).
3. **Merge across joints.** While a course has a sliver, the vertical joint it touches most is
   removed (the two slabs become one longer stone, as a mason would cut one stone instead of two)
   and the slab is cut and split again.
4. **Re-cut the last slivers.** A remaining sliver is united with each touching wall block in turn
   and the union split again (or kept whole if convex); the best result replaces both if its worst
   block beats the sliver. Otherwise the sliver is dropped if thinner than ``hair`` (1 mm — the
   gap it leaves is a hair) and kept as it is if not.

Limits: a convex block can follow only one chord of the extrados, so an arch whose chords are much
shorter than a wall block (many voussoirs on a small ring, e.g. 100 voussoirs on 2.15 m) leaves
small blocks along the extrados. The result depends only on the parameters, is mirror-symmetric
about the arch axis, and every block is a convex polygon.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import LineString, Polygon, box

from ..blocks import GeometryError
from ..checks import COLLINEAR_RTOL, _next, _turn_cross, is_convex, signed_area

DUST = 1e-10  # m², pieces below this are clipping noise
EXHAUSTIVE = 2  # pieces with at most this many reflex vertices get an exhaustive split search


def _components(geom) -> list[Polygon]:
    """Polygons of a clipping result, dropping dust and lower-dimensional leftovers."""
    if geom.is_empty:
        return []
    parts = getattr(geom, "geoms", [geom])
    return [p for p in parts if isinstance(p, Polygon) and p.area > DUST]


def _ring(poly: Polygon) -> np.ndarray:
    """CCW exterior without repeat, collinear vertices or spikes."""
    xy = np.asarray(poly.exterior.coords)[:-1, :2]
    if signed_area(xy) < 0:
        xy = xy[::-1]
    return _clean(xy)


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
    joints: list[float], y0: float, y1: float, region: Polygon, centre: np.ndarray, limits: Limits, memo: dict
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
                    for r in convex_split(_ring(piece), centre, limits, memo)[1]
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
    if j < i:
        i, j = j, i
    return xy[i : j + 1], np.concatenate([xy[j:], xy[: i + 1]])


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _ray_hit(xy: np.ndarray, i: int, d: np.ndarray) -> tuple[int, np.ndarray] | None:
    """First edge e (xy[e]→xy[e+1]) hit strictly inside by the ray from vertex i along d, and the
    hit point; None if the ray first meets a vertex (vertex targets cover that case)."""
    n = len(xy)
    a = xy
    s = _next(xy) - xy
    w = a - xy[i]
    den = _cross(np.broadcast_to(d, s.shape), s)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = _cross(w, s) / den
        u = _cross(w, np.broadcast_to(d, s.shape)) / den
    ok = (np.abs(den) > 1e-15) & (t > 1e-12) & (u > -1e-12) & (u < 1 + 1e-12)
    ok[[i, (i - 1) % n]] = False
    if not ok.any():
        return None
    e = int(np.flatnonzero(ok)[np.argmin(t[ok])])
    if u[e] < 1e-9 or u[e] > 1 - 1e-9:
        return None
    return e, xy[i] + t[e] * d


def _clear(xy: np.ndarray, i: int, w: np.ndarray, skip: tuple[int, ...]) -> bool:
    """True if the open segment xy[i]→w touches no edge of the ring except the edges in ``skip``."""
    a, b = xy, _next(xy)
    v = xy[i]
    d = w - v
    tol = 1e-12 * float(np.abs(xy).max() + 1.0) ** 2
    o1, o2 = _cross(d, a - v), _cross(d, b - v)
    o3, o4 = _cross(b - a, v - a), _cross(b - a, w - a)
    hit = (o1 * o2 <= tol * tol) & (o3 * o4 <= tol * tol)
    # Colinear edges far along the same line give o1 = o2 = 0: only a real overlap counts.
    hit[list(skip)] = False
    return not hit.any()


def _reflex(xy: np.ndarray) -> np.ndarray:
    """Indices of the reflex vertices of a CCW ring (cleaned by :func:`_clean`)."""
    cross, scale = _turn_cross(xy)
    return np.flatnonzero(cross < -COLLINEAR_RTOL * scale)


def _clean(xy: np.ndarray) -> np.ndarray:
    """Drop from a CCW ring the vertices that shape nothing: straight angles, zero-width spikes, and
    any vertex whose triangle with its two neighbours is dust (area ≤ DUST).

    The dust rule is for an extrados vertex falling on, or a hair beside, a vertical joint: span 0.5 m
    puts the voussoir corner at x = -0.6 cos 60° = -0.30000000000000004 against the joint at -0.3,
    span 2.4176914536 one 1e-11 m beside the joint at -1.35. The piece then has an edge of 6e-17 or
    2e-11 m whose angle is round-off but far above the collinearity tolerance relative to that edge:
    the vertex looked reflex, every cut resolving it cut off dust, and the build failed. Dropping it
    moves the piece's outline by at most DUST m² (the overlap check allows 1e-9 m²).
    """
    while len(xy) > 3:
        cross, scale = _turn_cross(xy)
        flat = np.flatnonzero((np.abs(cross) <= COLLINEAR_RTOL * scale) | (np.abs(cross) <= 2.0 * DUST))
        if flat.size == 0:
            break
        xy = np.delete(xy, flat[0], axis=0)
    return xy


def _cuts(xy: np.ndarray, i: int, centre: np.ndarray):
    """Every admissible cut from reflex vertex i, as pairs of sub-rings.

    A cut along d from v = xy[i] leaves v convex on both sides iff d lies left of the incoming and
    of the outgoing edge (cross(e_in, d) ≥ 0 and cross(e_out, d) ≥ 0: the "resolving cone"); it is
    admissible if it also reaches its end — another vertex, or the first edge hit by a ray along
    a fixed direction — without touching the ring. The cone's bisector always qualifies.
    """
    n = len(xy)
    v = xy[i]
    e_in, e_out = v - xy[i - 1], xy[(i + 1) % n] - v

    def resolves(d: np.ndarray) -> bool:
        # Strictly left of both edges, or exactly along the extension of one of them (that side
        # then gets a straight angle at v, which normalisation removes).
        ok = True
        for e, forward in ((e_in, 1.0), (e_out, -1.0)):
            tol = COLLINEAR_RTOL * np.hypot(*d) * np.hypot(*e)
            c = _cross(e, d)
            ok &= bool(c > tol or (abs(c) <= tol and forward * float(np.dot(e, d)) > 0))
        return ok

    candidates = []
    for j in range(n):
        if j in (i, (i - 1) % n, (i + 1) % n) or not resolves(xy[j] - v):
            continue
        skip = {i, (i - 1) % n, j, (j - 1) % n}
        if _clear(xy, i, xy[j], tuple(skip)):
            candidates.append((xy, i, j))
    radial = v - centre
    left_in = np.array([-e_in[1], e_in[0]]) / np.hypot(*e_in)
    left_out = np.array([-e_out[1], e_out[0]]) / np.hypot(*e_out)
    directions = [
        (0.0, 1.0),
        (0.0, -1.0),
        (1.0, 0.0),
        (-1.0, 0.0),
        radial / np.hypot(*radial),  # continues the voussoir joint
        e_in,
        -e_out,  # extends an edge of the piece
        left_in + left_out,  # bisects the cone: always admissible
    ]
    for d in directions:
        d = np.asarray(d, dtype=np.float64)
        d = d / np.hypot(*d)
        if not resolves(d):
            continue
        hit = _ray_hit(xy, i, d)
        if hit is None:
            continue
        e, point = hit
        ext = np.insert(xy, e + 1, point, axis=0)
        candidates.append((ext, i + 1 if i > e else i, e + 1))
    for ring, ii, jj in candidates:
        if not _off_cut(ring, ii, jj):
            continue
        a, b = _split_ring(ring, ii, jj)
        if signed_area(a) > DUST and signed_area(b) > DUST:
            yield a, b


def _off_cut(ring: np.ndarray, i: int, j: int) -> bool:
    """True if no vertex other than the ends lies on the segment ring[i]–ring[j] (a cut grazing a
    vertex would make a self-touching side)."""
    p, q = ring[i], ring[j]
    d = q - p
    length2 = float(d @ d)
    others = np.delete(ring, [i, j], axis=0) - p
    t = np.clip(others @ d / length2, 0.0, 1.0)
    gap = np.hypot(*(others - t[:, None] * d).T)
    return bool(np.all(gap > 1e-9 * np.sqrt(length2)))


def _split_key(parts: list[np.ndarray], limits: Limits) -> tuple:
    """Ranking of a decomposition: worst quality first, then fewer parts, then the other qualities
    (leximin). Qualities are rounded so mirror-image pieces rank their mirror-image cuts alike."""
    q = sorted(round(limits.quality(p), 9) for p in parts)
    return (q[0], -len(parts), tuple(q))


def convex_split(
    xy: np.ndarray, centre: np.ndarray, limits: Limits, memo: dict | None = None
) -> tuple[tuple, list[np.ndarray]]:
    """Step 3: split a CCW ring into convex rings by straight cuts from its reflex vertices.

    Returns (ranking key, parts) for the best decomposition found: the one whose worst part has
    the highest :meth:`Limits.quality` (ties: fewer parts, then the next-worst part, ...). ``memo``: ring
    bytes -> result, shared by the calls of one ``centre`` and ``limits`` (a course splits the same
    pieces again as its joints are dropped); None: a fresh one.

    Pseudo-code::

        if no reflex vertex: return [ring]
        for each reflex vertex v, for each cut from v (to another vertex, or along a ray up / down /
        left / right / away from ``centre``) that stays inside the ring and leaves v convex on
        both sides:
            decompose both sides recursively
        return the best-ranked decomposition
    """
    memo = {} if memo is None else memo
    xy = _clean(xy)
    memo_key = xy.tobytes()
    if memo_key in memo:
        return memo[memo_key]
    reflex = _reflex(xy)
    if reflex.size == 0:
        return _split_key([xy], limits), [xy]
    # Every reflex vertex is tried as the first cut, so mirror-image pieces get mirror-image splits.
    cuts = [ab for v in reflex.tolist() for ab in _cuts(xy, v, centre)]
    if not cuts:
        raise GeometryError("spandrel: could not split a wall piece into convex blocks (builder bug)")
    if reflex.size > EXHAUSTIVE:
        # Many reflex vertices (a fine extrados along a long piece): greedy, to bound the search —
        # take the cut whose two sides rank best as they are, then split those.
        a, b = max(cuts, key=lambda ab: _split_key(list(ab), limits))
        parts = convex_split(a, centre, limits, memo)[1] + convex_split(b, centre, limits, memo)[1]
        best = (_split_key(parts, limits), parts)
    else:
        best = None
        for a, b in cuts:
            parts = convex_split(a, centre, limits, memo)[1] + convex_split(b, centre, limits, memo)[1]
            key = _split_key(parts, limits)
            if best is None or key > best[0]:
                best = (key, parts)
    memo[memo_key] = best
    return best


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
    min_thickness: float = 0.15,
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
    memo: dict[bytes, tuple] = {}
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
        for poly in _course_blocks([x_min, *inner, x_max], y0, y1, region, centre, limits, memo):
            pieces.append((c, poly))
    pieces = _merge_slivers(pieces, centre, limits, hair)
    pieces.sort(key=lambda cp: (cp[0], cp[1].centroid.x))
    return pieces


def _merge_slivers(pieces: list[tuple[int, Polygon]], centre: np.ndarray, limits: Limits, hair: float):
    """Step 4: re-cut each remaining sliver together with a touching block.

    Pseudo-code::

        while some block p has quality < 1 (and was not given up on):
            for each block q sharing an edge with p:
                u = p ∪ q; parts = [u] if u is convex else convex_split(u)
            take the best-ranked parts; if their worst quality beats min(quality p, quality q),
            replace p and q by them (a merge when parts == [u]); otherwise drop p if it is thinner
            than a hair, else keep it as it is.
    """
    pieces = list(pieces)
    kept: set[int] = set()  # ids of slivers we gave up on
    memo: dict[bytes, tuple] = {}  # convex_split's, for this centre and these limits
    for _ in range(10 * len(pieces) + 10):
        small = [
            (q, k) for k, (c, p) in enumerate(pieces) if (q := limits.quality(_ring(p))) < 1.0 and id(p) not in kept
        ]
        if not small:
            break
        q_p, k = min(small)
        c, p = pieces[k]
        best = None
        for m, (cm, q) in enumerate(pieces):
            if m == k or not p.intersects(q) or _shared_length(p, q) <= 1e-9:
                continue
            union = shapely.union(p, q)
            if not isinstance(union, Polygon) or union.interiors:
                continue
            ring = _ring(union)
            try:
                parts = [ring] if is_convex(ring) else convex_split(ring, centre, limits, memo)[1]
            except GeometryError:  # a degenerate union (pieces touching at a vertex)
                continue
            key = _split_key(parts, limits)
            if key[0] > round(min(q_p, limits.quality(_ring(q))), 9) and (best is None or key > best[0]):
                best = (key, m, min(c, cm), parts)
        if best is not None:
            _, m, course, parts = best
            pieces = [cp for n, cp in enumerate(pieces) if n not in (k, m)]
            pieces += [(course, Polygon(r)) for r in parts]
        elif 2.0 * p.area / p.length < hair:
            del pieces[k]
        else:
            kept.add(id(p))
    return pieces
