"""Coloured SIMD sweeps (simd_sweep.py) against the engine's accelerated sweep on captured steps.

    python -m benchmarks.solver_lab.simd_bench [--case wall-248] [--duration 1] [--every 10] [--rounds 5]
        [--variants split fused levels] [--reference]
    python -m benchmarks.solver_lab.simd_bench --asm
    python -m benchmarks.solver_lab.simd_bench --whole-run [--case wall-248] [--duration 1] [--rounds 3]
        [--ensemble OUT [--copies 2]]

The steps: the inputs of every ``--every``-th accelerated first-stage call that ``dispatch.solve`` makes on
``--case`` (bench_kernel.capture). On each, the engine's ``dispatch.first_stage`` (momentum; the lane
sweeps while ``Tuning.lanes``, the default, else the 4-run interleaved order) and each coloured variant run
from the same inputs to the engine's tolerance, stall window 200.
Timing: ``--rounds`` rounds, each running the engine and then every variant over all steps (the order
rotated from round to round), CPU time (``time.process_time``) per pass; the minimum over rounds.
Reported per method: sweeps per step, ns per contact·sweep (CPU / Σ contacts × sweeps), CPU per step of
the first stage, steps ending above the tolerance (stalled: the engine would hand them to stalled.py),
and with ``--reference`` the distance of v from a tight solve of the same step (momentum to 1e-9 m/s with
no stall window, cap TIGHT_CAP; plain NLGS if that misses it, the closer of the two kept): RMS over the
step's bodies and components, then mean and max over steps. ``--asm``: what LLVM made of each phase.
``--whole-run``: whole runs with the engine's first stage by its lane sweeps (``Tuning.lanes``, the default)
and by the 4-run scalar sweep (``lanes`` False); "lanes+vec" in ``--variants`` is the lane sweeps alone.
"""

from __future__ import annotations

import argparse
import contextlib
import re
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from benchmarks.bench_kernel import capture
from benchmarks.solver_lab import simd_sweep
from masonrycli.engine import dispatch, interleaved, nlgs
from masonrycli.engine.tuning import TUNING

TIGHT = 1e-9
TIGHT_CAP = 50_000


def _engine(call):
    contact_body, pack, count, mu, tolerance, cap, v, r, status, accelerate, stall = call
    v, r, status = v.copy(), r.copy(), status.copy()
    sweeps, residual = dispatch.first_stage(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall)
    return sweeps, residual, v


def _coloured(call, variant):
    contact_body, pack, count, mu, tolerance, cap, v, r, status, accelerate, stall = call
    v, r, status = v.copy(), r.copy(), status.copy()
    sweeps, residual, _ = simd_sweep.solve(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall,
                                           variant)  # fmt: skip
    return sweeps, residual, v


def _tight(call):
    # Momentum to TIGHT with a stall window as long as the cap (no hand-over), then plain NLGS if that
    # still misses it. Returns (v, residual).
    contact_body, pack, count, mu, tolerance, cap, v, r, status, accelerate, stall = call
    v1, r1, s1 = v.copy(), r.copy(), status.copy()
    _, residual = dispatch.first_stage(contact_body, pack, count, mu, TIGHT, TIGHT_CAP, v1, r1, s1, TIGHT_CAP)
    if residual > TIGHT:
        v2, r2, s2 = v.copy(), r.copy(), status.copy()
        _, res2 = interleaved.sweeps(contact_body, pack, count, mu, TIGHT, TIGHT_CAP, v2, r2, s2, interleaved.PLAIN)
        if res2 < residual:
            v1, residual = v2, res2
    return v1, residual


