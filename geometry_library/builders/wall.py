"""Running-bond wall on a ground support (the paper's 51- and 248-block walls).

Layout
------
Courses are numbered from 1 at the bottom. Odd courses hold ``n`` full blocks; even courses hold
``n − 1`` full blocks closed by a half block at each end, so the vertical joints of consecutive
courses are offset by half a block and both ends of the wall are straight. With ``C`` courses the
block count is

    N(C, n) = C·n + ⌊C/2⌋

For a requested count we list every integer solution (C ≥ 1, n ≥ 1), keep the walls at least as
wide as tall (length n·l ≥ height C·h) and take the one with the most courses (the squarest); if
no wall is wider than tall, the squarest overall. With 0.30 × 0.20 m blocks:

=======  =====================  ==========================  ===============
blocks   solutions (C × n)      chosen                      size (L × H)
=======  =====================  ==========================  ===============
51       1×51, 2×25, 6×8        6 courses × 8 (8 / 7+2½)    2.40 × 1.20 m
248      1×248, 7×35, 16×15     16 courses × 15 (15 / 14+2½) 4.50 × 3.20 m
=======  =====================  ==========================  ===============

:func:`wall_layout` returns the chosen layout with its per-course table; ``courses`` or ``length``
pin one dimension instead. The wall is centred on x = 0 with its base at y = 0, on a ground
rectangle 2 m wider on each side and 0.5 m deep (top at y = 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from shapely.geometry import box

from ..blocks import Assembly, Block, GeometryError
from ..values import check_block_total, check_dimensions, check_positive, number_problem
from ._common import make_block, make_support, name_width


@dataclass(frozen=True)
class WallLayout:
    """A running-bond layout: ``courses`` courses, ``full_per_course`` full blocks in odd courses.

    Attributes
    ----------
    blocks : int — total block count.
    courses : int.
    full_per_course : int — n: odd courses have n full blocks, even ones n − 1 full + 2 halves.
    block_length, block_height : float, m — full block size.
    """

    blocks: int
    courses: int
    full_per_course: int
    block_length: float = 0.30
    block_height: float = 0.20

    @property
    def length(self) -> float:
        """Wall length, m."""
        return self.full_per_course * self.block_length

    @property
    def height(self) -> float:
        """Wall height, m."""
        return self.courses * self.block_height

    def rows(self) -> tuple[tuple[int, int, int, int], ...]:
        """Per course (bottom first): (course number, full blocks, half blocks, blocks)."""
        n = self.full_per_course
        out = []
        for c in range(1, self.courses + 1):
            full, halves = (n, 0) if c % 2 == 1 else (n - 1, 2)
            out.append((c, full, halves, full + halves))
        return tuple(out)

    def table(self) -> str:
        """The layout as a small text table."""
        lines = [
            f"{self.blocks} blocks = {self.courses} courses, {self.length:.2f} m × {self.height:.2f} m "
            f"(blocks {self.block_length:g} × {self.block_height:g} m)",
            "course  full  halves  blocks",
        ]
        lines += [f"{c:6d}  {f:4d}  {h:6d}  {b:6d}" for c, f, h, b in self.rows()]
        return "\n".join(lines)


def wall_layouts(blocks: int) -> list[tuple[int, int]]:
    """Every (courses, full_per_course) with courses·n + ⌊courses/2⌋ == blocks, fewest courses first."""
    if number_problem(blocks, integer=True, ge=1) is not None:
        raise GeometryError(f"wall: blocks must be a positive integer, got {blocks!r}", keys=("blocks",))
    check_block_total("wall", blocks, keys=("blocks",))
    out = []
    for c in range(1, blocks + 1):
        rest = blocks - c // 2
        if rest >= c and rest % c == 0:
            out.append((c, rest // c))
    return out


def wall_layout(
    blocks: int | None = 51,
    courses: int | None = None,
    length: float | None = None,
    block_length: float = 0.30,
    block_height: float = 0.20,
) -> WallLayout:
    """Choose the running-bond layout for a block count (see the module docstring's table).

    Parameters
    ----------
    blocks : total count; may be None when both ``courses`` and ``length`` are given.
    courses : pin the number of courses.
    length : pin the wall length, m (a whole number of blocks).

    Raises
    ------
    GeometryError (one line) when the count cannot be made with the given constraints.
    """
    check_dimensions("wall", block_length=block_length, block_height=block_height)
    n_pinned = None
    if length is not None:
        check_positive("wall", length=length)
        n_float = length / block_length
        n_pinned = round(n_float)
        if n_pinned < 1 or abs(n_float - n_pinned) > 1e-9 * max(1.0, n_float):
            lo = max(1, math.floor(n_float))  # the lengths that fit on either side, to pick from
            fits = ", ".join(f"{k * block_length:g} m is {k}" for k in sorted({lo, math.floor(n_float) + 1}))
            raise GeometryError(
                f"wall: length {length:g} m is not a whole number of {block_length:g} m blocks ({fits})",
                keys=("length",),
            )
    if courses is not None and number_problem(courses, integer=True, ge=1) is not None:
        raise GeometryError(f"wall: courses must be a positive integer, got {courses!r}", keys=("courses",))
    if blocks is None:
        if courses is None or n_pinned is None:
            raise GeometryError(
                "wall: give a block count, or both courses and length", keys=("blocks", "courses", "length")
            )
        blocks = courses * n_pinned + courses // 2
        check_block_total("wall", blocks, f"{courses} courses of length {length:g} m", keys=("courses", "length"))
    candidates = wall_layouts(blocks)
    if courses is not None:
        candidates = [(c, n) for c, n in candidates if c == courses]
    if n_pinned is not None:
        candidates = [(c, n) for c, n in candidates if n == n_pinned]
    if not candidates:
        pinned = []
        if courses is not None:
            pinned.append(f"{courses} courses")
        if n_pinned is not None:
            pinned.append(f"length {length:g} m ({n_pinned} blocks per course)")
        if pinned:
            why = "with " + " and ".join(pinned)
        else:
            why = "at all"
        possible = ", ".join(f"{c}×{n}" for c, n in wall_layouts(blocks))
        raise GeometryError(
            f"wall: {blocks} blocks cannot be laid in running bond {why} "
            f"(courses × full blocks per odd course: {possible})",
            keys=("blocks", *(["courses"] if courses is not None else []), *(["length"] if length is not None else [])),
        )

    def aspect(cn: tuple[int, int]) -> float:
        return cn[1] * block_length / (cn[0] * block_height)

    wide = [cn for cn in candidates if aspect(cn) >= 1.0 - 1e-12]
    if wide:
        c, n = max(wide)
    else:
        c, n = min(candidates, key=lambda cn: abs(math.log(aspect(cn))))
    return WallLayout(blocks, c, n, block_length, block_height)


@dataclass(frozen=True)
class WallSpec:
    """Parameters of a running-bond wall standing on a ground support (the TOML ``[structure]`` options).

    Attributes
    ----------
    blocks : int — block count (default 51: 6 courses × 8, 2.40 × 1.20 m; 248: 16 courses × 15,
        4.50 × 3.20 m). None when ``courses`` and ``length`` are both given.
    courses, length : optional, pin the number of courses / the wall length (m).
    block_length, block_height : full block size, m.
    density : kg/m³. thickness : m.
    ground_margin : m the ground extends beyond each end of the wall. ground_depth : m.
    ground_role : role of the "ground" support; the loading decides how it moves.
    """

    blocks: int | None = 51
    courses: int | None = None
    length: float | None = None
    block_length: float = 0.30
    block_height: float = 0.20
    density: float = 2500.0
    thickness: float = 1.0
    ground_margin: float = 2.0
    ground_depth: float = 0.5
    ground_role: str = "fixed"

    def build(self) -> Assembly:
        """The wall: blocks named ``cCC-bBB`` (course from the bottom, block from the left, both from 1),
        ordered course by course, left to right; one support ``"ground"``."""
        block_height, density, thickness = self.block_height, self.density, self.thickness
        layout = wall_layout(self.blocks, self.courses, self.length, self.block_length, block_height)
        check_positive("wall", density=density, thickness=thickness)
        check_dimensions("wall", ground_depth=self.ground_depth)
        if self.ground_margin < 0:
            raise GeometryError(f"wall: ground_margin must be ≥ 0, got {self.ground_margin!r}", keys=("ground_margin",))
        x0 = -0.5 * layout.length
        cw = name_width(layout.courses)
        bw = name_width(layout.full_per_course + 1)
        out: list[Block] = []
        for c, full, halves, _ in layout.rows():
            y0 = (c - 1) * block_height
            # Joints on the integer grid of half blocks: no round-off drift along long courses.
            units = [2] * full
            if halves:
                units = [1] + units + [1]
            m = 0
            for k, u in enumerate(units, start=1):
                xa, xb = x0 + m * 0.5 * self.block_length, x0 + (m + u) * 0.5 * self.block_length
                name = f"c{c:0{cw}d}-b{k:0{bw}d}"
                out.append(make_block(box(xa, y0, xb, y0 + block_height), name, density, thickness))
                m += u
        half = 0.5 * layout.length + self.ground_margin
        ground = make_support(box(-half, -self.ground_depth, half, 0.0), "ground", self.ground_role)
        return Assembly(tuple(out), (ground,))


def build_wall(**options) -> Assembly:
    """A running-bond wall standing on a ground support: ``WallSpec(**options).build()``."""
    return WallSpec(**options).build()
