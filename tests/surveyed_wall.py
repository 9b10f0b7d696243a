"""A rubble wall as a heritage survey traces it: irregular stones, hand-tracing slips, a GIS's coordinates.

The stones tile the face exactly before any slip is added: course boundaries are straight lines, each
slightly tilted; joints within a course lean a little; every stone's corners are chamfered (rubble has no
sharp corners, and the chamfers leave the voids of a dry wall where four stones meet). Then, as a hand traces
each stone on an orthophoto on its own:

- every vertex moves by up to ``slip`` metres (a mm: neighbours overlap or gap by about that much);
- a few stones get an extra vertex pushed ``dent`` metres into one edge (a slightly non-convex outline);
- the coordinates are those of a projected CRS (``offset``: Lambert-93 x ≈ 651 234 m, y ≈ 6 861 210 m),
  or millimetres (``scale`` = 1000), or image rows (``flip_y``: y pointing down);
- properties as a QGIS layer has them (``id``, ``stone_type``, ``layer``), no ``role``; the foundation is
  a polygon of its own (``layer`` = "foundation"), marked ``"role": "support"`` when ``mark_ground``.

``python tests/surveyed_wall.py OUT.geojson [--offset] [--mm] [--flip-y] [--clean]`` writes one.
"""

from __future__ import annotations

import json
import sys

import numpy as np

LAMBERT93 = (651234.12, 6861210.55)
"""A point of a wall near Paris in EPSG:2154 (Lambert-93), metres."""


def stones(length=4.0, courses=7, seed=0, chamfer=0.02):
    """The exact stones (list of (k, 2) CCW rings, m) and the foundation's ring, y up from 0 at the wall's foot."""
    rng = np.random.default_rng(seed)
    heights = rng.uniform(0.16, 0.28, courses)
    base = np.concatenate(([0.0], np.cumsum(heights)))
    slope = np.concatenate(([0.0], rng.uniform(-0.03, 0.03, courses)))  # the ground's line is level

    def line(k, x):
        return base[k] + slope[k] * (x - length / 2)

    rings = []
    for k in range(courses):
        joints = [0.0]
        while joints[-1] < length - 0.25:
            joints.append(min(joints[-1] + rng.uniform(0.22, 0.5), length))
        joints[-1] = length
        lean = np.concatenate(([0.0], rng.uniform(-0.04, 0.04, len(joints) - 2), [0.0]))
        for a, b in zip(range(len(joints) - 1), range(1, len(joints))):
            xa0, xb0 = joints[a] - lean[a] / 2, joints[b] - lean[b] / 2  # foot of each joint
            xa1, xb1 = joints[a] + lean[a] / 2, joints[b] + lean[b] / 2  # head
            quad = np.array(
                [[xa0, line(k, xa0)], [xb0, line(k, xb0)], [xb1, line(k + 1, xb1)], [xa1, line(k + 1, xa1)]]
            )
            rings.append(_chamfered(quad, chamfer * rng.uniform(0.5, 1.5, 4)))
    ground = np.array([[-0.3, -0.3], [length + 0.3, -0.3], [length + 0.3, 0.0], [-0.3, 0.0]])
    return rings, ground


def _chamfered(quad, cuts):
    """The quadrilateral with each corner cut ``cuts[i]`` along both its edges (a convex octagon)."""
    out = []
    for i, p in enumerate(quad):
        prev, nxt = quad[i - 1], quad[(i + 1) % 4]
        out.append(p + (prev - p) / np.hypot(*(prev - p)) * cuts[i])
        out.append(p + (nxt - p) / np.hypot(*(nxt - p)) * cuts[i])
    return np.array(out)


