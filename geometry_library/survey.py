"""A surveyed wall as a GIS hands it over: a map grid's coordinates, other units, y pointing down, stones
traced by hand. What the readers (:mod:`geometry_library.io`) do to such a file before the checks.

A heritage survey traces each stone of a wall's face on an orthophoto. Its file differs from a drawn one in
ways that each stopped a run:

- **a map grid** (Lambert-93: x ≈ 651 234 m, y ≈ 6 861 210 m) — beyond ``MAX_COORDINATE`` every vertex was
  refused. Coordinates beyond ``RECENTRE_BEYOND`` (10 km) are read moved by whole kilometres to near the
  origin (always, no option: the mechanics do not depend on where the wall stands, and float32 — the
  recording's positions, the engine's first sweeps — keeps 0.5 m at 6.9e6 m). The shift is said, and added
  to a refusal's coordinates, so a stone is found again on the map;
- **other units** (``units``: ``"mm"``, ``"cm"``, or metres per unit: ``"0.002"`` for a photograph's pixels
  of 2 mm, traced in an image tool): read into metres. A wall in millimetres read as metres
  has stones hundreds of metres across; with no ``units`` given, stones whose median size exceeds
  ``HUGE_STONE`` (20 m) are said to be likely millimetres;
- **y pointing down** (image rows, ``flip_y``): read with y negated, so gravity pulls the wall towards its
  foot. Without it, a support lying above half the blocks is said to be likely upside down;
- **slightly non-convex stones** (``convex_hull``, opt-in): a stone refused as not convex is read as its
  convex hull, if that adds at most ``MAX_HULL_GAIN`` (5 %) of its area — the area added is said; more
  is a stone of another shape, still refused (split it in QGIS);
- **a ground traced as a line** along the wall's foot (a GeoJSON ``LineString``): the support under it
  (:func:`ground_from_line`: one convex body, its top the line's upper hull, refused over a step);
- **neighbours overlapping by a tracing slip** (``trim_overlaps`` = the deepest overlap to trim, m, opt-in):
  each overlapping pair is cut along the chord of their overlap, where their outlines cross
  (:func:`geometry_library.trim.trim_overlaps`).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import shapely
from shapely.geometry import Polygon

from .blocks import Assembly, GeometryError
from .checks import NotConvexError, body_label, polygon_from_coords, signed_area
from .float32 import float32_resolution
from .trim import trim_overlaps

RECENTRE_BEYOND = 1e4
"""m: coordinates farther than this from the origin are moved near it."""
RECENTRE_UP_TO = 1e8
"""m: coordinates farther than this are not moved (float64 keeps 1.5e-8 m there; any map grid is nearer, Web
Mercator's 2e7 m included): the checks refuse them as they are, beyond ``MAX_COORDINATE``."""
RECENTRE_STEP = 1e3
"""m: the shift is a whole number of these (the local coordinates keep the survey's last digits)."""
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}
"""Metres per unit of a file's coordinates."""
MAX_HULL_GAIN = 0.05
"""The most area (fraction of the stone's) a convex hull may add: more is no tracing slip."""
HUGE_STONE = 20.0
"""m: a median stone larger than this across is a wall in millimetres or centimetres read as metres."""
TINY_STONE = 0.01
"""m: a median stone smaller than this across (read with ``units``) is a wall in other units: refused."""


@dataclasses.dataclass(frozen=True)
class Survey:
    """How to read a surveyed file (module docstring). The default reads a file as it is, moved near the
    origin when it is far."""

    units: str = "m"
    flip_y: bool = False
    convex_hull: bool = False
    trim_overlaps: float = 0.0
    """m: the deepest overlap of two bodies trimmed (0: none trimmed, an overlap is refused by the checks)."""
    done: dict = dataclasses.field(default_factory=dict, compare=False, repr=False)
    """What the last file read with it was read as (:func:`reading_record`), filled by :func:`finish_reading`: a
    run's parameters record it, so a history says which reading of its file it is of."""

    def __post_init__(self):
        if unit_scale(self.units) is None:
            raise GeometryError(
                f"units must be one of {', '.join(UNITS)} or metres per unit (0.002: pixels of 2 mm), got {self.units!r}"
            )
        if not (math.isfinite(self.trim_overlaps) and 0.0 <= self.trim_overlaps <= 0.1):
            raise GeometryError(f"trim depth must be between 0 and 0.1 m (a tracing slip), got {self.trim_overlaps!r}")