def run(case, duration, every, rounds, variants, reference):
    calls = capture(case, duration, every)
    methods = {"engine": _engine} | {v: (lambda call, v=v: _coloured(call, v)) for v in variants}
    outcome = {}
    for name, method in methods.items():  # compile, and the outcome of every step
        outcome[name] = [method(call) for call in calls]
    cpu = {name: np.inf for name in methods}
    names = list(methods)
    for k in range(rounds):
        for name in names[k % len(names) :] + names[: k % len(names)]:
            start = time.process_time()
            for call in calls:
                methods[name](call)
            cpu[name] = min(cpu[name], time.process_time() - start)
    refs = [_tight(call) for call in calls] if reference else None
    counts = np.array([call[2] for call in calls])
    tolerance = calls[0][4]
    rows = []
    for name in names:
        sweeps = np.array([o[0] for o in outcome[name]])
        residual = np.array([o[1] for o in outcome[name]])
        row = {
            "method": name,
            "sweeps": sweeps.mean(),
            "median": np.median(sweeps),
            "ns": cpu[name] / float((sweeps * counts).sum()) * 1e9,
            "ms_step": cpu[name] / len(calls) * 1e3,
            "stalled": int((residual > tolerance).sum()),
        }
        if refs is not None:
            err = np.array([np.sqrt(np.mean((o[2] - ref[0]) ** 2)) for o, ref in zip(outcome[name], refs)])
            row["err_mean"], row["err_max"] = err.mean(), err.max()
        rows.append(row)
    colours = [simd_sweep.solve(*call[:4], call[4], call[5], call[6].copy(), call[7].copy(), call[8].copy(),
                                call[10])[2] for call in calls]  # fmt: skip
    print(f"{case} {duration} s, every {every}th first-stage call: {len(calls)} steps, {counts.mean():.0f} contacts "
          f"a step, tolerance {tolerance:g} m/s, minimum of {rounds} rounds" + (
          f"; reference: tight solve to {TIGHT:g} (worst residual {max(r[1] for r in refs):.1e})" if refs else ""))  # fmt: skip
    engine = rows[0]
    print("| method | sweeps/step mean (median) | ns per contact·sweep | first stage ms/step | ÷ engine | stalled steps |"
          + (" v error mean / max (m/s) |" if refs else ""))  # fmt: skip
    print("|---|---|---|---|---|---|" + ("---|" if refs else ""))
    for row in rows:
        line = (f"| {row['method']} | {row['sweeps']:.1f} ({row['median']:.0f}) | {row['ns']:.2f} | {row['ms_step']:.3f} | "
                f"{row['ms_step'] / engine['ms_step']:.2f} | {row['stalled']} |")  # fmt: skip
        if refs is not None:
            line += f" {row['err_mean']:.2e} / {row['err_max']:.2e} |"
        print(line)
    print(
        f"colours a step: {np.mean(colours):.1f} (min {min(colours)}, max {max(colours)}); "
        f"contacts a colour {np.mean(counts / np.array(colours)):.0f} on average"
    )
    return rows


@contextlib.contextmanager
def first_stage_timed():
    """While open, ``dispatch.solve``'s float64 first stage (``dispatch.first_stage``: momentum to the stall
    window) is timed: the engine's lane sweeps (engine/lane_sweeps.py, the default) or, with the runs'
    Tuning.lanes False, the 4-run scalar sweep (interleaved._accelerated, the default before them); stalled
    steps go on by stalled.py either way. Yields a tally: first-stage CPU s and sweeps, steps handed to
    stalled.py."""
    from masonrycli.engine import stalled

    kernel, cont = dispatch.first_stage, stalled.continue_stalled
    tally = {"first_cpu": 0.0, "first_sweeps": 0, "stalled": 0}

    def first_stage(*args, **kw):  # dispatch.solve calls it once a step, for the first stage alone
        t = time.process_time()
        out = kernel(*args, **kw)
        tally["first_cpu"] += time.process_time() - t
        tally["first_sweeps"] += out[0]
        return out

    def counted(*args):
        tally["stalled"] += 1
        return cont(*args)

    dispatch.first_stage, stalled.continue_stalled = first_stage, counted
    try:
        yield tally
    finally:
        dispatch.first_stage, stalled.continue_stalled = kernel, cont


def whole_runs(case, duration, rounds):
    """Whole runs of ``case`` with the engine's first stage by the 4-run scalar sweep (``Tuning.lanes``
    False) and by the lane sweeps (True, the default), timed by first_stage_timed. Rounds interleaved, CPU
    minimum; top-course / mean slip at 0.1 and 0.2 s against a tight solve (plain NLGS at 1e-7 m/s,
    bench_solver's TIGHT)."""
    from benchmarks.bench_solver import run_masonry
    from benchmarks.solver_reference import TIGHT, errors_pct

    def one(lanes, seconds):
        with first_stage_timed() as tally:
            row = run_masonry(case, seconds, False, tuning=replace(TUNING, lanes=lanes))
        return row | tally

    one(True, 0.003)  # compile both
    one(False, 0.003)
    runs = {False: [], True: []}
    for k in range(rounds):
        for lanes in (False, True) if k % 2 == 0 else (True, False):
            runs[lanes].append(one(lanes, duration))
    reference = run_masonry(case, min(duration, 0.2), False, **TIGHT)["samples"]
    for lanes, rows_ in runs.items():
        best = min(rows_, key=lambda x: x["cpu_s"])
        errs = "  ".join(f"{int(k) / 1000:g} s {t:+.2f} / {m:+.2f} %" for k, (t, m) in
                         errors_pct(best["samples"], reference).items())  # fmt: skip
        name = "lanes=True (lane sweeps)" if lanes else "lanes=False (4-run scalar)"
        print(f"{case} {name}: {best['cpu_s'] / best['sim_s']:.3f} CPU s per sim s (solve {best['nlgs_share']:.0%}), "
              f"{best['sweeps_mean']:.1f} sweeps a step (max {best['sweeps_max']}), unconverged "
              f"{best['unconverged']}, handed to stalled.py {best['stalled']}; first stage "
              f"{best['first_cpu'] / best['sim_s']:.3f} CPU s per sim s, {best['first_sweeps']} sweeps; top / mean "
              f"slip error {errs}")  # fmt: skip
    return runs


