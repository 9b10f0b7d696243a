"""Reading and writing assemblies: GeoJSON (WKT: :mod:`geometry_library.wkt`).

GeoJSON
-------
A ``FeatureCollection`` with one ``Polygon`` feature per body (coordinates in metres, exterior ring
only; a ``MultiPolygon`` of one part, as QGIS saves polygon layers, is that polygon; a ``LineString``, or a
``MultiLineString`` of one part, is a ground line: the support under it, ``survey.ground_from_line``). Feature properties
(a ``null`` one is not given: its default applies):

=================  =========================================================================
``role``           ``"block"`` (default) or ``"support"``
``name``           unique label (default ``<column>-<value>`` of a GIS id column, ``id-17``, when those differ
                   (:func:`id_names`); else ``block-<i>`` / ``support-<j>``)
``density``        kg/m³, blocks only (default: the reader's ``density`` argument)
``thickness``      m, blocks only (default: the reader's ``thickness`` argument)
``velocity``       [vx, vy, ω] initial velocity, blocks only (default [0, 0, 0])
``support_role``   ``"fixed"`` (default) or ``"driven"``, supports only
``carried_mass``   kg ≥ 0, blocks only: a dead mass the block carries (a bridge's fill), with
``carried_at``     [x, y] m, where it is lumped (``Block.carried_mass``; default none)
=================  =========================================================================

Other properties, and a block's on a support or a support's on a block, are not read: ``read_geojson`` lists
them (with the first body carrying each) in its ``unknown`` argument, for its caller to warn about, except a
GIS's feature-id columns (``id``, ``fid``, ``ogc_fid``, ``objectid``, any case) that a QGIS or ogr2ogr export
adds to every layer.

Blocks keep the order of their features, supports too. :func:`write_geojson` writes the same
format with full float precision, so ``read_geojson(write_geojson(a))`` gives back ``a``.

WKT: :mod:`geometry_library.wkt`.

Errors are one-line :class:`GeometryError` messages naming the file, the feature / line and, once known,
the body as every message names one (:func:`~geometry_library.checks.body_label`), in one format::

    walls.geojson: feature 3: block 2 ("B12"): polygon is not convex (reflex vertex at (1, 2))
    walls.wkt: line 5: support 1 ("ground"): polygon has holes; blocks are solid

Features, lines and bodies are all numbered from 1 (feature 3 is the third in the file, block 2 the
second block), and unnamed bodies are called ``block-1``, ``block-2``, … as in a TOML scenario.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import Polygon

from .blocks import SUPPORT_ROLES, Assembly, Block, GeometryError, Support, ccw_vertices, name_problem, quoted_name
from .checks import body_label, polygon_from_coords
from .fill import FILL_DENSITY
from .survey import GROUND_DEPTH, Survey, finish_reading, frame_of, ground_from_line, surveyed_polygon
from .traced_fill import carry_fills, fill_outline
from .values import check_positive, is_real

LINES = ("LineString", "MultiLineString")


def _word(value):
    """An enumerated word (a role) in lower case, as a WKT label's is read; anything else as given."""
    return value.strip().lower() if isinstance(value, str) else value


GEOJSON_PROPERTIES = ("role", "name", "density", "thickness", "velocity", "support_role", "carried_mass", "carried_at")
"""The feature properties the reader uses."""
BLOCK_PROPERTIES = ("density", "thickness", "velocity", "carried_mass", "carried_at")
"""The properties read on blocks only: on a support they are not used (listed in ``unknown``)."""
SUPPORT_PROPERTIES = ("support_role",)
"""The properties read on supports only: on a block they are not used (listed in ``unknown``)."""
NOT_FILL_PROPERTIES = tuple(k for k in GEOJSON_PROPERTIES if k not in ("role", "name", "density"))
"""The properties a traced fill (``"role": "fill"``) does not use (listed in ``unknown``)."""
GIS_ID_COLUMNS = ("id", "fid", "ogc_fid", "objectid")
"""Feature ids a GIS export adds to every layer (compared lower-case): not read, not reported."""


