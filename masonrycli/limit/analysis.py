"""One limit analysis, end to end: scenario → model → joints → LP → mechanism, hinges, line of thrust.

:func:`analyse` is what ``masonry limit`` runs; :class:`LimitResult` holds everything it reports, and
:meth:`LimitResult.summary` is the JSON object of ``--json``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from masonrycli.errors import InputError
from masonrycli.limit.joints import Joints, find_joints, joint_names
from masonrycli.limit.kinematics import JointMotion, joint_motion, rigid_parts
from masonrycli.limit.problem import (
    LimitError,
    LiveLoad,
    LPSolution,
    NoEquilibrium,
    gravity_mechanism,
    load_vectors,
    solve_limit,
    support_thrust_range,
)
from masonrycli.limit.thrust import ThrustLine, thrust_line
from masonrycli.model import Model, build_model


@dataclass(frozen=True, eq=False)
class LimitResult:
    """A limit analysis: the program's answer and its reading."""

    scenario_name: str
    load: LiveLoad
    model: Model
    joints: Joints
    solution: LPSolution
    motion: JointMotion
    thrust: ThrustLine
    reference_force: float
    """N: the live load at λ = 1 (total weight, or the loaded block's weight)."""
    analysis_time: float
    """s: joints + assembly + solve + reading (model building excluded)."""
    thickness: float | None = None
    """m: the blocks' out-of-plane thickness, which the newtons are for (None: not one for every block, or
    a model analysed without its scenario)."""
    ring: object | None = None
    """The :class:`~masonrycli.limit.thickness.LeastThickness` of a built-in arch (its ring thickness, the least
    that carries its own weight, whether the builder bounded the search); None unless asked for (``masonry
    limit --min-thickness``)."""
    settled: object | None = None
    """The :class:`~masonrycli.settle.Settling` of ``masonry limit --settle`` (the wall analysed where the
    engine let it come to rest), None without it."""
    places: tuple | None = None
    """The places a ``--worst`` point load was tried at (:class:`masonrycli.limit.worst.Place`), left to right;
    None without ``--worst``."""
    map_origin: tuple[float, float] | None = None
    """m: the map coordinates of the origin a file was read moved to (its reading's ``map_origin_m``), so that a
    place is also said on the survey; None for a file read as it is, or a built-in."""
    support_thrust: tuple[tuple[str, str, float, float], ...] | None = None
    """(support, outward direction, least N, greatest N) of each support under the dead load alone
    (:func:`support_thrusts`; ±inf: no bound, null in JSON); None unless asked for (``masonry limit --thrust``)."""

    @property
    def load_factor(self) -> float:
        return self.solution.load_factor

    @property
    def names(self) -> list[str]:
        return joint_names(self.model, self.joints)

    @property
    def hinges(self) -> list[str]:
        return [n for n, h in zip(self.names, self.motion.joint_hinged) if h]

    @property
    def sliding_joints(self) -> list[str]:
        return [n for n, s in zip(self.names, self.motion.joint_sliding) if s]

    def hinges_largest_first(self) -> list[str]:
        """The hinges, the fastest-turning first (|Δω| × joint length): the mechanism's main hinges lead."""
        order = np.argsort(-self.motion.joint_turn, kind="stable")
        names = self.names
        return [names[k] for k in order if self.motion.joint_hinged[k]]

    def opening_largest_first(self) -> list[str]:
        """The joints whose faces turn as they part all along (no end in contact), the fastest first."""
        order = np.argsort(-self.motion.joint_turn, kind="stable")
        names = self.names
        return [names[k] for k in order if self.motion.joint_opening[k]]

    def sliding_largest_first(self) -> list[str]:
        """The sliding joints, the fastest-sliding first."""
        order = np.argsort(-self.motion.joint_slide, kind="stable")
        names = self.names
        return [names[k] for k in order if self.motion.joint_sliding[k]]

    @property
    def moving_blocks(self) -> list[str]:
        return [n for n, m in zip(self.model.block_name, self.motion.block_moving) if m]

    @property
    def part_indices(self) -> list[np.ndarray]:
        """The moving blocks (indices) as the mechanism's rigid parts, largest first (:func:`rigid_parts`)."""
        return rigid_parts(self.model, self.joints, self.motion)

    @property
    def rigid_parts(self) -> list[list[str]]:
        """:attr:`part_indices` by name."""
        return [[str(self.model.block_name[k]) for k in p] for p in self.part_indices]

    def tilt_angle(self) -> float | None:
        """Degrees: the tilting table's critical angle atan(λ) (body-force loads only)."""
        return None if self.load.kind == "point" else math.degrees(math.atan(self.load_factor))

    def summary(self) -> dict:
        """Everything ``--json`` prints: plain numbers, strings and lists."""
        m, j, th = self.model, self.joints, self.thrust
        names = self.names
        hinge_idx = np.flatnonzero(self.motion.joint_hinged)
        line = [
            {
                "joint": names[k],
                "point": _finite(th.joint_point[k]),
                "normal_force": float(th.joint_normal_force[k]),
                "shear_force": float(th.joint_shear_force[k]),
                "eccentricity": _finite(th.joint_eccentricity[k]),
            }
            for k in range(j.joint_count)
        ]
        return {
            "scenario": self.scenario_name,
            "load": {
                "kind": self.load.kind,
                "direction": self.load.direction,
                "block": self.load.block,
                "at_m": self.load.at,
                "force_N": self.load.force,
                "spread_deg": self.load.spread,
                "spread_onto": None
                if self.load.patches is None
                else [{"block": b, "point": [x, y], "share": w} for b, x, y, w in self.load.patches],
                "worst": self.load.worst,
            },
            "places": None
            if self.places is None
            else [{"at_m": p.at, "block": p.block, "load_factor": p.load_factor} for p in self.places],
            "load_factor": self.load_factor,
            "tilt_angle_deg": self.tilt_angle(),
            "collapse_load_N": self.load_factor * self.reference_force,
            "reference_load_N": self.reference_force,
            "thickness_m": self.thickness,
            "ring_thickness_m": None if self.ring is None else self.ring.thickness,
            "least_ring_thickness_m": None if self.ring is None else self.ring.least,
            "geometric_factor": None if self.ring is None else self.ring.factor,
            # why least_ring_thickness_m is only an upper bound (the ring still stood there), or null
            "least_ring_thickness_bounded_by": None if self.ring is None else self.ring.bounded_by,
            "support_thrust": None
            if self.support_thrust is None
            else [
                {"support": name, "direction": d, "least_N": _finite(lo), "greatest_N": _finite(hi)}
                for name, d, lo, hi in self.support_thrust
            ],
            "friction": m.friction,
            "fill_load_N": float(m.block_carried_mass.sum() * np.hypot(*m.gravity)),  # weight riding on the blocks
            "blocks": m.block_count,
            "supports": m.support_count,
            "joints": j.joint_count,
            "settled": None if self.settled is None else self.settled.summary(),
            "map_origin_m": None if self.map_origin is None else list(self.map_origin),
            "contact_points": j.contact_count,
            "hinges": self.hinges,
            "hinge_points": [[float(x), float(y)] for x, y in self.motion.hinge_point],
            "sliding_joints": self.sliding_joints,
            "opening_joints": self.opening_largest_first(),
            "moving_blocks": self.moving_blocks,
            "rigid_parts": self.rigid_parts,
            "mechanism": {
                name: [float(v) for v in vel]
                for name, vel, moving in zip(m.block_name, self.solution.block_velocity, self.motion.block_moving)
                if moving
            },
            "line_of_thrust": line,
            "hinge_joint_index": hinge_idx.tolist(),
            "solve_time_s": self.solution.solve_time,
            "analysis_time_s": self.analysis_time,
            "lp_iterations": self.solution.iterations,
        }


