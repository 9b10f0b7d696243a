"""A surveyed rubble bridge read from its GeoJSON, the researcher's way (docs/scenario-format.md, "A bridge's fill
traced as an outline"): a semicircle of 17 uneven voussoirs on coursed abutments, the ground traced as one line under
each abutment, the fill traced as an outline up to the road. Its λ under a horizontal acceleration and the thrust on
each abutment's ground are checked against the slow references of tests/four_hinge_reference.py, given the same ring
and the fill's columns over its extrados chords computed here by the shoelace formula: no LP, no reading of files."""

from __future__ import annotations

import json

import numpy as np
import pytest
from four_hinge_reference import least_load_factor, right_support_thrust
from traced_bridge import FILL, ROAD, SPRING, STONE, G, R, T, joint_angles, write

from cli_helpers import invoke


def _ring_loads():
    """Joints left to right, and each voussoir's weight with its fill's, at their common centre of mass (only the
    abscissa of a vertical load matters); the fill's column over a chord: the quadrilateral up to the road."""
    t = joint_angles()[::-1]
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
    write(path)
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
