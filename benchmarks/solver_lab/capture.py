"""Capture the lab's problems: run each case at its default solver settings and keep three steps.

    cold     step 1: no warm start (every impulse 0)
    typical  step TYPICAL_STEP (0.3 s into the shaking, before the walls crack)
    hard     the step whose NLGS took the most sweeps from step HARD_FROM on (the latest of equals: once
             the walls crack and rock), i.e. the worst the run met after its start

The run uses the engine's default solver unless ``--solver`` says otherwise (then the problems' names end
in ``-<solver>``): its trajectory, and its hardest step, are that solver's. The run is driven from
outside: ``dispatch.solve`` is wrapped and the problem copied just before the solve (see ``problems.py``).
Then each kept problem gets its tight reference solution and is written to ``data/<name>.npz``.
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.solver_lab import law
from benchmarks.solver_lab.problems import DATA, REF_CAP, REF_RESIDUAL, Problem
from masonrycli.engine import dispatch
from masonrycli.run import Simulation
from masonrycli.scenario.motion import Constant, Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

SINE = Sine(direction=(1.0, 0.0), amplitude=1.0, frequency=2.0)
SETTLE = Constant(velocity=(0.0, -0.01))
TYPICAL_STEP = 300
HARD_FROM = 20
DEFAULT_SOLVER = "nlgs-accel"
"""The trajectory (and the "hard" step: the one *this* solver found hardest) is the run's solver's: the
float64 accelerated solver, the one the lab's methods are measured against (the engine's default since 28
Nov 2026, "nlgs-accel32", starts each step in float32)."""


def _wall(courses: int) -> dict:
    # running bond, 15 full blocks in odd courses, 14 + two halves in even ones
    return {"blocks": 15 * courses + courses // 2, "courses": courses}


CASES = {
    # name: (builder, options, simulated seconds captured, motions) — walls are C courses × 15 blocks
    "wall-8": ("wall", _wall(8), 0.6, {"ground": SINE}),
    "wall-16": ("wall", _wall(16), 0.6, {"ground": SINE}),
    "wall-32": ("wall", _wall(32), 0.6, {"ground": SINE}),
    "wall-64": ("wall", _wall(64), 0.6, {"ground": SINE}),
    "arch": ("arch", {}, 0.6, {"right-foundation": SETTLE}),
    "aqueduct-shaken": ("aqueduct", {}, 0.6, {"left-foundation": SINE, "right-foundation": SINE}),
}


def _align(key, prev_key, prev_r):
    """prev_r re-ordered to ``key`` (prev_key sorted); (r, found mask)."""
    r = np.zeros((key.size, 2))
    if prev_key.size == 0:
        return r, np.zeros(key.size, dtype=bool)
    pos = np.minimum(np.searchsorted(prev_key, key), prev_key.size - 1)
    hit = prev_key[pos] == key
    r[hit] = prev_r[pos[hit]]
    return r, hit


def reference(problem: Problem) -> None:
    """Engine NLGS continued in growing chunks until the contact-law residual ≤ REF_RESIDUAL m/s."""
    pack = problem.pack()
    H = law.h_matrix(problem, pack)
    c = problem.count
    r = problem.r_warm.copy()
    status = np.zeros(c, dtype=np.int8)
    sweeps, chunk = 0, 500
    while True:
        v = problem.v_free.copy()
        its, _ = dispatch.solve(problem.body, pack, c, problem.shim(0.0, chunk), v, r, status)
        sweeps += its
        res = float(law.law_residual(problem, pack, H, v, r).max(initial=0.0))
        if res <= REF_RESIDUAL or sweeps >= REF_CAP:
            break
        chunk = min(2 * chunk, 20_000)
    problem.v_ref, problem.r_ref, problem.ref_sweeps, problem.ref_residual = v, r, sweeps, res


def capture_case(case: str, solver: str = DEFAULT_SOLVER) -> tuple[list[Problem], int]:
    """The cold, typical and hard problems of ``case`` run with ``solver`` (named ``<case>-<kind>``, with
    ``-<solver>`` appended for a solver other than the default), without references; and the run's number of
    unconverged steps."""
    builder, options, duration, motions = CASES[case]
    sc = scenario_from_builder(builder, options, RunConfig(duration=duration, solver=solver), Material(), motions)
    kept, unconverged = capture_run(Simulation(sc), TYPICAL_STEP)
    suffix = "" if solver == DEFAULT_SOLVER else f"-{solver}"
    for kind, p in kept.items():
        p.name = f"{case}-{kind}{suffix}"
    return [kept[k] for k in ("cold", "typical", "hard") if k in kept], unconverged


def capture_run(sim: Simulation, typical_step: int) -> tuple[dict[str, Problem], int]:
    """Step ``sim`` to its end with ``dispatch.solve`` wrapped; ({"cold", "typical", "hard"} → problem, the number
    of steps whose solve ended above its tolerance)."""
    solver, m = sim.solver, sim.model
    hist = [(np.empty(0, np.int64), np.empty((0, 2))), (np.empty(0, np.int64), np.empty((0, 2)))]
    kept: dict[str, Problem] = {}
    hard_sweeps = -1
    unconverged = 0
    original = dispatch.solve

    def snapshot(count, v, r) -> Problem:
        bf = solver.buffers
        key = bf.contact_key[:count].copy()
        r_prev2, has2 = _align(key, *hist[0])
        z = np.zeros(0)
        return Problem(
            name="",
            body=bf.contact_body[:count].astype(np.int32),
            point=bf.contact_point[:count].copy(),
            normal=bf.contact_normal[:count].copy(),
            gap=bf.contact_gap[:count].copy(),
            key=key,
            q_m=solver.body_q_m.copy(),
            inv_mass=m.body_inv_mass.copy(),
            inv_inertia=m.body_inv_inertia.copy(),
            radius=m.body_radius.copy(),
            v_free=v.copy(),
            v_n=solver.body_v_n.copy(),  # v_n: the velocities the step began with (θ-update)
            r_warm=r[:count].copy(),
            r_prev2=r_prev2,
            has_prev2=has2,
            mu=float(m.friction),
            dt=float(m.dt),
            step=sim.state.step + 1,
            engine_sweeps=0,
            v_ref=z,
            r_ref=z,
            ref_sweeps=0,
            ref_residual=np.nan,
        )

    def hooked(contact_body, pack, count, model, v, r, status, *args, **kwargs):
        nonlocal hard_sweeps, unconverged
        prob = snapshot(count, v, r)
        its, res = original(contact_body, pack, count, model, v, r, status, *args, **kwargs)
        prob.engine_sweeps = int(its)
        unconverged += bool(res > model.tolerance)
        if prob.step == 1:
            kept["cold"] = prob
        elif prob.step == typical_step:
            kept["typical"] = prob
        if prob.step >= HARD_FROM and its >= hard_sweeps:
            hard_sweeps = its
            kept["hard"] = prob
        key = solver.buffers.contact_key[:count]
        order = np.argsort(key, kind="stable")
        hist[0], hist[1] = hist[1], (key[order].copy(), r[:count][order].copy())
        return its, res

    dispatch.solve = hooked
    try:
        for _ in range(m.n_steps):
            solver.step(sim.state)
    finally:
        dispatch.solve = original
    return kept, unconverged


def capture(cases: list[str], solver: str = DEFAULT_SOLVER) -> None:
    DATA.mkdir(exist_ok=True)
    for case in cases:
        t = time.perf_counter()
        probs, unconverged = capture_case(case, solver)
        took = time.perf_counter() - t
        print(
            f"{case}: ran {CASES[case][2]:g} s with {solver} in {took:.1f} s, {unconverged} unconverged steps",
            flush=True,
        )
        for p in probs:
            t = time.perf_counter()
            reference(p)
            p.save(DATA / f"{p.name}.npz")
            print(
                f"  {p.name}: step {p.step}, {p.count} contacts, {p.blocks} blocks, engine {p.engine_sweeps} sweeps;"
                f" reference {p.ref_sweeps} sweeps, residual {p.ref_residual:.1e} m/s ({time.perf_counter() - t:.1f} s)",
                flush=True,
            )
