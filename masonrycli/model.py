"""Model (what does not change during a run) and State (what does), as flat arrays.

``build_model`` turns a :class:`~masonrycli.scenario.scenario.Scenario` into a :class:`Model` once; the time loop
then only touches arrays. Bodies are the blocks (0..N-1, scenario order) followed by the supports
(N..N+S-1). Supports have zero inverse mass: they move with their imposed velocity and ignore impulses.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from geometry_library.blocks import JOINT_SEPARATOR
from geometry_library.mass import mass_properties
from masonrycli.scenario.motion import support_velocity


@dataclass(frozen=True, eq=False)
class Model:
    """Immutable description of a run. Arrays are float64 unless stated."""

    block_count: int
    """N, number of dynamic blocks."""
    support_count: int
    """S, number of supports."""
    body_mass: np.ndarray
    """(B,) kg (per the block thickness); supports: inf."""
    body_inertia: np.ndarray
    """(B,) kg·m², polar, about the centroid; supports: inf."""
    body_inv_mass: np.ndarray
    """(B,) 1/kg; 0 for supports."""
    body_inv_inertia: np.ndarray
    """(B,) 1/(kg·m²); 0 for supports."""
    body_dynamic: np.ndarray
    """(B,) bool; True for blocks."""
    body_vert_start: np.ndarray
    """(B+1,) int64; vertices of body b are vert_local[start[b]:start[b+1]]."""
    vert_local: np.ndarray
    """(V, 2) m; CCW polygon vertices relative to the body's initial centroid, at θ = 0."""
    body_q0: np.ndarray
    """(B, 3) initial pose: centroid x, y (m), θ = 0 (rad)."""
    body_v0: np.ndarray
    """(B, 3) initial velocity vx, vy (m/s), ω (rad/s); supports take their imposed velocity at t = 0."""
    block_volume: np.ndarray
    """(N,) m³: area × thickness."""
    body_radius: np.ndarray
    """(B,) m: largest distance from the centroid to a vertex (bounds the speed of any point)."""
    block_depth: float
    """The structure's height in blocks as built: the blocks' vertical extent over their median height (about
    the courses of a wall; the solver's first stage waits longer on deeper structures, engine/momentum.py)."""
    gravity: np.ndarray
    """(2,) m/s²."""
    friction: float
    """Coulomb coefficient μ of every contact."""
    dt: float
    """Time step, s."""
    theta: float
    """Moreau–Jean θ ∈ [0.5, 1]."""
    tolerance: float
    """NLGS stopping tolerance, m/s: RMS contact-law violation of a sweep (masonrycli.engine.nlgs)."""
    max_iterations: int
    """NLGS sweep cap."""
    solver: str
    """Contact solver (RunConfig.solver): "nlgs-accel", "nlgs-accel32" or "nlgs" (masonrycli.engine.dispatch.solve)."""
    alert_distance: float
    """Contacts whose gap is below this are kept, m."""
    n_steps: int
    """Number of time steps of the run."""
    support_velocity: SupportVelocity
    """``support_velocity[k]`` (S, 2) m/s: imposed support velocity at t_k = k·dt, k = 0 … n_steps."""
    block_name: tuple
    """(N,) str: the blocks' names, scenario order."""
    support_name: tuple
    """(S,) str: the supports' names, scenario order."""
    block_carried_mass: np.ndarray
    """(N,) kg: the part of each block's mass that is a dead mass it carries (a bridge's fill over a voussoir,
    ``Block.carried_mass``); body_mass, body_q0 and body_inertia include it."""
    block_centroid: np.ndarray
    """(N, 2) m: each block's own (polygon's) centroid relative to its body's centre at θ = 0: exactly 0 but for
    a block that carries a mass, whose body's centre of mass it pulls away (the cells' points,
    ``masonrycli.analysis.tensors``)."""
    block_applied: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    """(N, 6) or no rows: a force applied at a point of each block, as the engine's free velocity reads it —
    Fx/m, Fy/m (m/s²), the point relative to the body's centre at θ = 0 (m), Fx/I, Fy/I (1/(m·s²)). Only
    ``masonry limit --verify`` gives one (a point load along ±x or up, :func:`applied_forces`)."""

    @property
    def body_count(self) -> int:
        return self.block_count + self.support_count

    def joint_names(self, joint_body) -> list[str]:
        """``"a|b"`` for each row (a, b) of body indices (blocks, then supports): how hinge lists, the limit
        analysis and its verification name a joint (body names may not contain the separator)."""
        names = self.block_name + self.support_name
        return [f"{names[a]}{JOINT_SEPARATOR}{names[b]}" for a, b in joint_body]


