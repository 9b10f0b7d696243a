"""Stalled steps: capture the steps whose accelerated solve stalls, and run each method alone on them.

    python -m benchmarks.solver_lab stalled capture [--cases h16 h32 h64] [--duration 0.2]
    python -m benchmarks.solver_lab stalled table

``capture`` runs each case of :mod:`benchmarks.solver_cases` with the default solver and keeps the input
of every step that :mod:`masonrycli.engine.stalled` had to finish (dispatch.solve's arguments as the engine
passed them: body pairs, packed rows, v_free, warm start), in ``data/stalled/<case>-<step>.npz``.
``table`` solves each kept step from its warm start with the engine's ``dispatch.solve`` and with each
method alone, to the engine's tolerance and cap, and prints sweep units, CPU ms (minimum of --repeat) and
whether the tolerance was met:

    engine        dispatch.solve as shipped (momentum, then stalled.py's round-robin)
    turning       accelerated sweeps whose direction turns at every restart, no stall window
    momentum      accelerated sweeps with no stall window
    alternating   plain sweeps, every second one in reverse order (10 000-sweep stall window)
    plain         plain sweeps in one direction (10 000-sweep stall window)
    faces         faces from momentum's iterate at its 500-sweep stall
    newton        stalled.py's Alart–Curnier resume (Newton steps, then turning sweeps) with the whole cap

``table --methods engine --cap 100000`` gives the engine alone at its default cap (the figure of benchmarks/JOURNAL.md, "Alart–Curnier in the
engine": 101 kept steps of h32 and h64).

(Faces' sweep units cost ~2× a point sweep's time; compare the ms.) The figures of stalled.py's module doc
and of benchmarks/JOURNAL.md, "Stalled steps", come from here.
"""

from __future__ import annotations

import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from benchmarks.solver_cases import make_scenario
from benchmarks.solver_lab.problems import DATA, Problem
from masonrycli.engine import dispatch, faces, interleaved, nlgs, stalled
from masonrycli.engine.tuning import TUNING, Tuning
from masonrycli.run import Simulation, simulate

STALLED = DATA / "stalled"
TOLERANCE, CAP = 1e-5, 50_000


def capture(cases: list[str], duration: float, tuning: Tuning = TUNING) -> None:
    """Run ``cases`` for ``duration`` simulated s with the engine's ``tuning``; write the input of each step
    stalled.py finished."""
    STALLED.mkdir(parents=True, exist_ok=True)
    for case in cases:
        steps, kept = _capture_case(case, duration, tuning)
        print(f"{case}: {steps} steps, {len(kept)} stalled: {' '.join(kept)}", flush=True)


def _capture_case(case: str, duration: float, tuning: Tuning = TUNING) -> tuple[int, list[str]]:
    solve, finish = dispatch.solve, stalled.continue_stalled
    step, pending, kept = [0], {}, []

    def watched(contact_body, pack, count, model, v, r, status, tuning=TUNING):
        pending.update(body=contact_body[:count].copy(), pack=pack[:count].copy(), v_free=v.copy())
        pending.update(r_warm=r[:count].copy(), mu=model.friction, stalled=False)
        out = solve(contact_body, pack, count, model, v, r, status, tuning)
        if pending["stalled"]:
            path = STALLED / f"{case}-{step[0]}.npz"
            np.savez(path, **{k: val for k, val in pending.items() if k != "stalled"})
            kept.append(path.name)
        step[0] += 1
        return out

    def marked(*args):
        pending["stalled"] = True
        return finish(*args)

    dispatch.solve, stalled.continue_stalled = watched, marked
    try:
        sc = make_scenario(case, duration)
        simulate(sc, [], sim=Simulation(sc, tuning=tuning))
    finally:
        dispatch.solve, stalled.continue_stalled = solve, finish
    return step[0], kept


