"""First-stage variants in whole runs: what a variant's per-step savings become once its own trajectory and
warm starts follow.

    python -m benchmarks.solver_lab ordinary-runs --cases wall-248 … [--variants NAME …] [--duration 1]

A kept step (``ordinary.py``) starts from the warm start of the engine's own run; a variant that stops its
steps at another iterate hands the next step another warm start, and moves the trajectory. So each variant
also runs the whole case: ``dispatch.solve`` is replaced by the lab kernel of ``ordinary.py`` with the variant's
parameters on the engine's interleaved order (the engine's parameters give the engine's run, checked by
the "engine" row), and a step it leaves stalled goes on by the engine's ``stalled.continue_stalled`` as in
``dispatch.solve``. Reported: total sweep units, mean and max per step, unconverged steps, and the top-course /
mean slip at 0.1 and 0.2 s against the tight solve of ``bench_solver`` (plain NLGS at 1e-7 m/s, cap 20 000;
computed once and kept in ``data/trajectory/<case>/tight.json``).
"""

from __future__ import annotations

import json

import numpy as np

from benchmarks.bench_solver import TIGHT, errors_pct, run_masonry
from benchmarks.solver_lab.capture import _align
from benchmarks.solver_lab.ordinary import ENGINE, STALL, VARIANTS, _accelerated, kernel_args
from benchmarks.solver_lab.sweep_orders import interleave
from benchmarks.solver_lab.trajectory import TRAJECTORY
from masonrycli.engine import dispatch, stalled
from masonrycli.engine.tuning import TUNING


def _tight(case: str, duration: float) -> dict:
    path = TRAJECTORY / case / "tight.json"
    if path.exists():
        return json.loads(path.read_text())
    path.parent.mkdir(parents=True, exist_ok=True)
    samples = run_masonry(case, min(duration, 0.2), record=False, **TIGHT)["samples"]
    path.write_text(json.dumps(samples))
    return samples


def run_variant(case: str, params: dict, duration: float) -> dict:
    """One whole run of ``case`` with the first stage of every step replaced by the lab kernel (module doc)."""
    q = ENGINE | params
    original = dispatch.solve
    hist = [(np.empty(0, np.int64), np.empty((0, 2)))] * 2
    sims = []

    def solve(contact_body, pack, count, model, v, r, status, tuning=TUNING):
        o = interleave(count)
        body = np.ascontiguousarray(contact_body[:count][o].astype(np.uint32))
        pk = np.ascontiguousarray(pack[:count][o])
        r_o = r[:count][o].copy()
        key = None
        if q["gamma"]:
            key = sims[0].solver.buffers.contact_key[:count]
            r2, has2 = _align(key, *hist[0])
            r2, has2 = r2[o], has2[o]
            r_o[has2] += q["gamma"] * (r_o[has2] - r2[has2])
            r_o[:, 1] = np.maximum(r_o[:, 1], 0.0)
            lim = model.friction * r_o[:, 1]
            r_o[:, 0] = np.clip(r_o[:, 0], -lim, lim)
        v_free, r_warm = v.copy(), r[:count].copy()
        st_o = np.zeros(count, dtype=status.dtype)
        mu, tol, cap = model.friction, model.tolerance, model.max_iterations
        its, res = _accelerated(body, pk, count, mu, tol, cap, v, r_o, st_o, STALL, *kernel_args(params), np.zeros(0))
        r[o] = r_o
        status[o] = st_o
        if res > model.tolerance and its < model.max_iterations:  # stalled: as dispatch.solve
            its, res = stalled.continue_stalled(
                contact_body,
                pack,
                count,
                model.friction,
                model.tolerance,
                model.max_iterations,
                v,
                r,
                status,
                v_free,
                r_warm,
                its,
                res,
                tuning,
            )
        if q["gamma"]:
            order = np.argsort(key, kind="stable")
            hist[0], hist[1] = hist[1], (key[order].copy(), r[:count][order].copy())
        return its, res

    # run_masonry builds its Simulation inside; the key history needs it: catch it on construction.
    from benchmarks import bench_solver

    made = bench_solver.Simulation

    def catching(*args, **kwargs):
        sim = made(*args, **kwargs)
        sims.append(sim)
        return sim

    bench_solver.Simulation = catching
    dispatch.solve = solve
    try:
        return run_masonry(case, duration, record=False)
    finally:
        dispatch.solve = original
        bench_solver.Simulation = made


def table(case: str, names: list[str] | None, duration: float) -> None:
    names = names or ["engine"]
    tight = _tight(case, duration)
    print(f"\n{case}, {duration:g} s")
    print(
        "| variant | sweep units | ÷ engine | per step mean (max) | unconverged |"
        " error % top / mean at 0.1 s | at 0.2 s |"
    )
    print("|---|---|---|---|---|---|---|")
    base = None
    for name in names:
        out = run_variant(case, VARIANTS[name], duration)
        steps = round(out["sim_s"] / 1e-3)
        total = out["sweeps_mean"] * steps
        base = base or total
        e = errors_pct(out["samples"], tight)
        errs = " | ".join(f"{e[k][0]:+.2f} / {e[k][1]:+.2f}" if k in e else "–" for k in ("100", "200"))
        print(
            f"| {name} | {total:.0f} | {total / base:.3f} | {out['sweeps_mean']:.0f} ({out['sweeps_max']}) |"
            f" {out['unconverged']} | {errs} |",
            flush=True,
        )
