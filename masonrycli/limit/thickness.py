"""The least ring thickness of an arch and its geometric factor of safety (``masonry limit --min-thickness``): the
built-in arch's, or a surveyed ring's (a geometry file's: thinned about its centre line, :mod:`geometry_library.ring`).

Heyman's geometric factor of safety of a masonry arch is its ring thickness over the least thickness whose
ring, on the same supports, can still carry its own weight (at the least one the thrust line touches the
intrados and the extrados at a mechanism's hinges). Here the arch is rebuilt with the same span, rise,
voussoirs and piers and a thinner ring until the limit-analysis program has no equilibrium:

    t_hi = the given thickness (it must stand); halve t_lo = t_hi / 2 until it does not stand (≤ HALVINGS times)
    if the builder refuses t_lo (its 1 mm floor, skewbacks under 0.1 mm, …): bisect [t_lo, t_hi] on "builds"
        to the least ring it makes, t_b; if t_b stands, the answer is "at most t_b" (the builder's bound)
        else t_lo = t_b
    bisect [t_lo, t_hi] to a relative width of 1e-4: the least thickness is t_hi

"Stands" is the program's feasibility under the dead load alone (the same joints, cones and friction as
``masonry limit``), so sliding joints count as the LP reads them (associative, an upper bound of the
strength where sliding matters, docs/limit.md). A ring the builder refuses is no answer either way: read
as "does not stand" it made the search report the builder's floor as the least thickness (0.001 m for an
arch that stands at 1 mm; 0.800 m for a segmental arch of rise 3.9995 m on an 8 m span, whose skewbacks
reach the builder's 0.1 mm there, where the semicircle beside it needs 0.454 m).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from masonrycli.errors import InputError
from masonrycli.limit.joints import find_joints
from masonrycli.limit.problem import LiveLoad, NoEquilibrium, load_vectors, solve_limit
from masonrycli.model import build_model

RTOL = 1e-4
"""Relative width at which the bisection stops."""
HALVINGS = 40
"""Most halvings before the bisection. They stopped at 12 (1/4096 of the ring), where the search said the ring
was the least one though it still stood; the builder's 1 mm floor now ends them."""


@dataclass(frozen=True)
class LeastThickness:
    thickness: float
    """m: the ring thickness analysed."""
    least: float
    """m: the least ring thickness that still carries its own weight (within RTOL above it); with
    ``bounded_by``, the thinnest ring the builder makes, which still stands: the least is at most this."""
    bounded_by: str | None = None
    """Why no thinner ring was tried (the builder's refusal of one, in its words), when the ring still stands
    at the thinnest tried: ``least`` is then an upper bound and the factor a lower bound. None: the search
    found where the ring stops standing."""
    traced: str | None = None
    """A surveyed ring's voussoirs ("v01 … v17, 17 voussoirs"), whose thickness is its joints' mean length; None:
    the built-in arch's ring."""

    @property
    def factor(self) -> float:
        """Heyman's geometric factor of safety: thickness / least (at least this with ``bounded_by``)."""
        return self.thickness / self.least

    def describe(self) -> str:
        """The table's line."""
        if self.bounded_by is None:
            ring = (
                f"{self.thickness:g} m"
                if self.traced is None
                else f"{self.thickness:.4g} m ({self.traced}, thinned about its centre line)"
            )
            return f"{self.least:.4g} m for a ring of {ring}: geometric factor of safety {self.factor:.2f} (Heyman)"
        return (
            f"at most {self.least:.4g} m for a ring of {self.thickness:g} m: it still stands at the thinnest "
            f"tried ({self.bounded_by}); geometric factor of safety at least "
            f"{self.factor:.2f} (Heyman)"
        )


