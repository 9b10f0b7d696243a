"""Where an ordinary step's sweeps go: the tail near the tolerance, and what it buys.

    python -m benchmarks.solver_lab trajectory --case h64 --every 10 --duration 0.5 --name rs-h64
    python -m benchmarks.solver_lab tail --sample rs-h64 [--levels 3e-5 2e-5 1.5e-5]

Each ordinary step of ``data/trajectory/SAMPLE`` (those the run's first stage converged without handing
them to stalled.py) is solved again from its kept warm start by the lab's copy of the first stage with the
engine's parameters (:mod:`benchmarks.solver_lab.ordinary`: float64 momentum in 4 runs, stall window 500),
with its residual history. Per step:

    at LEVEL   sweeps to the first in-sweep residual ≤ LEVEL (then ≤ the tolerance: the step's sweeps)
    own        sweeps until the iterate's own law residual ≤ the tolerance (ordinary's check after every
               sweep, the checks not counted): the in-sweep residual is taken at extrapolated points
    restarts   sweeps whose in-sweep residual grew by more than the restart factor (momentum's RESTART_GROWTH)
    error      RMS over the blocks of |Δv| (translations, m/s) from the tight solve's velocities
               (ordinary.references), at each level's iterate (the solve stopped after that many sweeps;
               the same path, it is deterministic) and at the end

Printed per sample: the sums and medians of those sweep counts, the restarts, the mean and median errors.
What it showed on the height suite's walls: benchmarks/JOURNAL.md, "The tall walls' ordinary steps: a tail".
"""

from __future__ import annotations

import numpy as np

from benchmarks.solver_lab.ordinary import CAP, TOLERANCE, Step, references
from benchmarks.solver_lab.trajectory import TRAJECTORY
from masonrycli.engine import momentum

LEVELS = (3e-5, 2e-5, 1.5e-5)
NO_STALL = 10**9
"""The check variant runs without a stall window: only the iterate's own residual stops it (or the cap)."""


def first_at(history: np.ndarray, level: float) -> int:
    """Sweeps until the in-sweep residual is first ≤ ``level`` (the whole history's length if never)."""
    hit = np.flatnonzero(history <= level)
    return int(hit[0]) + 1 if hit.size else history.size


def block_error(step: Step, v: np.ndarray) -> float:
    """m/s: RMS over the blocks of the translation velocity's distance from the tight solve's."""
    d = (v - step.v_ref)[step.blocks, :2]
    return float(np.sqrt((d**2).sum(axis=1).mean()))


def step_tail(step: Step, levels=LEVELS) -> dict:
    """The figures of one step (module doc)."""
    history = np.zeros(CAP)
    n, res, v, _ = step.solve({}, history=history)
    history = history[:n]
    at = [min(first_at(history, lv), n) for lv in levels]
    errors = [block_error(step, step.solve({}, cap=k)[2]) for k in at] + [block_error(step, v)]
    checked = np.zeros(CAP + 1)
    its, own_res, _, _ = step.solve({"check": np.inf}, stall=NO_STALL, history=checked)
    own = int(its - checked[-1]) if own_res <= TOLERANCE else -1
    restarts = int((history[1:] > momentum.RESTART_GROWTH * history[:-1]).sum())
    return dict(step=step.step, sweeps=n, converged=res <= TOLERANCE, at=at, own=own, restarts=restarts, errors=errors)


def table(sample: str, levels=LEVELS) -> list[dict]:
    """Run :func:`step_tail` on the sample's ordinary steps and print the summary (module doc)."""
    steps = [Step(p) for p in sorted((TRAJECTORY / sample).glob("step-*.npz"))]
    steps = [s for s in steps if not s.stalled]
    references(sample, steps)
    rows = [step_tail(s, levels) for s in steps]
    sweeps = np.array([r["sweeps"] for r in rows])
    at = np.array([r["at"] for r in rows])
    own = np.array([r["own"] for r in rows])
    err = np.array([r["errors"] for r in rows])
    heads = [f"≤ {lv:g}" for lv in levels] + [f"≤ {TOLERANCE:g} (the step)"]
    print(
        f"{sample}: {len(rows)} ordinary steps, {sum(not s.ref_ok for s in steps)} references above their"
        f" tolerance, {sum(not r['converged'] for r in rows)} not converged; restarts {sum(r['restarts'] for r in rows)}"
        f" ({sweeps.sum() / max(1, sum(r['restarts'] for r in rows)):.0f} sweeps apart)"
    )
    print("| in-sweep residual | sweeps Σ | median | velocity error mean / median (m/s) |")
    print("|---|---|---|---|")
    for k, head in enumerate(heads):
        col = at[:, k] if k < len(levels) else sweeps
        print(f"| {head} | {col.sum()} | {np.median(col):.0f} | {err[:, k].mean():.2e} / {np.median(err[:, k]):.2e} |")
    ok = own >= 0
    print(
        f"own law residual ≤ {TOLERANCE:g}: Σ {own[ok].sum()} sweeps, median {np.median(own[ok]):.0f}"
        f" ({(~ok).sum()} steps not reached), against the step's {sweeps[ok].sum()}"
    )
    return rows
