"""A surveyed rubble bridge read from its GeoJSON, the researcher's way (docs/scenario-format.md, "A bridge's fill
traced as an outline"): a semicircle of 17 uneven voussoirs on coursed abutments, the ground traced as one line under
each abutment, the fill traced as an outline up to the road. Its λ under a horizontal acceleration and the thrust on
each abutment's ground are checked against the slow references of tests/four_hinge_reference.py, given the same ring
and the fill's columns over its extrados chords computed here by the shoelace formula: no LP, no reading of files."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from four_hinge_reference import least_load_factor, right_support_thrust

from cli_helpers import invoke

R, T, SPRING, ROAD = 3.0, 0.5, 2.0, 6.0  # intrados radius, ring, springing line, road (m)
STONE, FILL, G = 2300.0, 1900.0, 9.81
ABUTMENT = 2.2  # m wide, 4 courses of 0.5 m


def _joint_angles() -> np.ndarray:
    rng = np.random.default_rng(7)
    w = rng.uniform(7.0, 14.0, 17)
    return np.radians(np.r_[0.0, np.cumsum(w / w.sum() * 180.0)])


def _polygon(ring, **props) -> dict:
    ring = [list(map(float, p)) for p in ring]
    return {"type": "Feature", "properties": props, "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]}}


def _line(points, **props) -> dict:
    return {"type": "Feature", "properties": props, "geometry": {"type": "LineString", "coordinates": points}}


def _bridge(path) -> None:
    a = _joint_angles()
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
    features.append(_line([[-R - ABUTMENT - 1, 0.0], [-R + 0.5, 0.0]], name="left-ground"))
    features.append(_line([[R - 0.5, 0.0], [R + ABUTMENT + 1, 0.0]], name="right-ground"))
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))


def _ring_loads():
    """Joints left to right, and each voussoir's weight with its fill's, at their common centre of mass (only the
    abscissa of a vertical load matters); the fill's column over a chord: the quadrilateral up to the road."""
    t = _joint_angles()[::-1]
    intrados = np.stack([R * np.cos(t), SPRING + R * np.sin(t)], axis=1)
    extrados = np.stack([(R + T) * np.cos(t), SPRING + (R + T) * np.sin(t)], axis=1)

    def shoelace(p):
        x, y = p[:, 0], p[:, 1]
        cross = x * np.roll(y, -1) - np.roll(x, -1) * y
        area = 0.5 * cross.sum()
        return abs(area), np.array([(x + np.roll(x, -1)) @ cross, (y + np.roll(y, -1)) @ cross]) / (6 * area)

    stone, fill = [], []
    for k in range(17):
        stone.append(shoelace(np.array([intrados[k], intrados[k + 1], extrados[k + 1], extrados[k]])))
        e0, e1 = extrados[k], extrados[k + 1]
        fill.append(shoelace(np.array([e0, e1, [e1[0], ROAD], [e0[0], ROAD]])))
    return intrados, extrados, stone, fill


@pytest.fixture(scope="module")
def bridge(tmp_path_factory):
    path = tmp_path_factory.mktemp("bridge") / "bridge.geojson"
    _bridge(path)
    return path


def test_its_collapse_acceleration_is_the_four_hinge_references(bridge):
    """The fill's weight holds the abutments: the ring's own four hinges govern, its λ the enumeration's (the fill's
    inertia loaded too, at its columns' centroids)."""
    intrados, extrados, stone, fill = _ring_loads()
    mass = np.array([STONE * a for a, _ in stone])
    fmass = np.array([FILL * a for a, _ in fill])
    centre, fcentre = np.array([c for _, c in stone]), np.array([c for _, c in fill])
    weight = lambda m: np.stack([0 * m, -G * m], axis=1)  # noqa: E731
    push = lambda m: np.stack([G * m, 0 * m], axis=1)  # noqa: E731
    extra = (("dead", weight(fmass), fcentre), ("live", push(fmass), fcentre))
    expected, (joints, _) = least_load_factor(intrados, extrados, centre, weight(mass), push(mass), extra=extra)
    result = invoke("limit", bridge, "--json")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["load_factor"] == pytest.approx(expected, rel=1e-6)
    names = [f"v{17 - j:02d}|v{18 - j:02d}" for j in joints if 0 < j < 17]  # left to right: v17 is the left springer
    assert set(names) <= set(data["hinges"]) and len(data["hinges"]) == 4, (names, data["hinges"])


def test_each_abutments_ground_takes_the_rings_thrust(bridge):
    """With the ground traced under each abutment apart, --thrust gives each ground the least and greatest thrust
    of the ring and its fill on rigid springers (the abutments carry it to their ground unchanged), both ways."""
    intrados, extrados, stone, fill = _ring_loads()
    mass = np.array([STONE * a for a, _ in stone]) + np.array([FILL * a for a, _ in fill])
    x = (np.array([STONE * a * c[0] for a, c in stone]) + np.array([FILL * a * c[0] for a, c in fill])) / mass
    centre = np.stack([x, np.zeros_like(x)], axis=1)
    least, greatest = right_support_thrust(intrados, extrados, centre, np.stack([0 * mass, -G * mass], axis=1))
    data = json.loads(invoke("limit", bridge, "--thrust", "--json").stdout)
    thrust = {t["support"]: t for t in data["support_thrust"]}
    assert thrust["right-ground"]["direction"] == "+x" and thrust["left-ground"]["direction"] == "-x"
    for t in thrust.values():
        assert (t["least_N"], t["greatest_N"]) == pytest.approx((least, greatest), rel=1e-6)
