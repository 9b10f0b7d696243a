"""Gauss–Seidel sweep variants for stalled steps: under-relaxation, other sweep orders, whole bodies.

A step whose accelerated solve stalls (:mod:`masonrycli.engine.stalled`) is on a tall sliding wall where
one-way sweeps can cycle: a block lifts one corner of its bed joint, the other corner takes the load, the
block slides back. Three ways of breaking such a cycle that the round-robin of stalled.py does not try,
written as one kernel each so that the solver lab can run them alone on captured hard steps
(benchmarks/solver_lab/hard_methods.py; figures in benchmarks/JOURNAL.md, "New methods on hard steps"):

* under-relaxation (``omega`` < 1): r_α ← r_α + ω (r_α^loc − r_α), which stays in the friction cone
  (a convex combination of two points of it), plain or after a Nesterov extrapolation as in
  :mod:`masonrycli.engine.momentum` (then projected into the cone, the extrapolation can leave it);
  ``adaptive``: ω per contact, halved (down to ``omega``) whenever the contact's status changes from
  one sweep to the next and raised back towards 1 (× ADAPT_RAISE) while it does not: damping the
  contacts that flip only;
* other orders: alternating direction, direction turning at momentum's restarts, a new pseudo-random
  permutation of the contacts every sweep (xorshift seeded by ``seed``: deterministic), or of the faces
  (runs of consecutive contacts with one body pair), each face's points in their order;
* body-wise block Gauss–Seidel (:func:`body_sweeps`): the bodies in turn, all contacts of one body
  solved together by inner point rounds until a round moves less than ``inner_drop`` of the first.

The residual is the engine's (nlgs module doc): RMS over the contacts of |W_αα (r_α^loc − r_α)| at the
contact's first visit in a sweep, where r_α is the (extrapolated) impulse the visit starts from; a relaxed
sweep has the same fixed points as a plain one, so this residual reaching 0 means the law holds. A solve
that meets the tolerance on a relaxed sweep goes on with ω = 1 until an unrelaxed sweep meets it, so that
the step ends, as in the engine, on a sweep that replaced every r_α by its local solution. Work is
counted in sweep units (contact visits / C).
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import njit
from masonrycli.engine.bodies import _body_lists
from masonrycli.engine.momentum import RESTART_GROWTH
from masonrycli.engine.nlgs import (
    P_WNN,
    P_WTN,
    P_WTT,
    _local_solve,
    _push,
    _relative_velocity,
)

ORDER_FORWARD, ORDER_ALTERNATE, ORDER_TURN, ORDER_RANDOM, ORDER_RANDOM_FACES = 0, 1, 2, 3, 4
"""Sweep orders of :func:`variant_sweeps` (module doc)."""
ADAPT_RAISE = 1.25
"""adaptive: a contact's ω is multiplied by this (up to 1) after each sweep in which its status holds."""