def ensembles(cases, duration, copies, out):
    """solver_lab.ensemble's runs (12 ground motions × ``copies``) with the 4-run scalar first stage
    (``Tuning.lanes`` False), written to OUT-scalar.json, and with the lane sweeps (True), to OUT-lanes.json;
    then ``ensemble compare`` of the two."""
    from benchmarks.solver_lab import ensemble

    paths = [Path(f"{out}-scalar.json"), Path(f"{out}-lanes.json")]
    for lanes, path in zip((False, True), paths):
        ensemble.run(cases, ensemble.MOTIONS, duration, path, copies=range(copies), override=f"lanes={lanes}")
    return ensemble.compare(*paths)


def _fresh_lane_sweeps():
    # The engine's kernel compiled in this process: numba shows no machine code of a kernel it loaded from
    # its cache (engine/__pycache__), so compile a twin with the cache off (_jit.njit's flags otherwise).
    from masonrycli.engine import _jit, lane_sweeps

    kernel = _jit.njit(cache=False)(lane_sweeps._lane_sweeps.py_func)
    n = 8
    body, pack = np.zeros((n, 2), np.int32), np.zeros((n, nlgs.PACK_WIDTH))
    kernel(body, pack, 0, 0.5, 1e-5, 10, np.zeros((n, 3)), np.zeros((n, 2)), np.zeros(n, np.int8), 10)  # the types
    return kernel


def asm_summary():
    """What LLVM made of each phase (``inspect_asm``): instructions, lines naming zmm / ymm registers,
    gathers, packed and scalar double operations (moves left out)."""
    n = 8
    ia, K, X = np.zeros(n, np.uint64), np.zeros((simd_sweep.K_ROWS, n)), np.zeros((4, n))
    D, U, v, st = np.zeros((3, n)), np.zeros((2, n)), np.zeros(3 * n), np.zeros(n, np.int8)
    simd_sweep._gather_u(0, n, ia, ia, K, v, U)
    simd_sweep._solve_u(0, n, K, U, 0.0, 0.5, X, D, st)
    simd_sweep._phase_a(0, n, ia, ia, K, v, 0.0, 0.5, X, D, st)
    simd_sweep._phase_b(0, n, ia, ia, K, v, D)
    kernels = {"split: _gather_u": simd_sweep._gather_u, "split: _solve_u": simd_sweep._solve_u,
               "fused: _phase_a": simd_sweep._phase_a, "_phase_b": simd_sweep._phase_b,
               "lanes+vec: the engine's lane_sweeps._lane_sweeps": _fresh_lane_sweeps()}  # fmt: skip
    for name, kernel in kernels.items():
        for asm in kernel.inspect_asm().values():
            lines = asm.splitlines()
            ops = [x.split()[0] for x in lines if x.startswith("\t") and not x.strip().startswith(".")]
            packed = sum(bool(re.match(r"v.*pd$", o)) and not o.startswith("vmov") for o in ops)
            scalar = sum(bool(re.match(r"v.*sd$", o)) and not o.startswith("vmov") for o in ops)
            print(f"{name}: {len(ops)} instructions, zmm in {sum('zmm' in x for x in lines)} lines, ymm in "
                  f"{sum('ymm' in x for x in lines)}, gathers {sum('gather' in o for o in ops)}, scatters {sum('scatter' in o for o in ops)}, packed double ops "
                  f"{packed}, scalar double ops {scalar}")  # fmt: skip


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case", default="wall-248")
    parser.add_argument("--duration", type=float, default=1.0)
    parser.add_argument("--every", type=int, default=10)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--variants", nargs="*", default=["split", "fused"])
    parser.add_argument("--reference", action="store_true")
    parser.add_argument("--asm", action="store_true", help="only print what LLVM made of each phase")
    parser.add_argument("--whole-run", action="store_true", help="whole runs, Tuning.lanes True and False (whole_runs)")
    parser.add_argument("--ensemble", metavar="OUT", help="with --whole-run: ensembles of short runs (ensembles)")
    parser.add_argument("--copies", type=int, default=2, help="--ensemble: runs a motion")
    args = parser.parse_args(argv)
    if args.asm:
        return asm_summary()
    if args.whole_run and args.ensemble:
        return ensembles([args.case], args.duration, args.copies, args.ensemble)
    if args.whole_run:
        return whole_runs(args.case, args.duration, args.rounds)
    return run(args.case, args.duration, args.every, args.rounds, args.variants, args.reference)


if __name__ == "__main__":
    main()
