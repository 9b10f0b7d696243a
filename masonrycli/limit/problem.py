"""The limit-analysis linear program: equilibrium of rigid blocks on no-tension Coulomb joints.

Unknowns are the forces at the joints' contact points. In 2-D the Coulomb cone {N ≥ 0, |T| ≤ μN} is
exactly the set of non-negative combinations of its two edges g± = n ± μ t, so each contact k carries
two unknowns α⁺, α⁻ ≥ 0, its force on body b is α⁺ g⁺ + α⁻ g⁻ (the opposite on a), and
N = α⁺ + α⁻, T = μ(α⁺ − α⁻). No linearisation of the cone is needed.

Each block gives three equations (force x, force y, moment about its centroid); supports give none:

    maximise λ   subject to   A α + λ L = −D,   α ≥ 0,  λ ≥ 0            (static theorem)

with D the dead load (own weight) and L the live load. The dual of this program is the kinematic
theorem: block velocities u with A_jᵀ u ≥ 0 for every cone edge (joints may open and slide, a slide
dilating by μ — associative flow), Lᵀ u = 1, minimising the dead-load power −Dᵀ u = λ. HiGHS returns
both; the dual values of the equilibrium rows are the collapse mechanism.

Rows and unknowns are scaled to O(1) (mean block weight, mean block radius) before the solve and
scaled back after it, so the tolerances of HiGHS mean the same thing for a pebble and a pier.
"""

from __future__ import annotations

import difflib
import math
import re
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog
from scipy.sparse.csgraph import connected_components

from geometry_library.checks import body_label
from geometry_library.mass import mass_properties
from masonrycli.errors import InputError
from masonrycli.limit.joints import Joints
from masonrycli.model import Model

LOAD_KINDS = ("horizontal", "tilt", "point")
DIRECTIONS = {"+x": (1.0, 0.0), "-x": (-1.0, 0.0), "+y": (0.0, 1.0), "-y": (0.0, -1.0)}


METHOD = "highs-ipm"
"""HiGHS's interior point with crossover (a vertex solution, so a clean mechanism): on the 346-block
aqueduct it takes 35 iterations and 0.6 s where the dual simplex needs 9348 pivots and 2.3 s."""


class LimitError(InputError):
    """No collapse load exists (infeasible or unbounded program); the message is one line."""


class NoEquilibrium(LimitError):
    """The blocks cannot carry their own weight (the program is infeasible)."""


