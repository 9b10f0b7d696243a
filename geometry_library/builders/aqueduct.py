"""A segment of the Arles aqueduct: the arch of :mod:`.arch` plus running-bond spandrel walls.

Geometry (defaults)
-------------------
The arch is :func:`~.arch.build_arch` with its defaults (98 blocks: span 3.60 m, ring 0.35 m,
30 voussoirs, piers 0.90 × 3.40 m in 17 courses of 2 blocks). On the piers and around the ring,
the spandrel wall is laid in 18 courses of 0.30 × 0.20 m blocks in running bond, from the
springing line (y = 3.40 m) to a level top at y = 7.00 m (1.45 m above the crown extrados),
across the full width between the piers' outer faces (x = ±2.70 m, 18 full blocks; alternate
courses closed by half blocks). Blocks meeting the extrados are cut along its chords and split so
every block is convex (rules in :mod:`.spandrel`); slivers are merged away.

Result: 248 wall blocks (176 full, 18 half, 54 cut along the arch; the smallest is 8.5 % of a
full block and 3.2 cm thick, as 2·area/perimeter) + 98 arch blocks = 346. These defaults (span,
ring, pier width, course count, sliver limits) were chosen among the combinations giving exactly
the paper's 248 wall blocks for the best smallest block. Other parameters give other counts.

Block order: the arch's 98 blocks, then the wall bottom course first, left to right, named
``wall-cCC-bBB`` (course from the springing line, block from the left).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from shapely.geometry import Polygon

from ..blocks import Assembly, GeometryError
from ..values import check_block_total, check_count, check_dimensions
from ._common import make_block, name_width
from .arch import ArchSpec, arch_parts
from .spandrel import spandrel_blocks


@dataclass(frozen=True)
class AqueductSpec(ArchSpec):
    """Parameters of the aqueduct: those of the arch (:class:`~.arch.ArchSpec`) and of its spandrel walls.

    Attributes (beyond the arch's)
    ------------------------------
    wall_courses : int — spandrel courses above the springing line (default 18); the level top is
        at springing + wall_courses · block_height and should clear the crown.
    block_length, block_height : float, m — full wall block (0.30 × 0.20).
    first_course_offset : bool — start the bond with half blocks at the ends of the first course.
    min_fraction, min_thickness : sliver limits — a wall block smaller than ``min_fraction`` of a
        full block, or thinner (2·area/perimeter) than ``min_thickness`` × block_height, is merged
        or re-cut with a neighbour (see :mod:`.spandrel`).
    """

    wall_courses: int = 18
    block_length: float = 0.30
    block_height: float = 0.20
    first_course_offset: bool = False
    min_fraction: float = 0.05
    min_thickness: float = 0.15

    def build(self) -> Assembly:
        """The arch's blocks, then the wall's; supports "left-foundation", "right-foundation".

        Raises GeometryError (one line) for invalid parameters, or a wall top below the crown.
        """
        check_count("aqueduct", 1, wall_courses=self.wall_courses)
        if self.rise is not None and self.rise != 0.5 * self.span:  # the spandrel is cut to a semicircle's extrados
            raise GeometryError(
                f"aqueduct: rise {self.rise:g} m: the aqueduct's arch is semicircular (a segmental arch is the arch "
                "builder's: masonry build arch --rise)",
                keys=("rise",),
            )
        if self.abutments != "courses":  # its spandrel walls stand on the piers' courses
            raise GeometryError(
                f"aqueduct: abutments {self.abutments!r}: the aqueduct's piers are courses under its spandrel walls "
                "(solid or fixed abutments are the arch builder's)",
                keys=("abutments",),
            )
        given = [k for k in ("fill_to", "fill_cover", "fill_density") if getattr(self, k) is not None]
        if given:  # its spandrel walls are blocks, not fill
            raise GeometryError(
                f"aqueduct: {given[0]}: the aqueduct's spandrel is masonry walls, not fill (fill is the arch "
                "builder's: masonry build arch --fill-to)",
                keys=tuple(given),
            )
        check_dimensions("aqueduct", block_length=self.block_length, block_height=self.block_height)
        blocks, supports, geom = arch_parts(self)
        top = geom.springing + self.wall_courses * self.block_height
        crown = geom.springing + geom.extrados_radius
        if top < crown:
            raise GeometryError(
                f"aqueduct: the wall top ({top:g} m) is below the crown of the extrados ({crown:g} m); raise the wall courses (--wall-courses, or wall_courses in a scenario file)",
                keys=("wall_courses",),
            )
        # Bound the spandrel count before cutting it: every course spans the width between the piers'
        # outer faces, at most one block per block length plus the two ends.
        per_course = math.ceil(2.0 * geom.half_width / self.block_length) + 2
        check_block_total(
            "aqueduct",
            len(blocks) + self.wall_courses * per_course,
            f"{self.wall_courses} wall courses of {self.block_length:g} m blocks over {2.0 * geom.half_width:g} m",
            bound=True,
            keys=("wall_courses", "block_length"),
        )
        region = Polygon(geom.extrados)
        pieces = spandrel_blocks(
            region,
            geom.centre,
            -geom.half_width,
            geom.half_width,
            geom.springing,
            self.wall_courses,
            self.block_length,
            self.block_height,
            first_offset=self.first_course_offset,
            min_fraction=self.min_fraction,
            min_thickness=self.min_thickness,
        )
        cw = name_width(self.wall_courses)
        counts: dict[int, int] = {}
        for c, _ in pieces:
            counts[c] = counts.get(c, 0) + 1
        bw = name_width(max(counts.values()))
        seen: dict[int, int] = {}
        for c, poly in pieces:
            seen[c] = seen.get(c, 0) + 1
            blocks.append(make_block(poly, f"wall-c{c + 1:0{cw}d}-b{seen[c]:0{bw}d}", self.density, self.thickness))
        return Assembly(tuple(blocks), tuple(supports))


def build_aqueduct(**options) -> Assembly:
    """Arch on two piers plus spandrel walls in running bond up to a level top: ``AqueductSpec(**options).build()``."""
    return AqueductSpec(**options).build()
