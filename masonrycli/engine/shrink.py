"""Shrinking sweeps: momentum's accelerated sweep (:mod:`masonrycli.engine.momentum`) that leaves out the
contacts found open at its first sweep, checking them every few sweeps and before it stops.

Measured on the 248-block wall's 1 s (benchmarks/bench_idle.py): 38.8 % of the accelerated sweep's contact
visits are idle (the local solve returns the extrapolated start: nothing pushed), 99 % of them open
contacts (an open contact stays open: 35.9 % of the visits follow ≥ 8 idle visits of the same contact),
and 31.8 % of the contacts are idle through their whole step. As in LIBLINEAR's shrinking, such contacts
need not be visited while they stay open. A quiet contact — r = r_prev = 0 after a visit — is left alone
exactly when its next visit would find it open, so:

* the sweeps visit only the contacts not quiet after the first sweep (the *active* ones), in the order
  of the full sweep, from compact copies of their rows (an index list read per visit cost 16 % more per
  visit than skipping saved; moving the quiet rows to the end of the rows changed the visit order, and
  with it the trajectory: 20 % more sweeps over wall-248's first 0.2 s);
* every ``check_every`` sweeps, and whenever a sweep meets the tolerance, a *check* computes the
  normal velocity of every left-out contact: open (u_n + max(g, 0)/dt ≥ 0) is exactly the outcome of
  its visit (r_y = 0, so the local solve's first test, and nothing pushed); a contact found closing
  joins the active ones (its visit is then the next sweep's, not this one's);
* a step stops only on a sweep that met the tolerance and whose check found every left-out contact
  open: that sweep is then the full sweep, every left-out visit done last, with the full sweep's
  residual (left-out contacts add e_α = 0), so the stopping test and the contact law at convergence are
  momentum's.

While no left-out contact closes, the sweeps are momentum's bit for bit (the active contacts' visits see
the same velocities, the left-out ones push nothing). The iterations count sweeps, as momentum's: the
stall window and the cap mean the same, and a partial sweep counts one.

Off by default (CHECK_EVERY = 0), measured (benchmarks/JOURNAL.md, "Shrinking sweeps"): with 16, 0.99× the
sweeps and 0.89× the first stage's CPU on wall-248's steps from the engine's warm starts, but that is ~8 %
of a step, within what any change of path moves one run by: on the benchmark's own wall-248 trajectory
10 % more sweeps ate it (2.33 → 2.37 CPU s per simulated s), and h32's 0.2 s met a stalled step of 93 427
units. It runs only as nlgs.solve's first stage.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine import momentum
from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import P_BIAS, P_WNN, P_WTN, P_WTT, _local_solve, _push, _relative_velocity

CHECK_EVERY = 0
"""Sweeps between checks of the left-out contacts in the engine's accelerated solve (0: no shrinking, every
sweep full: momentum's kernel)."""


@njit(inline="always")
def _sweep(body, pack, rr, status, n, v, beta, mu):
    # One accelerated sweep over rows [0, n): momentum._momentum_sweeps's contact loop (flip omitted),
    # the same operations in the same order. Returns Σ |e_α|².
    sum_e2 = 0.0
    for k in range(n):
        c = np.uint64(k)
        a = body[c, 0]
        b = body[c, 1]
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
    return sum_e2


@njit(inline="always")
def _compact(active, count, contact_body, pack, rr, status):
    # The rows of the active contacts, in row order: (rows, bodies, pack, rr, status) copies.
    n = 0
    for c in range(count):
        n += active[c]
    rows = np.empty(n, np.int64)
    body_a = np.empty((n, 2), contact_body.dtype)
    pack_a = np.empty((n, pack.shape[1]), np.float64)
    rr_a = np.empty((n, 4), np.float64)
    status_a = np.empty(n, status.dtype)
    i = 0
    for c in range(count):
        if active[c]:
            rows[i] = c
            body_a[i, 0] = contact_body[c, 0]
            body_a[i, 1] = contact_body[c, 1]
            for j in range(pack.shape[1]):  # element by element: numba's slice copy is slower (interleaved.py)
                pack_a[i, j] = pack[c, j]
            for j in range(4):
                rr_a[i, j] = rr[c, j]
            status_a[i] = status[c]
            i += 1
    return rows, body_a, pack_a, rr_a, status_a


