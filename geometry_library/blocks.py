"""Blocks, supports and assemblies: the geometric description of a masonry structure.

A block is a rigid convex polygon with a density and an out-of-plane thickness. A support is a
polygon whose motion is imposed (the ground, a foundation pad); its ``role`` says whether it stays
put (``"fixed"``) or is moved by a loading (``"driven"``). The geometry library knows nothing about
dynamics: motions, friction and time stepping belong to ``masonrycli``.

Coordinates are metres, density kg/m³, thickness m.
"""

from __future__ import annotations

import json
import unicodedata
from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely.geometry import Polygon

SUPPORT_ROLES = ("fixed", "driven")


JOINT_SEPARATOR = "|"
"""Joins the names of a joint's two bodies ("v04|v05": summaries, ``limit``'s hinges, the sweep's rows)."""


class GeometryError(ValueError):
    """Bad geometry. The message is one line naming the block (index and name) and the problem. ``keys``:
    the builder options it is about, when a builder's check raised it (a caller names them as the user gave
    them: ``--ring-thickness`` on the command line)."""

    def __init__(self, message: str, *, keys: tuple[str, ...] = ()):
        super().__init__(message)
        self.keys = tuple(keys)


LINE_BREAKING = ("Cc", "Zl", "Zp")
"""Unicode categories of the characters that can end a line of text: controls (newline, U+0085) and the line
and paragraph separators (U+2028, U+2029); str.splitlines breaks at each of these."""


def quoted_name(name) -> str:
    """``name`` in double quotes, every character of :data:`LINE_BREAKING` escaped (\\n, \\u2028): a bad name
    shown in an error keeps it on one line."""
    text = json.dumps(str(name), ensure_ascii=False)
    return "".join(f"\\u{ord(c):04x}" if unicodedata.category(c) in LINE_BREAKING else c for c in text)


def name_problem(name) -> str | None:
    """Why ``name`` cannot name a body, or None. Empty (or blank) names vanish from joints ("|b") and from
    every message; a control character (a newline) cuts a one-line message in two; and a "|" in a name made
    joints ambiguous ("a|b|ground" is a|b on ground, or a on b|ground)."""
    if not isinstance(name, str):
        return "must be a string"
    if not name.strip():
        return "must not be empty"
    if any(unicodedata.category(c) in LINE_BREAKING for c in name):
        return "must not contain control characters or line breaks"
    if JOINT_SEPARATOR in name:
        return f'must not contain "{JOINT_SEPARATOR}" (it joins the names of a joint\'s two bodies: "v04|v05")'
    return None


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
    carried_mass : float, kg — a dead mass the block carries (the fill over a bridge's voussoir,
        :mod:`geometry_library.fill`), for the block's thickness; 0: none.
    carried_at : (x, y), m — where that mass is lumped (the fill column's centroid); None without one.
        It moves with the block: :func:`masonrycli.model.build_model` adds it to the block's mass, moves
        the centre of mass and adds its parallel-axis inertia (a point mass: no rotary inertia of its own).
    """

    polygon: Polygon
    name: str
    density: float = 2500.0
    thickness: float = 1.0
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    carried_mass: float = 0.0
    carried_at: tuple[float, float] | None = None

    @property
    def vertices(self) -> np.ndarray:
        """Counter-clockwise vertices, shape (k, 2), m."""
        return ccw_vertices(self.polygon)


@dataclass(frozen=True, eq=False)
class Support:
    """A body with imposed motion (ground, foundation). ``role`` is ``"fixed"`` or ``"driven"``. ``line``: the
    ground line it was read from (m, as read: ``survey.ground_from_line`` of it is ``polygon``), written back as
    that line; None for a support drawn as a polygon."""

    polygon: Polygon
    name: str
    role: str = "fixed"
    line: tuple[tuple[float, float], ...] | None = None

    @property
    def vertices(self) -> np.ndarray:
        """Counter-clockwise vertices, shape (k, 2), m."""
        return ccw_vertices(self.polygon)


@dataclass(frozen=True, eq=False)
class TracedFill:
    """A fill traced as an outline in a surveyed file (:mod:`geometry_library.traced_fill`), as read: its blocks
    carry its weight; the writers write it back as the outline."""

    name: str
    density: float
    """kg/m³."""
    outline: Polygon
    """m, as read (near the origin)."""


@dataclass(frozen=True, eq=False)
class Assembly:
    """Blocks and supports, in a fixed order (block index = position in ``blocks``). ``fills``: the traced fills
    a file gave (their weight is in the blocks' ``carried_mass``), and ``uncarried`` the blocks before they carried
    them, so that a writer writes the outlines and not their weight twice (both empty without traced fills)."""

    blocks: tuple[Block, ...]
    supports: tuple[Support, ...] = field(default_factory=tuple)
    fills: tuple[TracedFill, ...] = ()
    uncarried: tuple[Block, ...] = ()

    def traced_fills(self) -> tuple[tuple[Block, ...], tuple[TracedFill, ...]]:
        """(the blocks as written, the fills as written): the blocks before their traced fills and those fills,
        or the blocks as they are and no fill when the assembly's blocks are no longer those the fills were
        carried by (moved, trimmed, rebuilt after reading: their carried masses are then all a writer has)."""
        same = len(self.uncarried) == len(self.blocks) and all(
            u.polygon is b.polygon and u.name == b.name and u.thickness == b.thickness
            for u, b in zip(self.uncarried, self.blocks)
        )
        return (self.uncarried, self.fills) if self.fills and same else (self.blocks, ())

    @property
    def block_count(self) -> int:
        return len(self.blocks)

    @property
    def support_count(self) -> int:
        return len(self.supports)

    def __repr__(self) -> str:
        # the counts and the end names, not every polygon: a notebook showing api.scenario("wall") printed 14 kB
        # of Block(polygon=<POLYGON …>, …) for 51 blocks, 70 kB for the aqueduct (every block: assembly.blocks)
        def names(bodies) -> str:
            shown = [b.name for b in bodies[:1]] + ([f"… {bodies[-1].name}"] if len(bodies) > 1 else [])
            return f" ({' '.join(shown)})" if shown else ""

        blocks, supports = len(self.blocks), len(self.supports)
        return (
            f"Assembly({blocks} block{'' if blocks == 1 else 's'}{names(self.blocks)}, "
            f"{supports} support{'' if supports == 1 else 's'}{names(self.supports)})"
        )

    def bounds(self, *, blocks_only: bool = False) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) over blocks and supports (or the blocks only), m."""
        polys = [b.polygon for b in self.blocks] + ([] if blocks_only else [s.polygon for s in self.supports])
        return tuple(shapely.total_bounds(np.array(polys, dtype=object)).tolist())