def _finite(value):
    arr = np.atleast_1d(np.asarray(value, dtype=float))
    if not np.isfinite(arr).all():
        return None
    return [float(v) for v in arr] if np.ndim(value) else float(arr[0])


MIN_GRAVITY = 1e-6
"""m/s²: below this the blocks' weight is taken as zero (a microgravity experiment has ~1e-5)."""


def _falls(model: Model, joints: Joints, dead: np.ndarray, shown: int = 4) -> str:
    """What gives way under the dead load alone (:func:`gravity_mechanism`), for the "no equilibrium" line:
    which blocks move, as which rigid parts, its hinges and sliding joints (an abutment tipped by an arch's
    thrust)."""
    motion = joint_motion(model, joints, gravity_mechanism(model, joints, dead))
    moving = int(np.count_nonzero(motion.block_moving))
    if not moving:
        return ""
    names = joint_names(model, joints)

    def fastest(rate, chosen):
        order = [k for k in np.argsort(-rate, kind="stable") if chosen[k]]
        more = f" and {len(order) - shown} more" if len(order) > shown else ""
        return ", ".join(names[k] for k in order[:shown]) + more

    parts = []
    for word, rate, chosen in (
        ("hinges", motion.joint_turn, motion.joint_hinged),
        ("sliding", motion.joint_slide, motion.joint_sliding),
        ("opening", motion.joint_turn, motion.joint_opening),
    ):
        if chosen.any():
            parts.append(f"{word} {fastest(rate, chosen)}")
    return (
        f"; under its own weight {moving} of {model.block_count} blocks give way{parts_text(model.block_name, rigid_parts(model, joints, motion))} — "
        + "; ".join(parts)
    )


