"""A surveyed rubble bridge as a researcher traces it, written as GeoJSON (tests/test_limit_traced_bridge.py checks it
against the slow references; test_doc_examples seeds docs/scenario-format.md's bridge.geojson with it): a semicircle
of 17 uneven voussoirs on coursed abutments, its fill traced as an outline up to the road ("role": "fill"), the
ground traced as one line under each abutment; ``offset`` moves it onto a map grid, ``ndigits`` rounds it (a survey's
mm: 3)."""

from __future__ import annotations

import json
import math

import numpy as np

R, T, SPRING, ROAD = 3.0, 0.5, 2.0, 6.0  # intrados radius, ring, springing line, road (m)
STONE, FILL, G = 2300.0, 1900.0, 9.81
ABUTMENT = 2.2  # m wide, 4 courses of 0.5 m


def joint_angles() -> np.ndarray:
    rng = np.random.default_rng(7)
    w = rng.uniform(7.0, 14.0, 17)
    return np.radians(np.r_[0.0, np.cumsum(w / w.sum() * 180.0)])


def _polygon(ring, **props) -> dict:
    ring = [list(map(float, p)) for p in ring]
    return {"type": "Feature", "properties": props, "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]}}


def _line(points, **props) -> dict:
    return {"type": "Feature", "properties": props, "geometry": {"type": "LineString", "coordinates": points}}


def write(path, offset: tuple[float, float] = (0.0, 0.0), ndigits: int | None = None) -> None:
    a = joint_angles()
    features = []
    for k in range(17):
        ring = [
            (r * math.cos(t), SPRING + r * math.sin(t))
            for r, t in ((R, a[k]), (R + T, a[k]), (R + T, a[k + 1]), (R, a[k + 1]))
        ]
        features.append(_polygon(ring, name=f"v{k + 1:02d}", density=STONE))
    for side in (1.0, -1.0):  # courses bonded: joints at 0.9 / 0.6 + 1.5 m from the springing
        for c in range(4):
            cuts = (
                [R, R + (0.9 if c % 2 == 0 else 0.6), R + ABUTMENT]
                if c % 2 == 0
                else [R, R + 0.6, R + 1.5, R + ABUTMENT]
            )
            for b, (xa, xb) in enumerate(zip(cuts[:-1], cuts[1:])):
                ring = [
                    (side * xa, 0.5 * c),
                    (side * xb, 0.5 * c),
                    (side * xb, 0.5 * c + 0.5),
                    (side * xa, 0.5 * c + 0.5),
                ]
                ring = ring if side > 0 else ring[::-1]
                features.append(_polygon(ring, name=f"{'RL'[side < 0]}-c{c + 1}-s{b + 1}", density=STONE))
    arc = [((R + T) * math.cos(t), SPRING + (R + T) * math.sin(t)) for t in np.linspace(0.0, math.pi, 200)]
    outline = [(R + ABUTMENT, SPRING), *arc, (-R - ABUTMENT, SPRING), (-R - ABUTMENT, ROAD), (R + ABUTMENT, ROAD)]
    features.append(_polygon(outline, role="fill", name="fill", density=FILL))
    features.append(_line([[-R - ABUTMENT - 1, 0.0], [-R + 0.5, 0.0]], name="left-ground", support_role="driven"))
    features.append(_line([[R - 0.5, 0.0], [R + ABUTMENT + 1, 0.0]], name="right-ground", support_role="driven"))
    for feature in features:
        rings = feature["geometry"]["coordinates"]
        points = rings[0] if feature["geometry"]["type"] == "Polygon" else rings
        moved = [[x + offset[0], y + offset[1]] for x, y in points]
        moved = moved if ndigits is None else [[round(x, ndigits), round(y, ndigits)] for x, y in moved]
        if feature["geometry"]["type"] == "Polygon":
            moved[-1] = moved[0]  # closed as it was
            feature["geometry"]["coordinates"] = [moved]
        else:
            feature["geometry"]["coordinates"] = moved
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