@dataclass(frozen=True)
class LiveLoad:
    """The load that grows with λ.

    kind : ``"horizontal"`` — a body force λ·m·|g| on every block (quasi-static earthquake);
        ``"tilt"`` — the same program read as a tilting table, tan ψ = λ;
        ``"point"`` — a force λ·m_B·|g| at the centroid of block ``block`` (its own weight times λ).
    direction : ``"+x"`` or ``"-x"`` (and ``"+y"``/``"-y"`` for a point load); None: ``"+x"`` for a body force,
        ``"-y"`` (down, as a live load on a deck) for a point load.
    block : name of the loaded block (point load only).
    at : m, or None — a point load on the topmost block over x = ``at`` instead of a named one (a load on
        the deck at that abscissa: "the quarter span"), acting at (``at``, ``top``), on the block's upper
        boundary, not at its centroid; :func:`~masonrycli.limit.analysis.analyse` names the block (``block``)
        and finds ``top`` from the structure.
    """

    kind: str = "horizontal"
    direction: str | None = None
    block: str | None = None
    at: float | None = None
    resolved: bool = False
    """True once ``block`` was found from ``at`` (the two then go together)."""
    top: float | None = None
    """m: the height of the loaded block's upper boundary over ``at`` (set with ``resolved``)."""
    worst: bool = False
    """A point load at the place of least λ over the structure's top (:mod:`masonrycli.limit.worst` finds it
    and sets ``block``, ``at``, ``top`` and ``resolved``)."""
    spread: float | None = None
    """Degrees from the vertical: a point load on the fill's surface spreads through the fill onto the blocks'
    top (``geometry_library.fill.spread_load``); None: it bears where it is put."""
    patches: tuple | None = None
    """((block name, x, y, share), ...): where a spread load bears, set with ``resolved``."""
    force: float | None = None
    """N: a point load's size (``--point-force 100kN``: an axle, for the blocks' thickness); λ multiplies it.
    None: the loaded block's own weight."""

    def __post_init__(self):
        if self.block is not None and not self.block.strip():  # '': taken as not given; ' ': "--block  : no such …"
            raise InputError(
                f"--block {self.block!r}: an empty name (the loaded block's name, as masonry check lists them)"
            )
        if self.kind not in LOAD_KINDS:
            raise InputError(f"--load {self.kind}: expected one of {', '.join(LOAD_KINDS)}")
        if self.direction is None:  # a point load pushed sideways by default surprised a bridge's engineer
            object.__setattr__(self, "direction", "-y" if self.kind == "point" else "+x")
        allowed = tuple(DIRECTIONS) if self.kind == "point" else ("+x", "-x")
        if self.direction not in allowed:
            raise InputError(
                f"--direction {self.direction}: expected one of {', '.join(allowed)} for a {self.kind} load"
            )
        if self.at is not None and not math.isfinite(self.at):
            raise InputError(f"--at {self.at}: the abscissa must be a finite number of metres")
        if self.worst and self.kind != "point":
            raise InputError("--worst: the worst place of a point load (use --load point)")
        if self.worst and not self.resolved and (self.block or self.at is not None):
            given = f"--block {self.block}" if self.block else f"--at {self.at:g}"
            raise InputError(f"--worst and {given}: --worst finds the place itself; give one")
        if self.kind == "point" and self.block and self.at is not None and not self.resolved:
            raise InputError(f"--block {self.block} and --at {self.at:g}: give the loaded block one way")
        if self.kind == "point" and not self.block and self.at is None and not self.worst:
            raise InputError(
                "--load point: name the loaded block with --block NAME, give its place with --at X (m), or find the "
                "worst place with --worst"
            )
        if self.kind != "point" and self.block:
            raise InputError(f"--block {self.block}: only a point load acts on one block (use --load point)")
        if self.kind != "point" and self.at is not None:
            raise InputError(f"--at {self.at:g}: only a point load acts at one place (use --load point)")
        if self.spread is not None and (
            self.kind != "point" or self.direction != "-y" or self.block and not self.resolved
        ):
            raise InputError(
                f"--spread {self.spread:g}: a point load down on the fill's surface spreads (--load point with "
                "--at X or --worst)"
            )
        if self.spread is not None and not (math.isfinite(self.spread) and 0.0 <= self.spread < 90.0):
            raise InputError(f"--spread {self.spread:g}: an angle from the vertical, 0 to 90 degrees (not 90)")
        if self.force is not None and self.kind != "point":
            raise InputError(f"--point-force {self.force:g} N: only a point load has a size (use --load point)")
        if self.force is not None and not (math.isfinite(self.force) and self.force > 0):
            raise InputError(f"--point-force {self.force:g} N: must be a force > 0")

    def describe(self) -> str:
        if self.kind == "point":
            where = "" if self.at is None else f" (the top block over x = {self.at:g} m, loaded there)"
            where = f" at x = {self.at:g} m (the worst place on the top)" if self.worst else where
            if self.spread is not None:
                n = len(self.patches or ())
                where += f", spread through the fill at {self.spread:g}° onto {n} stretch{'es' * (n != 1)} of the top"
            size = "its weight" if self.force is None else force_text(self.force)
            what = "point load" if self.force is None else f"point load of {force_text(self.force)}"
            return f"{what} on {self.block}{where}, {self.direction} (λ × {size})"
        what = "tilting table (tan ψ = λ)" if self.kind == "tilt" else "horizontal body force (λ × weight)"
        return f"{what}, {self.direction}"


