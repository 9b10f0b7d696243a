"""A trajectory sample: every k-th step of one run, kept as the engine's solver saw it.

    python -m benchmarks.solver_lab trajectory --case wall-248 [--every 5] [--duration 1] [--name DIR]

Runs a case of :mod:`benchmarks.solver_cases` with the engine's default solver and, from outside the
engine (``dispatch.solve`` wrapped, as ``capture.py``), keeps the input of every ``every``-th step in
``data/trajectory/<case>/step-NNNN.npz`` (``--name``: another directory than the case's):

    body (C, 2), pack (C, PACK_WIDTH)   the contacts as dispatch.solve got them
    v_free (B, 3), r_warm (C, 2), mu    the step's free velocities, warm start, friction
    r_prev2 (C, 2), has_prev2 (C,)      the impulses of the step before the warm start's, by contact key
                                        (0 / False where the contact did not exist then): for predictions
    point (C, 2)                        the contact points (m), for sweep orders by position
    step, sweeps, stalled               the engine's sweep units on that step, and whether stalled.py had
                                        to finish it (momentum stalled: not an "ordinary" step)

and the engine's sweep units and stalled flag of every step in ``steps.json``. The sample's steps are
solved again by :mod:`benchmarks.solver_lab.ordinary`.
"""

from __future__ import annotations

import json
import time

import numpy as np

from benchmarks.solver_cases import make_scenario
from benchmarks.solver_lab.capture import _align
from benchmarks.solver_lab.problems import DATA
from masonrycli.engine import dispatch, stalled
from masonrycli.engine.tuning import TUNING, Tuning
from masonrycli.run import Simulation

TRAJECTORY = DATA / "trajectory"


def capture(case: str, every: int, duration: float | None, name: str | None = None, tuning: Tuning = TUNING) -> None:
    """Run ``case`` with the engine's ``tuning`` and keep every ``every``-th step (module doc) in
    ``data/trajectory/<name or case>``."""
    out = TRAJECTORY / (name or case)
    out.mkdir(parents=True, exist_ok=True)
    for old in out.glob("step-*.npz"):
        old.unlink()
    sim = Simulation(make_scenario(case, duration), tuning=tuning)
    solver = sim.solver
    solve, finish = dispatch.solve, stalled.continue_stalled
    # The sorted keys and impulses of the last two steps: hist[1] the warm start's step, hist[0] the one before.
    hist = [(np.empty(0, np.int64), np.empty((0, 2))), (np.empty(0, np.int64), np.empty((0, 2)))]
    steps: list[tuple[int, bool]] = []
    flag = [False]

    def watched_finish(*args, **kwargs):
        flag[0] = True
        return finish(*args, **kwargs)

    def watched(contact_body, pack, count, model, v, r, status, tuning=TUNING):
        step = len(steps) + 1
        keep = step % every == 0 or step == 1
        if keep:
            key = solver.buffers.contact_key[:count].copy()
            r_prev2, has2 = _align(key, *hist[0])
            kept = dict(
                body=contact_body[:count].copy(),
                pack=pack[:count].copy(),
                v_free=v.copy(),
                r_warm=r[:count].copy(),
                r_prev2=r_prev2,
                has_prev2=has2,
                mu=model.friction,
                point=solver.buffers.contact_point[:count].copy(),
            )
        flag[0] = False
        its, res = solve(contact_body, pack, count, model, v, r, status, tuning)
        steps.append((int(its), flag[0]))
        if keep:
            np.savez(out / f"step-{step:04d}.npz", step=step, sweeps=its, stalled=flag[0], **kept)
        key = solver.buffers.contact_key[:count]
        order = np.argsort(key, kind="stable")
        hist[0], hist[1] = hist[1], (key[order].copy(), r[:count][order].copy())
        return its, res

    dispatch.solve, stalled.continue_stalled = watched, watched_finish
    t = time.process_time()
    try:
        for _ in range(sim.model.n_steps):
            solver.step(sim.state)
    finally:
        dispatch.solve, stalled.continue_stalled = solve, finish
    took = time.process_time() - t
    sweeps = np.array([s for s, _ in steps])
    stalls = [i + 1 for i, (_, st) in enumerate(steps) if st]
    summary = {"case": case, "every": every, "sweeps": sweeps.tolist(), "stalled": stalls}
    (out / "steps.json").write_text(json.dumps(summary))
    ordinary = np.array([s for s, st in steps if not st])
    print(
        f"{case}: {len(steps)} steps in {took:.1f} s CPU, {sweeps.sum()} sweep units (mean {sweeps.mean():.0f},"
        f" max {sweeps.max()}); {len(stalls)} stalled steps take {sweeps.sum() - ordinary.sum()} of them,"
        f" the {ordinary.size} ordinary ones {ordinary.sum()} (mean {ordinary.mean():.0f}, median"
        f" {np.median(ordinary):.0f}, 90th pct {np.percentile(ordinary, 90):.0f}); kept"
        f" {len(list(out.glob('step-*.npz')))} steps in {out}",
        flush=True,
    )