@dataclass(eq=False)
class State:
    """What the time loop advances. Mutated in place by the solver."""

    body_q: np.ndarray
    """(B, 3) centroid x, y (m), rotation θ from the initial orientation (rad, CCW)."""
    body_v: np.ndarray
    """(B, 3) vx, vy (m/s), ω (rad/s)."""
    step: int = 0
    """Time steps taken since t = 0."""
    time: float = 0.0
    """Simulated time, s."""

    def copy(self) -> State:
        return State(self.body_q.copy(), self.body_v.copy(), self.step, self.time)


def build_model(scenario) -> Model:
    """Flatten a scenario into a :class:`Model` (mass properties, CSR vertices, support motion table)."""
    run, assembly = scenario.run, scenario.assembly
    blocks, supports = assembly.blocks, assembly.supports
    n, s = len(blocks), len(supports)
    mass = np.empty(n + s)
    inertia = np.empty(n + s)
    volume = np.empty(n)
    carried = np.zeros(n)
    own = np.zeros((n, 2))
    q0 = np.zeros((n + s, 3))
    v0 = np.zeros((n + s, 3))
    starts = [0]
    local = []
    for i, block in enumerate(blocks):
        xy = block.vertices
        props = mass_properties(xy, block.density, block.thickness)
        mass[i], inertia[i], volume[i] = props.mass, props.inertia, props.area * block.thickness
        centre = props.centroid
        carried[i] = block.carried_mass
        if carried[i] > 0.0:  # a point mass riding on the block: the body's centre of mass moves towards it
            at = np.asarray(block.carried_at, dtype=np.float64)
            total = mass[i] + carried[i]
            centre = (mass[i] * props.centroid + carried[i] * at) / total
            inertia[i] += mass[i] * _squared(props.centroid - centre) + carried[i] * _squared(at - centre)
            mass[i] = total
            own[i] = props.centroid - centre
        q0[i, :2] = centre
        v0[i] = block.velocity
        local.append(xy - centre)
        starts.append(starts[-1] + len(xy))
    for j, support in enumerate(supports):
        xy = support.vertices
        props = mass_properties(xy, 1.0, 1.0)
        q0[n + j, :2] = props.centroid
        local.append(xy - props.centroid)
        starts.append(starts[-1] + len(xy))
    mass[n:] = np.inf
    inertia[n:] = np.inf
    n_steps = run.n_steps
    table = SupportVelocity(tuple(scenario.motions), float(run.dt), n_steps)
    v0[n:, :2] = table[0]
    dynamic = np.zeros(n + s, dtype=np.bool_)
    dynamic[:n] = True
    return Model(
        block_count=n,
        support_count=s,
        body_mass=mass,
        body_inertia=inertia,
        body_inv_mass=np.where(dynamic, 1.0 / mass, 0.0),
        body_inv_inertia=np.where(dynamic, 1.0 / inertia, 0.0),
        body_dynamic=dynamic,
        body_vert_start=np.asarray(starts, dtype=np.int64),
        vert_local=np.ascontiguousarray(np.concatenate(local), dtype=np.float64),
        body_q0=q0,
        body_v0=v0,
        block_volume=volume,
        body_radius=_radii(np.asarray(starts, dtype=np.int64), np.concatenate(local)),
        block_depth=_depth(blocks),
        gravity=np.asarray(run.gravity, dtype=np.float64),
        friction=float(scenario.material.friction),
        dt=float(run.dt),
        theta=float(run.theta),
        tolerance=float(run.tolerance),
        max_iterations=int(run.max_iterations),
        solver=str(run.solver),
        alert_distance=float(run.alert_distance),
        n_steps=n_steps,
        support_velocity=table,
        block_name=tuple(b.name for b in blocks),
        support_name=tuple(sp.name for sp in supports),
        block_carried_mass=carried,
        block_centroid=own,
    )


