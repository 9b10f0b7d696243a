"""Gauss–Seidel in body order with momentum: the first method of a stalled solve.

The engine's sweeps visit the contacts in detection order (interleaved.py; lanes.py). Here a
sweep goes through the bodies in turn and visits, for each body with mass, every contact of that body:
a contact between two blocks is visited twice in a sweep (once from each block), a contact with a
support once. So each block's corners are solved one after the other with the block's velocity fresh,
and the load a block takes from below is passed on to the blocks it carries before the sweep leaves the
block. Each sweep starts from a Nesterov extrapolation of the last two sweeps' impulses and velocities,
restarted when the residual grows by more than momentum.RESTART_GROWTH, as in
:mod:`masonrycli.engine.momentum` (the extrapolation is applied to every contact and body at the sweep's
start, so v stays v_free + M⁻¹ H r).

Why: on the hard steps of the 32- and 64-course walls (tall walls sliding on their base, where momentum in
detection order cycles between stick and slip), alone from the step's warm start, this converges all 64
captured steps in 150 139 sweep units, where the engine took 956 975 and the best of stalled.py's methods
alone converge 54 (benchmarks/JOURNAL.md, "New methods on hard steps"). What matters is the second visit:
detection order is already sorted by each contact's lower body, so momentum in detection order is this body
order with each contact visited once, from its lower body, and it converges 19. On ordinary steps it takes
1.36–1.42× momentum's units at 1.3–1.4× the CPU per unit (the indirect visit order): it is for stalled
steps only.

It can stop on a step where it cycles (the 248-block wall's hard steps): after a few windows of sweeps whose
residual level stays well above its lowest residual (_cycling_windows; stalled.py's module doc, "Hand-over";
sooner when the stage stays far from the tolerance or its level far above its low: "Sooner"), and go on
later from where it stopped, as one long run would (Stage: stalled.py's "Re-entry").

The residual is the engine's (nlgs module doc): RMS over the contacts of |W_αα Δr_α| at the contact's
first visit in the sweep. Work is counted in sweep units, contact visits / C (a sweep is ~1.9 units on a
wall: every block–block contact twice).
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine import momentum  # its RESTART_GROWTH; a module import, as momentum imports nlgs
from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import (
    P_IIA,
    P_IIB,
    P_IMA,
    P_IMB,
    P_WNN,
    P_WTN,
    P_WTT,
    _local_solve,
    _push,
    _relative_velocity,
)

C_SWEEP, C_J, C_LAST, C_BEST, C_BEST_AT, C_BETA, C_RESIDUAL, C_REASON, C_WINDOW = range(9)
"""Slots of a stage's carry (float array of CARRY_SIZE): sweeps done, the momentum counter j, the last
residual, the lowest and its sweep, β of the next sweep, the residual, why it stopped (STOP_*), and
_cycling_windows' [log_sum, n, run, strong run] from C_WINDOW on. All a later call needs to go on as one long call."""
CARRY_SIZE = C_WINDOW + 4
STOP_BUDGET, STOP_TOLERANCE, STOP_STALL, STOP_CYCLING = range(4)
"""carry[C_REASON]: the budget ran out (or max_units ≤ 0), the tolerance was met, the stall window, the
hand-over rule (cycling windows)."""


@njit
def _body_lists(contact_body, pack, count, bodies):
    # CSR lists of each body's contacts, for the bodies with mass (a support's inverse mass and inertia are
    # 0 in its rows: it has no list), contacts in their order. Returns (start (B + 1,), members).
    start = np.empty(bodies + 1, np.int64)
    start[:] = 0
    for c in range(count):
        if pack[c, P_IMA] > 0.0 or pack[c, P_IIA] > 0.0:
            start[contact_body[c, 0] + 1] += 1
        if pack[c, P_IMB] > 0.0 or pack[c, P_IIB] > 0.0:
            start[contact_body[c, 1] + 1] += 1
    for i in range(bodies):
        start[i + 1] += start[i]
    members = np.empty(start[bodies], np.int64)
    fill = start[:bodies].copy()
    for c in range(count):
        if pack[c, P_IMA] > 0.0 or pack[c, P_IIA] > 0.0:
            members[fill[contact_body[c, 0]]] = c
            fill[contact_body[c, 0]] += 1
        if pack[c, P_IMB] > 0.0 or pack[c, P_IIB] > 0.0:
            members[fill[contact_body[c, 1]]] = c
            fill[contact_body[c, 1]] += 1
    return start, members


