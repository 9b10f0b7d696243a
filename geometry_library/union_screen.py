"""A screen for the assembly checks that stays linear in the number of blocks: one union of all bodies.

Why. :func:`geometry_library.assembly_checks.validate_assembly` looks for overlapping pairs and for blocks that
touch nothing with a shapely STRtree. A tree filters by bounding boxes, and the voussoirs of a fine arch
are slivers (0.35 m long, 2π·1.9 m / N wide) whose boxes, at 45° on the ring, are 0.25 m squares: each
box meets ~N/25 others, so the exact tests ran on ~N²/20 pairs (3.2 million at N = 8000: 0.9 s of
``intersects``, 3 s of ``dwithin``; 5.7 s of the 7 s that ``masonry check`` took). Any method working
on boxes or grid cells has the same count for slivers; the union does not.

What. With A_i the bodies' areas and U the union of all bodies (GEOS unary union, ~n log n):

    excess = Σ_blocks A_i + area(union of the supports) − area(U)

is the area covered twice or more, not counting two supports on each other (harmless, warned about by
the caller). Every pair overlapping by more than ``tol`` adds at least that much to ``excess``, so

    excess ≤ tol / 2  and  rounding ≤ tol / 4   ⇒   no pair overlaps by more than tol

where ``rounding`` bounds the float error of the areas (eps × extent × (Σ perimeters + perimeter of
U), × 4). Otherwise nothing is concluded and the caller runs its pairwise search, whose findings (which
pairs, their order, the message) are the reference; so the screen only ever saves time.

The same union gives contacts: a body of a connected part of U holding two or more bodies touches
another (a closed set at positive distance from the others would be a part of its own). Each body is
placed in its part by an interior point; a block not shown to touch this way is left to the caller's
exact ``dwithin`` test (normally none is).
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.strtree import STRtree

EPS = np.finfo(np.float64).eps


def union_screen(geoms: np.ndarray, n_blocks: int, tol: float) -> np.ndarray | None:
    """Blocks shown to touch another body (bool, (n_blocks,)), when the union shows that no pair other
    than two supports overlaps by more than ``tol`` m²; None when it cannot (module doc).

    ``geoms``: the normalised bodies, blocks first then supports (object array of shapely Polygons).
    """
    try:
        union = shapely.union_all(geoms)
        supports = shapely.union_all(geoms[n_blocks:]) if len(geoms) > n_blocks else None
    except shapely.errors.GEOSException:
        return None
    areas = shapely.area(geoms)
    excess = float(areas[:n_blocks].sum()) + (shapely.area(supports) if supports is not None else 0.0)
    excess -= shapely.area(union)
    x0, y0, x1, y1 = shapely.total_bounds(geoms)
    extent = max(abs(x0), abs(x1), abs(y0), abs(y1), x1 - x0, y1 - y0)
    perimeters = float(shapely.length(geoms).sum()) + shapely.length(union)
    rounding = 4.0 * EPS * extent * perimeters
    if not (rounding <= 0.25 * tol and excess <= 0.5 * tol):
        return None
    parts = shapely.get_parts(union)
    inside = STRtree(shapely.point_on_surface(geoms))
    part_of, body = inside.query(parts, predicate="intersects")
    members = np.bincount(part_of, minlength=len(parts))
    touched = np.zeros(len(geoms), dtype=bool)
    touched[body[members[part_of] >= 2]] = True
    return touched[:n_blocks]