def _read_text(path: Path) -> str:
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise GeometryError(f"{path}: cannot read file ({exc.__class__.__name__}: {exc})") from None
    # Notepad's "UTF-8 with BOM" was "invalid JSON (Unexpected UTF-8 BOM …)" (a scenario file reads it); a UTF-16
    # file was "byte 0, 0xff: … such as Windows-1252", a binary one named a line of its bytes
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise GeometryError(f"{path}: a UTF-16 text file (it starts with UTF-16's byte-order mark); save it as UTF-8")
    if b"\x00" in raw:
        raise GeometryError(f"{path}: not a text file (it holds NUL bytes: a binary file)")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:  # it said "(UnicodeDecodeError: 'utf-8' codec can't decode byte 0xe9 …)"
        line = raw.count(b"\n", 0, exc.start) + 1
        raise GeometryError(
            f"{path}:{line}: not a UTF-8 text file (byte {exc.start}, 0x{raw[exc.start]:02x}: a character saved in "
            "another encoding, such as Windows-1252); save it as UTF-8 (a GIS export: choose the UTF-8 encoding)"
        ) from None


def _number(value, what: str, where: str) -> float:
    check_positive(where, **{what: value})
    return float(value)


def _real(value) -> float:
    """A JSON number as a float: a bool or a string of a number ("1") is not one (float() took both, so
    ``true`` was read as 1.0 without a word); an int too large for a float is infinite (the caller says so)."""
    if not is_real(value):
        raise TypeError(f"not a number: {value!r}")
    try:
        return float(value)
    except OverflowError:  # a 400-digit integer: "int too large to convert to float" was a traceback
        return math.inf


def _carried(props: dict, where: str, frame) -> dict:
    """A block's ``carried_mass`` and ``carried_at`` (both or neither), the point in the polygons' ``frame``."""
    mass, at = props.get("carried_mass"), props.get("carried_at")
    if mass is None and at is None:
        return {}
    try:
        m, point = _real(mass), frame.local(np.array([_real(x) for x in at], dtype=np.float64))
    except (TypeError, ValueError):
        m, point = math.nan, ()
    if len(point) != 2 or not (np.all(np.isfinite(point)) and math.isfinite(m) and m >= 0.0):
        raise GeometryError(
            f"{where}: carried_mass (kg ≥ 0) and carried_at ([x, y] m) go together, got {mass!r}, {at!r}"
        )
    return {"carried_mass": m, "carried_at": (float(point[0]), float(point[1]))}


def _velocity(value, where: str) -> tuple[float, float, float]:
    try:
        v = tuple(_real(x) for x in value)
    except (TypeError, ValueError):
        v = ()
    if len(v) != 3 or not all(math.isfinite(x) for x in v):
        raise GeometryError(f"{where}: velocity must be [vx, vy, omega], got {value!r}")
    return v