@njit(inline="always")
def _cycling_windows(window_state, residual, best, window, level, strong):
    # The hand-over test (stalled.py's module doc, "Hand-over"): after each sweep,
    #   log_sum += log(residual) ; n += 1
    #   at the window's end (n = window): g = exp(log_sum / window), the window's level (geometric mean of
    #       its residuals); the window cycles if g > level × best (best: the lowest residual so far);
    #       run = run + 1 if it cycles, else 0; strong run likewise with g > strong × best;
    #       log_sum = n = 0
    # window_state = [log_sum, n, run, strong run]; returns run, the cycling windows in a row.
    # Why the level and not the lowest residual: a step that cycles dips now and then to a new low by a
    # hair, which restarts a stall window, while its level stays 2-5x above that low; a step that
    # converges slowly keeps its level near its low.
    window_state[0] += np.log(residual)
    window_state[1] += 1.0
    if window_state[1] >= window:
        g = np.exp(window_state[0] / window)
        if g > level * best:
            window_state[2] += 1.0
        else:
            window_state[2] = 0.0
        if g > strong * best:
            window_state[3] += 1.0
        else:
            window_state[3] = 0.0
        window_state[0] = 0.0
        window_state[1] = 0.0
    return window_state[2]


@njit
def _body_order_sweeps(
    contact_body,
    pack,
    count,
    mu,
    tolerance,
    max_units,
    v,
    r,
    status,
    stall,
    window,
    level,
    cycling,
    far,
    strong,
    far_cycling,
    history,
    carry,
    r_prev,
    v_prev,
):
    # v enters as v_free, r as the start; both leave consistent (v = v_free + M⁻¹ H r).
    # Or it goes on where an earlier call stopped (carry[C_SWEEP] > 0: stalled.py re-enters the stage after a
    # hand-over): v, r, r_prev, v_prev and carry as that call left them, v not rebuilt (rebuilding it from
    # v_free would round differently, and the resumed sweeps would not be the ones one long call makes).
    #   v ← v_free + M⁻¹ H r ; order = for each body with mass, its contacts (CSR lists) ; β = 0
    #   repeat (one sweep):
    #       r ← r + β (r − r_prev), v ← v + β (v − v_prev)                    (every contact and body)
    #       for α in order: r_α' = local_solve(H_αᵀ v − W r_α) ; v += M⁻¹ H_α (r_α' − r_α) ; r_α = r_α'
    #                       e_α = W (r_α' − r_α) counts in the residual at α's first visit in the sweep
    #       residual = sqrt(Σ e_α² / C)
    #       until residual ≤ tolerance, max_units sweep units (visits / C), stall sweeps without a new
    #       lowest residual, or `cycling` windows of `window` sweeps in a row whose level is above
    #       level × the lowest residual (_cycling_windows; cycling = 0: never), or `far_cycling` such
    #       windows in a row while the lowest residual is above far × tolerance, or `far_cycling` windows
    #       in a row whose level is above strong × the lowest (far_cycling = 0: never);
    #       restart (β = 0) when the residual grows by > RESTART_GROWTH
    # Every contact is visited in a sweep (one of its bodies has mass), so the extrapolated impulses,
    # which may leave the friction cone, are all replaced by local solutions before the sweep ends.
    # history (the lab's instrument): the residual of sweep s goes to history[s] while s < its length.
    # Returns (sweep units, rounded up; residual).
    # The visit is nlgs's written out again, as in momentum.py and faces.py: a shared visit function cost
    # 47–57 ns per visit against 8.7 inline (faces.py's measurement).
    if count == 0:
        return 0, 0.0
    sweep = int(carry[C_SWEEP])
    if sweep == 0:
        for c in range(count):
            _push(v, contact_body[c, 0], contact_body[c, 1], pack, c, r[c, 0], r[c, 1])
        r_prev[:count] = r[:count]
        v_prev[:] = v
        carry[C_J] = 1.0
        carry[C_LAST] = np.inf
        carry[C_BEST] = np.inf
        carry[C_BEST_AT] = 0.0
        carry[C_BETA] = 0.0
        carry[C_WINDOW : C_WINDOW + 4] = 0.0
    start, members = _body_lists(contact_body, pack, count, v.shape[0])
    visits_per_sweep = members.shape[0]
    seen = np.empty(count, np.int64)
    seen[:] = -1
    v_flat = v.reshape(v.size)
    v_prev_flat = v_prev.reshape(v.size)
    beta = carry[C_BETA]
    j = int(carry[C_J])
    last = carry[C_LAST]
    best = carry[C_BEST]
    best_at = int(carry[C_BEST_AT])
    window_state = carry[C_WINDOW : C_WINDOW + 4]  # a view: _cycling_windows updates carry
    residual = np.inf if sweep == 0 else carry[C_RESIDUAL]  # no sweep done (max_units ≤ 0): nothing is known
    reason = STOP_BUDGET
    visits = 0
    while visits < max_units * count:
        for i in range(v_flat.shape[0]):
            x = v_flat[i]
            v_flat[i] = x + beta * (x - v_prev_flat[i])
            v_prev_flat[i] = x
        for c in range(count):
            for k in range(2):
                x = r[c, k]
                r[c, k] = x + beta * (x - r_prev[c, k])
                r_prev[c, k] = x
        sum_e2 = 0.0
        for m in range(visits_per_sweep):
            # unsigned, as the interleaved sweeps' row index: no wrap-around test per row access (5 % of the
            # stage's CPU on wall-248's stalled steps), and their compiled _push and _relative_velocity
            c = np.uint64(members[m])
            a = contact_body[c, 0]
            b = contact_body[c, 1]
            ut, un = _relative_velocity(v, a, b, pack, c)
            rt0 = r[c, 0]
            rn0 = r[c, 1]
            wtt = pack[c, P_WTT]
            wtn = pack[c, P_WTN]
            wnn = pack[c, P_WNN]
            ut -= wtt * rt0 + wtn * rn0
            un -= wtn * rt0 + wnn * rn0
            rt, rn, st = _local_solve(ut, un, pack, c, mu)
            status[c] = st
            drt = rt - rt0
            drn = rn - rn0
            e2 = 0.0
            if drt != 0.0 or drn != 0.0:
                _push(v, a, b, pack, c, drt, drn)
                r[c, 0] = rt
                r[c, 1] = rn
                et = wtt * drt + wtn * drn
                en = wtn * drt + wnn * drn
                e2 = et * et + en * en
            if seen[c] != sweep:
                seen[c] = sweep
                sum_e2 += e2
        visits += visits_per_sweep
        sweep += 1
        residual = np.sqrt(sum_e2 / count)
        if sweep <= history.shape[0]:
            history[sweep - 1] = residual
        # the next sweep's extrapolation, set before the stopping tests so that carry holds it at any stop
        if residual > momentum.RESTART_GROWTH * last:
            j = 1
        last = residual
        beta = (j - 1.0) / (j + 2.0)
        j += 1
        if residual <= tolerance:
            reason = STOP_TOLERANCE
            break
        if residual < best:
            best = residual
            best_at = sweep
        elif sweep - best_at >= stall:
            reason = STOP_STALL
            break
        if cycling > 0:
            run = _cycling_windows(window_state, residual, best, window, level, strong)
            fast = run >= far_cycling and best > far * tolerance or window_state[3] >= far_cycling
            if run >= cycling or (far_cycling > 0 and fast):
                reason = STOP_CYCLING
                break
    carry[C_SWEEP] = sweep
    carry[C_J] = j
    carry[C_LAST] = last
    carry[C_BEST] = best
    carry[C_BEST_AT] = best_at
    carry[C_BETA] = beta
    carry[C_RESIDUAL] = residual
    carry[C_REASON] = reason
    return (visits + count - 1) // count, residual


