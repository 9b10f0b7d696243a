"""A semicircular arch against the classical closed forms (rigid voussoirs, no sliding: μ = 2).

References, for a continuous semicircular arch of mean radius R and ring thickness t (R_i = R − t/2,
R_e = R + t/2) under its own weight, half-arch from the crown (φ = 0) to a radial joint at φ:
    weight           W(φ)  = ½ (R_e² − R_i²) φ                      (per unit ρ g and depth)
    centroid abscissa x(φ) = (4/3) (R_e³ − R_i³)/(R_e² − R_i²) · sin²(φ/2)/φ     (annular sector)
A horizontal crown thrust H at height y_c crosses joint φ at radius ρ when moment balance about that
point holds:  H (y_c − ρ cos φ) = W(φ) (ρ sin φ − x(φ)).  The line is admissible when R_i ≤ ρ ≤ R_e on
every joint, i.e.  max_φ H_i(φ; y_c) ≤ H ≤ min_φ H_e(φ; y_c)  with H_i, H_e the thrusts putting the line
on the intrados and the extrados of joint φ (Heyman, *The Stone Skeleton*, 1966; *The Masonry Arch*,
1982; Ochsendorf, "The masonry arch on spreading supports", The Structural Engineer 84(2), 2006).
* Least thickness: the t for which the admissible range with the crown line on the extrados shrinks to
  one line — Milankovitch (1907): t/R = 0.1075 (here 0.10748, with H/W = 0.1976).
* Minimum thrust (supports spreading): crown on the extrados, H = max_φ H_i.
* Maximum thrust (supports pushed together): the lowest crown point whose range is not empty,
  H = min_φ H_e there.
Reference values evaluated below from these formulas on a 200 001-point grid in φ (error ~1e-10):
t/R = 0.15: H_min/W = 0.175873, H_max/W = 0.226976;  t/R = 0.20: 0.154042, 0.254554  (W = π R t).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from masonrycli.limit import LimitError, LiveLoad, analyse
from masonrycli.limit.joints import find_joints
from masonrycli.limit.problem import load_vectors, support_thrust_range
from masonrycli.model import build_model

from limit_helpers import semicircular_arch

REL = 5e-3
MILANKOVITCH = 0.1075


def _thrust_bounds(t: float, yc: float) -> tuple[float, float]:
    """(max_φ H_i, min_φ H_e) for crown height yc, R = 1, per unit ρ g."""
    phi = np.linspace(1e-4, np.pi / 2, 200_001)
    ri, re = 1 - t / 2, 1 + t / 2
    w = 0.5 * (re**2 - ri**2) * phi
    x = (4 / 3) * (re**3 - ri**3) / (re**2 - ri**2) * np.sin(phi / 2) ** 2 / phi
    lo = hi = None
    for rho in (ri, re):
        num, den = w * (rho * np.sin(phi) - x), yc - rho * np.cos(phi)
        ok = den > 0
        if rho == ri:
            lo = np.max(num[ok] / den[ok])
        else:
            hi = np.min(num[ok] / den[ok])
    return lo, hi


def closed_form_thrust(t: float) -> tuple[float, float]:
    """(H_min, H_max) / W of the continuous semicircular arch of thickness t/R."""
    ri, re = 1 - t / 2, 1 + t / 2
    h_min = _thrust_bounds(t, re)[0]
    gap = lambda yc: np.subtract(*_thrust_bounds(t, yc))  # noqa: E731
    yc = ri if gap(ri) <= 0 else brentq(gap, ri, re, xtol=1e-12)
    return h_min / (np.pi * t), _thrust_bounds(t, yc)[1] / (np.pi * t)


def test_the_closed_forms_reproduce_milankovitch_and_the_quoted_values():
    """Guards the reference formulas themselves (typos), independently of the code under test."""
    t_min = brentq(lambda t: np.subtract(*_thrust_bounds(t, 1 + t / 2)), 0.08, 0.2, xtol=1e-10)
    assert t_min == pytest.approx(MILANKOVITCH, rel=1e-3)
    np.testing.assert_allclose(closed_form_thrust(0.15), [0.175873, 0.226976], rtol=1e-5)
    np.testing.assert_allclose(closed_form_thrust(0.20), [0.154042, 0.254554], rtol=1e-5)


def _stands(t: float, voussoirs: int) -> bool:
    try:
        analyse(semicircular_arch(t, voussoirs, friction=2.0), LiveLoad("horizontal"))
    except LimitError:
        return False
    return True


@pytest.mark.parametrize("voussoirs", [30, 60])
def test_least_thickness_of_a_semicircular_arch_tends_to_milankovitch(voussoirs):
    """Bisection on t/R for the thickness where λ → 0 (below it no equilibrium exists at all)."""
    lo, hi = 0.09, 0.13
    assert _stands(hi, voussoirs) and not _stands(lo, voussoirs)
    while hi - lo > 1e-5:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _stands(mid, voussoirs) else (mid, hi)
    assert hi == pytest.approx(MILANKOVITCH, rel=REL)
    # Just above the least thickness the arch carries almost no extra horizontal load.
    lam = analyse(semicircular_arch(hi * 1.002, voussoirs, friction=2.0), LiveLoad("horizontal")).load_factor
    assert 0.0 <= lam < 2e-3


@pytest.mark.parametrize("t", [0.15, 0.20])
def test_minimum_and_maximum_thrust_on_spreading_supports(t):
    sc = semicircular_arch(t, 60, friction=2.0)
    model = build_model(sc)
    joints = find_joints(model)
    dead, _, _ = load_vectors(model, LiveLoad())
    weight = float(model.body_mass[: model.block_count].sum() * 9.81)
    h_min, h_max = support_thrust_range(model, joints, dead, support=0)  # right springer, pushed towards +x
    expected = closed_form_thrust(t)
    assert h_min / weight == pytest.approx(expected[0], rel=REL)
    assert h_max / weight == pytest.approx(expected[1], rel=REL)
    # The left springer takes the same thrust the other way.
    left = support_thrust_range(model, joints, dead, support=1, direction=(-1.0, 0.0))
    np.testing.assert_allclose(left, (h_min, h_max), rtol=1e-6)


def test_arch_mechanism_under_a_horizontal_load_has_four_hinges():
    """The classical mechanism of an arch on rigid springers: four hinges, no sliding (μ = 2)."""
    r = analyse(semicircular_arch(0.15, 40, friction=2.0), LiveLoad("horizontal"))
    assert len(r.hinges) == 4 and r.sliding_joints == []
    # Hinges lie on the intrados or the extrados (R = 1 ± t/2), where the thrust line touches the ring.
    radius = np.hypot(*r.motion.hinge_point.T)
    assert np.all(np.isclose(radius, 0.925, atol=1e-9) | np.isclose(radius, 1.075, atol=1e-9))


def test_a_symmetric_arch_fails_the_same_way_in_both_directions():
    """Mirror symmetry: the same λ for ±x, and the hinges of one mechanism are the mirror images of the other's."""
    sc = semicircular_arch(0.15, 40, friction=2.0)
    right, left = (analyse(sc, LiveLoad("horizontal", d)) for d in ("+x", "-x"))
    assert right.load_factor == pytest.approx(left.load_factor, rel=1e-6)
    mirrored = right.motion.hinge_point * [-1.0, 1.0]
    key = lambda p: np.round(p, 9).tolist()  # noqa: E731
    assert sorted(map(key, mirrored)) == sorted(map(key, left.motion.hinge_point))
