"""A bridge's fill traced as an outline in a geometry file: its weight, carried by the blocks under it.

A surveyed bridge's fill (the soil or rubble between the spandrel walls, over the ring up to the road) is no
block: it has no strength of its own and is read, as the arch builder's ``--fill-to``, as dead load only
(:mod:`geometry_library.fill`). In a GeoJSON file it is a feature with ``"role": "fill"`` (an optional
``density``, kg/m³, default :data:`~geometry_library.fill.FILL_DENSITY`); in WKT a line
``fill NAME DENSITY: POLYGON ((…))`` (its density optional). Its outline may be any simple polygon (not convex: the
fill over a ring's extrados never is), drawn down onto the stones or a little into them, and its top need not be
level (a cambered road):

    for each fill outline:
        the fill is each column from the top surface of the blocks and supports up to the outline's top, bearing
            on the body topmost under it (fill.traced_fill_over: the outline's top is the fill's surface, and the
            fill reaches down to the stones); a block carries its columns' mass, density × area × its
            thickness, at their centroid (fill.carry: Block.carried_mass, carried_at)
        a column over a support rests on it; the outline's part below the bodies' top or over no body is said

The reading says what it did, one note per outline (its mass, the blocks carrying it, the area left out).
"""

from __future__ import annotations

import numpy as np
import shapely
from shapely.geometry import Polygon

from .blocks import Assembly, GeometryError, TracedFill
from .checks import body_label
from .fill import carry, traced_fill_over
from .values import check_material


def fill_outline(xy: np.ndarray, where: str) -> Polygon:
    """The polygon of a traced fill's ring (m, near the origin): simple, of some area, not convex if need be."""
    xy = np.asarray(xy, dtype=np.float64)
    if len(xy) < 3 or not np.all(np.isfinite(xy)):
        raise GeometryError(f"{where}: a fill's outline needs three or more finite [x, y] points")
    outline = shapely.geometry.polygon.orient(Polygon(xy), sign=1.0)  # CCW as written back: a round trip is exact
    if not outline.is_valid:
        raise GeometryError(f"{where}: the fill's outline crosses itself: trace it as one simple polygon")
    if outline.area <= 0.0:
        raise GeometryError(f"{where}: the fill's outline has no area")
    return outline


def _stones_inside(blocks, outline: Polygon) -> str:
    """Where a fill's outline reaches into the stones deeper than a tracing's slip (``INSIDE_DEPTH``): how many, the
    deepest named ("" if none). Its part there is no fill (the fill reaches down to their top), so the weight is
    right; the words let a researcher find an outline drawn over the ring, or a stone traced as fill."""
    polys = np.array([b.polygon for b in blocks], dtype=object)
    overlaps = shapely.intersection(polys, outline)
    depth = np.array([_depth(o) for o in overlaps])
    deep = np.flatnonzero(depth > INSIDE_DEPTH)
    if not len(deep):
        return ""
    k = int(deep[np.argmax(depth[deep])])
    many = f"{len(deep)} stones, the deepest" if len(deep) > 1 else "a stone,"
    return (
        f"it reaches into {many} {body_label(k, blocks[k].name)} about {depth[k] * 1e3:.3g} mm deep (its part "
        "inside them is not fill: is its lower edge drawn over the stones?)"
    )


INSIDE_DEPTH = 0.01
"""m: an outline reaching deeper into a stone than this is said (a few mm is a tracing's slip)."""


def _depth(overlap) -> float:
    """m: how deep an overlap is (twice its area over its perimeter: a thin strip's width); 0 for none."""
    return 0.0 if overlap.is_empty or overlap.area <= 0.0 else 2.0 * overlap.area / overlap.length


def carry_fills(assembly: Assembly, outlines: list, notes: list | None) -> Assembly:
    """``assembly`` with its blocks carrying each traced fill of ``outlines`` ((where, name, density kg/m³,
    outline) each: module docstring); ``notes`` (if a list) receives one line per fill. A fill that no block
    carries is refused: it would be no load at all."""
    blocks = list(assembly.blocks)
    if not outlines:
        return assembly
    for where, _name, density, outline in outlines:
        check_material(where, density=density)  # the builder's --fill-density range: 1e9 kg/m³ ran, a typo
        traced = traced_fill_over(blocks, assembly.supports, outline)
        area = traced.fill.area
        if not (area > 0.0).any():
            raise GeometryError(
                f"{where}: no block is under this fill (it lies over the supports or over nothing): trace its outline "
                "over the stones that carry it, up to its surface"
            )
        before = sum(b.carried_mass for b in blocks)
        blocks = carry(blocks, traced.fill, density)
        mass = sum(b.carried_mass for b in blocks) - before
        left = [
            f"{a:.3g} m² {what}"
            for a, what in (
                (traced.on_supports, "over a support rests on it"),
                (traced.not_above, "of the outline below the stones' top or over no stone is not counted"),
            )
            if a > 1e-9 * outline.area
        ]
        inside = _stones_inside(blocks, outline)
        if inside:
            left.append(inside)
        if notes is not None:
            notes.append(
                f"{where}: a fill of {density:g} kg/m³, read as dead load: {area.sum():.4g} m², {mass:.4g} kg carried "
                f"by the {int((area > 0.0).sum())} blocks under it (no strength, no side pressure)"
                + "".join(f"; {text}" for text in left)
            )
    fills = tuple(TracedFill(name, float(density), outline) for _, name, density, outline in outlines)
    return Assembly(tuple(blocks), assembly.supports, fills, assembly.blocks)