def read_geojson(
    path,
    density: float = 2500.0,
    thickness: float = 1.0,
    unknown: dict | None = None,
    survey: Survey | None = None,
    notes: list | None = None,
) -> Assembly:
    """Read an assembly from a GeoJSON FeatureCollection (format in the module docstring).

    Parameters
    ----------
    path : str or Path.
    density : kg/m³, thickness : m — defaults for blocks without those properties.
    unknown : a dict given receives each property key the reader does not use (not in GEOJSON_PROPERTIES nor
        GIS_ID_COLUMNS) → the first body carrying it (``feature 2, block 2 ("B2")``), in file order.
    survey : how to read a surveyed file (units, y down, convex hulls, overlaps trimmed:
        :mod:`geometry_library.survey`); a file far from the origin is moved near it in any case.
    notes : a list given receives the one-line notes of that reading (the shift, hulls, trims, hints).

    Raises
    ------
    GeometryError — unreadable file, bad JSON, not a FeatureCollection, a feature that is not a
    Polygon, has holes, bad properties, or a polygon failing the checks of
    :func:`~geometry_library.checks.polygon_from_coords` (named by file, feature, body).
    """
    path = Path(path)
    text = _read_text(path)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise GeometryError(f"{path}: invalid JSON ({exc.msg} at line {exc.lineno}, column {exc.colno})") from None
    except RecursionError:  # thousands of nested [[[…]]]: the decoder recurses (a traceback, exit 1)
        raise GeometryError(f"{path}: invalid GeoJSON (JSON nested too deeply)") from None
    if not isinstance(data, dict) or data.get("type") != "FeatureCollection":
        # "got None" said nothing of a JSON file that is no GeoJSON (a package.json, a settings file)
        if not isinstance(data, dict):
            got = f"a JSON {type(data).__name__}"
        elif "type" not in data:
            got = 'a JSON object with no "type" (not GeoJSON)'
        else:
            got = repr(data["type"])
        raise GeometryError(f"{path}: expected a GeoJSON FeatureCollection, got {got}")
    features = data.get("features")
    if not isinstance(features, list):
        raise GeometryError(f"{path}: FeatureCollection has no 'features' list")
    blocks: list[Block] = []
    supports: list[Support] = []
    refused: list[tuple[str, str]] = []  # (message, body) of each polygon refused, said together at the end
    pending = []  # (feature_at, where, role, index, name, props, coords): made once every ring is read
    fills = []  # (where, name, density, coords) of each traced fill: its weight goes to the blocks under it
    lines: dict[int, np.ndarray] = {}  # pending's index -> a ground line's points as given
    by_id = id_names(features)  # feature number -> "id-17": a GIS layer's own numbering names its stones
    survey, said = survey or Survey(), []  # said: the ground lines read
    for k, feature in enumerate(features, start=1):  # numbered from 1, as the bodies are (body_label)
        feature_at = where = f"{path}: feature {k}"  # the body's label is added once its role is read
        if not isinstance(feature, dict) or feature.get("type") != "Feature":
            raise GeometryError(f"{where}: not a GeoJSON Feature")
        props = feature.get("properties") or {}
        if not isinstance(props, dict):
            raise GeometryError(f"{where}: 'properties' must be an object")
        # null is not given (a GIS writes an empty attribute cell as null): a block was named "None" and a
        # null density refused ("must be a positive number, got None")
        props = {key: value for key, value in props.items() if value is not None}
        geometry = feature.get("geometry")
        gtype = geometry.get("type") if isinstance(geometry, dict) else None
        line = gtype in ("LineString", "MultiLineString")  # a ground line traced along the foot: a support
        role = _word(props.get("role", "support" if line else "block"))  # "Support": "role must be 'block' or …"
        if role not in ("block", "support", "fill") or (line and role != "support"):
            allowed = "'support' (a line is the ground under it)" if line else "'block', 'support' or 'fill'"
            raise GeometryError(f"{where}: role must be {allowed}, got {role!r}")
        index = {"block": len(blocks), "support": len(supports), "fill": len(fills)}[role]
        name = props.get("name", "")
        if isinstance(name, str) and not name.strip():  # an empty attribute cell, as null: not given
            name = by_id.get(k) or ("ground" if line else f"{role}-{index + 1}")  # block-1 first, as in TOML
        if isinstance(name, (bool, list, dict)):  # a number is a GIS id column's (5 -> "5"); these were named
            raise GeometryError(f"{where}: name must be a string, got {name!r}")  # "{'a': 1}", "True"
        name = str(name)
        if name_problem(name) is not None:  # before the label quotes it: a newline would cut it in two
            raise GeometryError(f"{where}: name {quoted_name(name)} {name_problem(name)}")
        where = f"{feature_at}: {body_label(index, name, role)}"
        if unknown is not None:  # a support's velocity (or density) was not read either, without a word
            elsewhere = {"block": SUPPORT_PROPERTIES, "support": BLOCK_PROPERTIES, "fill": NOT_FILL_PROPERTIES}[role]
            for key in props:
                if key in elsewhere or (key not in GEOJSON_PROPERTIES and str(key).lower() not in GIS_ID_COLUMNS):
                    unknown.setdefault(key, f"feature {k}, {body_label(index, name, role)}")
        rings = geometry.get("coordinates") if gtype in ("Polygon", "MultiPolygon", *LINES) else None
        if line:  # [[x, y], …] (a MultiLineString of one part, as QGIS saves a line layer): the ground under it
            rings = rings[0] if gtype == "MultiLineString" and isinstance(rings, list) and len(rings) == 1 else rings
            try:
                traced = np.array([[_real(c) for c in xy[:2]] for xy in rings], dtype=np.float64)
                ring, dip = ground_from_line(traced, survey, where)
            except (TypeError, ValueError, IndexError) as exc:  # GeometryError is a ValueError: said as it is
                bad = f"{where}: a ground line is [[x, y], …] (a MultiLineString of one part)"
                raise GeometryError(str(exc) if isinstance(exc, GeometryError) else bad) from None
            said.append(
                f"{feature_at}: a {gtype} read as the ground under it, {GROUND_DEPTH:g} m deep (its upper hull: "
                f"dips up to {dip * 1e3:.2g} mm bridged)"
            )
            rings = [ring.tolist()]
        elif gtype == "MultiPolygon":  # QGIS saves a polygon layer as MultiPolygons, most of one part
            if not isinstance(rings, list) or len(rings) != 1:
                parts = len(rings) if isinstance(rings, list) else 0
                raise GeometryError(
                    f"{where}: a MultiPolygon of {parts} parts; a feature is one body (split it into single "
                    "parts, e.g. QGIS's Multipart to Singleparts)"
                )
            rings = rings[0]
        elif gtype != "Polygon":
            raise GeometryError(f"{where}: geometry must be a Polygon, got {gtype!r} (a LineString: a ground line)")
        if not isinstance(rings, list) or not rings:
            raise GeometryError(f"{where}: Polygon has no coordinates")
        if len(rings) > 1:
            raise GeometryError(f"{where}: polygon has {len(rings) - 1} hole(s); blocks are solid")
        try:
            coords = np.array([[_real(c) for c in xy[:2]] for xy in rings[0]], dtype=np.float64)
        except (TypeError, ValueError, IndexError):
            raise GeometryError(f"{where}: coordinates must be [x, y] number pairs") from None
        if role == "fill":  # no body: the blocks under it carry its weight (traced_fill.carry_fills)
            fills.append((where, name, _number(props.get("density", FILL_DENSITY), "density", where), coords))
            continue
        (blocks if role == "block" else supports).append(None)  # numbered now, made once the frame is known
        if line:
            lines[len(pending)] = traced
        pending.append((feature_at, where, role, index, name, props, coords))
    frame = frame_of([entry[-1] for entry in pending], survey)
    hulls: list[tuple[str, float, float]] = []
    (notes if notes is not None else []).extend(said)
    for k, (feature_at, where, role, index, name, props, coords) in enumerate(pending):
        line = frame.local(lines[k]) if k in lines else None  # the ground made again from it as read: written so
        coords = frame.local(coords) if line is None else ground_from_line(line, Survey(), where)[0]
        try:
            polygon = surveyed_polygon(coords, index, name, role, survey, hulls)
        except GeometryError as exc:
            refused.append((f"{feature_at}: {exc}", body_label(index, name, role)))  # exc starts with the label
            continue
        if role == "block":
            blocks[index] = Block(
                polygon,
                name,
                _number(props.get("density", density), "density", where),
                _number(props.get("thickness", thickness), "thickness", where),
                _velocity(props.get("velocity", (0.0, 0.0, 0.0)), where),
                **_carried(props, where, frame),
            )
        else:
            srole = _word(props.get("support_role", "fixed"))
            if srole not in SUPPORT_ROLES:
                raise GeometryError(f"{where}: support_role must be one of {SUPPORT_ROLES}, got {srole!r}")
            supports[index] = Support(polygon, name, srole, _line_of(line))
    outlines = [(where, name, rho, fill_outline(frame.local(xy), where)) for where, name, rho, xy in fills]
    return carry_fills(finish_reading(path, refused, blocks, supports, frame, survey, hulls, notes), outlines, notes)


