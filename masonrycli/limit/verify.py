"""Static and dynamic side by side: run the NSCD engine near the LP's collapse load.

The LP assumes associative friction (a sliding joint dilates by μ × its slip); real joints do not, so
where sliding matters the LP's λ is an upper bound. This module checks λ with the engine itself: the
structure starts at rest under gravity tilted to atan(f·λ) — the tilting table, which is the horizontal
body-force load λ·weight up to a factor on all loads that no rigid no-tension structure feels — for
f = 0.95 and 1.05, with every support fixed and a tight NLGS tolerance (``TOLERANCE``). It should
stand at 0.95 λ and collapse at 1.05 λ.

"Collapse" means some block moved more than ``COLLAPSE_SHARE`` × the median block radius; the run stops
there, and its displacement field is compared with the LP's mechanism:

    similarity = Σ_i d_i · u_i / (|d| |u|),   d_i = (Δx_i, Δy_i, Δθ_i r_i),  u_i = (vx_i, vy_i, ω_i r_i)

(r_i: block radius, so rotations weigh like the motion they give a block's corners), together with the
hinged joints of the dynamic run (``masonrycli.analysis.mechanism``) found at that instant.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from masonrycli.limit.analysis import LimitResult
from masonrycli.run import Simulation
from masonrycli.scenario.motion import Fixed

FACTORS = (0.95, 1.05)
"""Multiples of λ the engine is run at."""
DURATION = 2.0
"""s of simulated time per run (a run that collapses stops earlier)."""
TOLERANCE = 1e-6
MAX_ITERATIONS = 5000
"""NLGS settings of the verification runs. At the default 1.666e-4 / 1000 the default arch, at rest under
its own weight alone, rattles at 5–8 mm/s (sweep cap hit on some steps) and, tilted to 0.95 λ, rocks its
way down after ~3.5 s; at 1e-6 / 5000 it stays within 0.03 mm (0.1 mm/s) for 3 s at 0.95 λ."""
COLLAPSE_SHARE = 0.1
"""A block displaced by more than this × the median block radius means the structure is collapsing."""


@dataclass(frozen=True)
class DynamicCheck:
    """One engine run at f·λ."""

    factor: float
    tilt_deg: float | None
    """Gravity's tilt, or None for a point load (gravity as it is)."""
    collapsed: bool
    time: float
    """s: when the collapse threshold was crossed, or the end of the run."""
    max_displacement: float
    """m: largest block displacement at that time."""
    threshold: float
    """m: the collapse threshold."""
    max_speed: float
    """m/s: fastest block point at that time (a standing structure should be at rest again)."""
    similarity: float | None
    """Cosine between the dynamic displacement field and the LP mechanism (collapsing runs only)."""
    hinges: tuple[str, ...]
    """Joints hinged in the dynamic run at that time."""
    shared_hinges: tuple[str, ...]
    """Of those, the ones the LP's mechanism hinges too."""
    wall_time: float
    applied: str = "tilt"
    """How the engine was given the live load: "tilt" (gravity tilted), "weight" (a point load down, a mass its
    block carries) or "force" (a point load along ±x or up, applied at its point)."""

    @property
    def as_predicted(self) -> bool:
        return self.collapsed == (self.factor > 1.0)

    def summary(self) -> dict:
        return dataclasses.asdict(self) | {"as_predicted": self.as_predicted}


def load_point(scenario, load) -> tuple[float, float]:
    """m: where a point load acts: ``--at``'s place on the block's top, or the loaded block's own centroid."""
    if load.at is not None:
        return (load.at, load.top)
    block = next(b for b in scenario.assembly.blocks if b.name == load.block)
    return tuple(block.polygon.centroid.coords[0])


def applied_model(scenario, result: LimitResult, factor: float):
    """The model of ``scenario`` with the point load at ``factor`` × its collapse value as a force applied where
    it acts (each part of a spread load where it bears), along its direction: a point load along ±x or up,
    which no weight can be. No mass: a braking force or an uplift has no vehicle's inertia."""
    from masonrycli.limit.problem import DIRECTIONS
    from masonrycli.model import applied_forces, build_model

    load = result.load
    model = build_model(scenario)
    names = list(model.block_name)
    size = factor * result.load_factor * result.reference_force
    unit = np.asarray(DIRECTIONS[load.direction], dtype=np.float64)
    parts = load.patches or ((load.block, *load_point(scenario, load), 1.0),)
    return applied_forces(model, [(names.index(name), share * size * unit, (x, y)) for name, x, y, share in parts])


def as_weight(load) -> bool:
    """A point load down is verified as a weight its block carries (a vehicle's mass, inertia too); along
    ±x or up, as a force applied at its point (:func:`applied_model`)."""
    return load.kind == "point" and load.direction == "-y"