@njit(inline="always")
def _write_back(rows, rr_a, status_a, rr, status):
    # _compact's inverse for what the sweeps change: rr and status of row rows[i] ← the copies' row i.
    for i in range(rows.shape[0]):
        c = rows[i]
        for j in range(4):
            rr[c, j] = rr_a[i, j]
        status[c] = status_a[i]


@njit(inline="always")
def _check(active, count, contact_body, pack, v):
    # Each left-out contact: open at velocities v (its visit would push nothing), or it joins the active
    # ones. Returns how many joined.
    joined = 0
    for c in range(count):
        if not active[c]:
            _, un = _relative_velocity(v, contact_body[c, 0], contact_body[c, 1], pack, c)
            if un + pack[c, P_BIAS] < 0.0:
                active[c] = True
                joined += 1
    return joined


@njit
def _nlgs_shrinking(contact_body, pack, count, mu, tolerance, max_iterations, v, r, status, stall_after, check_every):
    # momentum._momentum_sweeps (flip omitted) with the left-out contacts of the module doc:
    #   v ← v_free + M⁻¹ H r_warm ; β = 0 ; sweep 1 over every contact (momentum's first sweep)
    #   active ← contacts not quiet after it (r_n or r_prev,n ≠ 0); compact copies of their rows
    #   repeat:
    #       v ← v + β (v − v_prev) ; sweep the active rows (momentum's visit)
    #       if the sweep met the tolerance or check_every sweeps since the last check:
    #           check the left-out contacts (open at v?); any closing → active, copies rebuilt
    #           stop if the sweep met the tolerance and none closed
    #       stall window, restart, β as momentum's
    for c in range(count):
        _push(v, contact_body[c, 0], contact_body[c, 1], pack, np.uint64(c), r[c, 0], r[c, 1])
    if count == 0:
        return 0, 0.0
    v_prev = v.copy()
    v_flat = v.reshape(v.size)
    v_prev_flat = v_prev.reshape(v.size)
    rr = np.empty((count, 4), np.float64)
    for c in range(count):
        rr[c, 0] = rr[c, 2] = r[c, 0]
        rr[c, 1] = rr[c, 3] = r[c, 1]
    momentum._extrapolate(v_flat, v_prev_flat, 0.0)  # β = 0: v_prev ← v, as momentum's first sweep
    residual = np.sqrt(_sweep(contact_body, pack, rr, status, count, v, 0.0, mu) / count)
    iterations = 1
    active = np.empty(count, np.bool_)
    for c in range(count):
        active[c] = rr[c, 1] != 0.0 or rr[c, 3] != 0.0
    rows, body_a, pack_a, rr_a, status_a = _compact(active, count, contact_body, pack, rr, status)
    best = np.inf
    best_at = 0
    last = np.inf
    j = 1
    since = 0
    it = 0
    while True:  # the bookkeeping after sweep `it` (0: the full first sweep), then sweep it + 1
        met = residual <= tolerance
        since += 1
        if met or since >= check_every:
            since = 0
            if _check(active, count, contact_body, pack, v) > 0:
                _write_back(rows, rr_a, status_a, rr, status)
                rows, body_a, pack_a, rr_a, status_a = _compact(active, count, contact_body, pack, rr, status)
            elif met:
                break
        if iterations >= max_iterations:
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
        momentum._extrapolate(v_flat, v_prev_flat, beta)
        residual = np.sqrt(_sweep(body_a, pack_a, rr_a, status_a, rows.shape[0], v, beta, mu) / count)
        iterations += 1
        it += 1
    _write_back(rows, rr_a, status_a, rr, status)
    for c in range(count):
        r[c, 0] = rr[c, 0]
        r[c, 1] = rr[c, 1]
    return iterations, residual
