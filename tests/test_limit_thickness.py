"""`masonry limit arch --min-thickness`: the least ring thickness that carries its own weight, and Heyman's
geometric factor of safety, against Milankovitch's least thickness of the semicircle (t/R = 0.1075) and the
independent four-hinge enumeration (tests/four_hinge_reference.py) on the segmental bridge arch."""

from __future__ import annotations

import json
import math

import pytest
from scipy.optimize import brentq
from test_limit_ring_mechanisms import reference, ring

from cli_helpers import assert_one_line_error, invoke


def least(*args) -> dict:
    result = invoke("limit", "arch", *args, "--friction", "10", "--min-thickness", "--json")
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_the_semicircles_least_thickness_is_milankovitchs():
    """Span 2 m (intrados radius 1) on piers 3 m wide, one course: as rigid springers. t/R of the mean radius."""
    data = least("--span", "2", "--ring-thickness", "0.3", "--pier-width", "3", "--pier-courses", "1")
    t = data["least_ring_thickness_m"]
    assert t / (1 + t / 2) == pytest.approx(0.1075, rel=5e-3)
    assert data["ring_thickness_m"] == 0.3 and data["geometric_factor"] == pytest.approx(0.3 / t)


def test_the_segmental_arch_least_thickness_is_the_four_hinge_references():
    """Span 8, rise 2 (intrados R = 5 m, embrace 2 × 53.13°), 30 voussoirs: the thickness at which the
    enumeration's least λ under a vanishing horizontal load reaches 0."""
    radius, alpha = 5.0, math.asin(0.8)
    expected = brentq(lambda t: reference(*ring(radius, t, alpha, 30), "horizontal")[0], 0.02, 0.3, xtol=1e-8)
    data = least("--span", "8", "--rise", "2", "--ring-thickness", "0.5", "--pier-width", "3", "--pier-courses", "5")
    assert data["least_ring_thickness_m"] == pytest.approx(expected, rel=2e-4)


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["wall", "--min-thickness"], "--min-thickness: the arch's ring only"),
        (
            ["arch", "--span", "8", "--rise", "2", "--ring-thickness", "0.5", "--min-thickness"],
            "no equilibrium",  # on the default slender piers it does not stand at all: the analysis says so first
        ),
    ],
)
def test_min_thickness_refusals_are_one_line(args, fragment):
    assert_one_line_error(invoke("limit", *args), fragment)