FORCE_UNITS = {"n": 1.0, "kn": 1e3, "mn": 1e6}
_FORCE = re.compile(r"\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*([A-Za-zµ/·*^0-9]*)\s*")


def parse_force(text: str) -> float:
    """N of ``--point-force`` as typed: a number and its unit, N, kN or MN ("100kN", "100 kN", "2.5e5 N"). A
    bare number is refused (100 what? an axle is quoted in kN, a block's weight in N), so is another unit."""
    match = _FORCE.fullmatch(str(text))
    if match is None:
        raise InputError(f"--point-force {text}: expected a force with its unit, e.g. 100kN (N, kN or MN)")
    number, unit = float(match.group(1)), match.group(2)
    if not unit:
        raise InputError(f"--point-force {text}: give its unit, e.g. {text}kN or {text}N (N, kN or MN)")
    if unit.lower() not in FORCE_UNITS:
        tonnes = {"kg": 1e-3, "t": 1.0}.get(unit.lower())
        hint = f": a mass; {text} weighs {number * tonnes * 9.81:g} kN" if tonnes else ""
        raise InputError(f"--point-force {text}: {unit} is not a unit of force (N, kN or MN){hint}")
    return number * FORCE_UNITS[unit.lower()]


def force_text(newtons: float) -> str:
    """100 kN, 2.5 MN, 850 N: a force as an engineer writes it."""
    for unit, size in (("MN", 1e6), ("kN", 1e3)):
        if abs(newtons) >= size:
            return f"{newtons / size:.4g} {unit}"
    return f"{newtons:.4g} N"


def load_vectors(model: Model, load: LiveLoad) -> tuple[np.ndarray, np.ndarray, float]:
    """Dead and live generalised loads (3N,) [N, N, N·m per block] and the live load's reference force [N].

    The reference force is the live load at λ = 1: the total weight (body forces) or the loaded block's
    weight (point load); λ × reference is the collapse load in newtons.
    """
    n = model.block_count
    mass = model.body_mass[:n]
    g = float(np.hypot(*model.gravity))
    dead = np.zeros((n, 3))
    dead[:, :2] = mass[:, None] * model.gravity[None, :]
    live = np.zeros((n, 3))
    direction = np.asarray(DIRECTIONS[load.direction])
    if load.kind == "point":
        names = list(model.block_name)
        if load.block in model.support_name:  # said "no such block (1 blocks, e.g. block-0)"
            raise InputError(f"--block {load.block}: a support, not a block (supports are rigid and fixed here)")
        if load.block not in names:
            close = difflib.get_close_matches(str(load.block), names, n=3)
            count = f"{n} block{'s' if n != 1 else ''}"
            hint = f" (did you mean {', '.join(close)}?)" if close else f" ({count}, e.g. {', '.join(names[:3])})"
            raise InputError(f"--block {load.block}: no such block{hint}")
        i = names.index(load.block)
        own = mass[i] - model.block_carried_mass[i]  # the block's own weight: not the fill it carries
        size = own * g if load.force is None else load.force
        live[i, :2] = size * direction
        if load.at is not None and load.top is not None:  # acting at (at, top): its moment about the centroid
            arm = np.array([load.at, load.top]) - model.body_q0[i, :2]
        elif model.block_carried_mass[i] > 0.0:  # at the block's own centroid: a carried fill moved the body's
            vertices = model.vert_local[model.body_vert_start[i] : model.body_vert_start[i + 1]]  # centre of mass
            arm = mass_properties(vertices).centroid
        else:
            arm = np.zeros(2)
        live[i, 2] = arm[0] * live[i, 1] - arm[1] * live[i, 0]
        reference = float(size)
        if load.patches:  # spread through the fill: each part at its place on its block, instead
            live[i] = 0.0
            for name, x, y, share in load.patches:
                k = names.index(name)
                force = share * size * direction
                arm = np.array([x, y]) - model.body_q0[k, :2]
                live[k] += (force[0], force[1], arm[0] * force[1] - arm[1] * force[0])
    else:
        live[:, :2] = (mass * g)[:, None] * direction[None, :]
        reference = float(mass.sum() * g)
    return dead.ravel(), live.ravel(), reference


