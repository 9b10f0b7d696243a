"""Gauss–Seidel by joints: each joint (all contact points between one pair of bodies) solved exactly in turn.

The lab's finding on ordinary steps ("Newton-type steps on ordinary steps", benchmarks/JOURNAL.md): what the
point sweeps spend their time on is how the impulses are shared among a joint's points and across the
hyperstatic joints, not the blocks' motion. This method removes the first part: a sweep visits one *joint*
at a time (the detection emits a pair's points next to each other; on every captured problem a joint has 1
or 2 points) and solves that joint's coupled Signorini–Coulomb problem, all other impulses held, before
moving on; then the two bodies' velocities are those of its impulses, as after the engine's visits.

The joint solve is an inner point Gauss–Seidel on the joint alone (the engine's exact 2×2 local solve at
each of its points, in turn) until a round moves no point's velocity by more than INNER_TOL m/s, at most
``rounds`` rounds. A joint of one point is exact after one round. ``rounds`` = 1 is the plain point sweep
in detection order (the control rows ``pointwise-…``); ``rounds`` = 2 a cheap partial joint solve.

    v ← v_free + M⁻¹ H r_warm ; β = 0
    repeat (one sweep):
        (accelerated) v ← v + β (v − v_prev); r_y,α = r_α + β (r_α − r_prev,α) for every contact
        for each joint J in detection order:
            r_0 = r_y on J's points
            repeat ≤ rounds: for α in J: the engine's visit (u_free = H_αᵀ v − W_αα r_α, exact local
                             solve, v += M⁻¹ H_α Δr_α); stop when the round moved no point's
                             velocity u_α = H_αᵀ v by more than INNER_TOL
            e_α = W_αα (r_α − r_0,α) for α in J           (the joint's analogue of the engine's e_α)
        in-sweep residual = sqrt(Σ |e_α|² / C); restart as the engine (growth 1.1: j = 1) ; β = (j−1)/(j+2)
        (check) the lab's law residual of the iterate (law.py, here in the kernel): stop when ≤ target
    until stopped, or the cap

Methods (stopped, like every lab method, when the RMS law residual of the returned (v, r) ≤ target; the
count is found with the in-kernel check, untimed, then re-run in one timed kernel call without checks):

    joint-gs           joints solved exactly (rounds ROUNDS_EXACT), plain sweeps
    joint-accel        the same with the engine's Nesterov momentum and restart (engine/momentum.py)
    joint-gs-r2, joint-accel-r2   two rounds per joint (a partial joint solve)
    pointwise-gs, pointwise-accel the same kernel with one round: point Gauss–Seidel in detection order
                       under the same stopping rule — the control that isolates what the joint solve does

Sweep units: CPU time of the timed call over one engine plain sweep's (``ctx.sweep_s``, as every other
non-Gauss–Seidel method of the harness); ``iterations`` are this kernel's sweeps, and the phases give the
mean number of point visits per contact and sweep ("visits/contact·sweep", a count, not seconds).
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.solver_lab.methods.gauss_seidel import CAP
from benchmarks.solver_lab.outcome import Clock, Outcome
from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import P_WNN, P_WTN, P_WTT, _local_solve, _push, _relative_velocity

INNER_TOL = 1e-12
"""m/s: a joint is solved when a round moves none of its points' relative velocities u_α by more."""
ROUNDS_EXACT = 200
"""Most rounds of the inner Gauss–Seidel on one joint (a joint not solved to INNER_TOL by then is counted)."""
GROWTH = 1.1
"""The engine's restart growth (momentum.RESTART_GROWTH)."""


def joint_starts(body: np.ndarray) -> np.ndarray:
    """(J + 1,) first contact of each joint and C: runs of consecutive contacts with the same body pair."""
    c = body.shape[0]
    new = np.ones(c, dtype=bool)
    if c > 1:
        new[1:] = (body[1:] != body[:-1]).any(axis=1)
    return np.append(np.flatnonzero(new), c).astype(np.int64)


