"""`masonry limit --thrust`: the least and greatest horizontal force a ring pushes on each support, outward,
against an independent reference: the three-hinge mechanisms of a springer that moves
(tests/four_hinge_reference.py ``right_support_thrust``: no LP), itself checked against the classical statics
of the continuous semicircle (tests/test_limit_arch.py). At the ring's least thickness the two bounds meet:
the thrust is the one the ring can have (Milankovitch's semicircle: H = 0.1976 W of the continuous arch).

Sign: a positive thrust towards "+x" on the right support (and "−x" on the left) is the ring pushing it away
from the span, as an arch pushes its abutments; both bounds are positive."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from four_hinge_reference import right_support_thrust
from scipy.optimize import brentq
from test_limit_arch import closed_form_thrust
from test_limit_ring_mechanisms import ring, segmental_reference_ring, voussoir_loads

from masonrycli.scenario.toml_file import dump_scenario

from cli_helpers import invoke
from limit_helpers import semicircular_arch


def semicircle_thrust(t: float, voussoirs: int) -> tuple[float, float]:
    """(least, greatest) / W of the reference's semicircle of mean radius 1, its weight W."""
    i, e = ring(1 - t / 2, t, np.pi / 2, voussoirs)
    centroid, area = voussoir_loads(i, e)
    least, greatest = right_support_thrust(i, e, centroid, np.stack([0 * area, -area], axis=1))
    return least / area.sum(), greatest / area.sum()


@pytest.mark.parametrize("t", [0.15, 0.20])
def test_the_reference_gives_the_continuous_arch_thrust(t):
    """Guards the reference: 60 voussoirs against the continuous arch's H_min, H_max within 0.1 %."""
    np.testing.assert_allclose(semicircle_thrust(t, 60), closed_form_thrust(t), rtol=1e-3)


def test_the_semicircle_at_its_least_thickness_pushes_each_springer_outward_with_its_one_thrust(tmp_path):
    """30 voussoirs at the reference's least thickness (+0.05 %, where the two bounds meet: t/R = 0.10741):
    the command's least and greatest thrust on each springer are the reference's to 1e-6, 0.1979 W, towards
    +x on the right springer and −x on the left."""
    t_min = brentq(lambda t: np.subtract(*semicircle_thrust(t, 30)), 0.09, 0.13, xtol=1e-10)
    assert t_min == pytest.approx(0.1075, rel=5e-3)  # Milankovitch
    t = 1.0005 * t_min
    least, greatest = semicircle_thrust(t, 30)
    assert greatest - least < 1e-3 * least and least == pytest.approx(0.1976, rel=5e-3)  # one thrust, the classical one
    path = tmp_path / "semicircle.toml"
    path.write_text(dump_scenario(semicircular_arch(t, 30, friction=10.0)))
    result = invoke("limit", path, "--thrust", "--json")
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    by_support = {s["support"]: s for s in data["support_thrust"]}
    assert by_support["right-springer"]["direction"] == "+x" and by_support["left-springer"]["direction"] == "-x"
    for s in by_support.values():
        assert s["least_N"] / data["reference_load_N"] == pytest.approx(least, rel=1e-6)
        assert s["greatest_N"] / data["reference_load_N"] == pytest.approx(greatest, rel=1e-6)


def test_the_segmental_bridge_on_fixed_abutments_pushes_them_apart_as_the_reference_says():
    """`masonry limit arch --span 8 --rise 2 --ring-thickness 0.5 --pier-width 3 --pier-courses 5 --abutments
    fixed --thrust`: the ring alone on its rigid skewbacks, 2500 kg/m³, 1 m wide."""
    i, e = segmental_reference_ring(30)
    centroid, area = voussoir_loads(i, e)
    weight = 2500.0 * 9.81 * area
    least, greatest = right_support_thrust(i, e, centroid, np.stack([0 * weight, -weight], axis=1))
    shape = ["--span", "8", "--rise", "2", "--ring-thickness", "0.5", "--pier-width", "3", "--pier-courses", "5"]
    result = invoke("limit", "arch", *shape, "--abutments", "fixed", "--thrust", "--json")
    assert result.exit_code == 0, result.output
    by_support = {s["support"]: s for s in json.loads(result.stdout)["support_thrust"]}
    assert by_support["right-foundation"]["direction"] == "+x" and by_support["left-foundation"]["direction"] == "-x"
    for s in by_support.values():
        assert s["least_N"] == pytest.approx(least, rel=1e-6) and s["greatest_N"] == pytest.approx(greatest, rel=1e-6)
    assert 0 < least < greatest and math.isfinite(greatest)


def test_one_support_under_every_block_has_no_thrust_to_give(tmp_path):
    """A surveyed bridge on one traced ground: 'thrust on ground: 0 … 0 N towards -x' (equilibrium: the dead load has
    no horizontal part, so neither has the one support's reaction) read as an arch pushing nothing. The table says
    why there is none, and where an abutment's thrust comes from; --json keeps the 0 … 0."""
    from cli_helpers import invoke

    geo = tmp_path / "one.geojson"
    ring = [[-1, -0.5], [2, -0.5], [2, 0], [-1, 0], [-1, -0.5]]
    stone = [[0, 0], [0.4, 0], [0.4, 0.2], [0, 0.2], [0, 0]]
    features = [
        {"type": "Feature", "properties": {"name": "s"}, "geometry": {"type": "Polygon", "coordinates": [stone]}},
        {"type": "Feature", "properties": {"role": "support"}, "geometry": {"type": "Polygon", "coordinates": [ring]}},
    ]
    geo.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    table = invoke("limit", geo, "--thrust")
    assert table.exit_code == 0, table.output
    assert "none to give: one support carries every block" in " ".join(table.stdout.split())
    assert "0 … 0" not in table.stdout
    data = json.loads(invoke("limit", geo, "--thrust", "--json").stdout)
    assert [(t["least_N"], t["greatest_N"]) for t in data["support_thrust"]] == [(0.0, 0.0)]
