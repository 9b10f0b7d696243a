"""Gauss–Seidel by faces: what a stalled plain "nlgs" solve continues with, and the last of stalled.py's
methods for the accelerated solvers.

Two blocks in contact along a face touch at two points (three for a point inside a face) that the
detection emits next to each other, with the same body pair. Point-by-point Gauss–Seidel visits them
one at a time. On tall walls that slide this can cycle for ever (nlgs module doc, "Stagnation"): a
sliding block rotates, lifts one corner of its bed joint, the other corner takes the load, the block
slides back; the residual wanders at 1e-4 m/s while hundreds of contacts change status every few
hundred sweeps.

Here each face is solved (nearly) exactly before moving on: its points are visited in turn, again and
again, until one round changes their velocities by less than INNER_DROP of what the first round did
(at most INNER_ROUNDS rounds). Measured on captured steps where point Gauss–Seidel never met 1e-5 m/s
(benchmarks/JOURNAL.md): the 32-course wall's step 74 reaches it after 21 179 sweeps (56 397 sweep units)
and the solver lab's wall-32-hard, whose 211 500-sweep point reference ends at 3e-4 m/s, after 4181
sweeps (9153 units). On steps point Gauss–Seidel does converge, faces cost 1.5–5× its sweep units,
which is why this is the fallback and not the default.

The residual is the point sweep's (root mean square over the contacts of |W_αα Δr_α| at each point's
first visit in the sweep), and the work is counted in sweep units: contact visits / C.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import P_WNN, P_WTN, P_WTT, _local_solve, _push, _relative_velocity

FACES_STALL = 10_000
"""Face sweeps without a new lowest residual after which the solve gives up (the step is unconverged)."""
INNER_ROUNDS = 10
"""Most rounds over one face's points per sweep."""
INNER_DROP = 1e-6
"""A face is left when a round moves its points' velocities (Σ|W Δr|²) by less than this fraction of its
first round."""


@njit
def _face_sweeps(contact_body, pack, count, mu, tolerance, max_units, v, r, status):
    # v enters consistent with r (v = v_free + M⁻¹ H r) and leaves so.
    #   faces = runs of consecutive contacts with the same body pair
    #   repeat (one sweep):
    #       for each face: round 1 visits its points (their |W Δr|² make the residual);
    #                      more rounds while a round moves > INNER_DROP × round 1 (≤ INNER_ROUNDS)
    #   until residual ≤ tolerance, the work cap (sweep units), or FACES_STALL sweeps without a new low.
    # A visit is the arithmetic of nlgs._nlgs's contact loop, written out here once (one call site):
    # calling a shared visit function cost 47–57 ns per visit against 8.7 ns inline (captured steps of
    # the 248-block wall; likely the reference counting of the arrays numba passes to a call it does not
    # inline — not verified).
    # Returns (sweep units done, rounded up; residual).
    if count == 0:
        return 0, 0.0
    start = np.empty(count + 1, np.int64)
    faces = 0
    for c in range(count):
        if c == 0 or contact_body[c, 0] != contact_body[c - 1, 0] or contact_body[c, 1] != contact_body[c - 1, 1]:
            start[faces] = c
            faces += 1
    start[faces] = count
    visits = 0
    residual = 0.0
    best = np.inf
    best_at = 0
    sweep = 0
    while visits < max_units * count:
        sum_e2 = 0.0
        for f in range(faces):
            c0 = start[f]
            c1 = start[f + 1]
            first = 0.0
            for rnd in range(INNER_ROUNDS):
                moved = 0.0
                for c in range(c0, c1):
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
                    if drt != 0.0 or drn != 0.0:
                        _push(v, a, b, pack, c, drt, drn)
                        r[c, 0] = rt
                        r[c, 1] = rn
                        et = wtt * drt + wtn * drn
                        en = wtn * drt + wnn * drn
                        moved += et * et + en * en
                visits += c1 - c0
                if rnd == 0:
                    first = moved
                    sum_e2 += first
                    if c1 - c0 == 1 or first == 0.0:
                        break
                elif moved <= INNER_DROP * first:
                    break
        residual = np.sqrt(sum_e2 / count)
        if residual <= tolerance:
            break
        if residual < best:
            best = residual
            best_at = sweep
        elif sweep - best_at >= FACES_STALL:
            break
        sweep += 1
    return (visits + count - 1) // count, residual


def face_sweeps(contact_body, pack, count, mu, tolerance, max_units, v, r, status) -> tuple[int, float]:
    """Continue a solve by faces from impulses ``r`` (C, 2) and the matching velocities ``v`` (B, 3), both
    updated in place, ``status`` (C,) out; stop at ``tolerance`` (m/s, > 0), after ``max_units`` sweep
    units, or when stalled. Returns (sweep units done, residual in m/s) — see the module doc."""
    return _face_sweeps(contact_body, pack, count, mu, tolerance, max_units, v, r, status)