@njit(cache=False)  # the engine's flags (masonrycli/engine/_jit.py); not cached: a lab kernel
def _law_rms(body, pack, count, mu, v, r):
    # The lab's contact-law residual (law.py) of the pair (v, r), RMS over the contacts: for each contact
    # the exact local solve given all other impulses, |W_αα (r* − r)|.
    s = 0.0
    for c in range(count):
        a = body[c, 0]
        b = body[c, 1]
        ut, un = _relative_velocity(v, a, b, pack, c)
        wtt = pack[c, P_WTT]
        wtn = pack[c, P_WTN]
        wnn = pack[c, P_WNN]
        ut -= wtt * r[c, 0] + wtn * r[c, 1]
        un -= wtn * r[c, 0] + wnn * r[c, 1]
        rt, rn, _ = _local_solve(ut, un, pack, c, mu)
        dt_ = rt - r[c, 0]
        dn = rn - r[c, 1]
        et = wtt * dt_ + wtn * dn
        en = wtn * dt_ + wnn * dn
        s += et * et + en * en
    return np.sqrt(s / count) if count else 0.0


@njit(cache=False)
def _joint_sweeps(body, pack, starts, joints, count, mu, target, max_sweeps, rounds, accelerate, check, v, r, stats):
    # Module doc. v enters as v_free and leaves as v(r); r enters as the warm start and leaves as the
    # iterate. stats out: [0] point visits, [1] joints left unsolved at the rounds cap, [2] last in-sweep
    # residual. Returns (sweeps done, law residual of the iterate if check else −1).
    for c in range(count):
        _push(v, body[c, 0], body[c, 1], pack, c, r[c, 0], r[c, 1])
    if count == 0:
        return 0, 0.0
    v_prev = v.copy()
    r_prev = r.copy()
    r0 = np.empty((count, 2))
    u_last = np.empty((count, 2))
    sweeps = 0
    law = -1.0
    last = np.inf
    j = 1
    beta = 0.0
    visits = 0
    unsolved = 0
    residual = 0.0
    for it in range(max_sweeps):
        sweeps = it + 1
        if accelerate:
            for i in range(v.shape[0]):
                for k in range(3):
                    x = v[i, k]
                    v[i, k] = x + beta * (x - v_prev[i, k])
                    v_prev[i, k] = x
            for c in range(count):
                for k in range(2):
                    x = r[c, k]
                    r[c, k] = x + beta * (x - r_prev[c, k])
                    r_prev[c, k] = x
        sum_e2 = 0.0
        for f in range(joints):
            c0 = starts[f]
            c1 = starts[f + 1]
            for c in range(c0, c1):
                r0[c, 0] = r[c, 0]
                r0[c, 1] = r[c, 1]
            for c in range(c0, c1):
                ut, un = _relative_velocity(v, body[c, 0], body[c, 1], pack, c)
                u_last[c, 0] = ut
                u_last[c, 1] = un
            solved = False
            for _ in range(rounds):
                for c in range(c0, c1):  # the engine's visit (nlgs._nlgs), written out at one call site
                    a = body[c, 0]
                    b = body[c, 1]
                    ut, un = _relative_velocity(v, a, b, pack, c)
                    rt0 = r[c, 0]
                    rn0 = r[c, 1]
                    wtt = pack[c, P_WTT]
                    wtn = pack[c, P_WTN]
                    wnn = pack[c, P_WNN]
                    ut -= wtt * rt0 + wtn * rn0
                    un -= wtn * rt0 + wnn * rn0
                    rt, rn, _ = _local_solve(ut, un, pack, c, mu)
                    drt = rt - rt0
                    drn = rn - rn0
                    if drt != 0.0 or drn != 0.0:
                        _push(v, a, b, pack, c, drt, drn)
                        r[c, 0] = rt
                        r[c, 1] = rn
                visits += c1 - c0
                # Converged when the round left the joint's point velocities where they were: on a face in
                # stick–stick the two tangential rows nearly coincide (W singular to rounding), and the
                # impulses drift along that null direction by ~1e-10 N·s a round without moving anything.
                moved = 0.0
                for c in range(c0, c1):
                    ut, un = _relative_velocity(v, body[c, 0], body[c, 1], pack, c)
                    moved = max(moved, (ut - u_last[c, 0]) ** 2 + (un - u_last[c, 1]) ** 2)
                    u_last[c, 0] = ut
                    u_last[c, 1] = un
                if c1 - c0 == 1 or moved <= INNER_TOL * INNER_TOL:
                    solved = True
                    break
            if not solved and rounds > 1:
                unsolved += 1
            for c in range(c0, c1):
                wtt = pack[c, P_WTT]
                wtn = pack[c, P_WTN]
                wnn = pack[c, P_WNN]
                drt = r[c, 0] - r0[c, 0]
                drn = r[c, 1] - r0[c, 1]
                et = wtt * drt + wtn * drn
                en = wtn * drt + wnn * drn
                sum_e2 += et * et + en * en
        residual = np.sqrt(sum_e2 / count)
        if check:
            law = _law_rms(body, pack, count, mu, v, r)
            if law <= target:
                break
        if residual > GROWTH * last:
            j = 1
        last = residual
        beta = (j - 1.0) / (j + 2.0) if accelerate else 0.0
        j += 1
    stats[0] = visits
    stats[1] = unsolved
    stats[2] = residual
    return sweeps, law


