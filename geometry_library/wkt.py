"""Reading and writing assemblies as WKT (GeoJSON: :mod:`geometry_library.io`).

One body per line; blank lines and lines starting with ``#`` are ignored. A line is a WKT
geometry, optionally preceded by a label and a colon::

    POLYGON ((0 0, 0.3 0, 0.3 0.2, 0 0.2, 0 0))            # block "block-<i>"
    c01-b01: POLYGON ((...))                                # block "c01-b01"
    block c01-b02: POLYGON ((...))
    support ground fixed: POLYGON ((...))                   # support, role fixed or driven
    support: POLYGON ((...))                                # support "support-<j>", fixed

A ``MULTIPOLYGON`` or ``GEOMETRYCOLLECTION`` of polygons gives one block per member (named
``<label>-<k>`` when labelled); the whole file may also be one such geometry spread over lines.
WKT carries no density or thickness: the reader's arguments apply to every block.

A ``LINESTRING`` (or a ``MULTILINESTRING`` of one part) is a ground line traced along the foot, as in GeoJSON:
the support under it (``survey.ground_from_line``), named ``ground`` unless labelled (``support ground: LINESTRING
(…)``, or the WKT alone); a line labelled ``block`` is refused.

Errors are one-line :class:`GeometryError` messages naming the file, the line and, once known, the body
(``walls.wkt: line 5: support 1 ("ground"): polygon has holes; blocks are solid``).
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import shapely.wkt
from shapely.geometry import GeometryCollection, LineString, MultiLineString, MultiPolygon, Polygon

from .blocks import Assembly, Block, GeometryError, Support
from .checks import body_label
from .fill import FILL_DENSITY
from .io import _line_of, _number, _read_text, _ring_coords, ground_line
from .survey import GROUND_DEPTH, Survey, finish_reading, frame_of, ground_from_line, surveyed_polygon
from .traced_fill import carry_fills, fill_outline

_LABEL = re.compile(
    r"^\s*(?:(?P<role>block|support|fill)\s+)?(?P<name>[^\s:]+)(?:\s+(?P<srole>fixed|driven))?\s*:\s*(?P<wkt>.+)$",
    re.IGNORECASE,
)
_ROLE_ONLY = re.compile(
    r"^\s*(?P<role>block|support|fill)(?:\s+(?P<srole>fixed|driven))?\s*:\s*(?P<wkt>.+)$", re.IGNORECASE
)
"""A role with no name (``support : POLYGON …``): _LABEL read its role word as the name of a block."""


def _polygons_of(geom, where: str) -> list[Polygon]:
    if isinstance(geom, Polygon):
        return [geom]
    if isinstance(geom, (MultiPolygon, GeometryCollection)):
        out = []
        for member in geom.geoms:
            if not isinstance(member, Polygon):
                raise GeometryError(f"{where}: collection member must be a POLYGON, got {member.geom_type}")
            out.append(member)
        return out
    raise GeometryError(
        f"{where}: geometry must be a POLYGON, MULTIPOLYGON or GEOMETRYCOLLECTION (a LINESTRING: a ground line), "
        f"got {geom.geom_type}"
    )


def _ground_polygon(
    geom, role: str, where: str, body: str, survey: Survey, said: list[str]
) -> tuple[Polygon, np.ndarray]:
    """The ground under a traced ground line (``survey.ground_from_line``, as a GeoJSON ``LineString``'s), in the
    file's coordinates, its line's points as ``traced``; the line said in ``said``. A line labelled ``block``, or of
    several parts, is refused; ``body``: ``where`` with the support's label, for the line's own faults."""
    kind = geom.geom_type.upper()
    if role != "support":
        raise GeometryError(f"{where}: a {kind} is the ground under it: label it 'support NAME:' (or not at all)")
    if isinstance(geom, MultiLineString):
        if len(geom.geoms) != 1:
            raise GeometryError(f"{where}: a MULTILINESTRING of {len(geom.geoms)} parts; a ground line is one line")
        geom = geom.geoms[0]
    traced = np.asarray(geom.coords, dtype=np.float64)[:, :2]
    ring, dip = ground_from_line(traced, survey, body)
    said.append(
        f"{where}: a {kind} read as the ground under it, {GROUND_DEPTH:g} m deep (its upper hull: dips up to "
        f"{dip * 1e3:.2g} mm bridged)"
    )
    return Polygon(ring), traced


def _parse_wkt(text: str, where: str):
    try:
        with warnings.catch_warnings():  # GEOS warns on NaN coordinates; the vertex check reports them
            warnings.simplefilter("ignore", RuntimeWarning)
            return shapely.wkt.loads(text)
    except Exception as exc:  # shapely raises GEOSException / ValueError variants
        msg = str(exc).splitlines()[0] if str(exc) else exc.__class__.__name__
        raise GeometryError(f"{where}: cannot parse WKT ({msg})") from None


def read_wkt(
    path, density: float = 2500.0, thickness: float = 1.0, survey: Survey | None = None, notes: list | None = None
) -> Assembly:
    """Read an assembly from a WKT file (format in the module docstring); ``survey`` and ``notes`` as
    :func:`read_geojson`'s.

    Raises
    ------
    GeometryError — unreadable file, unparsable WKT, wrong geometry type, holes, or a polygon failing
    the checks of :func:`~geometry_library.checks.polygon_from_coords` (named by file, line, body).
    """
    path = Path(path)
    _number(density, "density", str(path))
    _number(thickness, "thickness", str(path))
    lines = [
        (n, line.strip())
        for n, line in enumerate(_read_text(path).splitlines(), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not lines:
        raise GeometryError(f"{path}: no geometry in file")
    entries: list[tuple[str, str | None, str | None, str | None, str]] = []  # where, role, name, srole, wkt
    first = lines[0][1].upper()
    if first.startswith(("GEOMETRYCOLLECTION", "MULTIPOLYGON")) and len(lines) > 1 and not _complete(lines[0][1]):
        entries.append((f"{path}: line {lines[0][0]}", None, None, None, " ".join(t for _, t in lines)))
    else:
        for n, line in lines:
            if fill := _FILL.match(line):  # "fill road 1900: POLYGON …": a traced fill, its density after its name
                if fill["density"] is None and _is_number(fill["name"]):  # 'fill 1800:' ran at 2000, named "1800"
                    raise GeometryError(
                        f"{path}: line {n}: 'fill {fill['name']}:' reads {fill['name']} as the fill's name; its "
                        f"density goes after a name: 'fill NAME {fill['name']}: POLYGON ((…))'"
                    )
                entries.append((f"{path}: line {n}", "fill", fill["name"], fill["density"], fill["wkt"]))
                continue
            m = _ROLE_ONLY.match(line)
            if m and m["srole"] and m["role"].lower() == "block":
                m = None  # "block fixed: …" is a block named "fixed" (a block has no support role): write_wkt's
            m = m or _LABEL.match(line)
            if m:  # a name before a colon (WKT has none): "polygon1: POLYGON …" is the block polygon1
                name = m.groupdict().get("name")
                entries.append((f"{path}: line {n}", m["role"], name, m["srole"], m["wkt"]))
            elif ":" in line:  # WKT has no colon: a label the patterns refused (": POLYGON …" said "Unknown type: ':'")
                raise _bad_label(f"{path}: line {n}", line.split(":", 1)[0])
            elif (unlabelled := _NO_COLON.match(line)) is not None:  # "support g POLYGON …": "Unknown type: 'SUPPORT'"
                raise GeometryError(
                    f"{path}: line {n}: {unlabelled['label']!r} before {unlabelled['kind'].upper()}: a label ends "
                    f"with a colon ('{unlabelled['label']}: {unlabelled['kind'].upper()} ((…))')"
                )
            else:
                entries.append((f"{path}: line {n}", None, None, None, line))
    blocks: list[Block] = []
    supports: list[Support] = []
    refused: list[tuple[str, str]] = []
    pending = []  # (where, role, index, label, srole, coords): made once every ring is read
    survey, said = survey or Survey(), []  # said: the ground lines read
    fills = []  # (where, name, density, ring) of each traced fill
    lines: dict[int, np.ndarray] = {}  # pending's index -> a ground line's points as given
    for where, role, name, srole, text in entries:
        geom = _parse_wkt(text, where)
        line = isinstance(geom, (LineString, MultiLineString))  # a ground line traced along the foot
        if not line and (role or "").lower() == "fill":  # no body: the blocks under it carry its weight
            name = name or f"fill-{len(fills) + 1}"
            fills.append(_fill_entry(geom, f"{where}: {body_label(len(fills), name, 'fill')}", srole, name))
            continue
        if line:
            body = f"{where}: {body_label(len(supports), name or 'ground', 'support')}"
            ground, lines[len(pending)] = _ground_polygon(geom, (role or "support").lower(), where, body, survey, said)
            polys = [ground]
            role, name = "support", name or "ground"
        else:
            role = (role or ("support" if srole else "block")).lower()
            polys = _polygons_of(geom, where)
        if role == "support" and len(polys) != 1:
            raise GeometryError(f"{where}: a support must be a single POLYGON")
        for k, poly in enumerate(polys):
            index = len(blocks) if role == "block" else len(supports)
            label = name if len(polys) == 1 or name is None else f"{name}-{k + 1}"
            label = label or f"{role}-{index + 1}"
            if poly.is_empty:
                raise GeometryError(f"{where}: {body_label(index, label, role)}: polygon is empty")
            if poly.interiors:
                raise GeometryError(f"{where}: {body_label(index, label, role)}: polygon has holes; blocks are solid")
            (blocks if role == "block" else supports).append(None)  # numbered now, made once the frame is known
            pending.append((where, role, index, label, srole, np.asarray(poly.exterior.coords)[:, :2]))
    frame = frame_of([entry[-1] for entry in pending], survey)
    (notes if notes is not None else []).extend(said)
    outlines = [(where, name, rho, fill_outline(frame.local(xy), where)) for where, name, rho, xy in fills]
    hulls: list[tuple[str, float, float]] = []
    for k, (where, role, index, label, srole, coords) in enumerate(pending):
        line = frame.local(lines[k]) if k in lines else None  # the ground made again from it as read: written so
        coords = frame.local(coords) if line is None else ground_from_line(line, Survey(), where)[0]
        try:
            polygon = surveyed_polygon(coords, index, label, role, survey, hulls)
        except GeometryError as exc:
            refused.append((f"{where}: {exc}", body_label(index, label, role)))
            continue
        if role == "block":
            blocks[index] = Block(polygon, label, float(density), float(thickness))
        else:
            supports[index] = Support(polygon, label, (srole or "fixed").lower(), _line_of(line))
    return carry_fills(finish_reading(path, refused, blocks, supports, frame, survey, hulls, notes), outlines, notes)


def _fill_entry(geom, where: str, density: str | None, name: str) -> tuple[str, str, float, np.ndarray]:
    """(where, name, density kg/m³, ring) of a traced fill's line (``fill NAME [DENSITY]: POLYGON ((…))``; no
    density: FILL_DENSITY)."""
    rho = FILL_DENSITY if density is None else _number(_float(density, where), "density", where)
    polys = _polygons_of(geom, where)
    if len(polys) != 1 or polys[0].interiors:
        raise GeometryError(f"{where}: a fill is one POLYGON, without holes")
    return where, name, rho, np.asarray(polys[0].exterior.coords)[:, :2]


def _is_number(text: str | None) -> bool:
    try:
        float(text or "")
    except ValueError:
        return False
    return True


def _float(text: str, where: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise GeometryError(
            f"{where}: the fill's density {text!r} is not a number (kg/m³: 'fill NAME 1900: …')"
        ) from None


_FILL = re.compile(
    r"^\s*fill(?:\s+(?P<name>[^\s:]+))?(?:\s+(?P<density>[-+]?[0-9][^\s:]*))?\s*:\s*(?P<wkt>.+)$", re.IGNORECASE
)
"""A traced fill's label: ``fill``, its name, then its density (kg/m³; FILL_DENSITY without one)."""