def least_ring_thickness(build, thickness: float) -> LeastThickness:
    """``build(t)`` → the scenario with ring thickness ``t`` (m), InputError where the builder refuses it;
    ``thickness`` must stand."""
    refusals: dict[float, str] = {}

    def stands(t: float) -> bool | None:
        """True, False, or None: the builder refuses ``t`` (no ring, which tells nothing of standing)."""
        try:
            scenario = build(t)
        except InputError as exc:
            refusals[t] = str(exc)
            return None
        model = build_model(scenario)
        joints = find_joints(model)
        dead, live, _ = load_vectors(model, LiveLoad())
        try:
            solve_limit(model, joints, dead, live)
        except NoEquilibrium:
            return False
        return True

    def builds(t: float) -> bool:
        try:
            build(t)
        except InputError as exc:
            refusals[t] = str(exc)
            return False
        return True

    if not stands(thickness):
        raise InputError(
            f"--min-thickness: the ring of {thickness:g} m does not carry its own weight on these supports, so "
            "it has no geometric factor of safety (the analysis above says what gives way)"
        )
    hi, lo = thickness, thickness / 2
    for _ in range(HALVINGS):
        standing = stands(lo)
        if standing is None:  # the builder's floor lies in [lo, hi]: find it, then ask whether it stands there
            refused, built = lo, hi
            while built - refused > RTOL * built:
                mid = 0.5 * (refused + built)
                refused, built = (refused, mid) if builds(mid) else (mid, built)
            if stands(built):
                return LeastThickness(thickness, built, f"the builder makes no thinner: {refusals[refused]}")
            lo = built  # the thinnest ring built does not stand: the least is in [it, hi]
            break
        if not standing:
            break
        hi, lo = lo, lo / 2
    else:  # not reached by a builder whose floor is 1 mm (a ring of 1000 m halves to it 20 times)
        return LeastThickness(thickness, hi, f"the search halved the ring {HALVINGS} times and it still stood")
    while hi - lo > RTOL * hi:
        mid = 0.5 * (lo + hi)
        standing = stands(mid)
        if standing is None:  # the arch builder's limits are floors: none between two rings it built
            raise InputError(
                f"--min-thickness: the builder refused {mid:g} m between two rings it built: {refusals[mid]}"
            )
        lo, hi = (lo, mid) if standing else (mid, hi)
    return LeastThickness(thickness, hi)


def builtin_least_ring(structure: str, friction: float | None, structure_options: dict | None) -> LeastThickness:
    """The :class:`LeastThickness` of the built-in arch ``structure`` with its options."""
    from geometry_library.builders import ArchSpec
    from masonrycli.scenario.builtin import builtin, override_run

    check_min_thickness(structure, None)
    from masonrycli.cli.options import SURVEY

    given = {k: v for k, v in (structure_options or {}).items() if v is not None and k not in SURVEY}
    thickness = float(given.pop("ring_thickness", ArchSpec.ring_thickness))

    def build(t: float):
        return override_run(builtin("arch", ring_thickness=t, **given), friction=friction)

    return least_ring_thickness(build, thickness)


MIN_FACTOR = 1e-3
"""The thinnest a traced ring is made, over its thickness as traced (a 0.5 m ring: 0.5 mm)."""


def traced_least_ring(scenario) -> LeastThickness:
    """The :class:`LeastThickness` of the ring traced in a geometry file's ``scenario`` (:mod:`geometry_library.ring`:
    its voussoirs thinned about the ring's centre line, its traced fills carried again); InputError, one line, when
    it has none."""
    from geometry_library.blocks import GeometryError
    from geometry_library.ring import find_ring, thinner

    try:
        ring = find_ring(scenario.assembly)
    except GeometryError as exc:
        raise InputError(f"--min-thickness: {scenario.source}: {exc}") from None

    def build(t: float):
        factor = t / ring.thickness
        if factor < MIN_FACTOR:
            raise InputError(f"a ring under {MIN_FACTOR:g} of its traced thickness is made no thinner")
        try:
            return dataclasses.replace(scenario, assembly=thinner(scenario.assembly, ring, factor))
        except GeometryError as exc:
            raise InputError(str(exc)) from None

    found = least_ring_thickness(build, ring.thickness)
    return dataclasses.replace(found, traced=ring.describe(scenario.assembly))


def check_min_thickness(structure: str, settle: float | None) -> None:
    """Refuse ``--min-thickness`` on the wall and aqueduct built-ins, and with ``--settle``: the search builds the
    rings, laid exact (the builder's) or as traced, and a ring settled near its least thickness would be the
    engine's slow creep, not the ring. It searched the unsettled rings under the settled table."""
    from masonrycli.scenario.target import is_built_in

    if structure != "arch" and is_built_in(structure):
        raise InputError(
            f"--min-thickness: an arch's ring only (masonry limit arch …, or a surveyed arch's file); {structure} has "
            "no ring of its own to thin"
        )
    if settle is not None:
        rings = "the builder's rings, laid exact" if structure == "arch" else "the ring as traced, thinned"
        raise InputError(
            f"--min-thickness with --settle {settle:g}: the least thickness is searched over {rings}, not over a "
            "settled ring; drop --settle"
        )
