"""The lane groups of the default solver's first stage: its visit order, its clashes, its data layout.

The first stage (:mod:`masonrycli.engine.lane_sweeps`) visits the contacts in the interleaved order of
:mod:`masonrycli.engine.interleaved` with 8 runs instead of 4: runs of ``run = ⌈C/8⌉`` contacts of
detection order, and

    group j = run 0's j-th contact, run 1's, …, run 7's        (contact q·run + j in lane q)
    order   = group 0's lanes in lane order, group 1's, …

The 8 contacts of a group are visited at once, one lane of a ``<8 x double>`` each. That is Gauss–Seidel
in this order exactly when no two of them move the same body (a support, zero inverse mass and inertia,
is only read). A group where two do (a *clash*) is split into sub-groups without one, by greedy colouring
in lane order (lane q joins the first sub-group none of whose lanes it clashes with), visited in turn:
Gauss–Seidel in the order "the sub-groups' lanes, sub-group by sub-group". Clashes are rare where runs
(C/8 contacts of detection order) are far apart in the structure: none on the 248-block and taller walls
or the arch, 1 % of the groups on the aqueduct; but on the 8-course wall a run is about a course, lane q
and q + 1 meet on the blocks between them, and 54 % of the groups clash. Visited lane by lane, those
lanes formed one chain of dependent visits (19 ns per contact·sweep on its steps against 7.9 for the
4-run scalar sweep); split by colour, a group takes two vector visits (lanes 0, 2, 4, 6 and 1, 3, 5, 7).
The last groups have fewer than 8 lanes when C is not a multiple of 8 (lane q is present when
q·run + j < C).

Data layout (AoSoA): group j's values are ROWS rows of 8 doubles, lane q's value of row ``row`` at
``(j · ROWS + row) · 8 + q``, so that every vector load and store of the visit is one contiguous 64-byte
row. Rows 0 … PACK_WIDTH − 1 are the packed constants of :mod:`masonrycli.engine.nlgs` (same columns:
``P_NX`` …), then the momentum state r_t, r_n, r_prev,t, r_prev,n and the status (a double). The body
velocities are copied padded to 4 doubles a body, so that a full group reads and writes one 256-bit row
a lane (``_vector.gather_rows`` / ``scatter_rows``): a third of the memory operations of 3 doubles a
body read one by one (benchmarks/JOURNAL.md, explicit vectors addendum).
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import P_IIA, P_IIB, P_IMA, P_IMB, P_NA, P_NB, P_NX, P_NY, P_TA, P_TB, PACK_WIDTH

LANES = 8
"""Lanes: contacts of a group (``_vector.WIDTH``). (W in these modules' comments is the Delassus block W_αα.)"""
R_XT, R_XN, R_PT, R_PN, R_ST = PACK_WIDTH, PACK_WIDTH + 1, PACK_WIDTH + 2, PACK_WIDTH + 3, PACK_WIDTH + 4
ROWS = PACK_WIDTH + 5
"""Rows of a group: the packed constants, r_t, r_n, r_prev,t, r_prev,n, status."""
FULL = (1 << LANES) - 1
"""The lane mask of a group with all 8 lanes."""
TILE = 16
"""Groups whose rows pack_lanes fills at once (16 × 1.5 kB of rows, and 8 runs of 16 pack rows, in L1)."""


@njit(inline="always")
def _moves(Q, base, side, w):
    # The lane at Q[base] (a group's rows of w lanes, offset by its lane) moves its body a (side 0) or b
    # (side 1): a support has zero inverse mass and inertia. w: 8 here, 16 in lane_sweeps32 (its caller
    # passes its own constant, so the inlined copy indexes with a constant as before).
    if side == 0:
        return Q[base + P_IMA * w] > 0.0 or Q[base + P_IIA * w] > 0.0
    return Q[base + P_IMB * w] > 0.0 or Q[base + P_IIB * w] > 0.0


@njit(inline="always")
def colour_lane(Q, IA, IB, j, q, w, n, seen, held, sub):
    # Lane q of group j (groups of w lanes) joins the lowest of the group's n sub-groups that holds none of
    # the bodies it moves, or a new one; returns the group's sub-group count. One step of _sub_groups'
    # greedy colouring, shared with lane_sweeps32.pack_lanes32 (16 lanes, its own layout; the same ROWS).
    base = j * ROWS * w + q
    busy = 0
    for side in range(2):
        b = (IA[j * w + q] if side == 0 else IB[j * w + q]) >> 2
        if _moves(Q, base, side, w) and seen[b] == j:
            busy |= held[b]
    k = 0
    while busy >> k & 1:
        k += 1
    if k == n:
        sub[j, k] = 0
        n += 1
    sub[j, k] |= 1 << q
    for side in range(2):
        b = (IA[j * w + q] if side == 0 else IB[j * w + q]) >> 2
        if _moves(Q, base, side, w):
            if seen[b] != j:
                seen[b] = j
                held[b] = 0
            held[b] |= 1 << k
    return n


@njit(inline="always")
def _sub_groups(Q, IA, IB, count, run, j, seen, held, sub):
    # Group j's sub-groups (module doc): sub[j, k] = lane mask of sub-group k; returns their number.
    #   held[body] = the sub-groups of group j holding a lane that moves body (valid while seen[body] = j)
    #   for each lane q present (contact q·run + j < C), in lane order (colour_lane):
    #       k = the lowest sub-group holding none of the bodies q moves (greedy colouring; k = 0 unless
    #           the group clashes); sub[j, k] |= bit q; held[each body q moves] |= bit k
    # Bitmasks per body rather than comparing the 28 pairs of lanes: the pairs took 145 µs a step on the
    # 248-block wall (whose sweeps take ~600 µs a step), the masks ~5.
    n = 0
    for q in range(LANES):
        if q * run + j >= count:
            break
        n = colour_lane(Q, IA, IB, j, q, LANES, n, seen, held, sub)
    return n


@njit(inline="always")
def _push_lane(v, Q, base, a, b):
    # v ← v + M⁻¹ H r of the lane at Q[base] (its r in rows R_XT, R_XN): nlgs._push's operations on the same
    # values (the rows are copies of the pack), so the same bits; a support gets ±0.
    drt = Q[base + R_XT * LANES]
    drn = Q[base + R_XN * LANES]
    nx = Q[base + P_NX * LANES]
    ny = Q[base + P_NY * LANES]
    px = drt * ny + drn * nx
    py = -drt * nx + drn * ny
    ima = Q[base + P_IMA * LANES]
    v[a, 0] -= ima * px
    v[a, 1] -= ima * py
    v[a, 2] -= Q[base + P_IIA * LANES] * (Q[base + P_TA * LANES] * drt + Q[base + P_NA * LANES] * drn)
    imb = Q[base + P_IMB * LANES]
    v[b, 0] += imb * px
    v[b, 1] += imb * py
    v[b, 2] += Q[base + P_IIB * LANES] * (Q[base + P_TB * LANES] * drt + Q[base + P_NB * LANES] * drn)


@njit(inline="always")
def pack_lanes(contact_body, pack, count, v, r):
    # The first stage's arrays, in group order (module doc):
    #   Q[(j·ROWS + row)·8 + q]             pack row and r of contact q·run + j (r_prev = r), absent lanes 0
    #   IA, IB [j·8 + q]                    offsets 4a, 4b of its bodies in v4 (0 in absent lanes)
    #   per group j: sub[j], nsub[j]        _sub_groups
    #                v ← v + M⁻¹ H r_warm   its lanes' pushes in lane order (_push_lane; v enters as v_free)
    #   v4[4b … 4b + 2] = v[b], v4[4b + 3] = 0
    # Returns (Q, IA, IB, sub, nsub, v4).
    # Q is filled TILE groups at a time, and the sub-groups and pushes read Q, not the pack: pack rows
    # q·run + j of one group lie C/8 rows apart, and reading them group by group took 44 µs a step on the
    # 248-block wall against 31 (benchmarks/JOURNAL.md, "Where a wall-248 step goes at the lane sweeps").
    # Not shared with lane_sweeps32.pack_lanes32 (only colour_lane is): its pushes go in contact order from
    # the pack in float64, these in lane order from Q, so one kernel would change one path's bits.
    run = (count + LANES - 1) // LANES
    # np.empty, not np.zeros (_jit's rule): np.zeros compiled 2 signatures and a fill of its own, 0.1 s of a
    # first run's CPU (benchmarks/JOURNAL.md, "Cold start")
    # (every element of Q written once: an absent lane's rows and IA, IB and a present lane's status 0, the
    # zeros a fill of the whole of Q gave them before its rows were copied over it)
    Q = np.empty(run * ROWS * LANES, np.float64)
    IA = np.empty(run * LANES, np.int64)
    IB = np.empty(run * LANES, np.int64)
    for j in range(run):  # absent lanes: q·run + j ≥ C, in the last groups only
        for q in range(LANES):
            if q * run + j >= count:
                base = j * ROWS * LANES + q
                for row in range(ROWS):
                    Q[base + row * LANES] = 0.0
                IA[j * LANES + q] = 0
                IB[j * LANES + q] = 0
    for j0 in range(0, run, TILE):
        j1 = min(j0 + TILE, run)
        for q in range(LANES):
            for j in range(j0, j1):
                c = q * run + j
                if c >= count:
                    break
                base = j * ROWS * LANES + q
                for row in range(PACK_WIDTH):
                    Q[base + row * LANES] = pack[c, row]
                Q[base + R_XT * LANES] = r[c, 0]
                Q[base + R_PT * LANES] = r[c, 0]
                Q[base + R_XN * LANES] = r[c, 1]
                Q[base + R_PN * LANES] = r[c, 1]
                Q[base + R_ST * LANES] = 0.0
                IA[j * LANES + q] = 4 * contact_body[c, 0]
                IB[j * LANES + q] = 4 * contact_body[c, 1]
    sub = np.empty((run, LANES), np.int64)
    nsub = np.empty(run, np.int64)
    bodies = v.shape[0]
    seen = np.empty(bodies, np.int64)
    held = np.empty(bodies, np.int64)
    for b in range(bodies):
        seen[b] = -1
    for j in range(run):  # group by group in lane order: the solver lab's "lanes+split" order, whose bits these are
        nsub[j] = _sub_groups(Q, IA, IB, count, run, j, seen, held, sub)
        for q in range(LANES):
            if q * run + j >= count:
                break
            _push_lane(v, Q, j * ROWS * LANES + q, IA[j * LANES + q] >> 2, IB[j * LANES + q] >> 2)
    v4 = np.empty(4 * bodies, np.float64)
    for b in range(bodies):
        v4[4 * b] = v[b, 0]
        v4[4 * b + 1] = v[b, 1]
        v4[4 * b + 2] = v[b, 2]
        v4[4 * b + 3] = 0.0
    return Q, IA, IB, sub, nsub, v4


@njit(inline="always")
def unpack_lanes(Q, count, v4, v, r, status):
    # Back from group order: v[b] ← v4[4b … 4b + 2]; r, status of contact c ← its lane's rows.
    run = (count + LANES - 1) // LANES
    for b in range(v.shape[0]):
        v[b, 0] = v4[4 * b]
        v[b, 1] = v4[4 * b + 1]
        v[b, 2] = v4[4 * b + 2]
    for j in range(run):  # group by group: Q read where it lies (c in order took 2.5 µs more a step)
        for q in range(LANES):
            c = q * run + j
            if c >= count:
                break
            base = j * ROWS * LANES + q
            r[c, 0] = Q[base + R_XT * LANES]
            r[c, 1] = Q[base + R_XN * LANES]
            status[c] = np.int8(Q[base + R_ST * LANES])
