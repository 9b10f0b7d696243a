"""The least ring thickness of a built-in arch and its geometric factor of safety (``masonry limit --min-thickness``).

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

    @property
    def factor(self) -> float:
        """Heyman's geometric factor of safety: thickness / least (at least this with ``bounded_by``)."""
        return self.thickness / self.least

    def describe(self) -> str:
        """The table's line."""
        if self.bounded_by is None:
            return (
                f"{self.least:.4g} m for a ring of {self.thickness:g} m: geometric factor of safety "
                f"{self.factor:.2f} (Heyman)"
            )
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


def check_min_thickness(structure: str, settle: float | None) -> None:
    """Refuse ``--min-thickness`` on anything but the arch built-in, and with ``--settle``: the search builds
    the builder's rings, laid exact, where settling moves nothing, and a ring settled near its least thickness
    would be the engine's slow creep, not the ring. It searched the unsettled rings under the settled table."""
    if structure != "arch":
        from masonrycli.scenario.target import is_built_in

        survey = (
            ""
            if is_built_in(structure)
            else "; a surveyed ring's: the arch built-in of its span, rise and ring (masonry limit arch --span S "
            "--rise F --ring-thickness T --pier-width W --min-thickness), its voussoirs equal"
        )
        raise InputError(
            f"--min-thickness: the arch's ring only (masonry limit arch …); {structure} is not the arch built-in{survey}"
        )
    if settle is not None:
        raise InputError(
            f"--min-thickness with --settle {settle:g}: the least thickness is searched over the builder's rings, "
            "laid exact, with nothing to settle (--settle is for a traced file's gaps); drop --settle"
        )