@dataclasses.dataclass(frozen=True)
class Frame:
    """File coordinates → metres near the origin: ``(xy × scale) × (1, ±1) − shift``."""

    scale: float = 1.0
    flip_y: bool = False
    shift: tuple[float, float] = (0.0, 0.0)
    rounding: float | None = None
    """m: how far a float32 export's rounding may have moved the file's coordinates as given (None: not a
    float32 export) — once moved, the checks see coordinates that are no float32 values and cannot tell."""
    far: float = 0.0
    """m: the farthest a coordinate lies from the origin, read in its units (before any shift)."""

    def local(self, xy: np.ndarray) -> np.ndarray:
        out = np.asarray(xy, dtype=np.float64) * self.scale
        if self.flip_y:
            out = out * np.array([1.0, -1.0])
        return out - np.array(self.shift)

    def where(self) -> str:
        """The end of a message quoting local coordinates: how to find them on the map ("" if not moved)."""
        if self.shift == (0.0, 0.0):
            return ""
        return f" (coordinates read moved by ({-self.shift[0]:.0f}, {-self.shift[1]:.0f}) m: add {_pair(self.shift)} for the map's)"


def _pair(p) -> str:
    return f"({p[0]:.0f}, {p[1]:.0f})"


def frame_of(rings: list, survey: Survey) -> Frame:
    """The frame of a file's rings (each (k, 2) as given): units, flip, and the shift of whole kilometres that
    brings the lowest, leftmost corner of their bounding box near the origin when it is farther than
    ``RECENTRE_BEYOND`` (not when the rings span more than 1000 km: the checks refuse such a file as it is)."""
    scale = unit_scale(survey.units)
    frame = Frame(scale, survey.flip_y)
    xy = [np.asarray(r, dtype=np.float64).reshape(-1, 2) for r in rings if np.size(r)]
    xy = frame.local(np.vstack(xy)) if xy else np.zeros((0, 2))
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    if not len(xy):
        return frame
    low, high = xy.min(axis=0), xy.max(axis=0)
    far = np.abs(xy).max()
    frame = dataclasses.replace(frame, far=float(far))
    # beyond RECENTRE_UP_TO float64 itself has lost the millimetres (1e12 m: ±0.1 mm): refused as it is
    if far <= RECENTRE_BEYOND or far > RECENTRE_UP_TO or np.any(high - low > 1e6):
        return frame
    shift = np.floor(low / RECENTRE_STEP) * RECENTRE_STEP
    shift = np.where(np.maximum(np.abs(low), np.abs(high)) > RECENTRE_BEYOND, shift, 0.0)
    rounding = float32_resolution(
        np.vstack([np.asarray(r, dtype=np.float64).reshape(-1, 2) for r in rings if np.size(r)])
    )
    rounding = None if rounding is None else rounding * scale
    return dataclasses.replace(frame, shift=(float(shift[0]), float(shift[1])), rounding=rounding)


GROUND_DEPTH = 0.5
"""m: how far below a ground line's lowest point the ground read from it reaches."""
GROUND_DIP = 0.01
"""m: the deepest dip of a ground line its upper hull may bridge (deeper: a step to draw as polygons)."""


