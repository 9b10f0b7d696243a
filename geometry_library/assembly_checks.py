"""A whole assembly checked: every body normalised and its material checked, names unique, no block
overlapping another body by more than the tolerances (area and depth, :mod:`geometry_library.checks`'
Tolerances), and the warnings of a valid one (no support, a block touching nothing, supports overlapping,
float32 coordinates too far from the origin). One polygon's normalisation: :mod:`geometry_library.checks`."""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import Polygon
from shapely.strtree import STRtree

from .blocks import SUPPORT_ROLES, Assembly, GeometryError, name_problem, quoted_name
from .checks import (
    CONTACT_DISTANCE,
    MAX_SHAPE_TOLERANCE,
    OVERLAP_MAX_DEPTH,
    OVERLAP_RTOL,
    SHAPE_RTOL,
    body_label,
    normalise_polygon,
)
from .float32 import FLOAT32_RTOL, float32_hint, float32_resolution
from .union_screen import union_screen
from .values import check_carried, check_material


def overlap_depth(overlap) -> float:
    """How deep an overlap is, m: the minimum width of the overlap region (convex, being the intersection
    of two convex bodies; its hull is taken against rounding), i.e. over its edges the largest distance of
    a vertex to the edge's line (module docstring, Tolerances). 0 for an empty or flat overlap."""
    xy = shapely.get_coordinates(shapely.convex_hull(overlap))[:-1]
    if len(xy) < 3:
        return 0.0
    edge = np.concatenate((xy[1:], xy[:1])) - xy  # xy[i + 1] - xy[i], cyclic
    length = np.hypot(edge[:, 0], edge[:, 1])
    keep = length > 0.0
    edge, start, length = edge[keep], xy[keep], length[keep]
    # distance[i, j]: of vertex j to the line of edge i
    rel = xy[None, :, :] - start[:, None, :]
    distance = np.abs(edge[:, None, 0] * rel[:, :, 1] - edge[:, None, 1] * rel[:, :, 0]) / length[:, None]
    return float(distance.max(axis=1).min())


