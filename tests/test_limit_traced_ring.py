"""`masonry limit FILE --min-thickness`: a surveyed arch's least ring thickness and Heyman's geometric factor of
safety, its traced ring thinned about its centre line (geometry_library/ring.py). Checked against the independent
four-hinge enumeration (tests/four_hinge_reference.py, no LP) at the thickness where its least λ under a vanishing
horizontal load reaches 0: the semicircle (Milankovitch's t/R = 0.1075) and the traced rubble bridge with its fill
reaching down to the thinner ring. Before, every file was refused ('the arch's ring only')."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from four_hinge_reference import least_load_factor
from scipy.optimize import brentq
from test_limit_ring_mechanisms import reference, ring
from traced_bridge import FILL, ROAD, SPRING, STONE, G, R, T, joint_angles, write

from cli_helpers import assert_one_line_error, invoke, words


def least(path, *args) -> dict:
    result = invoke("limit", path, "--friction", "10", "--min-thickness", "--json", *args)
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_a_traced_semicircle_s_least_thickness_is_milankovitch_s(tmp_path):
    """The built-in semicircle (intrados radius 1, ring 0.3 m, 30 voussoirs, massive piers) as a GeoJSON file: its
    centre line (radius 1.15) keeps its place, so the least t over 1.15 is the four-hinge enumeration's t/R."""
    from geometry_library.builders import build_arch
    from geometry_library.io import write_geojson

    path = write_geojson(build_arch(span=2, ring_thickness=0.3, pier_width=3, pier_courses=1), tmp_path / "s.geojson")
    centre = 1.15

    def lam(t):
        return reference(*ring(centre - t / 2, t, np.pi / 2, 30), "horizontal")[0]

    expected = brentq(lam, 0.1, 0.14, xtol=1e-9)
    data = least(path)
    assert data["ring_thickness_m"] == pytest.approx(0.3, rel=1e-12)
    assert data["least_ring_thickness_m"] == pytest.approx(expected, rel=2e-4)
    assert data["least_ring_thickness_m"] / centre == pytest.approx(0.1075, rel=5e-3)  # Milankovitch
    assert data["geometric_factor"] == pytest.approx(0.3 / data["least_ring_thickness_m"])


def _bridge_load_factor(t: float) -> float:
    """The enumeration's λ of the traced bridge's ring thinned to ``t`` about its centre line (radius R + T / 2),
    each voussoir carrying the fill's column over its extrados chord up to the road (the fill reaches down to the
    thinner ring); rigid springers."""
    angle = joint_angles()[::-1]
    unit = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    intrados = unit * (R + (T - t) / 2) + (0, SPRING)
    extrados = unit * (R + (T + t) / 2) + (0, SPRING)

    def shoelace(p):
        x, y = p[:, 0], p[:, 1]
        cross = x * np.roll(y, -1) - np.roll(x, -1) * y
        area = 0.5 * cross.sum()
        return abs(area), np.array([(x + np.roll(x, -1)) @ cross, (y + np.roll(y, -1)) @ cross]) / (6 * area)

    stone = [shoelace(np.array([intrados[k], intrados[k + 1], extrados[k + 1], extrados[k]])) for k in range(17)]
    fill = [
        shoelace(np.array([extrados[k], extrados[k + 1], [extrados[k + 1][0], ROAD], [extrados[k][0], ROAD]]))
        for k in range(17)
    ]
    mass, fmass = np.array([STONE * a for a, _ in stone]), np.array([FILL * a for a, _ in fill])
    centre, fcentre = np.array([c for _, c in stone]), np.array([c for _, c in fill])
    weight = lambda m: np.stack([0 * m, -G * m], axis=1)  # noqa: E731
    push = lambda m: np.stack([G * m, 0 * m], axis=1)  # noqa: E731
    extra = (("dead", weight(fmass), fcentre), ("live", push(fmass), fcentre))
    return least_load_factor(intrados, extrados, centre, weight(mass), push(mass), extra=extra)[0]


def test_a_traced_bridge_s_least_ring_carries_its_fill_as_the_reference_does(tmp_path):
    """The rubble bridge of tests/traced_bridge.py (17 uneven voussoirs, fill to the road, ground lines) traced in
    Lambert-93 to the mm: its ring thinned, the fill carried again over the thinner extrados."""
    path = tmp_path / "bridge.geojson"
    write(path, offset=(651000.25, 6861000.5), ndigits=3)
    expected = brentq(_bridge_load_factor, 0.05, T, xtol=1e-9)
    data = least(path, "--trim-overlaps", "0.003")
    assert data["ring_thickness_m"] == pytest.approx(T, abs=2e-3)  # the joints' mean length, traced to the mm
    assert data["least_ring_thickness_m"] == pytest.approx(expected, rel=5e-3)
    assert data["geometric_factor"] == pytest.approx(data["ring_thickness_m"] / data["least_ring_thickness_m"])
    table = invoke("limit", path, "--trim-overlaps", "0.003", "--friction", "10", "--min-thickness").stdout
    assert "v01 … v17, 17 voussoirs, thinned about its centre line" in words(table.replace("│", " "))


@pytest.mark.parametrize(
    "builder, fragment",
    [
        ("aqueduct", 'touches the ring\'s voussoir block 35 ("v01") elsewhere than at its joints'),
        ("wall", "no ring of 3 or more voussoirs found"),
    ],
)
def test_a_file_without_a_ring_of_its_own_is_one_line(tmp_path, builder, fragment):
    from geometry_library.io import write_geojson
    from masonrycli.scenario.builtin import build_assembly

    path = write_geojson(build_assembly(builder), tmp_path / f"{builder}.geojson")
    assert_one_line_error(invoke("limit", path, "--min-thickness"), fragment)


def test_settle_is_refused_with_a_file_too(tmp_path):
    from geometry_library.builders import build_arch
    from geometry_library.io import write_geojson

    path = write_geojson(build_arch(), tmp_path / "a.geojson")
    assert_one_line_error(
        invoke("limit", path, "--settle", "0.5", "--min-thickness"), "the ring as traced, thinned, not over a settled"
    )
    assert math.isfinite(least(path)["least_ring_thickness_m"])