def _squared(d: np.ndarray) -> float:
    return float(d[0] * d[0] + d[1] * d[1])


class SupportVelocity:
    """The supports' imposed velocities at t_k = k·dt, evaluated ``CHUNK`` steps at a time when first asked.

    Nothing is held in proportion to the run's length (a table of every step of a 10⁸-step run would
    take gigabytes before step 1). ``table[k]`` is bit-identical to row k of
    ``support_velocity(motions, arange(n_steps + 1) * dt)``: the motions are evaluated elementwise in t.
    """

    CHUNK = 4096

    def __init__(self, motions: tuple, dt: float, n_steps: int):
        self.motions, self.dt, self.n_steps = motions, dt, n_steps
        self._start, self._rows = 0, np.zeros((0, len(motions), 2))

    def __len__(self) -> int:
        return self.n_steps + 1

    def __getitem__(self, k: int) -> np.ndarray:
        if not 0 <= k <= self.n_steps:
            raise IndexError(f"step {k} outside 0 … {self.n_steps}")
        if not self._start <= k < self._start + len(self._rows):
            self._start = k
            stop = min(k + self.CHUNK, self.n_steps + 1)
            self._rows = support_velocity(self.motions, np.arange(k, stop, dtype=np.float64) * self.dt)
        return self._rows[k - self._start]

    def between(self, start: int, stop: int) -> np.ndarray:
        """(stop − start, S, 2) the rows of steps start … stop − 1, evaluated now (not kept)."""
        return support_velocity(self.motions, np.arange(start, stop, dtype=np.float64) * self.dt)


def _depth(blocks) -> float:
    """The blocks' vertical extent over their median height (0 without blocks): once per model, not per step."""
    if not blocks:
        return 0.0
    low = np.array([b.vertices[:, 1].min() for b in blocks])
    high = np.array([b.vertices[:, 1].max() for b in blocks])
    return float((high.max() - low.min()) / np.median(high - low))


def _radii(start: np.ndarray, local: np.ndarray) -> np.ndarray:
    """(B,) largest |vertex − centroid| of each body (vectorised over the CSR vertices)."""
    dist = np.hypot(local[:, 0], local[:, 1])
    return np.maximum.reduceat(dist, start[:-1])


def initial_state(model: Model) -> State:
    return State(model.body_q0.copy(), model.body_v0.copy(), 0, 0.0)


def applied_forces(model: Model, forces) -> Model:
    """``model`` with forces applied at points of its blocks: ``forces`` is [(block index, (Fx, Fy) N, (x, y) m
    the point at θ = 0)]; several on one block (a spread load's parts) must be parallel: their resultant acts
    at their force-weighted mean point."""
    import dataclasses

    n = model.block_count
    applied = np.zeros((n, 6))
    total = np.zeros((n, 2))
    point = np.zeros((n, 2))
    weight = np.zeros(n)
    for b, force, at in forces:
        f, p = np.asarray(force, dtype=np.float64), np.asarray(at, dtype=np.float64)
        size = float(np.hypot(*f))
        total[b] += f
        point[b] += size * (p - model.body_q0[b, :2])
        weight[b] += size
    loaded = weight > 0
    point[loaded] /= weight[loaded, None]
    applied[:, 0:2] = total / model.body_mass[:n, None]
    applied[:, 2:4] = point
    applied[:, 4:6] = total / model.body_inertia[:n, None]
    return dataclasses.replace(model, block_applied=applied)
