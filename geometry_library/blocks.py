"""Blocks, supports and assemblies: the geometric description of a masonry structure.

A block is a rigid convex polygon with a density and an out-of-plane thickness. A support is a
polygon whose motion is imposed (the ground, a foundation pad); its ``role`` says whether it stays
put (``"fixed"``) or is moved by a loading (``"driven"``). The geometry library knows nothing about
dynamics: motions, friction and time stepping belong to ``masonrycli``.

Coordinates are metres, density kg/m³, thickness m.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely.geometry import Polygon

SUPPORT_ROLES = ("fixed", "driven")


class GeometryError(ValueError):
    """Bad geometry. The message is one line naming the block (index and name) and the problem."""


def ccw_vertices(polygon: Polygon) -> np.ndarray:
    """Exterior vertices of ``polygon``, counter-clockwise, without the closing repeat, shape (k, 2)."""
    ring = shapely.geometry.polygon.orient(polygon, sign=1.0).exterior
    xy = np.asarray(ring.coords, dtype=np.float64)
    return xy[:-1].copy()


@dataclass(frozen=True, eq=False)
class Block:
    """One rigid block.

    Attributes
    ----------
    polygon : shapely Polygon, m — convex, no holes.
    name : str — unique label shown in errors and recordings.
    density : float, kg/m³.
    thickness : float, m — out-of-plane depth; mass = density · area · thickness.
    velocity : (vx, vy, omega) — initial velocity, m/s and rad/s.
    """

    polygon: Polygon
    name: str
    density: float = 2500.0
    thickness: float = 1.0
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def vertices(self) -> np.ndarray:
        """Counter-clockwise vertices, shape (k, 2), m."""
        return ccw_vertices(self.polygon)


@dataclass(frozen=True, eq=False)
class Support:
    """A body with imposed motion (ground, foundation). ``role`` is ``"fixed"`` or ``"driven"``."""

    polygon: Polygon
    name: str
    role: str = "fixed"

    @property
    def vertices(self) -> np.ndarray:
        """Counter-clockwise vertices, shape (k, 2), m."""
        return ccw_vertices(self.polygon)


@dataclass(frozen=True, eq=False)
class Assembly:
    """Blocks and supports, in a fixed order (block index = position in ``blocks``)."""

    blocks: tuple[Block, ...]
    supports: tuple[Support, ...] = field(default_factory=tuple)

    @property
    def block_count(self) -> int:
        return len(self.blocks)

    @property
    def support_count(self) -> int:
        return len(self.supports)

    def bounds(self, *, blocks_only: bool = False) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) over blocks and supports (or the blocks only), m."""
        polys = [b.polygon for b in self.blocks] + ([] if blocks_only else [s.polygon for s in self.supports])
        return tuple(shapely.total_bounds(np.array(polys, dtype=object)).tolist())