_NO_COLON = re.compile(
    r"\s*(?P<label>[^\s(:][^(:]*?)\s+(?P<kind>POLYGON|MULTIPOLYGON|GEOMETRYCOLLECTION|LINESTRING|MULTILINESTRING)\b",
    re.I,
)
"""Words before the WKT with no colon after them: a label missing its colon."""


def _bad_label(where: str, label: str) -> GeometryError:
    """The error for a line whose text before its colon is not a label."""
    what = "nothing before the colon" if not label.strip() else f"{label.strip()!r} before the colon is not a label"
    return GeometryError(
        f"{where}: {what}; expected 'NAME: POLYGON ((…))', 'block NAME: …', 'support [NAME] [fixed|driven]: …', "
        "'fill NAME [DENSITY]: …' or the WKT alone (a name has no spaces or colons)"
    )


def _complete(text: str) -> bool:
    """True if the parentheses of a WKT text are balanced (one complete geometry on the line)."""
    return text.count("(") == text.count(")") and "(" in text


def _wkt_polygon(polygon: Polygon) -> str:
    ring = ", ".join(f"{x!r} {y!r}" for x, y in _ring_coords(polygon))
    return f"POLYGON (({ring}))"


def write_wkt(assembly: Assembly, path) -> Path:
    """Write ``assembly`` as labelled WKT lines (full precision): its traced fills as ``fill NAME DENSITY:``
    outlines, its ground lines as LINESTRINGs, so that reading the file gives the same assembly (coordinates as
    read: near the origin, in metres). Density and thickness are not kept (the reader's arguments give them); a
    block carrying a mass that is no traced fill's (the builder's ``fill_to``) is refused: WKT cannot hold it."""
    path = Path(path)
    blocks, fills = assembly.traced_fills()
    for body in (*blocks, *assembly.supports, *fills):
        if not body.name or re.search(r"[\s:]", body.name):
            raise GeometryError(f'{path}: name "{body.name}" cannot be written to WKT (spaces or colons)')
    for index, block in enumerate(blocks):
        if block.carried_mass > 0.0:
            raise GeometryError(
                f"{path}: {body_label(index, block.name)} carries {block.carried_mass:.4g} kg (a fill's weight), which "
                "WKT cannot hold: write GeoJSON (write_geojson keeps it as carried_mass)"
            )
    lines = ["# masonry assembly: one body per line, '<role> <name> [support role]: <WKT>', 'fill <name> <kg/m3>: …'"]
    lines += [f"block {b.name}: {_wkt_polygon(b.polygon)}" for b in blocks]
    lines += [f"fill {f.name} {f.density!r}: {_wkt_polygon(f.outline)}" for f in fills]
    for s in assembly.supports:
        line = ground_line(s)
        shape = (
            _wkt_polygon(s.polygon) if line is None else f"LINESTRING ({', '.join(f'{x!r} {y!r}' for x, y in line)})"
        )
        lines.append(f"support {s.name} {s.role}: {shape}")
    try:
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    except OSError as exc:
        raise GeometryError(f"{path}: cannot write file ({exc})") from None
    return path