_NO_HISTORY = np.empty(0)


def body_order_sweeps(
    contact_body,
    pack,
    count,
    mu,
    tolerance,
    max_units,
    v,
    r,
    status,
    stall,
    window=1,
    level=np.inf,
    cycling=0,
    history=_NO_HISTORY,
    stage=None,
    far=np.inf,
    far_cycling=0,
    strong=np.inf,
) -> tuple[int, float]:
    """Momentum sweeps in body order (module doc) from impulses ``r`` (C, 2), in place; ``v`` (B, 3) enters
    as the free velocities and leaves as v_free + M⁻¹ H r; ``status`` (C,) out. Stops at ``tolerance``
    (m/s), after ``max_units`` sweep units (the sweep that crosses it ends), after ``stall`` sweeps
    without a new lowest residual, or after ``cycling`` windows of ``window`` sweeps in a row whose level
    (geometric mean of their residuals) is above ``level`` × the lowest residual so far (0: never), or after
    ``far_cycling`` such windows when that lowest residual is still above ``far`` × ``tolerance``, or after
    ``far_cycling`` windows in a row whose level is above ``strong`` × the lowest (0: never; counted only
    while ``cycling`` > 0).
    ``history`` (float array, optional): the residual of each sweep, as many as it holds. ``stage``
    (optional, from new_stage): the run's state; a call with the ``stage``, ``v``, ``r`` and ``status``
    an earlier call left goes on from where it stopped, as one long call would (its stall window too;
    ``stage.carry[C_REASON]`` says why a call stopped). Returns (sweep units done, residual m/s)."""
    if stage is None:
        stage = new_stage(count, v.shape[0])
    return _body_order_sweeps(
        contact_body,
        pack,
        count,
        mu,
        tolerance,
        max_units,
        v,
        r,
        status,
        stall,
        window,
        level,
        cycling,
        far,
        strong,
        far_cycling,
        history,
        stage.carry,
        stage.r_prev,
        stage.v_prev,
    )


class Stage:
    """A run of the stage that can go on: its carry (C_* slots) and the impulses and velocities of the sweep
    before the last (the extrapolation's). Its iterate (v, r, status) is the caller's."""

    __slots__ = ("carry", "r_prev", "v_prev")

    def __init__(self, count: int, bodies: int):
        self.carry = np.zeros(CARRY_SIZE)
        self.r_prev = np.zeros((count, 2))
        self.v_prev = np.zeros((bodies, 3))


def new_stage(count: int, bodies: int) -> Stage:
    """A stage not yet run (carry[C_SWEEP] = 0: the first call builds v from v_free)."""
    return Stage(count, bodies)