def ground_from_line(xy, survey: Survey, where: str) -> tuple[np.ndarray, float]:
    """The ring (file coordinates) of the ground under a traced ground line ``xy`` (k, 2): the convex hull of the
    line and of two points ``GROUND_DEPTH`` below its lowest one (below: y down with ``flip_y``), one convex
    support whose top is the line's upper hull; and the deepest dip of the line that hull bridges, m. Raises
    when that dip exceeds ``GROUND_DIP`` (a step: draw the ground as convex polygons)."""
    xy = np.asarray(xy, dtype=np.float64)
    if xy.ndim != 2 or len(xy) < 2 or not np.all(np.isfinite(xy)):
        raise GeometryError(f"{where}: a ground line needs two or more finite [x, y] points")
    scale = unit_scale(survey.units)
    down = 1.0 if survey.flip_y else -1.0
    base = (xy[:, 1].max() if survey.flip_y else xy[:, 1].min()) + down * GROUND_DEPTH / scale
    hull = shapely.convex_hull(shapely.multipoints([*xy, [xy[:, 0].min(), base], [xy[:, 0].max(), base]]))
    if (
        hull.geom_type != "Polygon"
    ):  # a vertical line, or one point repeated: a hull of no area (it said AttributeError)
        raise GeometryError(f"{where}: a ground line runs along the wall's foot: its points span no width in x")
    dip = float(shapely.distance(hull.exterior, shapely.points(xy)).max()) * scale
    if dip > GROUND_DIP:
        raise GeometryError(
            f"{where}: the ground line dips {dip * 1e3:.3g} mm below the straight line over its dip, more than "
            f"{GROUND_DIP * 1e3:g} mm (the ground read from a line is one convex support): draw the ground as convex "
            "polygons"
        )
    return np.asarray(hull.exterior.coords)[:-1], dip


def unit_scale(units: str) -> float | None:
    """Metres per unit of ``units`` (a name of ``UNITS`` or a number of metres, in (0, 1000]); None if neither."""
    if units in UNITS:
        return UNITS[units]
    try:
        scale = float(units)
    except (TypeError, ValueError):
        return None
    return scale if math.isfinite(scale) and 0.0 < scale <= 1e3 else None


def survey_notes(path, frame: Frame, survey: Survey, assembly: Assembly) -> list[str]:
    """One-line notes on a surveyed file once read: the shift, the likely units or y-axis slips, the likely
    ground of a file with no support."""
    blocks = [b.polygon for b in assembly.blocks]
    supports = [s.polygon for s in assembly.supports]
    notes = []
    if frame.shift != (0.0, 0.0):
        notes.append(
            f"{path}: coordinates {_far(frame) / 1e3:,.0f} km from the origin (a map grid's) read moved by "
            f"({-frame.shift[0]:.0f}, {-frame.shift[1]:.0f}) m, near it: add {_pair(frame.shift)} to map a "
            "result back onto the survey"
        )
    if frame.rounding is not None and frame.rounding >= 1e-5:
        notes.append(
            f"{path}: its coordinates are float32 values, exact only to ±{frame.rounding:.2g} m that far from the "
            "origin: every outline is rounded by that much; export them in float64 (QGIS: a GeoJSON's default)"
        )
    hint = units_hint(blocks, survey)
    if hint:
        notes.append(f"{path}: {hint}")
    if supports and blocks and not survey.flip_y:
        feet = np.median([p.bounds[1] for p in blocks])
        above = [k for k, s in enumerate(supports) if s.bounds[1] >= feet]
        if len(above) == len(supports):
            what = "the supports lie" if len(supports) > 1 else "the support lies"
            notes.append(
                f"{path}: {what} above half the blocks: is the y axis pointing down (image rows)? --flip-y reads "
                "it pointing up"
            )
    hint = ground_hint(assembly)
    return notes + ([f"{path}: {hint}"] if hint else [])


def ground_hint(assembly: Assembly) -> str:
    """With no support, the block that looks like the ground or a foundation — the lowest, spanning at least
    ``GROUND_SPAN`` of the blocks' width — named ("" if none): a QGIS layer's ``layer = "foundation"`` column is
    not read, and the no-support warning left the user to find which feature to mark."""
    blocks = assembly.blocks
    if assembly.support_count or len(blocks) < 2:
        return ""
    bounds = np.array([b.polygon.bounds for b in blocks])
    lowest = int(np.argmin(bounds[:, 1]))
    width = bounds[:, 2].max() - bounds[:, 0].min()
    if bounds[lowest, 2] - bounds[lowest, 0] < GROUND_SPAN * width:
        return ""
    return (
        f"{body_label(lowest, blocks[lowest].name)} lies lowest and spans the structure: if it is the ground or a "
        'foundation, give it "role": "support" (in QGIS, a text field role valued support)'
    )


GROUND_SPAN = 0.8
"""The share of the blocks' width a block must span to be named as the likely ground."""


def _far(frame: Frame) -> float:
    return float(np.hypot(*frame.shift))


