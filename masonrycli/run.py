"""The one time loop: motion → detect → solve → tensors → record → progress.

``simulate`` owns no I/O format: it hands each recorded :class:`~masonrycli.outputs.frame.Frame` to the sinks it
is given (:class:`~masonrycli.outputs.sinks.FrameSink`: a history, a recorder); the caller closes them. It stops
early when ``stop()`` says so (a signal, see :mod:`masonrycli.interrupt`), when the state diverges, or
when a sink cannot write (``OSError``: the result says which sink and why).
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import datetime

import numpy as np

from masonrycli.analysis.collapse import CollapseMonitor, rule_for
from masonrycli.analysis.mechanism import JointTracker, contact_states
from masonrycli.analysis.tensors import TensorComputer
from masonrycli.analysis.triangulation import build_triangles, chain_neighbours
from masonrycli.engine import integrate
from masonrycli.engine.solver import Solver, StepStats
from masonrycli.engine.tuning import TUNING, Tuning
from masonrycli.interrupt import StopStep, abandonable, raise_dropped
from masonrycli.model import Model, State, build_model, initial_state
from masonrycli.outputs.frame import Frame
from masonrycli.outputs.sinks import COMPLETED, DIVERGED, FAILED, INTERRUPTED
from masonrycli.outputs.verdict import describe_hinges, describe_outcome, describe_peak_drift  # noqa: F401 (theirs)
from masonrycli.records.intensity import describe as describe_intensity
from masonrycli.records.intensity import intensity_measures, shaking_support

DIVERGENCE_SPEED = 1e3
"""m/s: a block faster than this (or a non-finite state) stops the run as diverged."""


@dataclass
class SolverTally:
    """Running aggregates of the per-step solver statistics, in constant memory however long the run:
    what the summary and a study's row need. Means are exact (integer totals over the step count), and the
    largest residual is NaN once a step's was, as a maximum over the per-step array would be."""

    cap: int
    """The sweep cap (``max_iterations``): a step that used as many sweeps counts as capped."""
    steps: int = 0
    """Steps counted."""
    sweeps: int = 0
    """NLGS sweeps, in total."""
    sweeps_max: int = 0
    """The most sweeps of one step."""
    capped: int = 0
    """Steps that used the whole sweep cap."""
    contacts: int = 0
    """Contacts over the steps, in total."""
    contacts_max: int = 0
    """The most contacts of one step."""
    residual_max: float = 0.0
    """m/s: the largest residual of a step."""
    residual_last: float = 0.0
    """m/s: the last step's residual."""
    residual_max_step: int = 0
    """The step (1-based) whose residual is ``residual_max``: the first such; 0 before any step."""

    def add(self, stats: StepStats) -> None:
        """Count one step."""
        sweeps, contacts, residual = int(stats.iterations), int(stats.contact_count), float(stats.residual)
        self.steps += 1
        self.sweeps += sweeps
        self.sweeps_max = max(self.sweeps_max, sweeps)
        self.capped += sweeps >= self.cap
        self.contacts += contacts
        self.contacts_max = max(self.contacts_max, contacts)
        if (residual > self.residual_max or residual != residual) and self.residual_max == self.residual_max:
            self.residual_max = residual  # a NaN residual makes the maximum NaN for good
            self.residual_max_step = self.steps
        self.residual_last = residual

    @property
    def sweeps_mean(self) -> float:
        return self.sweeps / self.steps if self.steps else 0.0

    @property
    def contacts_mean(self) -> float:
        return self.contacts / self.steps if self.steps else 0.0


@dataclass
class RunResult:
    """What happened, for the summary table."""

    status: str
    """One of :data:`masonrycli.outputs.sinks.STATUSES` but "running": "completed", "interrupted", "diverged" or "failed"."""
    message: str
    """One line on how the run stopped ("" when it ran all its steps)."""
    steps: int
    """Time steps run."""
    time: float
    """Simulated time reached, s."""
    wall_time: float
    """Elapsed time of the loop, s."""
    tally: SolverTally
    """The solver's effort over the steps run (per-step values: the history, or a sink's ``log_step``)."""
    max_penetration: float
    """m: the largest penetration at detection over the steps run."""
    energy_initial: float
    """J: kinetic + potential at t = 0 (per block thickness)."""
    energy_final: float
    """J: kinetic + potential at the end."""
    energy_dissipated: float
    """J: dissipated at the contacts since t = 0."""
    support_work: float
    """J: work of the supports on the blocks since t = 0."""
    frames: int
    """Frames handed to the sinks."""
    unconverged: int = 0
    """Steps whose solve did not meet its tolerance before the sweep cap."""
    solver: str = ""
    """The contact solver that ran (RunConfig.solver)."""
    extra: dict = field(default_factory=dict)
    """Further summary rows, label → text (e.g. the hinged joints at the end)."""
    intensity: dict = field(default_factory=dict)
    """Intensity measures of the shaking support's motion as applied (:mod:`masonrycli.records.intensity`), or {}."""
    outcome: dict = field(default_factory=dict)
    """What happened to the structure (:func:`run_outcome`): state, collapse time, drifts, hinges, ..."""
    failed_sink: object = None
    """The sink whose ``on_frame`` raised ``OSError`` (status "failed"), else None."""


