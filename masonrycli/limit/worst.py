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

A load spread through the fill (``--spread``) is no longer linear along a stretch (its strip's edges move
over the blocks): λ has kinks where the strip's centre or an edge passes a stretch's end, and the scan tries
those and the midpoints between them — close, not exact.

A place where no mechanism follows the load (the LP is unbounded: a pier's top pressed down onto its
foundation) has no λ and is skipped; a structure that cannot carry its own weight fails the whole scan.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from geometry_library.fill import spread_load, top_surface
from masonrycli.errors import InputError
from masonrycli.limit.joints import find_joints
from masonrycli.limit.problem import LimitError, LiveLoad, NoEquilibrium, load_vectors, solve_limit
from masonrycli.model import build_model
from masonrycli.scenario.fill import fill_surface


@dataclass(frozen=True)
class Place:
    """One scanned position: abscissa (m), the loaded block, the height loaded (m) and λ there (None: no
    mechanism follows the load there)."""

    at: float
    block: str
    top: float
    load_factor: float | None


def placed(load: LiveLoad, blocks, at: float, block: str, top: float, level: float | None) -> LiveLoad:
    """``load`` at abscissa ``at`` on ``block`` (its top there at ``top``), spread through the fill up to
    ``level`` when ``load.spread`` says so (``geometry_library.fill.spread_load``)."""
    resolved = replace(load, block=block, at=at, resolved=True, top=top)
    if load.spread is None:
        return resolved
    if level is None:
        raise _no_fill(load)
    parts = spread_load(blocks, at, level, load.spread)
    return replace(resolved, patches=tuple((blocks[b].name, x, y, share) for b, x, y, share in parts))


def _no_fill(load: LiveLoad) -> InputError:
    return InputError(
        f"--spread {load.spread:g}: no fill to spread through (an arch built with --fill-to or --fill-cover, or "
        "a file whose blocks' carried masses are one fill's)"
    )


def _spread_places(pieces, level: float, angle: float) -> list[float]:
    """Where a spread load's λ has its kinks (the strip's centre or an edge on a stretch's end: b ± h(x)),
    and the midpoints between them: λ between them is not checked (module docstring)."""
    ends = sorted({p.a for p in pieces} | {p.b for p in pieces})
    tan = math.tan(math.radians(angle))

    def half(x):
        under = [p.y(x) for p in pieces if p.a <= x <= p.b]
        return max(level - max(under), 0.0) * tan if under else 0.0

    xs = set(ends)
    for b in ends:
        for side in (-1.0, 1.0):
            x = b
            for _ in range(20):  # x + side·h(x) = b, h varying slowly with x: a fixed point
                x = b - side * half(x)
            xs.add(x)
    xs = sorted(x for x in xs if ends[0] <= x <= ends[-1])
    return sorted(set(xs) | {0.5 * (a + b) for a, b in zip(xs[:-1], xs[1:])})


def scan_places(scenario, load: LiveLoad) -> tuple[Place, ...]:
    """λ of ``load`` (a point load, its place not given) at both ends of every stretch of the top surface of
    ``scenario``'s blocks, left to right (module docstring); a spread load at :func:`_spread_places`."""
    blocks = scenario.assembly.blocks
    lo = min(float(b.polygon.bounds[0]) for b in blocks)
    hi = max(float(b.polygon.bounds[2]) for b in blocks)
    model = build_model(scenario)
    joints = find_joints(model)
    pieces = top_surface(blocks, lo, hi)
    level = fill_surface(scenario) if load.spread is not None else None
    if load.spread is None:
        tried = [(x, p) for p in pieces for x in (p.a, p.b)]
    else:
        if level is None:
            raise _no_fill(load)
        tried = [(x, next(p for p in pieces if p.a <= x <= p.b)) for x in _spread_places(pieces, level, load.spread)]
    places, seen = [], set()
    for x, piece in tried:
        name = blocks[piece.block].name
        if (x, name) not in seen:
            seen.add((x, name))
            at = placed(load, blocks, x, name, piece.y(x), level)
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
    level = fill_surface(scenario) if load.spread is not None else None
    return placed(load, scenario.assembly.blocks, worst.at, worst.block, worst.top, level), places
