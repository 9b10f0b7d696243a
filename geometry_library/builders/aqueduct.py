"""A segment of the Arles aqueduct: the arch of :mod:`.arch` plus running-bond spandrel walls.

Geometry (defaults)
-------------------
The arch is :func:`build_arch` with its defaults (98 blocks: span 3.0 m, ring 0.35 m, 30
voussoirs, piers 0.90 × 3.40 m in 17 courses). On top of the piers and around the arch ring, the
spandrel wall is laid in courses of 0.30 × 0.20 m blocks in running bond, from the springing line
(y = 3.40 m) up to a level top, across the full width between the piers' outer faces
(x = ±2.40 m, 16 blocks). Blocks meeting the extrados are cut along it and split so every block
is convex (see :mod:`.spandrel` for the cut / merge / split rules; minimum piece 5 % of a block).

TODO-tuned defaults: see ``build_aqueduct``.
"""

from __future__ import annotations

from shapely.geometry import Polygon

from ..blocks import Assembly
from ._common import check_count, check_positive, make_block, name_width
from .arch import arch_parts
from .spandrel import spandrel_blocks


def build_aqueduct(
    voussoirs: int = 30,
    pier_courses: int = 17,
    span: float = 3.0,
    ring_thickness: float = 0.35,
    pier_width: float = 0.90,
    pier_course_height: float = 0.20,
    wall_courses: int = 19,
    block_length: float = 0.30,
    block_height: float = 0.20,
    first_course_offset: bool = False,
    min_fraction: float = 0.05,
    min_thickness: float = 0.1,
    density: float = 2500.0,
    thickness: float = 1.0,
    foundation_margin: float = 0.30,
    foundation_depth: float = 0.50,
    left_role: str = "fixed",
    right_role: str = "fixed",
) -> Assembly:
    """Arch on two piers plus spandrel walls in running bond up to a level top."""
    check_count("aqueduct", 1, wall_courses=wall_courses)
    check_positive("aqueduct", block_length=block_length, block_height=block_height)
    blocks, supports, geom = arch_parts(
        voussoirs, pier_courses, span, ring_thickness, pier_width, pier_course_height, density,
        thickness, foundation_margin, foundation_depth, left_role, right_role,
    )
    region = Polygon(geom.extrados)
    pieces = spandrel_blocks(
        region,
        geom.centre,
        -geom.half_width,
        geom.half_width,
        geom.springing,
        wall_courses,
        block_length,
        block_height,
        first_offset=first_course_offset,
        min_fraction=min_fraction,
        min_thickness=min_thickness,
    )
    cw = name_width(wall_courses)
    counts: dict[int, int] = {}
    for c, _ in pieces:
        counts[c] = counts.get(c, 0) + 1
    bw = name_width(max(counts.values()))
    seen: dict[int, int] = {}
    for c, poly in pieces:
        seen[c] = seen.get(c, 0) + 1
        blocks.append(make_block(poly, f"wall-c{c + 1:0{cw}d}-b{seen[c]:0{bw}d}", density, thickness))
    return Assembly(tuple(blocks), tuple(supports))