def validate_assembly(
    assembly: Assembly,
    overlap_tolerance: float | None = None,
    contact_distance: float = CONTACT_DISTANCE,
) -> list[str]:
    """Check every body of ``assembly`` and their overlaps; return warnings, raise on errors.

    Errors (GeometryError, one line naming the body): not a polygon / holes / NaN / fewer than 3
    vertices / self-intersection / zero or absurd area / non-convex; non-positive density or
    thickness; an absurd carried mass (:func:`~geometry_library.values.check_carried`); unknown support role; duplicate names; no blocks; a block overlapping another block
    or a support by more than ``OVERLAP_RTOL`` × the smaller one's area (module docstring, Tolerances),
    or by more than ``overlap_tolerance`` m² if given, or more than ``OVERLAP_MAX_DEPTH`` deep (either way).

    Warnings: no support at all (everything falls: a GeoJSON drawn without ``"role": "support"`` on its
    ground ran as 52 falling blocks and was reported collapsed); a block farther than
    ``contact_distance`` m from every other body (it touches nothing); two supports overlapping
    (supports never interact, so this is harmless but suspicious); coordinates that are all float32 values
    so far from the origin that their rounding is a tenth of the smallest shape tolerance or more.

    Overlaps and contacts are cleared by one union of all bodies (:mod:`geometry_library.union_screen`),
    else found pairwise with a shapely STRtree: an 8000-voussoir arch, whose slivers' bounding boxes meet
    ~N²/20 others, is checked in linear time, a few hundred blocks in milliseconds.
    """
    if assembly.block_count == 0:
        raise GeometryError("assembly has no blocks")
    labels: list[str] = []
    polys: list[Polygon] = []
    seen: dict[str, str] = {}
    for k, body in enumerate((*assembly.blocks, *assembly.supports)):  # first: every message quotes the names
        if name_problem(body.name) is not None:
            kind, index = ("block", k) if k < assembly.block_count else ("support", k - assembly.block_count)
            raise GeometryError(f"{kind} {index + 1}: name {quoted_name(body.name)} {name_problem(body.name)}")
    for i, block in enumerate(assembly.blocks):
        label = body_label(i, block.name)
        polys.append(normalise_polygon(block.polygon, i, block.name))
        check_material(label, density=block.density, thickness=block.thickness)
        check_carried(label, block, block.density * polys[-1].area * block.thickness, polys[-1].centroid.coords[0])
        labels.append(label)
    for j, support in enumerate(assembly.supports):
        label = body_label(j, support.name, "support")
        polys.append(normalise_polygon(support.polygon, j, support.name, "support"))
        if support.role not in SUPPORT_ROLES:
            raise GeometryError(f"{label}: role must be one of {SUPPORT_ROLES}, got {support.role!r}")
        labels.append(label)
    names = [b.name for b in assembly.blocks] + [s.name for s in assembly.supports]
    for label, name in zip(labels, names):
        if name in seen:
            raise GeometryError(f"{label}: duplicate name, also used by {seen[name]}")
        seen[name] = label

    n_blocks = assembly.block_count
    geoms = np.array(polys, dtype=object)
    tree = STRtree(geoms)
    body_areas = shapely.area(geoms)
    x0, y0, x1, y1 = shapely.bounds(geoms).T
    widths = body_areas / np.hypot(x1 - x0, y1 - y0)
    h_min = min(SHAPE_RTOL * float(np.min(widths)), MAX_SHAPE_TOLERANCE)  # the smallest shape tolerance
    coords = shapely.get_coordinates(geoms)
    warnings: list[str] = []
    resolution = float32_resolution(coords)
    if resolution is not None and resolution >= 0.1 * h_min:
        warnings.append(
            f"coordinates are all float32 values reaching {resolution / FLOAT32_RTOL:,.0f} m from the origin, where "
            f"float32 keeps only ±{resolution:.2g} m ({resolution / h_min:.0%} of the narrowest body's shape "
            f"tolerance, {h_min:.2g} m): shift them near the origin or export them in float64 for exact geometry"
        )
    if assembly.support_count == 0:
        warnings.append(
            f"no supports: nothing holds the {n_blocks} block{'s' if n_blocks != 1 else ''} up, "
            f"{'they fall' if n_blocks != 1 else 'it falls'} freely (in GeoJSON a feature is a block unless its "
            'properties say "role": "support"; in WKT a line is one unless it starts with "support NAME:")'
        )

    # Bounding boxes of slivers (a fine arch's voussoirs) meet ~N²/20 others: one union first, and the
    # pairwise search below (the reference) only when it cannot clear the bodies (union_screen.py).
    # tolerance of a pair: OVERLAP_RTOL × the smaller area; the screen must use the smallest of them
    screen_tolerance = OVERLAP_RTOL * float(body_areas.min()) if overlap_tolerance is None else overlap_tolerance
    # and below the area of any overlap deeper than OVERLAP_MAX_DEPTH: a convex region of minimum width w
    # covers at least w² / √3 (Pál: the equilateral triangle is the least), and the screen clears a pair only
    # if it overlaps by less than 3/4 of its tolerance, so D² / 2 (< 4/3 × D² / √3) proves no overlap too deep
    screen_tolerance = min(screen_tolerance, 0.5 * OVERLAP_MAX_DEPTH**2)
    touched = union_screen(geoms, n_blocks, screen_tolerance)
    left, right = tree.query(geoms if touched is None else geoms[n_blocks:], predicate="intersects")
    left = left if touched is None else left + n_blocks  # then only supports on supports, for warnings
    pair = left < right
    left, right = left[pair], right[pair]
    overlaps = shapely.intersection(geoms[left], geoms[right]) if left.size else np.zeros(0, dtype=object)
    areas = shapely.area(overlaps) if left.size else np.zeros(0)
    if overlap_tolerance is None:
        tolerances = OVERLAP_RTOL * np.minimum(body_areas[left], body_areas[right])
    else:
        tolerances = np.full(len(areas), float(overlap_tolerance))
    # Only an overlap of at least D² / 2 m² can be deeper than D (Pál, above): the rest need no depth.
    deep_enough = 0.5 * OVERLAP_MAX_DEPTH**2
    bad = []
    for k, (a, b, area, tol) in enumerate(zip(left.tolist(), right.tolist(), areas.tolist(), tolerances.tolist())):
        if area <= tol and (area < deep_enough or overlap_depth(overlaps[k]) <= OVERLAP_MAX_DEPTH):
            continue
        if a >= n_blocks:  # support / support
            warnings.append(f"{labels[a]} and {labels[b]} overlap by {area:.3g} m² (supports only)")
            continue
        bad.append((a, b, area, tol, overlaps[k]))
    if bad:
        a, b, area, tol, overlap = bad[0]
        # the other pairs named, so a drawing with a few slips is mended in one go (it was one per run of check,
        # "and 4 more overlapping pair(s)" naming none); the pairs of blocks, names joined by "/"
        others = [f"{names[p]}/{names[q]}" for p, q, *_ in bad[1:]]
        shown = ", ".join(others[:5]) + (f", … ({len(others) - 5} more)" if len(others) > 5 else "")
        more = f" (and {len(others)} more overlapping pair{'s' if len(others) > 1 else ''}: {shown})" if others else ""
        if b < n_blocks:
            what = f'blocks {a + 1} ("{names[a]}") and {b + 1} ("{names[b]}")'
        else:
            what = f"{labels[a]} and {labels[b]}"
        hint = float32_hint(coords, h_min, "their")
        depth = overlap_depth(overlap)
        # two digits, written out: 99.7 mm said '1e+02 mm deep' (a stone traced 10 cm into another)
        depth = f"{float(f'{depth * 1e3:.2g}'):g} mm deep" if depth < 0.1 else f"{depth:.3g} m deep"
        twice = " — one covers the other: the same stone drawn twice?" * bool(area >= 0.9 * body_areas[[a, b]].min())
        raise GeometryError(
            f"{what} overlap by {area:.3g} m², {depth}{twice} (tolerance {tol:.3g} m², "
            f"{OVERLAP_MAX_DEPTH * 1e3:g} mm deep){more}{hint}"
        )

    if touched is None:
        touched = np.zeros(n_blocks, dtype=bool)
        unknown = np.arange(n_blocks)
    else:
        unknown = np.flatnonzero(~touched)  # not shown to touch by the union: the exact test decides
    near_a, near_b = tree.query(geoms[unknown], predicate="dwithin", distance=contact_distance)
    near_a = unknown[near_a]
    touched[near_a[near_a != near_b]] = True
    for i in np.flatnonzero(~touched).tolist():
        others = np.delete(geoms, i)
        if not others.size:  # said "nearest body inf m away"
            warnings.append(f"{labels[i]} touches nothing (it is the only body): it will fall freely")
            continue
        gap = float(shapely.distance(geoms[i], others).min())
        warnings.append(
            f"{labels[i]} touches nothing (nearest body {gap:.3g} m away, more than "
            f"{contact_distance:g} m): it will fall freely"
        )
    return warnings