def parts_text(names, parts: list[np.ndarray], shown: int = 4) -> str:
    """ ", as 3 rigid parts (v01 … v05, 5 blocks; …)" of the rigid parts ``parts`` (block indices, largest first):
    a part of consecutive blocks by its first and last, another by its first two; "" when each moving block is
    a part of its own (nothing to group)."""
    if all(p.size == 1 for p in parts):
        return ""

    def part(p):
        if p.size == 1:
            return str(names[p[0]])
        if p.size == 2 or np.all(np.diff(p) == 1):
            return f"{names[p[0]]} {'…' if p.size > 2 else 'and'} {names[p[-1]]}" + (
                f", {p.size} blocks" if p.size > 2 else ""
            )
        return f"{names[p[0]]}, {names[p[1]]} and {p.size - 2} more"

    if len(parts) == 1:
        return f", as one rigid part ({part(parts[0])})"
    more = f"; and {len(parts) - shown} more" if len(parts) > shown else ""
    return f", as {len(parts)} rigid parts ({'; '.join(part(p) for p in parts[:shown])}{more})"


def analyse_model(model: Model, load: LiveLoad, scenario_name: str = "") -> LimitResult:
    """Limit analysis of a built model (supports are rigid and fixed whatever their motion in a run)."""
    t0 = time.perf_counter()
    g = float(np.hypot(*model.gravity))
    # λ does not depend on |g|, but the LP is scaled by the weight: at g = 0 a ZeroDivisionError, at
    # 1e-300 m/s² "no equilibrium" for a block standing on the ground
    if not g >= MIN_GRAVITY:
        raise LimitError(
            f"gravity is zero or negligible (|g| = {g:.3g} m/s², [run] gravity): the blocks weigh nothing, and "
            "every load of limit analysis is λ times a weight"
        )
    joints = find_joints(model)
    dead, live, reference = load_vectors(model, load)
    try:
        solution = solve_limit(model, joints, dead, live)
    except NoEquilibrium as exc:
        raise NoEquilibrium(f"{exc}{_falls(model, joints, dead)}") from None
    motion = joint_motion(model, joints, solution.block_velocity)
    weight = float(np.mean(model.body_mass[: model.block_count]) * np.hypot(*model.gravity))
    thrust = thrust_line(joints, solution.contact_force, loaded=1e-9 * weight)
    return LimitResult(
        scenario_name=scenario_name,
        load=load,
        model=model,
        joints=joints,
        solution=solution,
        motion=motion,
        thrust=thrust,
        reference_force=reference,
        analysis_time=time.perf_counter() - t0,
    )


