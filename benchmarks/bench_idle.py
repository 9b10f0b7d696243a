"""Idle contact visits of the accelerated sweep: how many visits change nothing, and could be skipped.

    .venv/bin/python -m benchmarks.bench_idle [--case wall-248] [--duration 1] [--json PATH]

Runs ``--case`` (benchmarks.solver_cases, the solver benchmark's trajectory) with the engine's default
solver and, for every call of the scalar accelerated sweep (``interleaved.sweeps`` in its MOMENTUM mode: the sweeps of every step until momentum converges or stalls, its first stage run by that
sweep rather than by the lane sweeps, and stalled.py's "momentum" resumes), solves
the same input again with the lab copy below, which is ``momentum._nlgs_accelerated`` with counters (its
sweeps, residual, v and r are checked equal to the engine's, bit for bit). Per visit of a contact:

    idle     the local solve returned the extrapolated start r_y itself: Δr = 0, no push, e_α = 0
    status   open / stick / slip, the local solve's verdict at that visit
    run ≥ K  the contact's previous K visits (K = 2, 4, 8) were all idle: a shrinking sweep that skips
             contacts idle for K sweeps would have skipped this visit; "missed" counts those of them that
             were not idle (the skip would have left a violation for a later full sweep)

and per step the contacts idle at every visit of the step. What a shrinking sweep could save is bounded by
the skippable visits times the cost of an idle visit (open ones exit the local solve at its first test,
and no push follows), which is below the mean visit cost.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

import numpy as np

os.environ.setdefault("RERUN_ANALYTICS", "0")
ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from masonrycli.engine import dispatch, interleaved, momentum  # noqa: E402
from masonrycli.engine._jit import njit  # noqa: E402
from masonrycli.engine.nlgs import P_WNN, P_WTN, P_WTT, _local_solve, _push, _relative_velocity  # noqa: E402

KS = (2, 4, 8)
"""Idle-run lengths after which a shrinking sweep would skip a contact."""
STATUS_NAMES = ("open", "stick", "slip")


@njit(cache=False)  # the engine's flags; not cached: a lab copy
def _counted(contact_body, pack, count, mu, tolerance, max_iterations, v, r, status, stall_after, ks, tally):
    # interleaved._accelerated → momentum._nlgs_accelerated (flip omitted) as in the engine, plus counters:
    # tally[0, s] visits with status s, tally[1, s] idle ones; tally[2 + 2i, s] visits after ≥ ks[i] idle
    # visits of the same contact, tally[3 + 2i, s] those of them not idle; tally[2 + 2 len(ks), 0] contacts
    # idle through the whole step, [.., 1] contacts, [.., 2] sweeps.
    order, body, pk, rr2, st_o = interleaved._in_order(contact_body, pack, count, r, status)
    for c in range(count):
        _push(v, body[c, 0], body[c, 1], pk, np.uint64(c), rr2[c, 0], rr2[c, 1])
    iterations = 0
    residual = 0.0
    if count == 0:
        return iterations, residual
    v_prev = v.copy()
    v_flat = v.reshape(v.size)
    v_prev_flat = v_prev.reshape(v.size)
    rr = np.empty((count, 4), np.float64)
    for c in range(count):
        rr[c, 0] = rr[c, 2] = rr2[c, 0]
        rr[c, 1] = rr[c, 3] = rr2[c, 1]
    run = np.zeros(count, np.int64)  # idle visits in a row before the current one
    ever = np.zeros(count, np.int64)  # 1 once the contact had a non-idle visit in this step
    best = np.inf
    best_at = 0
    last = np.inf
    j = 1
    beta = 0.0
    for it in range(max_iterations):
        iterations = it + 1
        momentum._extrapolate(v_flat, v_prev_flat, beta)
        sum_e2 = 0.0
        for k in range(count):
            c = np.uint64(k)
            a = body[c, 0]
            b = body[c, 1]
            ut, un = _relative_velocity(v, a, b, pk, c)
            xt = rr[c, 0]
            xn = rr[c, 1]
            rt0 = xt + beta * (xt - rr[c, 2])
            rn0 = xn + beta * (xn - rr[c, 3])
            rr[c, 2] = xt
            rr[c, 3] = xn
            wtt = pk[c, P_WTT]
            wtn = pk[c, P_WTN]
            wnn = pk[c, P_WNN]
            ut -= wtt * rt0 + wtn * rn0
            un -= wtn * rt0 + wnn * rn0
            rt, rn, st = _local_solve(ut, un, pk, c, mu)
            st_o[c] = st
            rr[c, 0] = rt
            rr[c, 1] = rn
            drt = rt - rt0
            drn = rn - rn0
            idle = not (drt != 0.0 or drn != 0.0)
            tally[0, st] += 1
            if idle:
                tally[1, st] += 1
            for i in range(ks.shape[0]):
                if run[c] >= ks[i]:
                    tally[2 + 2 * i, st] += 1
                    if not idle:
                        tally[3 + 2 * i, st] += 1
            if idle:
                run[c] += 1
            else:
                run[c] = 0
                ever[c] = 1
                _push(v, a, b, pk, c, drt, drn)
                et = wtt * drt + wtn * drn
                en = wtn * drt + wnn * drn
                sum_e2 += et * et + en * en
        residual = np.sqrt(sum_e2 / count)
        if residual <= tolerance:
            break
        if residual < best:
            best = residual
            best_at = it
        elif tolerance > 0.0 and it - best_at >= stall_after:
            break
        if residual > momentum.RESTART_GROWTH * last:
            j = 1
        last = residual
        beta = (j - 1.0) / (j + 2.0)
        j += 1
    for c in range(count):
        rr2[c, 0] = rr[c, 0]
        rr2[c, 1] = rr[c, 1]
    row = 2 + 2 * ks.shape[0]
    for c in range(count):
        tally[row, 0] += 1 - ever[c]
    tally[row, 1] += count
    tally[row, 2] += iterations
    interleaved._back(order, count, rr2, st_o, r, status)
    return iterations, residual


def measure(case: str, duration: float) -> dict:
    """Run ``case`` for ``duration`` s with every first-stage accelerated call counted (module doc)."""
    from benchmarks.solver_cases import FLOAT64, make_scenario
    from masonrycli.run import Simulation, simulate

    ks = np.array(KS, np.int64)
    tally = np.zeros((3 + 2 * len(KS), 3), np.int64)
    kernel, first, calls = interleaved.sweeps, dispatch.first_stage, [0]

    def counted(contact_body, pack, count, mu, tolerance, cap, v, r, status, mode, stall=0):
        if mode == interleaved.MOMENTUM:
            v2, r2, s2 = v.copy(), r.copy(), status.copy()
            out2 = _counted(contact_body, pack, count, mu, tolerance, cap, v2, r2, s2, stall, ks, tally)
        out = kernel(contact_body, pack, count, mu, tolerance, cap, v, r, status, mode, stall)
        if mode == interleaved.MOMENTUM:
            same = out2 == out and np.array_equal(v2, v) and np.array_equal(r2[:count], r[:count])
            assert same, "the counted copy left the engine's path"
            calls[0] += 1
        return out

    def scalar_first_stage(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall, lanes=True, *growth):
        # by interleaved.sweeps, which the lab copy follows (at momentum.RESTART_GROWTH: growth not passed)
        return first(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall, False)

    interleaved.sweeps, dispatch.first_stage = counted, scalar_first_stage
    try:
        scenario = make_scenario(case, duration, solver=FLOAT64)  # the float64 first stage it times
        simulate(scenario, [], sim=Simulation(scenario))
    finally:
        interleaved.sweeps, dispatch.first_stage = kernel, first
    visits = int(tally[0].sum())
    row = {"case": case, "duration": duration, "calls": calls[0], "visits": visits, "sweeps": int(tally[-1, 2])}
    row["by_status"] = {
        name: {"visits": int(tally[0, s]), "idle": int(tally[1, s])} for s, name in enumerate(STATUS_NAMES)
    }
    row["idle_share"] = float(tally[1].sum() / visits)
    row["skippable"] = {
        str(k): {
            "visits": int(tally[2 + 2 * i].sum()),
            "share": float(tally[2 + 2 * i].sum() / visits),
            "missed": int(tally[3 + 2 * i].sum()),
            "by_status": {name: int(tally[2 + 2 * i, s]) for s, name in enumerate(STATUS_NAMES)},
        }
        for i, k in enumerate(KS)
    }
    row["contacts_idle_whole_step"] = int(tally[-1, 0])
    row["contacts"] = int(tally[-1, 1])
    return row


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--case", default="wall-248", help="benchmarks.solver_cases case")
    parser.add_argument("--duration", type=float, default=1.0, help="simulated s")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    row = measure(args.case, args.duration)
    v = row["visits"]
    print(f"{row['case']} {row['duration']:g} s: {row['calls']} accelerated calls, {row['sweeps']} sweeps, "
          f"{v} contact visits; idle (Δr = 0) {row['idle_share']:.1%}")  # fmt: skip
    for name, s in row["by_status"].items():
        share = s["idle"] / s["visits"] if s["visits"] else 0.0
        print(f"  {name:5}: {s['visits'] / v:6.1%} of visits, {share:6.1%} of them idle ({s['idle'] / v:.1%} of all)")
    for k, s in row["skippable"].items():
        by = ", ".join(f"{n} {x / v:.1%}" for n, x in s["by_status"].items())
        print(f"  after ≥ {k} idle visits: {s['share']:.1%} of visits ({by}); not idle then: {s['missed']}")
    print(f"  contacts idle through a whole step: {row['contacts_idle_whole_step'] / row['contacts']:.1%}")
    if args.json:
        args.json.write_text(json.dumps(row, indent=1) + "\n")
    return row


if __name__ == "__main__":
    main()