def joint_solve(body, pack, mu, v_free, r_start, target, max_sweeps, rounds, accelerate, check, starts=None):
    """Run the kernel (module doc) on contacts ``body`` / ``pack`` from impulses ``r_start``; ``starts``: the
    joints (default: runs of one body pair; ``np.arange(C + 1)`` makes every point its own joint).
    Returns (v, r, sweeps, law residual or −1 without check, stats)."""
    count = body.shape[0]
    if starts is None:
        starts = joint_starts(body)
    v = v_free.copy()
    r = r_start.copy()
    stats = np.zeros(3)
    sweeps, law = _joint_sweeps(
        np.ascontiguousarray(body, dtype=np.int64), pack, starts, starts.size - 1, count, mu, target,
        max_sweeps, rounds, accelerate, check, v, r, stats,
    )  # fmt: skip
    return v, r, int(sweeps), float(law), stats


def _method(rounds: int, accelerate: bool, pointwise: bool = False):
    found = {}  # (problem, target) → (sweeps, converged): the search is not timed, do it once

    def solve(ctx, target) -> Outcome:
        p = ctx.p
        starts = np.arange(p.count + 1, dtype=np.int64) if pointwise else joint_starts(p.body)
        key = (p.name, target)
        if key not in found:
            _, _, n, law, _ = joint_solve(p.body, ctx.pack, p.mu, p.v_free, p.r_warm, target, CAP, rounds, accelerate,
                                          True, starts)  # fmt: skip
            found[key] = n, law <= target
        n, ok = found[key]
        clock = Clock()
        t = time.process_time()
        v, r, _, _, stats = joint_solve(p.body, ctx.pack, p.mu, p.v_free, p.r_warm, target, n, rounds, accelerate,
                                        False, starts)  # fmt: skip
        cpu = time.process_time() - t
        clock.phases["sweeps"] = cpu
        out = Outcome(v, r, n, cpu / ctx.sweep_s, clock.phases, converged=ok, cpu_s=cpu)
        out.phases["visits/contact·sweep"] = stats[0] / (n * p.count) * 1e-3 if n else 0.0  # shown ×1e3 as "ms"
        return out

    return solve


METHODS = {
    "joint-gs": _method(ROUNDS_EXACT, False),
    "joint-accel": _method(ROUNDS_EXACT, True),
    "joint-gs-r2": _method(2, False),
    "joint-accel-r2": _method(2, True),
    "pointwise-gs": _method(1, False, pointwise=True),
    "pointwise-accel": _method(1, True, pointwise=True),
}
