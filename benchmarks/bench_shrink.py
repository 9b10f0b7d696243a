"""Shrinking sweeps in whole runs: CPU, sweeps and accuracy of the default solver with
``shrink.CHECK_EVERY`` set to each value, in one process, interleaved.

    .venv/bin/python -m benchmarks.bench_shrink [--cases wall-248] [--every 0 16] [--rounds 3]
        [--duration S] [--record] [--per-step] [--json PATH]

Each round runs every case once with each value of ``--every`` (0: every sweep full, the engine's default),
in turn, in this process (the kernels of both compiled once, before the rounds). Per case and value:
CPU s per simulated s (minimum over rounds; ``simulate`` only, with a Rerun recording every 10 steps if
``--record``, as bench_solver), the CPU of the sweeps (``nlgs._nlgs_interleaved``, and
``interleaved._shrinking``: the first stage when shrinking), sweeps per step
(mean, max), steps handed to stalled.py, unconverged steps, and the top-course / mean slip at 0.1 and
0.2 s against bench_solver's tight solve (plain NLGS at 1e-7 m/s, cap 20 000: read from the solver lab's
``data/trajectory/<case>/tight.json`` if there, else computed once and kept there). The sweep counts and
slips are deterministic: one round gives them; the rounds are for the CPU time.

``--per-step`` instead runs each case once with the engine's default and solves every first-stage
accelerated call again, on copies, with each shrinking value (per_step): the sweeps and CPU of the same
steps from the same warm starts, which a whole run's own trajectory (another path, other hard steps)
cannot give.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("RERUN_ANALYTICS", "0")
ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.bench_solver import run_masonry  # noqa: E402
from benchmarks.solver_cases import FLOAT64  # noqa: E402
from benchmarks.solver_reference import TIGHT, errors_pct  # noqa: E402
from masonrycli.engine import interleaved, nlgs, shrink, stalled  # noqa: E402

TRAJECTORY = ROOT / "benchmarks" / "solver_lab" / "data" / "trajectory"


def tight(case: str, duration: float) -> dict:
    """The tight solve's slip samples of ``case`` over min(duration, 0.2) s (cached, module doc)."""
    path = TRAJECTORY / case / "tight.json"
    if path.exists():
        return json.loads(path.read_text())
    samples = run_masonry(case, min(duration, 0.2), record=False, **TIGHT)["samples"]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(samples))
    return samples


def one_run(case: str, duration: float | None, every: int, record: bool) -> dict:
    """One run with CHECK_EVERY = ``every``: run_masonry's figures, the sweeps' CPU and stalled steps."""
    sweeps, shrinking, cont = nlgs._nlgs_interleaved, interleaved._shrinking, stalled.continue_stalled
    cpu, handed = [0.0], [0]

    def timer(kernel):
        def timed(*args, **kw):
            t = time.process_time()
            out = kernel(*args, **kw)
            cpu[0] += time.process_time() - t
            return out

        return timed

    def counted(*args, **kw):
        handed[0] += 1
        return cont(*args, **kw)

    saved = shrink.CHECK_EVERY
    shrink.CHECK_EVERY = every
    nlgs._nlgs_interleaved, interleaved._shrinking = timer(sweeps), timer(shrinking)
    stalled.continue_stalled = counted
    try:
        row = run_masonry(case, duration, record, solver=FLOAT64)
    finally:
        shrink.CHECK_EVERY = saved
        nlgs._nlgs_interleaved, interleaved._shrinking, stalled.continue_stalled = sweeps, shrinking, cont
    row["sweeps_cpu_s"] = cpu[0]
    row["stalled_steps"] = handed[0]
    return row