def traced(rings, slip=1e-3, dent=0.0, dents=0, seed=1):
    """``rings`` as a hand traces them: each vertex moved up to ``slip`` m; ``dents`` stones given an extra
    vertex ``dent`` m inside their longest edge's middle (non-convex)."""
    rng = np.random.default_rng(seed)
    out = [r + rng.uniform(-slip, slip, r.shape) for r in rings]
    for i in rng.choice(len(out), size=dents, replace=False):
        r = out[i]
        edge = np.hypot(*(np.roll(r, -1, axis=0) - r).T)
        j = int(np.argmax(edge))
        a, b = r[j], r[(j + 1) % len(r)]
        inward = np.array([-(b - a)[1], (b - a)[0]]) / edge[j]  # left of a CCW edge: inside
        out[i] = np.insert(r, j + 1, (a + b) / 2 + dent * inward, axis=0)
    return out


def feature_collection(
    rings,
    ground,
    offset=(0.0, 0.0),
    scale=1.0,
    flip_y=False,
    mark_ground=True,
    multipolygon=True,
    ndigits=3,
    ground_line=False,
):
    """A GeoJSON FeatureCollection (dict) of the stones then the foundation, in a GIS's coordinates:
    ``(x + offset) × scale``, y as an image's rows when ``flip_y``; rounded to ``ndigits`` (mm in metres). With
    ``ground_line`` the foundation is the line along its top (a LineString traced along the wall's foot)."""

    def coords(ring):
        xy = np.asarray(ring, dtype=float)
        if flip_y:
            xy = xy * [1.0, -1.0]
        xy = (xy + offset) * scale
        closed = np.vstack((xy, xy[:1]))
        return [[round(float(x), ndigits), round(float(y), ndigits)] for x, y in closed]

    def geometry(ring):
        if multipolygon:  # as QGIS saves a polygon layer
            return {"type": "MultiPolygon", "coordinates": [[coords(ring)]]}
        return {"type": "Polygon", "coordinates": [coords(ring)]}

    kinds = ("limestone", "sandstone", "limestone", "schist")
    features = [
        {
            "type": "Feature",
            "properties": {"id": i + 1, "stone_type": kinds[i % 4], "layer": "stones"},
            "geometry": geometry(r),
        }
        for i, r in enumerate(rings)
    ]
    props = {"id": len(rings) + 1, "stone_type": None, "layer": "foundation"}
    if mark_ground:
        props["role"] = "support"
    if ground_line:  # the foundation's top, from left to right, with a vertex under every metre
        top = np.array([[x, 0.0] for x in np.linspace(ground[0, 0], ground[1, 0], 6)])
        line = coords(top)[:-1]
        features.append(
            {"type": "Feature", "properties": props, "geometry": {"type": "LineString", "coordinates": line}}
        )
    else:
        features.append({"type": "Feature", "properties": props, "geometry": geometry(ground)})
    crs = {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::2154"}}
    return {"type": "FeatureCollection", "name": "wall", "crs": crs, "features": features}


def write(path, **options) -> dict:
    """Write a traced wall (``stones`` → ``traced`` → ``feature_collection``; options split between them by
    name) to ``path``; returns the FeatureCollection."""
    wall = {k: options.pop(k) for k in ("length", "courses", "seed", "chamfer") if k in options}
    trace = {k: options.pop(k) for k in ("slip", "dent", "dents") if k in options}
    rings, ground = stones(**wall)
    data = feature_collection(traced(rings, **trace), ground, **options)
    with open(path, "w", encoding="utf-8") as f:
        json.dump(data, f)
    return data


if __name__ == "__main__":
    args = sys.argv[1:]
    opts = {"offset": LAMBERT93 if "--offset" in args else (0.0, 0.0)}
    if "--mm" in args:
        opts.update(scale=1000.0, ndigits=0)
    if "--flip-y" in args:
        opts["flip_y"] = True
    if "--clean" in args:
        opts.update(slip=0.0)
    else:
        opts.update(dent=2e-3, dents=4)
    data = write(args[0], **opts)
    print(f"{args[0]}: {len(data['features']) - 1} stones and a foundation")