def block_over(blocks, x: float) -> tuple[str, float]:
    """The name of the block whose upper boundary is highest over abscissa ``x`` (m), and that height (m):
    where a load placed on the structure's top surface at ``x`` bears (a bridge's deck load at the quarter
    span → the voussoir there). On a joint's vertical line the first such block in order is taken."""
    best, name = -math.inf, None
    for block in blocks:
        xy = np.asarray(block.vertices, dtype=float)
        p, q = xy, np.roll(xy, -1, axis=0)
        lo, hi = np.minimum(p[:, 0], q[:, 0]), np.maximum(p[:, 0], q[:, 0])
        over = (lo <= x) & (x <= hi)
        if not over.any():
            continue
        dx = q[:, 0] - p[:, 0]
        # an edge's height at x; a vertical edge at x counts with its higher end
        t = np.where(dx != 0, (x - p[:, 0]) / np.where(dx != 0, dx, 1.0), 1.0)
        y = np.where(dx != 0, p[:, 1] + t * (q[:, 1] - p[:, 1]), np.maximum(p[:, 1], q[:, 1]))
        top = float(y[over].max())
        if top > best + 1e-12:
            best, name = top, block.name
    if name is None:
        xs = np.concatenate([np.asarray(b.vertices)[:, 0] for b in blocks])
        raise InputError(f"--at {x:g}: no block over x = {x:g} m (the blocks span x = {xs.min():g} … {xs.max():g} m)")
    return name, best


def support_thrusts(model: Model, joints: Joints) -> tuple[tuple[str, str, float, float], ...]:
    """(support name, "+x"/"-x", least, greatest) horizontal force in N that the blocks can push on each
    support, outward (away from the blocks' centre of mass), under their own weight alone over every
    admissible set of joint forces: an arch's thrust on its abutments, least when they spread, greatest
    when they are pushed together (Heyman's active and passive states)."""
    dead, _, _ = load_vectors(model, LiveLoad())
    n = model.block_count
    mass = model.body_mass[:n]
    centre = float(np.sum(mass * model.body_q0[:n, 0]) / mass.sum())
    out = []
    for s, name in enumerate(model.support_name):
        outward = 1.0 if model.body_q0[n + s, 0] >= centre else -1.0
        least, greatest = support_thrust_range(model, joints, dead, s, (outward, 0.0))
        out.append((str(name), "+x" if outward > 0 else "-x", least, greatest))
    return tuple(out)


def analyse(scenario, load: LiveLoad, thrust: bool = False) -> LimitResult:
    """Limit analysis of ``scenario`` (its blocks, supports, material and gravity) under ``load``; a point
    load given by its place (``load.at``) is put on :func:`block_over` that place, a ``--worst`` one where its
    λ is least (:mod:`masonrycli.limit.worst`); ``thrust``: with
    :func:`support_thrusts` too."""
    places = None
    if load.worst and not load.resolved:
        from masonrycli.limit.worst import worst_load

        load, places = worst_load(scenario, load)
    if load.kind == "point" and load.at is not None and not load.resolved:
        block, top = block_over(scenario.assembly.blocks, load.at)
        load = replace(load, block=block, resolved=True, top=top)
        if load.spread is not None:  # through the fill onto the blocks around
            from masonrycli.limit.worst import fill_surface, placed

            load = placed(load, scenario.assembly.blocks, load.at, block, top, fill_surface(scenario))
    result = replace(analyse_model(build_model(scenario), load, scenario.name), places=places)
    thicknesses = {b.thickness for b in scenario.assembly.blocks}
    if len(thicknesses) == 1:
        result = replace(result, thickness=thicknesses.pop())
    return replace(result, support_thrust=support_thrusts(result.model, result.joints)) if thrust else result
