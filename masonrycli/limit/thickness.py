"""The least ring thickness of a built-in arch and its geometric factor of safety (``masonry limit --min-thickness``).

Heyman's geometric factor of safety of a masonry arch is its ring thickness over the least thickness whose
ring, on the same supports, can still carry its own weight (at the least one the thrust line touches the
intrados and the extrados at a mechanism's hinges). Here the arch is rebuilt with the same span, rise,
voussoirs and piers and a thinner ring until the limit-analysis program has no equilibrium:

    t_hi = the given thickness (it must stand); halve t_lo = t_hi / 2 until it does not stand (≤ 12 times)
    bisect [t_lo, t_hi] to a relative width of 1e-4: the least thickness is t_hi

"Stands" is the program's feasibility under the dead load alone (the same joints, cones and friction as
``masonry limit``), so sliding joints count as the LP reads them (associative, an upper bound of the
strength where sliding matters, docs/limit.md).
"""

from __future__ import annotations

from dataclasses import dataclass

from masonrycli.errors import InputError
from masonrycli.limit.joints import find_joints
from masonrycli.limit.problem import LiveLoad, NoEquilibrium, load_vectors, solve_limit
from masonrycli.model import build_model

RTOL = 1e-4
"""Relative width at which the bisection stops."""


@dataclass(frozen=True)
class LeastThickness:
    thickness: float
    """m: the ring thickness analysed."""
    least: float
    """m: the least ring thickness that still carries its own weight (within RTOL above it)."""

    @property
    def factor(self) -> float:
        """Heyman's geometric factor of safety: thickness / least."""
        return self.thickness / self.least


def least_ring_thickness(build, thickness: float) -> LeastThickness:
    """``build(t)`` → the scenario with ring thickness ``t`` (m); ``thickness`` must stand."""

    def stands(t: float) -> bool:
        try:
            scenario = build(t)
        except InputError:  # thinner than the builder builds (1 mm): no ring to speak of
            return False
        model = build_model(scenario)
        joints = find_joints(model)
        dead, live, _ = load_vectors(model, LiveLoad())
        try:
            solve_limit(model, joints, dead, live)
        except NoEquilibrium:
            return False
        return True

    if not stands(thickness):
        raise InputError(
            f"--min-thickness: the ring of {thickness:g} m does not carry its own weight on these supports, so "
            "it has no geometric factor of safety (the analysis above says what gives way)"
        )
    hi, lo = thickness, thickness / 2
    for _ in range(12):
        if not stands(lo):
            break
        hi, lo = lo, lo / 2
    else:
        return LeastThickness(thickness, hi)  # stands at 1/4096 of it: the supports, not the ring, hold it
    while hi - lo > RTOL * hi:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if stands(mid) else (mid, hi)
    return LeastThickness(thickness, hi)