def units_hint(blocks: list, survey: Survey) -> str:
    """A sentence when the median block (shapely polygons, m) is more than ``HUGE_STONE`` across, or read with
    ``units`` less than ``TINY_STONE``, naming the units that make it a stone's size ("" otherwise)."""
    if not blocks:
        return ""
    sizes = [math.hypot(x1 - x0, y1 - y0) for x0, y0, x1, y1 in (p.bounds for p in blocks)]
    median = float(np.median(sizes))
    given = survey.units != "m"
    if median <= HUGE_STONE and (median >= TINY_STONE or not given):
        return ""
    as_read = f" read with --units {survey.units}" if given else ""
    as_file = median / unit_scale(survey.units)  # the median stone in the file's own numbers
    fits = [u for u in UNITS if TINY_STONE <= as_file * UNITS[u] <= HUGE_STONE]
    fits.sort(key=lambda u: abs(math.log(as_file * UNITS[u] / 0.4)))  # the nearest to a stone's 0.4 m
    word = {"m": "metres? without --units they are read so", "cm": "centimetres? --units cm reads them so"}
    word["mm"] = "millimetres? --units mm reads them so (--units cm: centimetres)"
    guess = f"are the coordinates {word[fits[0]]}" if fits else "which unit are they? --units 0.002: 2 mm per unit"
    return f"the blocks are {_lengths(min(sizes), max(sizes))} across{as_read} (median {_lengths(median)}): {guess}"


def _lengths(*metres: float) -> str:
    """Lengths as "321–718 m", or "0.32–0.716 mm" when the largest is under 0.1 m."""
    unit, factor = ("m", 1.0) if max(metres) >= 0.1 else ("mm", 1e3)
    return "–".join(f"{m * factor:.3g}" for m in metres) + f" {unit}"


def hull_of(xy: np.ndarray, label: str) -> tuple[np.ndarray, float]:
    """The convex hull of a ring (k, 2) refused as not convex, and the fraction of its area it adds; raises
    when that is more than ``MAX_HULL_GAIN`` (or the ring self-intersects: no area to compare)."""
    ring = Polygon(xy)
    area = abs(signed_area(np.asarray(xy, dtype=np.float64)))
    hull = shapely.convex_hull(ring)
    gain = hull.area / area - 1.0 if ring.is_valid and area > 0.0 else math.inf
    if not gain <= MAX_HULL_GAIN:
        raise GeometryError(
            f"{label}: polygon is not convex, and its convex hull would add {gain:.1%} of its area, more than "
            f"--convex-hull takes ({MAX_HULL_GAIN:.0%}: a tracing slip): split it into convex stones"
        )
    return np.asarray(hull.exterior.coords)[:-1], gain


def hull_note(path, hulls: list[tuple[str, float, float]]) -> str:
    """The note of the stones read as their hulls (``hulls``: label, fraction of its area added, m² added)."""
    label, most, _ = max(hulls, key=lambda h: h[1])
    least = min(h[1] for h in hulls)
    return (
        f"{path}: {len(hulls)} non-convex polygon{'s' if len(hulls) > 1 else ''} read as {'their' if len(hulls) > 1 else 'its'} "
        f"convex hull{'s' if len(hulls) > 1 else ''} (--convex-hull), adding {least:.2%}–{most:.2%} of the area (most: {label})"
    )


def surveyed_polygon(xy, index: int, name: str, role: str, survey: Survey, hulls: list) -> Polygon:
    """The checked polygon of a body (``polygon_from_coords``), or with ``survey.convex_hull`` that of its hull
    when it is not convex (``hulls`` receives its label and the area the hull adds)."""
    try:
        return polygon_from_coords(xy, index, name, role)
    except NotConvexError:
        if not survey.convex_hull:
            raise
    except GeometryError as exc:  # a stone too small read with --units: the unit, not degrees, is what is wrong
        if survey.units == "m" or "is zero or too small" not in str(exc):
            raise
        from .checks import DEGREES_HINT

        size = float(np.hypot(*np.ptp(np.asarray(xy, dtype=np.float64), axis=0)))
        said = f" (a stone {size:.2g} m across read with --units {survey.units}: is that the coordinates' unit?)"
        raise GeometryError(str(exc).replace(DEGREES_HINT, "") + said) from None
    label = body_label(index, name, role)
    hull, gain = hull_of(xy, label)
    polygon = polygon_from_coords(hull, index, name, role)
    hulls.append((label, gain, polygon.area * gain / (1.0 + gain)))
    return polygon