@njit
def _xorshift(state):
    # xorshift64: a deterministic generator independent of numba's and numpy's.
    x = state[0]
    x ^= (x << np.uint64(13)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    x ^= x >> np.uint64(7)
    x ^= (x << np.uint64(17)) & np.uint64(0xFFFFFFFFFFFFFFFF)
    state[0] = x
    return x


@njit
def _shuffle(items, n, state):
    # Fisher–Yates on items[:n].
    for i in range(n - 1, 0, -1):
        j = np.int64(_xorshift(state) % np.uint64(i + 1))
        items[i], items[j] = items[j], items[i]


@njit
def _variant_sweeps(
    contact_body, pack, count, mu, tolerance, max_units, v, r, status, omega, accelerate, order, seed, adaptive, stall
):
    # v enters as v_free, r as the start; both leave consistent (v = v_free + M⁻¹ H r).
    #   v ← v_free + M⁻¹ H r ; w_α = ω (adaptive: 1) ; β = 0
    #   repeat (one sweep):
    #       perm ← the sweep's order (forward / reversed every sweep / reversed at restarts / shuffled
    #              contacts / shuffled faces)
    #       accelerate: v ← v + β (v − v_prev)
    #       for α in perm: y_α = r_α (+ β (r_α − r_prev,α)) ; r^loc = local_solve(H_αᵀ v − W y_α)
    #                      e_α = W (r^loc − y_α)                       (the engine's residual term)
    #                      r_α = y_α + w_α (r^loc − y_α), projected into the cone if accelerated
    #                      v += M⁻¹ H_α (r_α − y_α)
    #                      adaptive: w_α ← max(w_α / 2, ω) if α's status changed, else min(1, w_α ADAPT_RAISE)
    #       residual = sqrt(Σ e_α² / C); met on a relaxed sweep → ω = 1 from now (finish on a plain one)
    #       until met, max_units sweeps, or stall sweeps without a new lowest residual
    #       restart (β = 0, j = 1; ORDER_TURN reverses) when the residual grows by > RESTART_GROWTH
    # Returns (sweep units, residual).
    for c in range(count):
        _push(v, contact_body[c, 0], contact_body[c, 1], pack, c, r[c, 0], r[c, 1])
    if count == 0:
        return 0, 0.0
    perm = np.arange(count)
    starts = np.empty(count + 1, dtype=np.int64)  # faces: runs of one body pair
    faces = 0
    for c in range(count):
        if c == 0 or contact_body[c, 0] != contact_body[c - 1, 0] or contact_body[c, 1] != contact_body[c - 1, 1]:
            starts[faces] = c
            faces += 1
    starts[faces] = count
    face_perm = np.arange(faces)
    state = np.array([np.uint64(seed) * np.uint64(2654435761) + np.uint64(88172645463325252)], dtype=np.uint64)
    w = np.full(count, 1.0 if adaptive else omega)
    r_prev = r[:count].copy()
    v_prev = v.copy()
    v_flat = v.reshape(v.size)
    v_prev_flat = v_prev.reshape(v.size)
    relaxed = omega < 1.0
    best = np.inf
    best_at = 0
    last = np.inf
    j = 1
    beta = 0.0
    reverse = False
    residual = 0.0
    sweeps = 0
    while sweeps < max_units:
        if order == ORDER_ALTERNATE:
            reverse = sweeps % 2 == 1
        if order == ORDER_RANDOM:
            _shuffle(perm, count, state)
        elif order == ORDER_RANDOM_FACES:
            _shuffle(face_perm, faces, state)
            k = 0
            for f in range(faces):
                for c in range(starts[face_perm[f]], starts[face_perm[f] + 1]):
                    perm[k] = c
                    k += 1
        if accelerate:
            for i in range(v_flat.shape[0]):
                x = v_flat[i]
                v_flat[i] = x + beta * (x - v_prev_flat[i])
                v_prev_flat[i] = x
        sum_e2 = 0.0
        for k in range(count):
            c = perm[count - 1 - k] if reverse else perm[k]
            a = contact_body[c, 0]
            b = contact_body[c, 1]
            ut, un = _relative_velocity(v, a, b, pack, c)
            yt = r[c, 0]
            yn = r[c, 1]
            if accelerate:
                xt, xn = yt, yn
                yt = xt + beta * (xt - r_prev[c, 0])
                yn = xn + beta * (xn - r_prev[c, 1])
                r_prev[c, 0] = xt
                r_prev[c, 1] = xn
            wtt = pack[c, P_WTT]
            wtn = pack[c, P_WTN]
            wnn = pack[c, P_WNN]
            ut -= wtt * yt + wtn * yn
            un -= wtn * yt + wnn * yn
            lt, ln, st = _local_solve(ut, un, pack, c, mu)
            if adaptive and relaxed:
                if st != status[c]:
                    w[c] = max(0.5 * w[c], omega)
                else:
                    w[c] = min(1.0, w[c] * ADAPT_RAISE)
            status[c] = st
            wc = w[c] if relaxed else 1.0
            rt = yt + wc * (lt - yt)
            rn = yn + wc * (ln - yn)
            if accelerate and wc < 1.0:  # y may lie outside the cone; r^loc does not
                if rn < 0.0:
                    rn = 0.0
                lim = mu * rn
                if rt > lim:
                    rt = lim
                elif rt < -lim:
                    rt = -lim
            r[c, 0] = rt
            r[c, 1] = rn
            drt = rt - yt
            drn = rn - yn
            if drt != 0.0 or drn != 0.0:
                _push(v, a, b, pack, c, drt, drn)
            et = wtt * (lt - yt) + wtn * (ln - yn)
            en = wtn * (lt - yt) + wnn * (ln - yn)
            sum_e2 += et * et + en * en
        sweeps += 1
        residual = np.sqrt(sum_e2 / count)
        if residual <= tolerance:
            if not relaxed:
                break
            relaxed = False  # finish on an unrelaxed sweep (module doc)
        if residual < best:
            best = residual
            best_at = sweeps
        elif sweeps - best_at >= stall:
            break
        if accelerate:
            if residual > RESTART_GROWTH * last:
                j = 1
                if order == ORDER_TURN:
                    reverse = not reverse
            last = residual
            beta = (j - 1.0) / (j + 2.0)
            j += 1
    return sweeps, residual


def variant_sweeps(
    contact_body,
    pack,
    count,
    mu,
    tolerance,
    max_units,
    v,
    r,
    status,
    omega=1.0,
    accelerate=False,
    order=ORDER_FORWARD,
    seed=0,
    adaptive=False,
    stall=10_000,
) -> tuple[int, float]:
    """Sweeps of a variant (module doc) from impulses ``r`` (C, 2), in place; ``v`` (B, 3) enters as the free
    velocities and leaves as v_free + M⁻¹ H r; ``status`` (C,) int8 in (adaptive: the statuses the first
    sweep compares with) and out. Stops at ``tolerance`` (m/s), ``max_units`` sweeps, or ``stall`` sweeps
    without a new lowest residual. Returns (sweep units, residual m/s)."""
    return _variant_sweeps(
        contact_body,
        pack,
        count,
        mu,
        tolerance,
        max_units,
        v,
        r,
        status,
        omega,
        accelerate,
        order,
        seed,
        adaptive,
        stall,
    )


@njit
def _body_sweeps(
    contact_body, pack, count, mu, tolerance, max_units, v, r, status, rounds, drop, alternate, stall, accelerate=False
):
    # v enters as v_free, r as the start; both leave consistent.
    #   groups: for each body with mass (a support's inverse mass is 0 in its rows), its contacts
    #   repeat (one sweep; alternate: bodies in reverse order every second sweep):
    #       for each body: point rounds over its contacts (visit = nlgs's) while a round moves
    #                      Σ|W Δr|² > drop × the first round's, at most ``rounds``
    #                      (a contact's e_α counts in the residual at its first visit in the sweep)
    #   until residual ≤ tolerance, max_units sweep units, or stall sweeps without a new low.
    #   accelerate: each sweep starts from r ← r + β (r − r_prev), v ← v + β (v − v_prev) (all contacts and
    #   bodies at once, so v stays v_free + M⁻¹ H r), β and its restart as in momentum.py.
    for c in range(count):
        _push(v, contact_body[c, 0], contact_body[c, 1], pack, c, r[c, 0], r[c, 1])
    if count == 0:
        return 0, 0.0
    bodies = v.shape[0]
    degree, members = _body_lists(contact_body, pack, count, bodies)  # the engine's CSR lists (bodies.py)
    seen = np.full(count, -1, dtype=np.int64)
    r_prev = r[:count].copy()
    v_prev = v.copy()
    v_flat = v.reshape(v.size)
    v_prev_flat = v_prev.reshape(v.size)
    beta = 0.0
    j = 1
    last = np.inf
    visits = 0
    residual = 0.0
    best = np.inf
    best_at = 0
    sweep = 0
    while visits < max_units * count:
        if accelerate:
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
        for i in range(bodies):
            body = bodies - 1 - i if alternate and sweep % 2 == 1 else i
            c0 = degree[body]
            c1 = degree[body + 1]
            if c1 == c0:
                continue
            first = 0.0
            for rnd in range(rounds):
                moved = 0.0
                for m in range(c0, c1):
                    c = members[m]
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
                    moved += e2
                    if seen[c] != sweep:
                        seen[c] = sweep
                        sum_e2 += e2
                visits += c1 - c0
                if rnd == 0:
                    first = moved
                    if first == 0.0:
                        break
                elif moved <= drop * first:
                    break
        sweep += 1
        residual = np.sqrt(sum_e2 / count)
        if residual <= tolerance:
            break
        if residual < best:
            best = residual
            best_at = sweep
        elif sweep - best_at >= stall:
            break
        if accelerate:
            if residual > RESTART_GROWTH * last:
                j = 1
            last = residual
            beta = (j - 1.0) / (j + 2.0)
            j += 1
    return (visits + count - 1) // count, residual


def body_sweeps(
    contact_body,
    pack,
    count,
    mu,
    tolerance,
    max_units,
    v,
    r,
    status,
    rounds=10,
    drop=1e-6,
    alternate=False,
    stall=10_000,
    accelerate=False,
) -> tuple[int, float]:
    """Body-wise block Gauss–Seidel (module doc) from impulses ``r`` (C, 2), in place; ``v`` (B, 3) enters as
    the free velocities and leaves as v_free + M⁻¹ H r; ``status`` (C,) out. Returns (sweep units, residual)."""
    return _body_sweeps(
        contact_body, pack, count, mu, tolerance, max_units, v, r, status, rounds, drop, alternate, stall, accelerate
    )