def per_step(case: str, duration: float | None, values: list[int]) -> dict:
    """The engine's own run of ``case`` (every sweep full); each first-stage accelerated call is solved
    again, on copies, by the shrinking sweep with CHECK_EVERY = each of ``values``, and each solve (the
    engine's own included) is timed call by call, in turn: sweeps and CPU from the same warm starts."""
    import numpy as np

    kernel = nlgs._nlgs_interleaved
    tally = {e: {"sweeps": 0, "cpu_s": 0.0, "over_tolerance": 0} for e in [0, *values]}

    def both(contact_body, pack, count, mu, tolerance, cap, v, r, status, accelerate, stall, alternate=False):
        first_stage = accelerate and not alternate
        for e in values if first_stage else ():
            v2, r2, s2 = v.copy(), r.copy(), status.copy()
            t = time.process_time()
            its, res = interleaved._shrinking(contact_body, pack, count, mu, tolerance, cap, v2, r2, s2, stall, e)
            tally[e]["cpu_s"] += time.process_time() - t
            tally[e]["sweeps"] += its
            tally[e]["over_tolerance"] += bool(res > tolerance)
        t = time.process_time()
        its, res = kernel(contact_body, pack, count, mu, tolerance, cap, v, r, status, accelerate, stall, alternate)
        if first_stage:
            tally[0]["cpu_s"] += time.process_time() - t
            tally[0]["sweeps"] += its
            tally[0]["over_tolerance"] += bool(res > tolerance)
        return its, res

    for e in values:  # compile
        interleaved._shrinking(np.zeros((0, 2), np.int32), np.zeros((0, nlgs.PACK_WIDTH)), 0, 0.5, 1e-5, 1,
                               np.zeros((1, 3)), np.zeros((0, 2)), np.zeros(0, np.int8), 1, e)  # fmt: skip
    saved = shrink.CHECK_EVERY
    shrink.CHECK_EVERY = 0
    nlgs._nlgs_interleaved = both
    try:
        run_masonry(case, duration, False, solver=FLOAT64)
    finally:
        nlgs._nlgs_interleaved, shrink.CHECK_EVERY = kernel, saved
    for e in values:
        tally[e]["sweeps_ratio"] = tally[e]["sweeps"] / tally[0]["sweeps"]
        tally[e]["cpu_ratio"] = tally[e]["cpu_s"] / tally[0]["cpu_s"]
    return tally


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", nargs="+", default=["wall-248"], help="benchmarks.solver_cases cases")
    parser.add_argument("--every", nargs="+", type=int, default=[0, 16], help="CHECK_EVERY values")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--duration", type=float, default=None, help="simulated s (default: the case's)")
    parser.add_argument("--record", action="store_true", help="a Rerun recording every 10 steps")
    parser.add_argument("--per-step", action="store_true", help="the same warm starts: the engine's run (above)")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    if args.per_step:
        out = {case: per_step(case, args.duration, [e for e in args.every if e > 0]) for case in args.cases}
        for case, tally in out.items():
            for e, t in tally.items():
                ratios = f", ÷ engine: sweeps {t['sweeps_ratio']:.3f}, CPU {t['cpu_ratio']:.3f}" if e else ""
                print(f"{case} every {e:3}: first-stage sweeps {t['sweeps']}, CPU {t['cpu_s']:.3f} s, "
                      f"ended above the tolerance (to stalled.py) {t['over_tolerance']}{ratios}")  # fmt: skip
        if args.json:
            args.json.write_text(json.dumps(out, indent=1) + "\n")
        return out
    for every in args.every:  # compile every kernel first
        one_run(args.cases[0], 0.003, every, args.record)
    runs: dict = {case: {e: [] for e in args.every} for case in args.cases}
    for _ in range(args.rounds):
        for case in args.cases:
            for every in args.every:
                runs[case][every].append(one_run(case, args.duration, every, args.record))
    out: dict = {"args": {k: v for k, v in vars(args).items() if k != "json"}, "cases": {}}
    for case in args.cases:
        reference = tight(case, args.duration or 1.0)
        out["cases"][case] = {}
        for every, rows in runs[case].items():
            best = min(rows, key=lambda r: r["cpu_s"])
            err = errors_pct(best["samples"], reference)
            figures = {
                "cpu_per_sim_s": best["cpu_s"] / best["sim_s"],
                "sweeps_cpu_per_sim_s": min(r["sweeps_cpu_s"] for r in rows) / best["sim_s"],
                "sweeps_mean": best["sweeps_mean"],
                "sweeps_max": best["sweeps_max"],
                "stalled_steps": best["stalled_steps"],
                "unconverged": best["unconverged"],
                "errors_pct": err,
            }
            out["cases"][case][every] = figures
            errs = "  ".join(f"{int(s) / 1000:g} s {t:+.2f} / {m:+.2f} %" for s, (t, m) in err.items())
            print(f"{case} every {every:3}: {figures['cpu_per_sim_s']:.3f} CPU s per sim s (sweeps "
                  f"{figures['sweeps_cpu_per_sim_s']:.3f}), {figures['sweeps_mean']:.1f} sweeps a step (max "
                  f"{figures['sweeps_max']}), stalled {figures['stalled_steps']}, unconverged "
                  f"{figures['unconverged']}; top / mean slip error {errs}")  # fmt: skip
    if args.json:
        args.json.write_text(json.dumps(out, indent=1) + "\n")
    return out


if __name__ == "__main__":
    main()