def _line_of(xy) -> tuple[tuple[float, float], ...] | None:
    """A ground line's points (m, as read) as ``Support.line`` keeps them; None for no line."""
    return None if xy is None else tuple((float(x), float(y)) for x, y in np.asarray(xy))


def id_names(features: list) -> dict[int, str]:
    """Feature number (from 1) → ``"<column>-<value>"`` (``id-17``) for the features with no ``name`` but a GIS
    id column (``GIS_ID_COLUMNS``, a whole number or a word), when those names all differ from each other and
    from the names given ({} otherwise: every body keeps its default name). A stone refused or overlapping was
    ``block 4 ("block-4")``, which a QGIS attribute table does not show (block 4 is feature 5 when the
    foundation comes first); its id is there."""
    named, found = set(), {}
    for k, feature in enumerate(features, start=1):
        props = (feature.get("properties") if isinstance(feature, dict) else None) or {}
        props = props if isinstance(props, dict) else {}
        if isinstance(props.get("name"), str) and props["name"].strip():
            named.add(props["name"])
            continue
        for key, value in props.items():
            if str(key).lower() in GIS_ID_COLUMNS and isinstance(value, (int, str)) and not isinstance(value, bool):
                found[k] = f"{key}-{value}"
                break
    names = list(found.values())
    unique = len(set(names)) == len(names) and not named.intersection(names)
    return found if unique and all(name_problem(n) is None for n in names) else {}


