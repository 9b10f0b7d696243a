"""The worst place for a point load (``masonry limit --load point --worst``): the least λ over every position
on the structure's top — an assessor's axle rolled across the bridge.

For one collapse mechanism, the power of a point load at x on one straight stretch of a block's top is
linear in x (a rigid block's velocity is affine in position), so that mechanism's λ = dead-load power /
live-load power is monotone in x along the stretch; λ(x), the least over the mechanisms (the kinematic
theorem the LP solves), is therefore least at an end of a stretch. The scan is exact with those ends
(``geometry_library.fill.top_surface``: one stretch per straight top edge of a block), each loaded on the
block the stretch belongs to — at a joint, once on each side of it:

    for stretch in the top surface, left to right:
        for x in (stretch.a, stretch.b): λ(x) = the LP with the load at (x, y(x)) on stretch.block
    worst = the least λ (the leftmost on a tie)

A place where no mechanism follows the load (the LP is unbounded: a pier's top pressed down onto its
foundation) has no λ and is skipped; a structure that cannot carry its own weight fails the whole scan.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from geometry_library.fill import top_surface
from masonrycli.limit.joints import find_joints
from masonrycli.limit.problem import LimitError, LiveLoad, NoEquilibrium, load_vectors, solve_limit
from masonrycli.model import build_model


@dataclass(frozen=True)
class Place:
    """One scanned position: abscissa (m), the loaded block, the height loaded (m) and λ there (None: no
    mechanism follows the load there)."""

    at: float
    block: str
    top: float
    load_factor: float | None


def scan_places(scenario, load: LiveLoad) -> tuple[Place, ...]:
    """λ of ``load`` (a point load, its place not given) at both ends of every stretch of the top surface of
    ``scenario``'s blocks, left to right (module docstring)."""
    blocks = scenario.assembly.blocks
    lo = min(float(b.polygon.bounds[0]) for b in blocks)
    hi = max(float(b.polygon.bounds[2]) for b in blocks)
    model = build_model(scenario)
    joints = find_joints(model)
    places, seen = [], set()
    for piece in top_surface(blocks, lo, hi):
        name = blocks[piece.block].name
        for x in (piece.a, piece.b):
            if (x, name) in seen:
                continue
            seen.add((x, name))
            at = replace(load, block=name, at=x, resolved=True, top=piece.y(x))
            dead, live, _ = load_vectors(model, at)
            try:
                lam = solve_limit(model, joints, dead, live).load_factor
            except NoEquilibrium:  # the dead load alone: no place helps
                raise
            except LimitError:  # unbounded there: no mechanism follows a load at this place
                lam = None
            places.append(Place(x, name, at.top, lam))
    return tuple(places)


def worst_load(scenario, load: LiveLoad) -> tuple[LiveLoad, tuple[Place, ...]]:
    """``load`` placed where its λ is least (:func:`scan_places`), and the scan."""
    places = scan_places(scenario, load)
    found = [p for p in places if p.load_factor is not None]
    if not found:
        raise LimitError("--worst: no place on the structure's top where a mechanism follows the load")
    worst = min(found, key=lambda p: p.load_factor)  # min keeps the first (leftmost) of equal ones
    return replace(load, block=worst.block, at=worst.at, resolved=True, top=worst.top), places
