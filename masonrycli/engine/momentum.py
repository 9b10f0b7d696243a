"""Gauss–Seidel with momentum: the sweep of solvers "nlgs-accel" and "nlgs-accel32" (the default).

This module's kernel is the scalar sweep in the engine's interleaved order (4 runs): stalled.py's momentum
stages use it, and the first stage did until :mod:`masonrycli.engine.lane_sweeps` (the same rule, 8 runs,
8 contacts visited at once in vectors) replaced it there (``Tuning.lanes``).

Each sweep of :mod:`masonrycli.engine.nlgs` starts from a Nesterov extrapolation of the last two sweeps'
impulses and velocities; the momentum is dropped whenever a sweep's residual grows by more than
RESTART_GROWTH (adaptive restart). The contact law, the local solve, the residual and the stopping test
are nlgs's, and a step still ends on a sweep, so what a converged step satisfies is unchanged; only the
path is shorter (pseudo-code above _momentum_sweeps):

    repeat: (r, v) ← (r, v) + β (r − r_prev, v − v_prev);  the sweep of nlgs from there
            stop at the tolerance, or after stall_after sweeps without a new lowest residual
            a residual > RESTART_GROWTH × the last: j = 1;  β = (j − 1)/(j + 2), j += 1

Why momentum works here: Gauss–Seidel moves load through a stack of hyperstatic joints about one course
per sweep, so on a wall of N courses its error decays like a diffusion, ~N² sweeps per decade. Nesterov's
extrapolation turns that into ~N on linear problems; the restart keeps it safe where the nonsmooth law
switches a contact between open, stick and slip (a sweep whose residual jumps has just crossed one).
Measured on captured steps: 2.5–4.6× fewer sweeps on walls of 8–32 courses at the same distance from a
1e-9 m/s reference, one accelerated sweep costing ~1.2× a plain one (benchmarks/JOURNAL.md, "nlgs-accel:
Gauss–Seidel with Nesterov momentum").

Stall window: on tall sliding walls momentum can drive a step into a stick/slip cycle where its residual
wanders above the tolerance. So a solve stops after Tuning.first_stall accelerated sweeps without a new lowest
residual, and dispatch.solve hands the step to :mod:`masonrycli.engine.stalled` (whose body-order stage
finishes almost every such step from the warm start). 200 rather than 500 gets the step there sooner:
ensembles of 48 runs, mean sweep units a step 0.614× on the 32-course wall ("Momentum's stall window and
the round-robin's order").

Near the tolerance: a step handed over is solved again from its warm start, so a first stage that stalls
just above the tolerance throws its progress away. So once its lowest residual is within NEAR × the
tolerance, the float64 part of the default's first stage (lane_sweeps32.first_stage: lane_sweeps._lane_sweeps
after the float32 sweeps) waits stall_near(model, tuning) = max(Tuning.first_stall, STALL_NEAR × Model.block_depth) sweeps
for a new low: the plateaus of momentum are longer on deeper structures, as load moves about one block a
sweep (the depth, not the contact count: long low walls have the contacts of tall ones). Replayed, the
64-course wall's 177 steps of ≥ 2500 units: 1 319 183 units at window 200, 915 518 at 2000 ("Near the
tolerance: the first stage waits longer").
"nlgs-accel" (the float64 path) and the lab lever Tuning.lanes = False keep the
plain window.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import kernel_only, njit
from masonrycli.engine.nlgs import P_WNN, P_WTN, P_WTT, _local_solve, _push, _relative_velocity
from masonrycli.engine.tuning import TUNING

RESTART_GROWTH = TUNING.lane_growth
"""The accelerated sweep drops its momentum when a sweep's residual exceeds the previous one by this factor
(1.3 or more diverges on the 248-block wall; 1.05–1.2 all converge): the shipped Tuning.lane_growth, compiled
into this module's sweep and the body-order stage's (the lane sweeps take Tuning.lane_growth as an argument)."""
NEAR = 3.0
"""× the tolerance: a first stage whose lowest residual is this close waits stall_near(model) sweeps without a new
low instead of Tuning.first_stall before it hands the step over (module doc, "Near the tolerance")."""
STALL_NEAR = 25.0
"""The first stage's stall window once its lowest residual is within NEAR × the tolerance, in sweeps per block
of the structure's depth (Model.block_depth, at least Tuning.first_stall): 400 sweeps on the 16-course 248-block
wall, 1600 on the 64-course wall; 200, as before, on walls of 8 courses or fewer however long."""


def stall_near(model, tuning=TUNING) -> int:
    """Sweeps the first stage waits for a new low once it is within NEAR × the tolerance (module doc); a model
    without ``block_depth`` (the lab's replays of older captures) keeps ``tuning.first_stall``."""
    return max(tuning.first_stall, int(STALL_NEAR * getattr(model, "block_depth", 0.0)))


@kernel_only
def _extrapolate(x, x_prev, beta):
    # x ← x + β (x − x_prev), x_prev ← old x, element by element (the bodies' velocities, once a sweep).
    # Its own function: compiled apart from the sweep, LLVM vectorises the loop (several doubles an
    # operation, each lane the same IEEE operations, so the same bits); inside the sweep it stayed scalar.
    # 3 % less time per contact·sweep on wall-248 (762 velocities against 1233 contacts a sweep).
    for i in range(x.shape[0]):
        xi = x[i]
        x[i] = xi + beta * (xi - x_prev[i])
        x_prev[i] = xi


@njit
def _nlgs_accelerated(contact_body, pack, count, mu, tolerance, max_iterations, v, r, status, stall_after, flip=False):
    # _momentum_sweeps with v viewed flat here (tests, the solver lab). The engine's launcher passes a view
    # numpy made instead: numba's reshape compiles a shape check, 0.35 s of a first run's CPU.
    v_flat = v.reshape(v.size)
    return _momentum_sweeps(
        contact_body, pack, count, mu, tolerance, max_iterations, v, v_flat, r, status, stall_after, flip
    )


@kernel_only
def _momentum_sweeps(
    contact_body, pack, count, mu, tolerance, max_iterations, v, v_flat, r, status, stall_after, flip=False
):
    # _nlgs with Nesterov momentum and adaptive restart; its contact loop is _nlgs's written out again with
    # the extrapolated start (a shared visit function cost 47–57 ns per visit against 8.7 inline: faces.py).
    # x_k: the (r, v) a sweep leaves. The next sweep starts from the extrapolated
    # y_k = x_k + β_k (x_k − x_k−1), β_k = (j − 1)/(j + 2), j counting the sweeps since the last restart; a sweep whose residual grows by more than RESTART_GROWTH restarts
    # (j = 1, β = 0: a plain sweep). v is linear in r (v = v_free + M⁻¹ H r), so extrapolating the
    # bodies' v and each contact's r alike keeps the pair consistent, and no projection is needed: the
    # visit replaces r_α by its local solution, which is in the cone, and the step ends on a sweep.
    #   v ← v_free + M⁻¹ H r_warm ; β = 0
    #   repeat:
    #       v ← v + β (v − v_prev), v_prev ← old v                         (bodies)
    #       for α in order: r_y = r_α + β (r_α − r_prev,α), r_prev,α ← r_α
    #                       the visit of _nlgs from r_y (e_α = W_αα (r_α' − r_y))
    #       residual and stopping as in _nlgs, the stall rule with a window of stall_after sweeps (then
    #       dispatch.solve hands the step to stalled.py); then j, β from the restart rule, and with flip the
    #       sweep order reverses at each restart (stalled.py's "turning" method)
    for c in range(count):
        # c unsigned as in the sweep below: one compiled _push serves both
        _push(v, contact_body[c, 0], contact_body[c, 1], pack, np.uint64(c), r[c, 0], r[c, 1])
    iterations = 0
    residual = 0.0
    if count == 0:
        return iterations, residual
    # v_flat: v viewed as (3B,), so that the extrapolation of the bodies is one flat loop (_extrapolate)
    v_prev_flat = v_flat.copy()
    # The sweep keeps each contact's (r_t, r_n, r_prev,t, r_prev,n) in one row of rr: one array fewer to
    # address in the contact loop (1–2 % less time per contact·sweep), r copied back at the end.
    rr = np.empty((count, 4), np.float64)
    for c in range(count):
        rr[c, 0] = rr[c, 2] = r[c, 0]
        rr[c, 1] = rr[c, 3] = r[c, 1]
    best = np.inf
    best_at = 0
    last = np.inf
    j = 1
    beta = 0.0
    first, step = 0, 1
    for it in range(max_iterations):
        iterations = it + 1
        _extrapolate(v_flat, v_prev_flat, beta)
        sum_e2 = 0.0
        for k in range(count):
            # unsigned: numba drops the negative-index wrap-around of every row access, and LLVM walks the
            # rows by pointer increments. Matters when flip is passed (stalled.py's turning: 7 % less time
            # per contact·sweep on wall-248's steps); with flip omitted LLVM had already proved c ≥ 0.
            c = np.uint64(first + step * k)
            a = contact_body[c, 0]
            b = contact_body[c, 1]
            ut, un = _relative_velocity(v, a, b, pack, c)
            xt = rr[c, 0]
            xn = rr[c, 1]
            rt0 = xt + beta * (xt - rr[c, 2])
            rn0 = xn + beta * (xn - rr[c, 3])
            rr[c, 2] = xt
            rr[c, 3] = xn
            wtt = pack[c, P_WTT]
            wtn = pack[c, P_WTN]
            wnn = pack[c, P_WNN]
            ut -= wtt * rt0 + wtn * rn0
            un -= wtn * rt0 + wnn * rn0
            rt, rn, st = _local_solve(ut, un, pack, c, mu)
            status[c] = st
            rr[c, 0] = rt
            rr[c, 1] = rn
            drt = rt - rt0
            drn = rn - rn0
            if drt != 0.0 or drn != 0.0:
                _push(v, a, b, pack, c, drt, drn)
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
        if residual > RESTART_GROWTH * last:
            j = 1
            if flip:  # stalled.py: the sweep direction turns at every restart
                first, step = (count - 1, -1) if step == 1 else (0, 1)
        last = residual
        beta = (j - 1.0) / (j + 2.0)
        j += 1
    for c in range(count):
        r[c, 0] = rr[c, 0]
        r[c, 1] = rr[c, 1]
    return iterations, residual