def _ring_coords(polygon: Polygon) -> list[list[float]]:
    """Closed CCW exterior ring as [[x, y], ...] (RFC 7946 orientation)."""
    xy = shapely.geometry.polygon.orient(polygon, sign=1.0).exterior.coords
    return [[float(x), float(y)] for x, y in np.asarray(xy)[:, :2]]


def ground_line(support: Support) -> list[tuple[float, float]] | None:
    """The ground line ``support`` was read from, when the ground made from it again is its polygon to the bit
    (None otherwise: a support drawn as a polygon, or one trimmed since: its polygon is what it is)."""
    if support.line is None:
        return None
    try:
        ring, _ = ground_from_line(np.asarray(support.line, dtype=np.float64), Survey(), support.name)
        made = polygon_from_coords(ring, 0, support.name, "support")
    except GeometryError:
        return None
    return list(support.line) if np.array_equal(ccw_vertices(made), support.vertices) else None


def write_geojson(assembly: Assembly, path) -> Path:
    """Write ``assembly`` as a GeoJSON FeatureCollection (full precision); returns the path. A surveyed file's
    traced fills are written as their outlines (``"role": "fill"``, the blocks without their weight) and its ground
    lines as lines, so that reading the file written gives the same assembly (in the coordinates read: near the
    origin, in metres)."""
    path = Path(path)
    features = []
    blocks, fills = assembly.traced_fills()
    for block in blocks:
        props = {"role": "block", "name": block.name, "density": block.density, "thickness": block.thickness}
        if any(v != 0.0 for v in block.velocity):
            props["velocity"] = [float(v) for v in block.velocity]
        if block.carried_mass > 0.0:
            props["carried_mass"] = float(block.carried_mass)
            props["carried_at"] = [float(x) for x in block.carried_at]
        features.append(_feature(block.polygon, props))
    for fill in fills:
        features.append(_feature(fill.outline, {"role": "fill", "name": fill.name, "density": fill.density}))
    for support in assembly.supports:
        props = {"role": "support", "name": support.name, "support_role": support.role}
        line = ground_line(support)
        if line is None:
            features.append(_feature(support.polygon, props))
        else:
            geometry = {"type": "LineString", "coordinates": [[x, y] for x, y in line]}
            features.append({"type": "Feature", "properties": props, "geometry": geometry})
    data = {"type": "FeatureCollection", "features": features}
    try:
        path.write_text(json.dumps(data, indent=1) + "\n", encoding="utf-8")
    except OSError as exc:  # its cause kept: masonry build names its --out, not this temporary file
        raise GeometryError(f"{path}: cannot write file ({exc})") from exc
    return path


def _feature(polygon: Polygon, props: dict) -> dict:
    return {
        "type": "Feature",
        "properties": props,
        "geometry": {"type": "Polygon", "coordinates": [_ring_coords(polygon)]},
    }