def _cone_edges(model: Model, joints: Joints) -> np.ndarray:
    """(2C, 2): the cone edges g⁺ = n + μt, g⁻ = n − μt of every contact, interleaved (μ = 0 at a corner on a
    corner: :mod:`masonrycli.limit.corners`)."""
    mu = joints.contact_friction(model.friction)[:, None]
    normal, tangent = joints.contact_normal, joints.contact_tangent
    return np.stack([normal + mu * tangent, normal - mu * tangent], axis=1).reshape(-1, 2)


def equilibrium_matrix(model: Model, joints: Joints) -> sp.csc_matrix:
    """(3N, 2C) sparse A: column 2k (2k+1) is the generalised force of cone edge g⁺ (g⁻) of contact k
    on the blocks — +g on body b, −g on body a, with its moment about each centroid; supports have no rows.
    """
    n = model.block_count
    c = joints.contact_count
    edges = _cone_edges(model, joints)
    point = np.repeat(joints.contact_point, 2, axis=0)
    column = np.arange(2 * c)
    rows, cols, vals = [], [], []
    for side, sign in ((0, -1.0), (1, 1.0)):
        body = np.repeat(joints.contact_body[:, side], 2)
        on_block = body < n
        b, col, f, p = body[on_block], column[on_block], sign * edges[on_block], point[on_block]
        lever = p - model.body_q0[b, :2]
        moment = lever[:, 0] * f[:, 1] - lever[:, 1] * f[:, 0]
        rows += [3 * b, 3 * b + 1, 3 * b + 2]
        cols += [col, col, col]
        vals += [f[:, 0], f[:, 1], moment]
    return sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(3 * n, 2 * c))


@dataclass(frozen=True, eq=False)
class LPSolution:
    """What HiGHS found, in physical units."""

    load_factor: float
    """λ at collapse [-]."""
    contact_force: np.ndarray
    """(C, 2) N: normal force N ≥ 0 and tangential force T on body b of each contact (one admissible set)."""
    block_velocity: np.ndarray
    """(N, 3) collapse mechanism vx, vy [-], ω [1/m], scaled so that the fastest block point moves at 1."""
    solve_time: float
    """s, wall time of the HiGHS call."""
    iterations: int


def _scales(model: Model) -> tuple[float, float]:
    n = model.block_count
    weight = float(np.mean(model.body_mass[:n]) * np.hypot(*model.gravity))
    length = float(np.mean(model.body_radius[:n]))
    return weight, length


def _row_scale(model: Model) -> np.ndarray:
    weight, length = _scales(model)
    return np.tile([1.0 / weight, 1.0 / weight, 1.0 / (weight * length)], model.block_count)


def _check_supported(model: Model, joints: Joints) -> None:
    """Every group of touching blocks must touch a support, else no equilibrium exists: say which (the LP
    said "the blocks cannot carry their own weight (the linear program is infeasible)", for a scenario with
    no support at all too)."""
    n = model.block_count
    if model.support_count == 0:
        raise LimitError(f"no support: nothing holds the {n} block{'s' * (n != 1)} up, so no equilibrium exists")
    # node n stands for every support: a group of blocks is held if it is connected to it
    ends = np.minimum(joints.contact_body.reshape(-1, 2), n)
    graph = sp.coo_matrix((np.ones(len(ends)), (ends[:, 0], ends[:, 1])), shape=(n + 1, n + 1))
    _, group = connected_components(graph, directed=False)
    loose = np.flatnonzero(group[:n] != group[n])
    if loose.size:
        index = int(loose[0])
        others = int(np.count_nonzero(group[:n] == group[index])) - 1
        label = body_label(index, model.block_name[index])
        raise NoEquilibrium(  # a stone drawn a gap above the others: settling may close it (limit --settle)
            f"{label} touches nothing: it has no support, so no equilibrium exists"
            if others == 0
            else f"{label} and the {others} block{'s' * (others != 1)} it touches rest on no support, so no "
            "equilibrium exists"
        )