def finish_reading(path, refused, blocks, supports, frame: Frame, survey: Survey, hulls, notes) -> Assembly:
    """The assembly read (refusals raised, with where the coordinates they quote are on the map and a units
    hint), overlaps trimmed when ``survey`` says so; ``notes`` (if a list) receives what was done."""
    read = [p.polygon for p in blocks if p is not None]
    hint = units_hint(read, survey) if refused else ""
    if refused and not hint and survey.units == "m" and RECENTRE_UP_TO < frame.far <= RECENTRE_UP_TO / UNITS["mm"]:
        # a map grid's millimetres (Lambert-93 × 1000): refused as far, with no word of the unit that reads them
        hint = (
            f"coordinates up to {frame.far:.3g} from the origin: a map grid's in millimetres? --units mm reads them so"
        )
    if refused and frame.rounding is not None and frame.rounding >= 1e-5:  # the likely cause, said with it
        hint = (
            f"{hint}; " * bool(hint)
            + f"its coordinates are float32 values, exact only to ±{frame.rounding:.2g} m there"
        )
    raise_refused(refused, frame.where() + (f"; {hint}" if hint else ""))
    hint = units_hint(read, survey)
    if hint:  # stones of a km (a survey in mm read as metres), or of a mm read with --units: no masonry. The
        # first ran with a warning, and a bridge's traced fill was refused as "carried_at … absurd (a likely typo)"
        raise GeometryError(f"{path}: {hint}")
    assembly = Assembly(tuple(blocks), tuple(supports))
    said = survey_notes(path, frame, survey, assembly)
    if hulls:
        said.append(hull_note(path, hulls))
    counts = {"pairs": 0, "deepest_m": 0.0}
    if survey.trim_overlaps > 0.0 and assembly.block_count:
        try:
            assembly, trimmed = trim_overlaps(assembly, survey.trim_overlaps, counts)
        except GeometryError as exc:
            raise GeometryError(f"{path}: {exc}{frame.where()}") from None
        said += [f"{path}: {trimmed}"] if trimmed else []
    if notes is not None:
        notes.extend(said)
    survey.done.clear()
    survey.done.update(reading_record(frame, survey, hulls, counts))
    return assembly


def reading_record(frame: Frame, survey: Survey, hulls: list, counts: dict) -> dict:
    """What a file was read as, only what applies (a file in metres near the origin, read as it is: {}):
    ``map_origin_m`` (the map coordinates of the origin read: add them to a result's, as the shift's note and a
    refusal say), ``units`` and ``metres_per_unit``, ``flip_y``, ``convex_hull`` (stones hulled, m² added),
    ``trim_overlaps`` (depth, pairs trimmed, deepest overlap)."""
    record: dict = {}
    if frame.shift != (0.0, 0.0):
        record["map_origin_m"] = [frame.shift[0], frame.shift[1]]
    if survey.units != "m":
        record |= {"units": survey.units, "metres_per_unit": frame.scale}
    if survey.flip_y:
        record["flip_y"] = True
    if survey.convex_hull:
        record["convex_hull"] = {"stones": len(hulls), "area_added_m2": float(sum(h[2] for h in hulls))}
    if survey.trim_overlaps > 0.0:
        record["trim_overlaps"] = {"depth_m": survey.trim_overlaps, **counts}
    return record


def raise_refused(refused: list[tuple[str, str]], end: str = "") -> None:
    """Raise the first refused polygon's error, the other refused bodies named after it: a drawing with
    several stones not convex (or self-intersecting) was mended one run of ``masonry check`` per stone."""
    if not refused:
        return
    others = [body for _, body in refused[1:]]
    shown = ", ".join(others[:5]) + (f", … ({len(others) - 5} more)" if len(others) > 5 else "")
    more = f" (and {len(others)} more polygon{'s' if len(others) > 1 else ''} refused: {shown})" if others else ""
    raise GeometryError(refused[0][0] + end + more)
