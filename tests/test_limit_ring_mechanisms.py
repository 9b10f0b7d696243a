"""`masonry limit` on a voussoir ring against an independent slow reference: the least load factor over
every admissible four-hinge mechanism (tests/four_hinge_reference.py: kinematics by instantaneous centres,
no LP, no contact detection), for what a bridge engineer asks first — the horizontal acceleration that
collapses a semicircular or segmental arch (λ g), and a point load at quarter span.

Both sides solve the same discrete ring exactly (no sliding: μ = 10), so they must agree to rounding,
hinge for hinge. The reference itself is checked against Milankovitch's least thickness (t/R = 0.1075,
whose λ = 0 is a closed form of the continuous arch; tests/test_limit_arch.py derives it a second way).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from four_hinge_reference import least_load_factor
from scipy.optimize import brentq

from geometry_library.builders import build_arch
from masonrycli.limit import LiveLoad, analyse

from limit_helpers import scenario, semicircular_arch

MU = 10.0  # no joint slides: the four-hinge mechanisms are all there is
G = 9.81


def ring(radius_in: float, thickness: float, half_angle: float, voussoirs: int, centre_y: float = 0.0):
    """Intrados and extrados joint points, left to right, of a circular ring of embrace 2α (equal angles)."""
    phi = np.pi / 2 + half_angle - 2 * half_angle * np.arange(voussoirs + 1) / voussoirs
    unit = np.stack([np.cos(phi), np.sin(phi)], axis=1)
    return unit * radius_in + (0, centre_y), unit * (radius_in + thickness) + (0, centre_y)


def voussoir_loads(intrados, extrados):
    """Centroids and weights (per unit ρ g e) of the quadrilaterals between consecutive joints (shoelace)."""
    quads = np.stack([intrados[:-1], intrados[1:], extrados[1:], extrados[:-1]], axis=1)
    x, y = quads[..., 0], quads[..., 1]
    xn, yn = np.roll(x, -1, axis=1), np.roll(y, -1, axis=1)
    cr = x * yn - xn * y
    area = 0.5 * cr.sum(axis=1)
    cx, cy = ((x + xn) * cr).sum(axis=1) / (6 * area), ((y + yn) * cr).sum(axis=1) / (6 * area)
    return np.stack([cx, cy], axis=1), np.abs(area)


def reference(intrados, extrados, load: str, block: int | None = None):
    """λ and the hinged joints of the reference, loads as masonry defines them (λ × weights)."""
    centroid, weight = voussoir_loads(intrados, extrados)
    dead = np.stack([0 * weight, -weight], axis=1)
    if load == "horizontal":
        live = np.stack([weight, 0 * weight], axis=1)
    else:  # a point load down on one voussoir, λ × its own weight
        live = np.zeros_like(dead)
        live[block] = (0.0, -weight[block])
    return least_load_factor(intrados, extrados, centroid, dead, live)


def test_the_reference_finds_milankovitch_least_thickness():
    """λ of the semicircle (30 voussoirs) under a vanishing horizontal load reaches 0 at t/R = 0.1075."""

    def lam(t):
        i, e = ring(1 - t / 2, t, np.pi / 2, 30)
        return reference(i, e, "horizontal")[0]

    t_min = brentq(lam, 0.10, 0.13, xtol=1e-6)
    assert t_min == pytest.approx(0.1075, rel=5e-3)


def _joint(k: int, n: int, first: str, last: str, name=lambda k: f"v{k:03d}") -> str:
    """Ring joint k (0: the left springer) named as the LP names joints, its two bodies in either order."""
    pair = (first, name(0)) if k == 0 else (name(n - 1), last) if k == n else (name(k - 1), name(k))
    return "|".join(sorted(pair))


def _unordered(names) -> set[str]:
    return {"|".join(sorted(n.split("|"))) for n in names}


@pytest.mark.parametrize("t", [0.12, 0.15, 0.20, 0.30])
def test_semicircle_collapses_under_the_horizontal_acceleration_of_the_four_hinge_reference(t):
    """λ g is the horizontal acceleration that turns the semicircular arch into a mechanism."""
    n = 30
    i, e = ring(1 - t / 2, t, np.pi / 2, n)
    expected, (hinged, _) = reference(i, e, "horizontal")
    # the helper numbers its voussoirs from the right springer: joint k from the left is v{n-k}|v{n-k-1}
    r = analyse(semicircular_arch(t, n, friction=MU), LiveLoad("horizontal"))
    assert r.load_factor == pytest.approx(expected, rel=1e-6)
    name = lambda k: f"v{n - 1 - k:03d}"  # noqa: E731
    want = {_joint(k, n, "left-springer", "right-springer", name) for k in hinged}
    assert _unordered(r.hinges) == want
    assert r.sliding_joints == []


SPAN, RISE, RING = 8.0, 2.0, 0.5  # a segmental bridge arch: span/rise 4, R = 5 m, embrace 2 × 53.13°


def segmental_ring_scenario(voussoirs: int):
    """The builder's segmental arch, its voussoirs on its two skewbacks held fixed (rigid abutments)."""
    assembly = build_arch(span=SPAN, rise=RISE, ring_thickness=RING, voussoirs=voussoirs, pier_width=1.0)
    blocks = [(b.name, b.polygon) for b in assembly.blocks if b.name.startswith("v")]
    springers = [(b.name, b.polygon) for b in assembly.blocks if b.name.endswith("skewback")]
    return scenario(blocks, springers, MU, name="segmental")