def _status_error(status: int, message: str, what: str) -> LimitError:
    if status == 2:
        return NoEquilibrium(f"no equilibrium: {what} (the linear program is infeasible)")
    if status == 3:
        return LimitError(
            "no collapse: the joints resist the live load at any factor (the linear program is unbounded) — "
            "choose a load that some mechanism can follow"
        )
    return LimitError(f"the linear program failed: {' '.join(message.split())}")


def solve_limit(
    model: Model, joints: Joints, dead: np.ndarray, live: np.ndarray, method: str = METHOD, options: dict | None = None
) -> LPSolution:
    """Maximise λ (see the module docstring). Raises :class:`LimitError` if infeasible or unbounded.

    ``method`` and ``options`` go to :func:`scipy.optimize.linprog` (the benchmark compares a tight solve).
    """
    _check_supported(model, joints)
    weight, _ = _scales(model)
    scale = _row_scale(model)
    a = sp.diags(scale) @ equilibrium_matrix(model, joints)  # unknowns α / weight: O(1)
    b_eq = -scale * dead / weight
    # λ's column is brought to the dead load's size by a power of two (exact), λ scaled back: a point force is the
    # user's (--point-force 1e15N gave a collapse load of 1.7 kN for 9.0 kN, 1e-3N 'unbounded'); a body force is a
    # weight as the dead load is, its factor 1
    column = scale * live / weight
    size, dead_size = float(np.abs(column).max()), float(np.abs(b_eq).max())
    factor = 2.0 ** round(math.log2(dead_size / size)) if size > 0.0 and dead_size > 0.0 else 1.0
    a_eq = sp.hstack([a, sp.csc_matrix(factor * column[:, None])], format="csc")
    cost = np.zeros(a_eq.shape[1])
    cost[-1] = -1.0
    t0 = time.perf_counter()
    res = linprog(cost, A_eq=a_eq, b_eq=b_eq, bounds=(0, None), method=method, options=options or {})
    elapsed = time.perf_counter() - t0
    if res.status != 0:
        shear = " with friction 0 (the joints carry no shear)" if model.friction == 0 else ""
        raise _status_error(res.status, res.message, f"the blocks cannot carry their own weight{shear}")
    alpha = res.x[:-1].reshape(-1, 2) * weight
    mu = joints.contact_friction(model.friction)
    force = np.stack([alpha.sum(axis=1), mu * (alpha[:, 0] - alpha[:, 1])], axis=1)
    # Dual of  min −λ, A z = b:  y with Aᵀy ≤ c. The mechanism is u = −y, back in unscaled rows.
    velocity = (-res.eqlin.marginals * scale).reshape(-1, 3)
    return LPSolution(
        load_factor=float(res.x[-1]) * factor + 0.0,  # HiGHS's λ at its bound 0 is -0.0 (shown as λ = -0.0000, -0 N)
        contact_force=force,
        block_velocity=velocity / max(_fastest_point(model, velocity), 1e-300),
        solve_time=elapsed,
        iterations=int(getattr(res, "nit", 0)),
    )