class Simulation:
    """Model, state, solver and tensor computer of one scenario, advanced step by step."""

    def __init__(self, scenario, model: Model | None = None, tuning: Tuning = TUNING):
        # tuning: the contact solve's numbers (engine/tuning.py); the solver lab passes others
        self.scenario = scenario
        # when the run started (its history, recording and in-memory run say the same second)
        self.started = datetime.now().isoformat(timespec="seconds")
        self.model = model if model is not None else build_model(scenario)
        self.state: State = initial_state(self.model)
        self.solver = Solver(self.model, tuning)
        m = self.model
        n = m.block_count
        # Cells and triangles come from the blocks touching in the initial configuration.
        count = self.solver.detect(self.state.body_q)
        body = self.solver.contact_body[:count]
        blocks_only = body[(body[:, 0] < n) & (body[:, 1] < n)]
        # on the blocks' own centroids (a carried fill moves the bodies' centres: tensors.py "Which point")
        own = m.body_q0[:n, :2] + m.block_centroid if m.block_centroid.any() else m.body_q0[:n, :2]
        self.triangles = build_triangles(own, blocks_only)
        weight = float(np.mean(m.body_mass[:n]) * np.hypot(*m.gravity)) if n else 0.0
        s = self.solver
        self.joints = JointTracker(body, s.contact_point, s.contact_normal, s.contact_gap, m.body_q0, n, weight)
        chain = chain_neighbours(n, body)
        self.tensors = TensorComputer(
            n, m.block_volume, self.triangles, centroids0=own, chain=chain, centroid_offset=m.block_centroid
        )
        self.energy_dissipated = 0.0
        self.support_work = 0.0
        self.unconverged = 0
        """Steps so far whose solve did not converge (StepStats.converged false)."""
        self.last: StepStats | None = None
        vertices = [b.vertices for b in scenario.assembly.blocks]
        self.monitor = CollapseMonitor(
            m, vertices, shaking_support(scenario.motions), rule_for(scenario), scenario.run.tolerance
        )

    def step(self) -> StepStats:
        stats = self.solver.step(self.state)
        n = self.model.block_count
        s = self.solver
        self.tensors.step(
            s.body_q_m[:n], self.state.body_v[:n], s.contact_body, s.contact_point, s.contact_force, self.model.dt
        )
        self.energy_dissipated += stats.dissipated
        self.support_work += stats.support_work
        self.unconverged += not stats.converged
        self.last = stats
        self.monitor.update(self.state.time, s, self.state.body_q, self.state.body_v)
        return stats

    def energies(self) -> tuple[float, float]:
        return integrate.energies(self.model, self.state.body_q, self.state.body_v)

    def frame(self) -> Frame:
        """Snapshot of the current state and the last step's contacts and tensors: every array is the frame's
        own (copied from the engine's buffers), so the sinks keep them without copying (sinks.FrameSink)."""
        m, st, s = self.model, self.state, self.solver
        n = m.block_count
        kinetic, potential = self.energies()
        if self.last is None:  # initial frame: contacts known, no impulses yet
            c = 0
            body = np.zeros((0, 2), dtype=np.int32)
            point = normal = force = np.zeros((0, 2))
            gap = np.zeros(0)
            status = np.zeros(0, dtype=np.int8)
            mobilised = np.zeros(0)
            r = np.zeros((0, 2))
            support_force = np.zeros((m.support_count, 2))
            iterations, residual = 0, 0.0
            hinged, hinge_point = np.zeros(self.joints.key.size, dtype=bool), np.zeros((0, 2))
        else:
            c = self.last.contact_count
            body, point, normal = s.contact_body, s.contact_point, s.contact_normal
            force, gap = s.contact_force, s.contact_gap
            r = s.contact_r
            status, mobilised = contact_states(
                s.contact_status, s.contact_tangential_velocity(st.body_v), r, m.friction
            )
            support_force = s.support_force
            iterations, residual = self.last.iterations, self.last.residual
        opening = self.joints.opening(st.body_q)  # once for both: the hinges and the block fields
        if self.last is not None:
            hinged, hinge_point = self.hinges(opening)
        joint_fields = self.joints.block_fields(st.body_q, body, r, status, opening)
        support_q = st.body_q[n:].copy()
        return Frame(
            step=st.step,
            time=st.time,
            block_q=st.body_q[:n].copy(),
            block_v=st.body_v[:n].copy(),
            support_q=support_q,
            support_v=st.body_v[n:, :2].copy(),
            support_force=np.array(support_force, copy=True),
            contact_body=np.array(body, copy=True),
            contact_point=np.array(point, copy=True),
            contact_normal=np.array(normal, copy=True),
            contact_force=np.array(force, copy=True),
            contact_gap=np.array(gap, copy=True),
            contact_status=np.array(status, copy=True),
            contact_mobilised=mobilised,
            tensors=self.tensors.fields() | joint_fields,
            energy_kinetic=float(kinetic),
            energy_potential=float(potential),
            energy_dissipated=self.energy_dissipated,
            support_work=self.support_work,
            nlgs_iterations=int(iterations),
            nlgs_residual=float(residual),
            contact_count=int(c),
            joint_body=self.joints.joint_body,
            joint_hinged=hinged,
            hinge_point=hinge_point,
            nlgs_unconverged=self.unconverged,
        )

    def hinges(self, opening: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(J,) hinged flags of the joints after the last step, and (H, 2) the hinge points (``opening``:
        the joint ends' openings in the current state, if already computed)."""
        s = self.solver
        hinged = self.joints.hinged(self.state.body_q, s.contact_body, s.contact_r[:, 1], self.model.dt, opening)
        return hinged, self.joints.hinge_points(s.contact_body, s.contact_point, s.contact_r[:, 1], hinged)

    def diverged(self) -> str:
        """Empty string, or why the state is no longer physical (from the last step's top block speed)."""
        if self.last is None:
            return ""
        speed = self.last.max_block_speed
        if not math.isfinite(speed):
            return "non-finite block position or velocity"
        if speed > DIVERGENCE_SPEED and (speed := self._speed_of_blocks_not_falling_clear()) > DIVERGENCE_SPEED:
            return f"a block reached {speed:.3g} m/s (> {DIVERGENCE_SPEED:g} m/s)"
        return ""

    def _speed_of_blocks_not_falling_clear(self) -> float:
        """The top speed |v| (m/s) of the blocks that are not falling clear of the model: a block wholly below
        every support's lowest point has nothing left to land on and falls freely, g·t faster each second
        (a shaken wall's stone walked off the ground's end at t ≈ 140 s and reached 1000 m/s 100 s later:
        'diverged' at t = 243 s, where the state was physical). Asked only once the top speed passed
        DIVERGENCE_SPEED, so no block loop runs in an ordinary step."""
        m, q, v = self.model, self.state.body_q, self.state.body_v
        blocks = m.block_count
        # supports translate only: a support vertex's height is its body's y plus its local y
        floor = (
            min(
                q[s, 1] + m.vert_local[m.body_vert_start[s] : m.body_vert_start[s + 1], 1].min()
                for s in range(blocks, blocks + m.support_count)
            )
            if m.support_count
            else -np.inf  # no support: nothing to fall clear of, every block is watched
        )
        clear = q[:blocks, 1] + m.body_radius[:blocks] < floor
        speed = np.hypot(v[:blocks, 0], v[:blocks, 1])
        return float(speed[~clear].max()) if (~clear).any() else 0.0


def simulate(
    scenario,
    sinks=(),
    on_progress: Callable | None = None,
    progress_every: int = 10,
    steps: int | None = None,
    sim: Simulation | None = None,
    stop_at_collapse: bool = False,
    stop: Callable[[], bool] | None = None,
) -> RunResult:
    """Run ``scenario`` to its end (or ``steps`` steps), handing every recorded frame to each sink's
    ``on_frame``, and a sink with ``log_step`` gets ``log_step(step, time, stats)`` after every step (solver
    health is cheap to keep for each step). Sinks are *not* closed here (the caller owns them).

    ``on_progress(sim, step_stats)`` is called every ``progress_every`` steps. ``stop()`` is polled after
    every step; when it is true the run ends "interrupted" after recording the state it reached. Pass
    ``sim`` to run an already built :class:`Simulation` (the caller needed its model or triangles first).
    ``stop_at_collapse`` ends the run at the first step where the structure has collapsed
    (:mod:`masonrycli.analysis.collapse`); the status stays "completed" and the message says so.
    """
    t0 = _time.perf_counter()
    sim = Simulation(scenario) if sim is None else sim
    m = sim.model
    n_steps = m.n_steps if steps is None else min(steps, m.n_steps)
    every = scenario.run.record_every
    tally = SolverTally(scenario.run.max_iterations)
    max_pen = 0.0
    e0 = sum(sim.energies())
    frames = 0

    failed_sink = None
    abandoned = False

    def emit(first: bool = False) -> bool:
        """Hand the current frame to every sink; False (and ``failed_sink`` set) if one cannot write, False
        and ``abandoned`` when a stop signal came while the frame's kernels compiled (none is handed on).
        The ``first`` frame (t = 0) is never abandoned: a history without one is no history."""
        nonlocal frames, failed_sink, abandoned
        if not sinks:  # a frame costs contact copies, tensors and joint states: build it only for a reader
            return True
        frame = sim.frame() if first else _abandonable(sim.frame)
        if frame is None:
            abandoned = True
            return False
        for sink in sinks:
            try:
                sink.on_frame(frame)
            except OSError as exc:
                failed_sink = (sink, exc)
                return False
        frames += 1
        return True

    per_step = [sink.log_step for sink in sinks if hasattr(sink, "log_step")]
    status, message = COMPLETED, ""
    done = 0
    before = sim.state.copy()
    ok = emit(first=True)
    for k in range(n_steps if ok else 0):
        stats = _step(sim, before)
        if stats is None:  # a stop signal during the step's numba compilation (interrupt.py): the step before
            abandoned = True
            break
        tally.add(stats)
        max_pen = max(max_pen, stats.max_penetration)
        done = k + 1
        for log_step in per_step:
            log_step(done, sim.state.time, stats)
        why = sim.diverged()
        recorded = done % every == 0 or done == n_steps
        if why:
            status, message = DIVERGED, f"diverged at t = {sim.state.time:.4f} s (step {done}): {why}"
            ok = emit()
            break
        if recorded and not emit():
            ok = False
            break
        if on_progress is not None and (done % progress_every == 0 or done == n_steps):
            on_progress(sim, stats)
        if stop_at_collapse and sim.monitor.collapse_time is not None:
            message = f"stopped at collapse, t = {sim.state.time:.4f} s (step {done} of {n_steps})"
            ok = recorded or emit()
            break
        if stop is not None and stop() and done < n_steps:
            status, message = INTERRUPTED, f"interrupted at t = {sim.state.time:.4f} s (step {done} of {n_steps})"
            ok = recorded or emit()
            break
    if abandoned and status == DIVERGED:
        pass  # said so; its last frame is the one before
    elif abandoned:
        status, message = (
            INTERRUPTED,
            (
                f"interrupted at t = {sim.state.time:.4f} s (step {done} of {n_steps}) while numba compiled the run's"
                " kernels"
            ),
        )
    elif not ok:
        sink, exc = failed_sink
        status, message = FAILED, f"stopped at t = {sim.state.time:.4f} s (step {done}): {exc.strerror or exc}"
    extra: dict[str, str] = {}
    hinge_count = 0
    # an abandoned step may have overwritten the contacts the hinges are read from
    if sim.last is not None and sim.joints.key.size and not abandoned:
        hinged, _ = sim.hinges()
        hinge_count = int(hinged.sum())
        extra["hinged joints (end)"] = describe_hinges(m.joint_names(sim.joints.joint_body[hinged]))
    # Stopped by the user: measure what was applied (the whole run's loading can be 10⁸ samples, minutes
    # of work after a Ctrl-C that should end the run at once).
    # Ended early otherwise (diverged: 'simulate wall --duration 1e5' at step 243 406 of 10⁸, then over
    # 10 minutes of eqsig's per-sample loop, deaf to signals), the same: what was applied up to the end.
    ims = applied_intensity(scenario, m, done if status in (INTERRUPTED, DIVERGED, FAILED) else None)
    if ims:
        extra[f"ground motion ({m.support_name[shaking_support(scenario.motions)]})"] = describe_intensity(ims)
    outcome = run_outcome(sim, hinge_count)
    extra["state"] = describe_outcome(outcome)
    if sim.monitor.n:  # the response during the shaking, which the state's residual values do not show
        extra["peak drift"] = describe_peak_drift(outcome["peak_drift"], sim.monitor.height)
    return RunResult(
        status=status,
        message=message,
        steps=done,
        time=sim.state.time,
        wall_time=_time.perf_counter() - t0,
        tally=tally,
        max_penetration=max_pen,
        energy_initial=e0,
        energy_final=float(sum(sim.energies())),
        energy_dissipated=sim.energy_dissipated,
        support_work=sim.support_work,
        frames=frames,
        unconverged=sim.unconverged,
        solver=m.solver,
        extra=extra,
        intensity=ims,
        outcome=outcome,
        failed_sink=failed_sink[0] if failed_sink else None,
    )


def _step(sim: Simulation, before) -> StepStats | None:
    """``sim.step()``, or None when a stop signal abandoned it (:class:`~masonrycli.interrupt.StopStep`): the
    state is then put back as it was before the step (``before``: a :class:`State` the size of the
    state's, overwritten here), so the run's last state is one the solver reached whole. Copying two (B, 3)
    arrays costs ~1 µs a step, against the ~0.5 ms of a step of the 51-block wall."""
    np.copyto(before.body_q, sim.state.body_q)
    np.copyto(before.body_v, sim.state.body_v)
    before.step, before.time = sim.state.step, sim.state.time
    stats = _abandonable(sim.step)
    if stats is None:
        np.copyto(sim.state.body_q, before.body_q)
        np.copyto(sim.state.body_v, before.body_v)
        sim.state.step, sim.state.time = before.step, before.time
    return stats


def _abandonable(work):
    """``work()``, or None when a stop signal abandoned it while numba compiled (interrupt.StopStep)."""
    try:
        with abandonable():
            try:
                return work()
            except Exception:
                raise_dropped()  # the StopStep that Python dropped inside numba's compiler caused this error
                raise
    except StopStep:
        return None


def run_outcome(sim: Simulation, hinges: int) -> dict:
    """The structure's state and the indicators behind it (:mod:`masonrycli.analysis.collapse`): ``state``,
    ``collapse_time`` (s, NaN if none), ``collapse_reason``, ``residual_drift`` and ``peak_drift``
    (× height), ``max_opening`` (m), ``max_displacement`` (m, the largest block's relative to the
    shaking ground: damage beyond 5 mm), ``hinges``, ``slide_time`` / ``rock_time`` (s, NaN if none),
    ``max_slide_speed`` (m/s), ``max_rock_speed`` (rad/s)."""
    mon, q = sim.monitor, sim.state.body_q
    opening = sim.joints.opening(q) if sim.joints.key.size else np.zeros(0)
    max_opening = float(np.maximum(opening, 0.0).max()) if opening.size else 0.0
    nan = float("nan")
    return {
        "state": mon.state(q, hinges, max_opening),
        "collapse_time": nan if mon.collapse_time is None else mon.collapse_time,
        "collapse_reason": mon.collapse_reason,
        "residual_drift": mon.drift(q) / mon.height,
        "peak_drift": mon.peak_drift,
        "max_opening": max_opening,
        "max_displacement": mon.max_block_displacement(q),
        "hinges": hinges,
        "slide_time": nan if mon.slide_time is None else mon.slide_time,
        "rock_time": nan if mon.rock_time is None else mon.rock_time,
        "max_slide_speed": mon.max_slide_speed,
        "max_rock_speed": mon.max_rock_speed,
    }


def applied_intensity(scenario, model: Model, steps: int | None = None) -> dict[str, float]:
    """Intensity measures of the shaking support's horizontal velocity over the run's duration (the
    loading as applied: scaled, windowed, corrected, cut at the duration — whether or not the run
    stopped early, so the measure belongs to the loading, not to the response), or {} when no
    support shakes. ``steps``: over the first ``steps`` steps only (a run that ended early: stopped, diverged, failed)."""
    j = shaking_support(scenario.motions)
    steps = model.n_steps if steps is None else steps
    if j is None or steps < 2:
        return {}
    return intensity_measures(model.support_velocity.between(0, steps + 1)[:, j, 0], model.dt)