def weighted_scenario(scenario, result: LimitResult, factor: float):
    """``scenario`` with the point load at ``factor`` × its collapse value as a mass the loaded block carries
    where the load acts (``Block.carried_mass``): a weight of f·λ·F, moving with the block."""
    load = result.load
    g = float(np.hypot(*scenario.run.gravity))
    blocks = list(scenario.assembly.blocks)
    names = [b.name for b in blocks]
    at = load_point(scenario, load)
    mass = factor * result.load_factor * result.reference_force / g
    for name, x, y, share in load.patches or ((load.block, *at, 1.0),):  # a spread load: each part where it bears
        i = names.index(name)
        block, part = blocks[i], share * mass
        before = block.carried_at if block.carried_mass > 0 else (x, y)
        total = block.carried_mass + part
        centre = (block.carried_mass * np.asarray(before) + part * np.asarray((x, y))) / total
        blocks[i] = dataclasses.replace(block, carried_mass=total, carried_at=(float(centre[0]), float(centre[1])))
    return dataclasses.replace(scenario, assembly=dataclasses.replace(scenario.assembly, blocks=tuple(blocks)))


def tilted_scenario(scenario, result: LimitResult, factor: float, duration: float):
    """``scenario`` with gravity tilted to atan(factor·λ) towards the live load (a point load down: as a
    weight, :func:`weighted_scenario`; along ±x or up: gravity as it is, the force applied by
    :func:`applied_model`), fixed supports, ``duration``."""
    if result.load.kind == "point":
        if as_weight(result.load):
            scenario = weighted_scenario(scenario, result, factor)
        gravity = tuple(scenario.run.gravity)
    else:
        g = float(np.hypot(*scenario.run.gravity))
        side = 1.0 if result.load.direction == "+x" else -1.0
        psi = math.atan(factor * result.load_factor)
        gravity = (side * g * math.sin(psi), -g * math.cos(psi))
    run = dataclasses.replace(
        scenario.run,
        gravity=gravity,
        duration=duration,
        record_every=10**6,
        tolerance=TOLERANCE,
        max_iterations=MAX_ITERATIONS,
    )
    return dataclasses.replace(scenario, run=run, motions=tuple(Fixed() for _ in scenario.motions))


def _similarity(displacement: np.ndarray, velocity: np.ndarray, radius: np.ndarray) -> float:
    d = displacement * np.array([1.0, 1.0, 0.0]) + np.outer(displacement[:, 2] * radius, [0.0, 0.0, 1.0])
    u = velocity * np.array([1.0, 1.0, 0.0]) + np.outer(velocity[:, 2] * radius, [0.0, 0.0, 1.0])
    norm = float(np.linalg.norm(d) * np.linalg.norm(u))
    return float((d * u).sum() / norm) if norm > 0 else 0.0


def run_check(scenario, result: LimitResult, factor: float, duration: float = DURATION) -> DynamicCheck:
    """Run the engine at ``factor`` × λ until it collapses or ``duration`` ends."""
    t0 = time.perf_counter()
    run = tilted_scenario(scenario, result, factor, duration)
    pushed = result.load.kind == "point" and not as_weight(result.load)
    sim = Simulation(run, model=applied_model(run, result, factor) if pushed else None)
    m = sim.model
    n = m.block_count
    threshold = COLLAPSE_SHARE * float(np.median(m.body_radius[:n]))
    q0 = m.body_q0[:n].copy()
    radius = m.body_radius[:n]

    def displacement() -> np.ndarray:
        d = sim.state.body_q[:n] - q0
        return np.hypot(d[:, 0], d[:, 1]) + np.abs(d[:, 2]) * radius

    collapsed = False
    for _ in range(m.n_steps):
        sim.step()
        if sim.diverged() or displacement().max() > threshold:
            collapsed = True
            break
    largest = float(displacement().max())
    v = sim.state.body_v[:n]
    speed = float((np.hypot(v[:, 0], v[:, 1]) + np.abs(v[:, 2]) * radius).max()) if n else 0.0
    hinged, _ = sim.hinges() if sim.last is not None else (np.zeros(0, dtype=bool), None)
    hinges = tuple(m.joint_names(sim.joints.joint_body[hinged]))
    similarity = None
    if collapsed:
        moved = sim.state.body_q[:n] - q0
        similarity = _similarity(moved, result.solution.block_velocity, radius)
    lp_hinges = set(result.hinges)
    return DynamicCheck(
        factor=factor,
        tilt_deg=None if result.load.kind == "point" else math.degrees(math.atan(factor * result.load_factor)),
        collapsed=collapsed,
        time=sim.state.time,
        max_displacement=largest,
        threshold=threshold,
        max_speed=speed,
        similarity=similarity,
        hinges=hinges,
        shared_hinges=tuple(h for h in hinges if h in lp_hinges),
        wall_time=time.perf_counter() - t0,
        applied="force" if pushed else "weight" if result.load.kind == "point" else "tilt",
    )


def verify(scenario, result: LimitResult, factors=FACTORS, duration: float = DURATION) -> list[DynamicCheck]:
    """One :func:`run_check` per factor (default 0.95 and 1.05)."""
    return [run_check(scenario, result, f, duration) for f in factors]