def gravity_mechanism(model: Model, joints: Joints, dead: np.ndarray) -> np.ndarray:
    """(N, 3) block velocities of a mechanism the dead load drives on its own, for a structure with no
    equilibrium, normalised so the fastest block point moves at 1.

    Farkas: {A f = b, f ≥ 0} has no solution iff some u has Aᵀu ≥ 0 (every cone edge does non-negative
    power: the joints open or slide and dilate, as a collapse mechanism's) and bᵀu < 0 (the dead load does
    positive work). Of those, one mechanism, not a sum of several:

        minimise Σ_e (Aᵀu)_e   subject to  Aᵀu ≥ 0,  bᵀu = −1        (u free)

    Σ_e (Aᵀu)_e is twice the joints' opening rate summed over their contact points: the mechanism that
    opens its joints least for the work the dead load does. Its vertex is an extreme ray of the cone of
    mechanisms, a single mechanism (an arch's four hinges). The box |u| ≤ 1 this maximised bᵀu over put
    every block it could at a corner of the box: a sum of mechanisms, 100 of 100 blocks giving way on 15 hinges
    and 10 sliding joints for the bridge on slender piers.
    """
    weight, _ = _scales(model)
    scale = _row_scale(model)
    a = sp.diags(scale) @ equilibrium_matrix(model, joints)
    b = -scale * dead / weight
    cost = np.asarray(a.sum(axis=1)).ravel()  # Σ_e (Aᵀu)_e = (A 1)ᵀ u
    res = linprog(
        cost,
        A_ub=-a.T.tocsc(),
        b_ub=np.zeros(a.shape[1]),
        A_eq=b[None, :],
        b_eq=[-1.0],
        bounds=(None, None),
        method=METHOD,
    )
    if res.status != 0:
        return np.zeros((model.block_count, 3))
    velocity = (res.x * scale).reshape(-1, 3)
    return velocity / max(_fastest_point(model, velocity), 1e-300)


def _fastest_point(model: Model, velocity: np.ndarray) -> float:
    """Largest speed of any block vertex under block velocities (N, 3)."""
    n = model.block_count
    start = model.body_vert_start
    owner = np.repeat(np.arange(n), np.diff(start[: n + 1]))
    r = model.vert_local[: start[n]]
    v = velocity[owner]
    vx = v[:, 0] - v[:, 2] * r[:, 1]
    vy = v[:, 1] + v[:, 2] * r[:, 0]
    return float(np.sqrt(vx * vx + vy * vy).max()) if n else 0.0


def support_thrust_range(
    model: Model, joints: Joints, dead: np.ndarray, support: int, direction=(1.0, 0.0)
) -> tuple[float, float]:
    """Least and greatest force [N] the blocks can push on support ``support`` (0..S-1) along ``direction``
    under their own weight alone, over every admissible set of joint forces.

    For an arch on two supports this is the range of its horizontal thrust: the minimum when the supports
    spread, the maximum when they are pushed together (Heyman's active and passive states). A bound is
    ±inf where there is none (blocks jammed between two supports: any self-stress of theirs is admissible;
    the unbounded LP failed the whole analysis as "no collapse"), and 0 within the LP's rounding of it
    (a lone column's ground: −4e-10 N).
    """
    _check_supported(model, joints)
    weight, _ = _scales(model)
    scale = _row_scale(model)
    a_eq = sp.diags(scale) @ equilibrium_matrix(model, joints)
    b_eq = -scale * dead / weight
    edges = _cone_edges(model, joints)
    on_support = np.repeat(joints.contact_body[:, 1] == model.block_count + support, 2)
    cost = np.where(on_support, edges @ np.asarray(direction, dtype=np.float64), 0.0)
    out = []
    for sign in (1.0, -1.0):
        res = linprog(sign * cost, A_eq=a_eq, b_eq=b_eq, bounds=(0, None), method=METHOD)
        if res.status == 3:
            out.append(-sign * np.inf)
            continue
        if res.status != 0:
            raise _status_error(res.status, res.message, "the blocks cannot carry their own weight")
        force = sign * res.fun * weight
        out.append(0.0 if abs(force) < 1e-9 * weight else force)
    return out[0], out[1]