def _method(name, p, v, r, status, cap=CAP):
    body, pack, mu, count = p["body"], p["pack"], float(p["mu"]), p["body"].shape[0]
    if name == "engine":
        model = SimpleNamespace(friction=mu, tolerance=TOLERANCE, max_iterations=cap, solver="nlgs-accel")
        return dispatch.solve(body, pack, count, model, v, r, status)
    if name == "faces":
        its, res = dispatch.first_stage(body, pack, count, mu, TOLERANCE, cap, v, r, status, TUNING.first_stall)
        if res <= TOLERANCE:
            return its, res
        units, res = faces.face_sweeps(body, pack, count, mu, TOLERANCE, cap - its, v, r, status)
        return its + units, res
    if name == "plain":
        return interleaved.sweeps(body, pack, count, mu, TOLERANCE, cap, v, r, status, interleaved.PLAIN)
    # turning, momentum, alternating, newton: stalled.py's own resume, from the warm start, with the whole cap
    state = stalled._State(None, r, status, np.inf)
    its = stalled._resume(name, state, body, pack, count, mu, TOLERANCE, cap, v.copy(), cap, TUNING)
    v[:] = state.v
    return its, state.residual


class StalledProblem(Problem):
    """A kept stalled step as a lab :class:`Problem` (``table --problems stalled/h32-80``): the engine's own
    packed rows stand in for the geometry, which the stalled capture does not keep."""

    stored_pack: np.ndarray | None = None

    def pack(self) -> np.ndarray:
        return self.stored_pack


def as_problem(path: Path) -> StalledProblem:
    """The step at ``path`` for the harness. Body inverse masses and inertias are read back from the packed
    rows (bodies in no contact: 0, their velocity is v_free anyway); there is no reference (the engine's
    capped solves are the point of these steps): v_ref is NaN, so the table's velocity error reads nan."""
    z = dict(np.load(path))
    body, pack, v_free = z["body"].astype(np.int32), z["pack"], z["v_free"]
    n, c = v_free.shape[0], body.shape[0]
    inv_mass, inv_inertia = np.zeros(n), np.zeros(n)
    for side, (im, ii) in enumerate(((nlgs.P_IMA, nlgs.P_IIA), (nlgs.P_IMB, nlgs.P_IIB))):
        inv_mass[body[:, side]] = pack[:, im]
        inv_inertia[body[:, side]] = pack[:, ii]
    nan = np.full((n, 3), np.nan)
    p = StalledProblem(
        name=f"stalled/{path.stem}",
        body=body,
        point=np.zeros((c, 2)),
        normal=np.zeros((c, 2)),
        gap=np.zeros(c),
        key=np.arange(c),
        q_m=np.zeros((n, 3)),
        inv_mass=inv_mass,
        inv_inertia=inv_inertia,
        radius=np.zeros(n),
        v_free=v_free,
        v_n=v_free.copy(),
        r_warm=z["r_warm"],
        r_prev2=z["r_warm"],
        has_prev2=np.zeros(c, bool),
        mu=float(z["mu"]),
        dt=1e-3,
        step=int(path.stem.rsplit("-", 1)[1]),
        engine_sweeps=-1,
        v_ref=nan,
        r_ref=np.full((c, 2), np.nan),
        ref_sweeps=0,
        ref_residual=np.nan,
    )
    p.stored_pack = pack
    return p


METHODS = ("engine", "turning", "momentum", "alternating", "plain", "faces", "newton")


def table(paths: list[Path] | None = None, repeat: int = 2, methods=METHODS, cap: int = CAP) -> None:
    """Each kept step solved by each of ``methods`` from its warm start, to ``cap`` sweep units: sweep units
    (* = tolerance missed), CPU ms."""
    paths = paths or sorted(STALLED.glob("*.npz"))
    print("| step | contacts | " + " | ".join(methods) + " |")
    print("|---|---|" + "---|" * len(methods))
    totals = {m: [0, 0.0, 0] for m in methods}
    for path in paths:
        p = dict(np.load(path))
        cells = []
        for m in methods:
            best = np.inf
            for _ in range(repeat):
                v, r = p["v_free"].copy(), p["r_warm"].copy()
                status = np.zeros(r.shape[0], dtype=np.int8)
                t = time.process_time()
                its, res = _method(m, p, v, r, status, cap)
                best = min(best, 1e3 * (time.process_time() - t))
            met = res <= TOLERANCE
            totals[m][0] += its
            totals[m][1] += best
            totals[m][2] += not met
            cells.append(f"{its}{'' if met else '*'} ({best:.0f} ms)")
        print(f"| {path.stem} | {p['body'].shape[0]} | " + " | ".join(cells) + " |", flush=True)
    total = [f"{u} ({ms:.0f} ms, {miss} missed)" for u, ms, miss in totals.values()]
    print(f"| all {len(paths)} | | " + " | ".join(total) + " |")
