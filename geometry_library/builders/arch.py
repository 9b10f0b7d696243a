"""Semicircular or segmental voussoir arch on two running-bond piers (the paper's 98-block arch).

Geometry (defaults)
-------------------
- Intrados radius R_i = span / 2 = 1.80 m, ring thickness t = 0.35 m, extrados R_e = 2.15 m
  (t / R_mid = 0.18, well above the ≈ 0.11 minimum thickness of a semicircular arch under its
  own weight).
- 30 voussoirs, each spanning 6°: exact convex quadrilaterals whose intrados and extrados are the
  straight chords between the circle points and whose joints are radial (they pass through the
  arch centre). With an even count there is a joint at the crown.
- Two piers, each 0.90 m wide and 17 courses of 0.20 m (3.40 m high), 2 blocks per course in
  running bond: a full block 0.60 m and a half block 0.30 m, swapping sides every course (vertical
  joints of consecutive courses offset by half a full block). The top course has its full block on
  the arch side, so each springing voussoir (0.35 m wide) rests on one 0.60 m block. The piers'
  inner faces are flush with the intrados (x = ±1.80 m), their outer faces at x = ±2.70 m.
- Each pier stands on its own foundation support ("left-foundation", "right-foundation"): the pier
  footprint widened by 0.30 m on each side, 0.50 m deep, top at y = 0.
- Springing line at y = 3.40 m, crown intrados at 5.20 m and extrados at 5.55 m; arch centre at
  x = 0. Overall 5.40 m wide (piers' outer faces).

Segmental arch (``rise`` below span / 2): the intrados is the circular arc through both springings
and the crown, radius R_i = (span²/4 + rise²) / (2 rise), centre R_i − rise below the springing line;
the voussoirs divide its embrace 2α (sin α = span / (2 R_i)) into equal angles, joints radial. The
springing joints are then inclined, so each pier carries a skewback stone (``left-skewback``,
``right-skewback``) across its whole width: from the intrados springing point up the radial joint to the
extrados springing point, t·cos α above the pier top, then level to the pier's outer face. These two
blocks come right after the left pier and right before the right pier.

Block count: 2 × 17 × 2 + 30 = 98 (+ 2 skewbacks for a segmental arch). Order: left pier (bottom up, left to right), voussoirs (left to
right, ``v01`` … ``v30``), right pier. Names: ``left-pier-c01-b1`` …, ``v01`` …, ``right-pier-c17-b2``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from shapely.geometry import box
from shapely.ops import unary_union

from ..blocks import SUPPORT_ROLES, Assembly, Block, GeometryError, Support
from ..fill import FILL_DENSITY, top_surface, with_fill
from ..values import (
    DIMENSION_RANGE,
    MATERIAL_RANGE,
    check_block_total,
    check_count,
    check_dimensions,
    check_positive,
    number_problem,
)
from ._common import make_block, make_support, name_width


@dataclass(frozen=True, eq=False)
class ArchGeometry:
    """Where the arch is, for builders that add to it (the aqueduct's spandrel walls).

    Attributes
    ----------
    centre : ndarray (2,), m — arch centre, on the springing line.
    intrados_radius, extrados_radius : float, m.
    springing : float, m — y of the springing line (top of the piers).
    half_width : float, m — x of the piers' outer faces is ±half_width.
    extrados : ndarray (N+1, 2), m — the extrados chain (voussoir outer chord ends), left to right.
    """

    centre: np.ndarray
    intrados_radius: float
    extrados_radius: float
    springing: float
    half_width: float
    extrados: np.ndarray


def _unit_segment(n: int, half_angle: float) -> np.ndarray:
    """(n+1, 2) points (cos φ_k, sin φ_k) from φ_0 = π/2 + α to φ_n = π/2 − α in equal steps, exactly
    mirror-symmetric about x = 0 (α = ``half_angle`` < π/2: a segmental arch's embrace is 2α)."""
    out = np.empty((n + 1, 2))
    for k in range(n + 1):
        j = min(k, n - k)
        if 2 * j == n:
            c, s = 0.0, 1.0
        else:
            phi = 0.5 * math.pi - half_angle + 2.0 * half_angle * j / n  # from the right springing up
            c, s = math.cos(phi), math.sin(phi)
        out[k] = (-c, s) if k == j else (c, s)
    return out


def _unit_half_circle(n: int) -> np.ndarray:
    """(n+1, 2) points (cos φ_k, sin φ_k), φ_k = π − πk/n, exactly mirror-symmetric about x = 0."""
    out = np.empty((n + 1, 2))
    for k in range(n + 1):
        j = min(k, n - k)  # mirror partner with angle ≥ π/2 measured from the left
        if 2 * j == n:
            c, s = 0.0, 1.0
        elif j == 0:
            c, s = 1.0, 0.0
        else:
            phi = math.pi * j / n
            c, s = math.cos(phi), math.sin(phi)
        out[k] = (-c, s) if k == j else (c, s)
    return out


@dataclass(frozen=True)
class ArchSpec:
    """Parameters of a semicircular or segmental arch on two running-bond piers (the TOML ``[structure]`` options).

    Attributes
    ----------
    voussoirs : int ≥ 2 — number of voussoirs (default 30, 6° each).
    pier_courses : int — courses per pier, 2 blocks each (default 17 → 34 blocks per pier).
    span : float, m — clear span between the piers = intrados diameter (default 3.6).
    ring_thickness : float, m — extrados radius − intrados radius (default 0.35), ≤ pier_width.
    rise : float, m, or None — height of the intrados crown above the springing line; None or span / 2 is
        the semicircle, less a segmental arch with a skewback on each pier (module docstring).
    pier_width : float, m (default 0.90; blocks 0.60 + 0.30). pier_course_height : m (0.20).
    density : kg/m³. thickness : m, out of plane.
    foundation_margin, foundation_depth : m — foundation pads under each pier.
    left_role, right_role : support roles of "left-foundation" / "right-foundation".
    fill_to : float, m, or None — fill over the arch up to this height above the springing line, between
        the piers' outer faces (a bridge's fill, dead load only: :mod:`geometry_library.fill`); below the
        crown the ring stands proud of it.
    fill_cover : float, m, or None — the same, its level given as the depth over the ring's top (≥ 0);
        give one of fill_to and fill_cover.
    fill_density : kg/m³ — the fill's (default 2000 when a fill is given).
    abutments : str — "courses" (default: each pier in running-bond courses, a skewback stone on top when
        segmental), "solid" (each pier and its skewback one block, ``left-abutment`` / ``right-abutment``: a
        massive abutment, bonded through) or "fixed" (that block rigid: it is the foundation support
        ``left-foundation`` / ``right-foundation`` itself, moving as the foundation's motion says).
    """

    voussoirs: int = 30
    pier_courses: int = 17
    span: float = 3.6
    ring_thickness: float = 0.35
    pier_width: float = 0.90
    pier_course_height: float = 0.20
    density: float = 2500.0
    thickness: float = 1.0
    foundation_margin: float = 0.30
    foundation_depth: float = 0.50
    left_role: str = "fixed"
    right_role: str = "fixed"
    rise: float | None = None
    fill_to: float | None = None
    fill_cover: float | None = None
    fill_density: float | None = None
    abutments: str = "courses"

    def build(self) -> Assembly:
        """The arch: 2·2·pier_courses + voussoirs blocks (98 by default; + 2 skewbacks when segmental)
        and two supports. See the module docstring for the layout, names and order. With a fill, the
        blocks under it carry its weight (:func:`fill_level`)."""
        blocks, supports, geometry = arch_parts(self)
        blocks, supports = solid_abutments(self, blocks, supports)
        level = fill_level(self, geometry)
        if level is not None:
            density = FILL_DENSITY if self.fill_density is None else self.fill_density
            blocks = with_fill(blocks, level, density, -geometry.half_width, geometry.half_width)
            if not any(b.carried_mass > 0.0 for b in blocks):  # only fill_to can: a cover is over the crown
                raise GeometryError(
                    f"arch: fill_to {self.fill_to:g} m puts the fill's surface at or below the blocks' top "
                    f"everywhere (their lowest top between the piers' outer faces is {_lowest_top(blocks, geometry):.4g} m "
                    "above the springing line): there is no fill; give a higher fill_to",
                    keys=("fill_to",),
                )
        return Assembly(tuple(blocks), tuple(supports))


def _lowest_top(blocks, geometry: ArchGeometry) -> float:
    """m above the springing line: the lowest point of the blocks' top surface between the piers' outer faces."""
    pieces = top_surface(blocks, -geometry.half_width, geometry.half_width)
    return min(min(p.y(p.a), p.y(p.b)) for p in pieces) - geometry.springing


ABUTMENTS = ("courses", "solid", "fixed")


def solid_abutments(spec: ArchSpec, blocks: list[Block], supports: list[Support]):
    """``blocks`` and ``supports`` with each pier and its skewback made one block (``spec.abutments`` "solid")
    or the foundation support itself ("fixed"); unchanged for "courses". The pier's courses and its skewback
    fill a convex polygon (a box, and the skewback's trapezoid across its whole top), which replaces them."""
    kind = spec.abutments.strip().lower() if isinstance(spec.abutments, str) else spec.abutments
    if kind not in ABUTMENTS:
        raise GeometryError(f"arch: abutments must be one of {', '.join(ABUTMENTS)}, got {kind!r}", keys=("abutments",))
    if kind == "courses":
        return blocks, supports
    out_blocks, out_supports = list(blocks), list(supports)
    for side in ("left", "right"):
        parts = [b for b in blocks if b.name.startswith(f"{side}-pier-") or b.name == f"{side}-skewback"]
        polygon = unary_union([b.polygon for b in parts]).convex_hull  # their union: convex already
        first = out_blocks.index(parts[0])
        out_blocks = [b for b in out_blocks if b not in parts]
        name = f"{side}-foundation"
        if kind == "solid":
            out_blocks.insert(first, make_block(polygon, f"{side}-abutment", spec.density, spec.thickness))
        else:  # the abutment is the support: rigid, where the foundation pad was
            k = [sp.name for sp in out_supports].index(name)
            out_supports[k] = make_support(polygon, name, out_supports[k].role)
    return out_blocks, out_supports


def fill_level(spec: ArchSpec, geometry: ArchGeometry) -> float | None:
    """y (m) of the fill's surface of ``spec`` (None: no fill), its options checked."""
    to, cover, density = spec.fill_to, spec.fill_cover, spec.fill_density
    if to is None and cover is None:
        if density is not None:
            raise GeometryError(
                "arch: fill_density without fill_to or fill_cover: give the fill's level (a height or a cover)",
                keys=("fill_density",),
            )
        return None
    if to is not None and cover is not None:
        raise GeometryError(
            "arch: the fill's level is given twice (a height and a cover): give one", keys=("fill_to", "fill_cover")
        )
    if density is not None:  # the sensible range of a block's density
        check_positive("arch", fill_density=density)
        lo, hi, unit = MATERIAL_RANGE["density"]
        if not lo <= density <= hi:
            raise GeometryError(
                f"arch: fill_density {density:g} {unit} is absurd (a likely typo: {lo:g} to {hi:g} {unit})",
                keys=("fill_density",),
            )
    crown = float(geometry.extrados[:, 1].max())
    if to is not None:
        check_dimensions("arch", fill_to=to)
        return geometry.springing + to
    problem = number_problem(cover, ge=0.0, le=DIMENSION_RANGE[1])
    if problem is not None:
        below = isinstance(cover, float | int) and cover < 0
        why = " (a cover is measured up from the ring's top: a fill below the crown is fill_to's)" if below else ""
        raise GeometryError(f"arch: fill_cover {cover:g} m {problem}{why}", keys=("fill_cover",))
    return crown + cover


def arch_parts(spec: ArchSpec) -> tuple[list[Block], list[Support], ArchGeometry]:
    """The blocks, supports and geometry of the arch of ``spec`` (an :class:`ArchSpec`, or a spec
    extending it such as the aqueduct's)."""
    voussoirs, pier_courses, span = spec.voussoirs, spec.pier_courses, spec.span
    ring_thickness, pier_width, pier_course_height = spec.ring_thickness, spec.pier_width, spec.pier_course_height
    density, thickness = spec.density, spec.thickness
    foundation_margin, foundation_depth = spec.foundation_margin, spec.foundation_depth
    # "Driven" as "driven", as a GeoJSON's support_role
    left_role, right_role = (r.strip().lower() if isinstance(r, str) else r for r in (spec.left_role, spec.right_role))
    check_count("arch", 2, voussoirs=voussoirs)
    check_count("arch", 1, pier_courses=pier_courses)
    check_block_total(
        "arch",
        voussoirs + 4 * pier_courses,
        f"{voussoirs} voussoirs and {pier_courses} pier courses",
        keys=("voussoirs", "pier_courses"),
    )
    check_positive("arch", density=density, thickness=thickness)
    check_dimensions(
        "arch",
        span=span,
        ring_thickness=ring_thickness,
        pier_width=pier_width,
        pier_course_height=pier_course_height,
        foundation_depth=foundation_depth,
    )
    if ring_thickness > pier_width:
        raise GeometryError(
            f"arch: ring_thickness {ring_thickness:g} m is wider than the pier ({pier_width:g} m): "
            "the pier top must carry the whole springing voussoir",
            keys=("ring_thickness", "pier_width"),
        )
    if foundation_margin < 0:
        raise GeometryError(
            f"arch: foundation_margin must be ≥ 0, got {foundation_margin!r}", keys=("foundation_margin",)
        )
    for key, role in (("left_role", left_role), ("right_role", right_role)):
        if role not in SUPPORT_ROLES:
            raise GeometryError(f"arch: {key} must be one of {SUPPORT_ROLES}, got {role!r}", keys=(key,))

    y_spring = pier_courses * pier_course_height
    half_angle = _half_angle(span, spec.rise)
    _check_skewback(span, spec.rise, ring_thickness, half_angle)
    if half_angle is None:  # the semicircle, as it always was built (bit for bit)
        r_in = 0.5 * span
        centre_y = y_spring
        unit = _unit_half_circle(voussoirs)
    else:
        r_in = 0.5 * span / math.sin(half_angle)
        centre_y = y_spring - r_in * math.cos(half_angle)
        unit = _unit_segment(voussoirs, half_angle)
    r_out = r_in + ring_thickness
    outer = 0.5 * span + pier_width
    intrados = unit * r_in + (0.0, centre_y)
    extrados = unit * r_out + (0.0, centre_y)
    intrados[[0, -1]] = [(-0.5 * span, y_spring), (0.5 * span, y_spring)]  # the springings, exactly
    if half_angle is None:
        extrados[:, 1][[0, -1]] = y_spring

    def pier(side: str, x_in: float, x_out: float) -> list[Block]:
        sign = 1.0 if x_out > x_in else -1.0
        full, part = 2.0 * pier_width / 3.0, pier_width / 3.0
        blocks = []
        cw = name_width(pier_courses)
        for c in range(1, pier_courses + 1):
            y0, y1 = (c - 1) * pier_course_height, c * pier_course_height
            from_top = pier_courses - c
            inner_len = full if from_top % 2 == 0 else part
            x_joint = x_in + sign * inner_len
            pieces = sorted([(x_in, x_joint), (x_joint, x_out)], key=lambda ab: min(ab))
            for k, (xa, xb) in enumerate(pieces, start=1):
                lo, hi = min(xa, xb), max(xa, xb)
                blocks.append(make_block(box(lo, y0, hi, y1), f"{side}-pier-c{c:0{cw}d}-b{k}", density, thickness))
        return blocks

    vw = name_width(voussoirs)
    ring = [
        make_block(
            np.array([intrados[k], intrados[k + 1], extrados[k + 1], extrados[k]]),
            f"v{k + 1:0{vw}d}",
            density,
            thickness,
        )
        for k in range(voussoirs)
    ]
    skewbacks: tuple[list[Block], list[Block]] = ([], [])
    if half_angle is not None:  # the inclined springing joint rests on a stone across the pier top
        y_top = extrados[0, 1]
        skewbacks = tuple(
            [
                make_block(
                    np.array([intrados[k], (side * outer, y_spring), (side * outer, y_top), extrados[k]]),
                    f"{name}-skewback",
                    density,
                    thickness,
                )
            ]
            for k, side, name in ((0, -1.0, "left"), (-1, 1.0, "right"))
        )
    half = 0.5 * span
    blocks = pier("left", -half, -outer) + skewbacks[0] + ring + skewbacks[1] + pier("right", half, outer)

    inner_margin = min(foundation_margin, 0.25 * span)
    supports = [
        make_support(
            box(-outer - foundation_margin, -foundation_depth, -half + inner_margin, 0.0),
            "left-foundation",
            left_role,
        ),
        make_support(
            box(half - inner_margin, -foundation_depth, outer + foundation_margin, 0.0),
            "right-foundation",
            right_role,
        ),
    ]
    geometry = ArchGeometry(
        centre=np.array([0.0, centre_y]),
        intrados_radius=r_in,
        extrados_radius=r_out,
        springing=y_spring,
        half_width=outer,
        extrados=extrados,
    )
    return blocks, supports, geometry


def _half_angle(span: float, rise: float | None) -> float | None:
    """α, half the embrace of a segmental arch of this span and intrados rise; None for the semicircle
    (rise None or span / 2). A rise above span / 2 (a horseshoe or a stilted arch) is refused."""
    if rise is None:
        return None
    check_dimensions("arch", rise=rise)
    if rise > 0.5 * span * (1.0 + 1e-12):
        raise GeometryError(
            f"arch: rise {rise:g} m is more than half the span ({0.5 * span:g} m): a segmental arch rises at most "
            "to a semicircle (leave rise out, or give span / 2, for the semicircle)",
            keys=("rise", "span"),
        )
    if rise >= 0.5 * span * (1.0 - 1e-12):
        return None
    radius = (0.25 * span * span + rise * rise) / (2.0 * rise)
    return math.asin(min(1.0, 0.5 * span / radius))


MIN_SKEWBACK = 1e-4
"""m: the least height of a skewback stone, t·cos α. A rise just under span / 2 makes the springing joints
all but vertical and the skewbacks slivers, on which the contact solve stalls: on the default arch (3.6 m
span, 0.2 s of simulate, two runs beside it on 2 cores) rise 1.7995 (skewback 0.1 mm) 124 steps/s,
1.79999 (2 µm) 19 steps/s with 7 steps at the sweep cap, 1.7999999 (2e-8 m) 6 steps/s; the semicircle 384."""


def _check_skewback(span: float, rise: float | None, ring_thickness: float, half_angle: float | None) -> None:
    """GeometryError (one line, the largest rise that works) when the skewbacks would be thinner than
    :data:`MIN_SKEWBACK`."""
    if half_angle is None or ring_thickness * math.cos(half_angle) >= MIN_SKEWBACK:
        return
    c = MIN_SKEWBACK / ring_thickness  # cos α at the limit: rise = R (1 − c), span / 2 = R sqrt(1 − c²)
    most = 0.5 * span * math.sqrt((1.0 - c) / (1.0 + c))
    raise GeometryError(
        f"arch: rise {rise:.8g} m leaves skewbacks {ring_thickness * math.cos(half_angle) * 1e3:.2g} mm thick under "
        f"springing joints {90.0 - math.degrees(half_angle):.2g}° from vertical (under 0.1 mm, too thin a "
        f"stone to compute): give at most {math.floor(most * 1e4) / 1e4:g} m, or {0.5 * span:g} m (span / 2) for the semicircle",
        keys=("rise",),
    )


def build_arch(**options) -> Assembly:
    """A semicircular arch of radial-jointed voussoirs on two running-bond piers: ``ArchSpec(**options).build()``."""
    return ArchSpec(**options).build()
