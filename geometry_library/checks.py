"""Validation and normalisation of block polygons, and the tolerances of the whole-assembly checks
(:mod:`geometry_library.assembly_checks`: ``validate_assembly``, ``overlap_depth``).

Every error is a :class:`GeometryError` whose message is one line naming the body, numbered from 1 in
the order of the file (:func:`body_label`), for example::

    block 7 ("c03-b02"): polygon is not convex (reflex vertex at (0.45, 0.6))
    blocks 4 ("c01-b04") and 5 ("c01-b05") overlap by 2.5e-05 m², 7 mm deep (tolerance 6e-05 m², 0.5 mm deep)

Normalised polygons are counter-clockwise, without the closing repeat, without duplicate or
collinear consecutive vertices (collinear points are allowed on input and silently removed).

Tolerances
----------
They scale with the block, so a file exact to float32 (GIS / CAD exports: ~7 significant digits) or to
0.1 mm (a wall drawn in CAD) is accepted and cleaned, whatever the units' origin, while a real dent or
overlap is refused. A block's *width* is ``w = area / size`` (size: its bounding-box diagonal; 0.17 m for
a 0.3 × 0.2 m block, 0.7 mm for a sliver voussoir of a 8000-block arch) and its *shape tolerance* is
``h = SHAPE_RTOL × w`` (``SHAPE_RTOL`` = 2e-3: 0.33 mm on a 0.3 × 0.2 m block), at most
``MAX_SHAPE_TOLERANCE`` = 0.5 mm, half the contact detection distance (a 20 × 2 m ground's 4 mm removed a
3 mm crown: the block resting on it floated above the cleaned ground, out of contact):

- two consecutive vertices closer than ``h`` are one vertex;
- a vertex less than ``h`` from the line through its two neighbours (and between them) is removed, on
  either side: a mid-edge vertex that rounding put just outside the edge (it would overlap the
  neighbour) or just inside (it would be "reflex"). The least deep goes first, until none is left, so
  the result is a fixed point (cleaning it again gives it back);
- a vertex more than ``h`` inside that line is a reflex vertex: the polygon is not convex;
- two bodies overlapping by at most ``OVERLAP_RTOL × `` the smaller one's area (1e-3, i.e. a sliver
  ``h / 2`` deep along a whole face) are accepted; ``validate_assembly(overlap_tolerance=…)`` sets an
  absolute tolerance in m² instead;
- and only if the overlap is at most ``OVERLAP_MAX_DEPTH`` (0.5 mm, half the contact detection distance)
  deep: an area alone let a 0.3 × 0.2 m block's corner sit 7 mm inside the ground (a 45° corner's
  triangle, 4.9e-5 m², is under 6e-5 m²) — seven times the distance at which the engine sees a contact.
  The depth is the overlap's *thickness*: the minimum width of the (convex) intersection, over its
  edges the largest distance of a vertex to the edge's line — for a corner inside a face the corner's
  distance to it, for a face sunk along its length how far it is sunk; a few vertices, so cheap, and it
  needs no choice of direction. Absolute, not ``h``: the engine's contact distance is absolute, and a
  rounded joint (0.14 mm at 0.1 mm rounding, 0.1 µm in float32 at 1 m) stays far below it. Small
  bodies are held by the area: a 1.6 cm square's 45° corner 0.5 mm deep is already over 1e-3 of its area.

Why 2e-3 of the width. Rounding to float32 moves a vertex by up to 2⁻²⁴ × its coordinate (6e-8 m at
1 m, 6e-5 m at 1000 m); rounding to 0.1 mm by up to 0.07 mm; the worst depth of a rounded mid-edge
vertex is about twice that (0.14 mm for 0.1 mm). ``h`` is above these for blocks wider than ~7 cm and,
for 0.3 × 0.2 m blocks, coordinates up to ~2 km from the origin, and three times below a 1 mm dent or overlap on a 0.3 × 0.2 m
block, which is refused. Removing one vertex within ``h`` changes the block's area by at most
``h × size / 2 = SHAPE_RTOL / 2 × area`` (0.1 %); removals add up (four faces each bulged by ``h`` on a
0.3 × 0.2 m block lose 0.37 %, a 1000-gon circle 0.16 %, measured 2026-11-27), and the cleaned outline
stays within ``h`` of the drawn one (on a 0.3 × 0.2 m block a third of the default contact detection
distance, 1 mm). (The old tests, 1e-9 relative angle and 1e-9 m² of
overlap, refused the built-in aqueduct exported in float32 — a spandrel block's rounded corner off a
voussoir's sloping extrados overlaps it by 8e-9 m² — and the arch with a vertex split on its joints.)

Coordinates far from the origin in float32 (a local map grid) are coarse: when every coordinate is a
float32 value and the float32 resolution there exceeds a tenth of the smallest ``h``,
``validate_assembly`` warns (one line), and a refusal says to shift the coordinates near the origin.

Units sanity bounds, not rounding tolerances: areas below ``MIN_AREA`` (1e-10 m², a 10 µm square) are
zero, above ``MAX_AREA`` (1e6 m²) absurd (wrong units); a vertex beyond ``MAX_COORDINATE`` (1e6 m) from
the origin is absurd too. ``COLLINEAR_RTOL`` (1e-9 × |e1| |e2| on the cross product) is the exact-geometry
test of :func:`is_convex`, which the builders use on float64 geometry they construct.

Normalised once
---------------
Normalising costs ~0.2 ms a polygon (validity, SVD, vertex loops) and is idempotent: a normalised ring
comes back unchanged. The builders and readers normalise every body and ``validate_assembly`` normalised
them all again (an 8000-voussoir arch: 16 140 passes for 8070 bodies). Polygons made here by
:func:`normalised_polygon` are remembered by identity (shapely geometries are immutable; a weak map, so
nothing is kept alive), and :func:`normalise_polygon` hands such a polygon back as it is. Any other
polygon, e.g. one a user put in a ``Block`` by hand or one that came back from another process, is
normalised and checked in full; if that leaves its ring exactly as it was (an unpickled normalised
polygon), the polygon itself is remembered and handed back, so a process checks it once.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry import Polygon

from .blocks import GeometryError
from .float32 import float32_hint

COLLINEAR_RTOL = 1e-9
# Shape tolerance h = SHAPE_RTOL × width of the block (module docstring, Tolerances).
SHAPE_RTOL = 2e-3
# m: h never exceeds half the default contact detection distance (CONTACT_DISTANCE below): a removed vertex
# of a wide support (20 × 2 m: 2e-3 × 1 m = 4 mm) must not leave the block resting on it out of contact.
MAX_SHAPE_TOLERANCE = 5e-4
# Overlap tolerance of a pair: OVERLAP_RTOL × the smaller body's area (a sliver h / 2 deep along a face).
OVERLAP_RTOL = 1e-3
# m: the deepest overlap accepted (the overlap's minimum width; module docstring, Tolerances).
OVERLAP_MAX_DEPTH = MAX_SHAPE_TOLERANCE
MIN_AREA = 1e-10
MAX_AREA = 1e6
# m: a vertex farther than this from the origin is refused. Products of larger coordinates (areas, cross
# products) overflow or lose all precision in float64, so the convexity test could no longer be trusted.
MAX_COORDINATE = 1e6
# vertices of one outline as given: the clean-up removes them one at a time (about n² work): 10 000 took
# 0.7 s of CPU, a 100 000-vertex circle over 60 s before any word. A stone traced at every pixel of a scan.
MAX_VERTICES = 10_000
CONTACT_DISTANCE = 1e-3

# id -> polygon made by normalised_polygon; the entry goes when the polygon does, so an id is never
# matched by a later object that reuses it.
_NORMALISED: weakref.WeakValueDictionary[int, Polygon] = weakref.WeakValueDictionary()


class NotConvexError(GeometryError):
    """A polygon refused as not convex (and nothing else): a reader may take its convex hull instead
    (:mod:`geometry_library.survey`)."""


def body_label(index: int, name: str, kind: str = "block") -> str:
    """``block 7 ("c03-b02")`` for ``blocks[6]`` — how every message names a body: ``index`` is its
    0-based position among the bodies of its kind, shown from 1 as the user counts them in the file (the
    TOML reader's ``[[block]] #7``; the overlap message said ``blocks 0 ("block-1")``)."""
    return f'{kind} {index + 1} ("{name}")'


def _fmt(p: Sequence[float]) -> str:
    return f"({p[0]:.6g}, {p[1]:.6g})"


def _next(xy: np.ndarray) -> np.ndarray:
    """Vertices shifted by one: xy[i + 1] (cyclic). Cheaper than np.roll on small arrays."""
    return np.concatenate((xy[1:], xy[:1]))


def _prev(xy: np.ndarray) -> np.ndarray:
    """xy[i − 1] (cyclic)."""
    return np.concatenate((xy[-1:], xy[:-1]))


def _turn_cross(xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cross products e_{i-1} × e_i at every vertex and their collinearity scale |e_{i-1}| |e_i|."""
    e_in = xy - _prev(xy)
    e_out = _next(xy) - xy
    cross = e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0]
    scale = np.hypot(e_in[:, 0], e_in[:, 1]) * np.hypot(e_out[:, 0], e_out[:, 1])
    return cross, scale


def _remove_collinear(xy: np.ndarray) -> np.ndarray:
    """Drop vertices lying on the straight line through their neighbours (CCW ring, no repeat)."""
    while len(xy) > 3:
        cross, scale = _turn_cross(xy)
        e_in = xy - _prev(xy)
        e_out = _next(xy) - xy
        dot = np.einsum("ij,ij->i", e_in, e_out)
        straight = np.flatnonzero((np.abs(cross) <= COLLINEAR_RTOL * scale) & (dot > 0.0))
        if straight.size == 0:
            break
        xy = np.delete(xy, straight[0], axis=0)
    return xy


def signed_area(xy: np.ndarray) -> float:
    """Shoelace signed area of a ring (k, 2) without closing repeat; > 0 for counter-clockwise."""
    p = xy - xy.mean(axis=0)
    q = _next(p)
    return 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))


def is_convex(xy: np.ndarray) -> bool:
    """True if the CCW ring ``xy`` (k, 2), collinear vertices allowed, is convex within tolerance."""
    xy = _remove_collinear(np.asarray(xy, dtype=np.float64))
    cross, scale = _turn_cross(xy)
    return bool(len(xy) >= 3 and np.all(cross > COLLINEAR_RTOL * scale))


def shape_tolerance(xy: np.ndarray) -> float:
    """The shape tolerance ``h`` of a ring (k, 2), m: ``SHAPE_RTOL × |area| / size``, at most
    ``MAX_SHAPE_TOLERANCE`` (module docstring)."""
    size = float(np.hypot(*(xy.max(axis=0) - xy.min(axis=0))))
    return min(SHAPE_RTOL * abs(signed_area(xy)) / size, MAX_SHAPE_TOLERANCE) if size > 0.0 else 0.0


def _depth(xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Signed distance of every vertex from the line through its two neighbours (> 0: a convex turn of a
    CCW ring, < 0: reflex), and whether the vertex lies between them (its two edges point the same way)."""
    e_in = xy - _prev(xy)
    e_out = _next(xy) - xy
    cross = e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0]  # = chord × distance
    chord = np.hypot(*(e_in + e_out).T)
    depth = np.divide(cross, chord, out=np.zeros_like(cross), where=chord > 0.0)  # a spike tip: 0, not between
    return depth, np.einsum("ij,ij->i", e_in, e_out) > 0.0


def _clean(xy: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """One pass of the clean-up at tolerance ``h`` of a CCW ring: vertices closer than h merged, then
    vertices within h of their neighbours' line removed, the least deep first. Returns the ring and the
    depths of its vertices (:func:`_depth`)."""
    while len(xy) > 3:
        close = np.flatnonzero(np.hypot(*(_next(xy) - xy).T) <= h)
        if close.size == 0:
            break
        xy = np.delete(xy, (close[0] + 1) % len(xy), axis=0)  # keep the first of the two
    while True:
        depth, between = _depth(xy)
        flat = np.flatnonzero(between & (np.abs(depth) <= h))
        if flat.size == 0 or len(xy) <= 3:
            return xy, depth
        xy = np.delete(xy, flat[np.argmin(np.abs(depth[flat]))], axis=0)


def normalise_coords(coords, label: str) -> np.ndarray:
    """Check a ring of vertices and return it normalised (CCW, no repeats, no collinear vertices).

    Parameters
    ----------
    coords : array_like (k, 2), m — exterior ring, either orientation, closing repeat optional.
    label : str — how to name the body in an error, e.g. ``block 7 ("c03-b02")``.

    Returns
    -------
    ndarray (m, 2) float64, m ≤ k.

    Raises
    ------
    GeometryError — NaN/inf, fewer than 3 distinct vertices, zero or absurd area, self-intersection,
    non-convex.
    """
    try:
        xy = np.array(coords, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise GeometryError(f"{label}: coordinates are not numbers ({exc})") from None
    if xy.ndim != 2 or xy.shape[1] != 2 or xy.shape[0] == 0:
        raise GeometryError(f"{label}: expected (k, 2) vertex coordinates, got shape {xy.shape}")
    given = len(xy) - int(len(xy) > 1 and bool(np.all(xy[0] == xy[-1])))  # a closed ring's repeat not counted
    if given > MAX_VERTICES:
        raise GeometryError(
            f"{label}: {given} vertices, more than {MAX_VERTICES} (an outline traced at every pixel? "
            "simplify it to about 1 mm: QGIS's Vector > Geometry Tools > Simplify)"
        )
    if not np.all(np.isfinite(xy)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(xy), axis=1))[0])
        raise GeometryError(f"{label}: vertex {bad} has a NaN or infinite coordinate")
    if np.any(np.abs(xy) > MAX_COORDINATE):
        bad = int(np.flatnonzero(np.any(np.abs(xy) > MAX_COORDINATE, axis=1))[0])
        raise GeometryError(
            f"{label}: vertex {bad} at {_fmt(xy[bad])} is more than {MAX_COORDINATE:g} m from the origin "
            "(coordinates are metres near the origin: move a map grid's, UTM or national, to a local origin)"
        )
    size = float(np.hypot(*(xy.max(axis=0) - xy.min(axis=0))))
    dup_tol = 1e-12 * max(size, 1e-300)
    # Drop the closing repeat and consecutive duplicates.
    keep = [0]
    for i in range(1, len(xy)):
        if np.hypot(*(xy[i] - xy[keep[-1]])) > dup_tol:
            keep.append(i)
    xy = xy[keep]
    if len(xy) > 1 and np.hypot(*(xy[-1] - xy[0])) <= dup_tol:
        xy = xy[:-1]
    distinct = len(np.unique(np.round(xy / max(dup_tol, 1e-300)), axis=0)) if size > 0 else 1
    if distinct < 3:
        raise GeometryError(f"{label}: polygon has fewer than 3 distinct vertices ({distinct})")
    # All vertices on one line: no area at all (checked before validity, which would call it a
    # self-intersection).
    centred = xy - xy.mean(axis=0)
    if np.linalg.svd(centred, compute_uv=False)[-1] <= 1e-12 * size:
        raise GeometryError(f"{label}: polygon has zero area (all vertices collinear)")
    poly = Polygon(xy)
    if not poly.is_valid:
        reason = shapely.is_valid_reason(poly)
        raise GeometryError(f"{label}: polygon self-intersects ({reason})")
    area = signed_area(xy)
    if abs(area) < MIN_AREA:
        # GeoJSON is longitude / latitude unless told otherwise (RFC 7946; QGIS exports so by default): a 0.3 m
        # block is then 3e-6 "m" wide, and the message said only "too small"
        on_globe = bool(np.all(np.abs(xy[:, 0]) <= 180.0) and np.all(np.abs(xy[:, 1]) <= 90.0))
        degrees = on_globe and 0.0 < size < 1e-3 and float(np.abs(xy).max()) > 1e3 * size
        raise GeometryError(f"{label}: polygon area {abs(area):.3g} m² is zero or too small{DEGREES_HINT * degrees}")
    if abs(area) > MAX_AREA:
        raise GeometryError(f"{label}: polygon area {abs(area):.3g} m² is absurd (coordinates must be metres)")
    if area < 0.0:
        xy = xy[::-1]
    given = xy
    h = min(
        SHAPE_RTOL * abs(area) / size, MAX_SHAPE_TOLERANCE
    )  # shape_tolerance(xy): duplicates removed leave the bounding box as it was
    while True:  # to a fixed point: h follows the area, so a normalised ring comes back unchanged
        cleaned, depth = _clean(xy, h)
        if len(cleaned) == len(xy):
            break
        xy = cleaned
        h = shape_tolerance(xy)
    reflex = np.flatnonzero(depth <= h)  # inside the neighbours' line by more than h (or a spike's tip)
    if reflex.size:
        raise NotConvexError(
            f"{label}: polygon is not convex (reflex vertex at {_fmt(xy[reflex[0]])}){float32_hint(given, h)}"
        )
    return np.ascontiguousarray(xy)


DEGREES_HINT = " (longitude / latitude in degrees? coordinates are metres: export in a projected CRS)"  # no --units


def polygon_from_coords(coords, index: int, name: str, kind: str = "block") -> Polygon:
    """Build a normalised convex shapely Polygon from vertex coordinates, or raise a one-line error.

    Parameters
    ----------
    coords : array_like (k, 2), m — either orientation; a closing repeat and collinear vertices are
        allowed (removed).
    index, name : the body's index and name, used in the error message.
    kind : ``"block"`` or ``"support"``.

    Raises
    ------
    GeometryError, e.g. ``block 7 ("c3-b2"): polygon is not convex (reflex vertex at (1, 2))``.
    """
    return normalised_polygon(coords, body_label(index, name, kind))


def normalised_polygon(coords, label: str) -> Polygon:
    """``Polygon(normalise_coords(coords, label))``, remembered as normalised (module docstring)."""
    polygon = Polygon(normalise_coords(coords, label))
    _NORMALISED[id(polygon)] = polygon
    return polygon


def normalise_polygon(geometry, index: int, name: str, kind: str = "block") -> Polygon:
    """Like :func:`polygon_from_coords` for a shapely geometry: also rejects holes and other types. A
    polygon made by :func:`normalised_polygon` is returned as it is (normalising it again gives it back),
    and so is one whose ring the normalisation leaves as it was (remembered: one that came back from
    another process is checked once there, not at every ``Scenario`` made from it)."""
    if _NORMALISED.get(id(geometry)) is geometry:
        return geometry
    label = body_label(index, name, kind)
    if not isinstance(geometry, Polygon):
        kind_name = getattr(geometry, "geom_type", type(geometry).__name__)
        raise GeometryError(f"{label}: expected a Polygon, got {kind_name}")
    if geometry.is_empty:
        raise GeometryError(f"{label}: polygon is empty")
    if len(geometry.interiors) > 0:
        raise GeometryError(f"{label}: polygon has {len(geometry.interiors)} hole(s); blocks are solid")
    given = np.asarray(geometry.exterior.coords)
    polygon = normalised_polygon(given[:, :2], label)
    if np.array_equal(given, np.asarray(polygon.exterior.coords)):  # it was normalised already (unpickled)
        _NORMALISED[id(geometry)] = geometry
        return geometry
    return polygon