def segmental_reference_ring(voussoirs: int):
    """The same ring from its definition: R_i = (s²/4 + f²)/(2 f), sin α = s/(2 R_i), springings at y = 0."""
    radius = (SPAN**2 / 4 + RISE**2) / (2 * RISE)
    alpha = math.asin(SPAN / (2 * radius))
    return ring(radius, RING, alpha, voussoirs, centre_y=-(radius - RISE))


@pytest.mark.parametrize("voussoirs", [20, 31])
def test_segmental_arch_horizontal_acceleration_and_quarter_span_load_match_the_reference(voussoirs):
    sc = segmental_ring_scenario(voussoirs)
    i, e = segmental_reference_ring(voussoirs)
    i, e = i + (0, 3.4), e + (0, 3.4)  # the builder's springing line: 17 courses of 0.20 m
    vw = max(2, len(str(voussoirs)))
    name = lambda k: f"v{k + 1:0{vw}d}"  # noqa: E731
    hinge_names = lambda ks: {_joint(k, voussoirs, "left-skewback", "right-skewback", name) for k in ks}  # noqa: E731

    expected, (hinged, _) = reference(i, e, "horizontal")
    r = analyse(sc, LiveLoad("horizontal"))
    assert r.load_factor == pytest.approx(expected, rel=1e-6)
    assert _unordered(r.hinges) == hinge_names(hinged)

    # the voussoir over the quarter span (its intrados straddles x = −s/4), loaded down, λ × its weight
    quarter = int(np.searchsorted(i[:, 0], -SPAN / 4)) - 1
    expected, (hinged, _) = reference(i, e, "point", block=quarter)
    r = analyse(sc, LiveLoad("point", "-y", block=name(quarter)))
    assert r.load_factor == pytest.approx(expected, rel=1e-6)
    assert _unordered(r.hinges) == hinge_names(hinged)
    weight = voussoir_loads(i, e)[1][quarter] * 2000.0 * G  # the helper's density
    assert r.load_factor * weight == pytest.approx(r.summary()["collapse_load_N"], rel=1e-9)


@pytest.mark.parametrize("x", [-2.0, -1.3])
def test_a_deck_load_at_x_acts_on_the_extrados_there(x):
    """`--at X`: the point load down on the voussoir whose extrados spans x = X, acting at (X, its extrados
    there), against the reference with that force's moment taken there (not at the centroid: --at -2 gave
    λ = 8.6225 of the centroid load on the bridge, the load at -2 on the deck 8.3903)."""
    voussoirs = 20
    sc = segmental_ring_scenario(voussoirs)
    i, e = segmental_reference_ring(voussoirs)
    i, e = i + (0, 3.4), e + (0, 3.4)
    k = int(np.searchsorted(e[:, 0], x)) - 1  # the voussoir whose extrados chord spans x
    w = (x - e[k, 0]) / (e[k + 1, 0] - e[k, 0])
    point = (1 - w) * e[k] + w * e[k + 1]
    centroid, weight = voussoir_loads(i, e)
    dead = np.stack([0 * weight, -weight], axis=1)
    live = np.zeros_like(dead)
    live[k] = (0.0, -weight[k])
    at = centroid.copy()
    at[k] = point
    expected, (hinged, _) = least_load_factor(i, e, centroid, dead, live, live_at=at)
    centred, _ = least_load_factor(i, e, centroid, dead, live)
    assert abs(expected / centred - 1) > 1e-3  # where the load acts matters here
    r = analyse(sc, LiveLoad("point", at=x))
    assert r.load.block == f"v{k + 1:02d}"
    assert r.load_factor == pytest.approx(expected, rel=1e-6)
