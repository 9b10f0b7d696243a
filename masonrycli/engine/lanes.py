"""The lane groups of the default solver's first stage: its visit order, its clashes, its data layout.

The first stage (:mod:`masonrycli.engine.lane_sweeps`) visits the contacts in the interleaved order of
:mod:`masonrycli.engine.interleaved` with 8 runs instead of 4: runs of ``run = ⌈C/8⌉`` contacts of
detection order, and

    group j = run 0's j-th contact, run 1's, …, run 7's        (contact q·run + j in lane q)
    order   = group 0's lanes in lane order, group 1's, …

The 8 contacts of a group are visited at once, one lane of a ``<8 x double>`` each. That is Gauss–Seidel
in this order exactly when no two of them move the same body (a support, zero inverse mass and inertia,
is only read). A group where two do (a *clash*: rare, runs are C/8 contacts apart in detection order) is
visited lane by lane. The last groups have fewer than 8 lanes when C is not a multiple of 8 (lane q is
present when q·run + j < C).

Data layout (AoSoA): group j's values are ROWS rows of 8 doubles, lane q's value of row ``row`` at
``(j · ROWS + row) · 8 + q``, so that every vector load and store of the visit is one contiguous 64-byte
row. Rows 0 … PACK_WIDTH − 1 are the packed constants of :mod:`masonrycli.engine.nlgs` (same columns:
``P_NX`` …), then the momentum state r_t, r_n, r_prev,t, r_prev,n and the status (a double). The body
velocities are copied padded to 4 doubles a body, so that a full group reads and writes one 256-bit row
a lane (``_vector.gather_rows`` / ``scatter_rows``): a third of the memory operations of 3 doubles a
body read one by one (benchmarks/README.md, explicit vectors addendum).
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import P_IIA, P_IIB, P_IMA, P_IMB, PACK_WIDTH, _push

W = 8
"""Lanes: contacts of a group (``_vector.WIDTH``)."""
R_XT, R_XN, R_PT, R_PN, R_ST = PACK_WIDTH, PACK_WIDTH + 1, PACK_WIDTH + 2, PACK_WIDTH + 3, PACK_WIDTH + 4
ROWS = PACK_WIDTH + 5
"""Rows of a group: the packed constants, r_t, r_n, r_prev,t, r_prev,n, status."""
FULL = (1 << W) - 1
"""The lane mask of a group with all 8 lanes."""


@njit(inline="always")
def _moves(pack, c, side):
    # Contact c moves its body a (side 0) or b (side 1): a support has zero inverse mass and inertia.
    if side == 0:
        return pack[c, P_IMA] > 0.0 or pack[c, P_IIA] > 0.0
    return pack[c, P_IMB] > 0.0 or pack[c, P_IIB] > 0.0


@njit(inline="always")
def _groups(contact_body, pack, count, run, gmask, clash):
    # For each group j: gmask[j] = its lanes (bit q: contact q·run + j exists), clash[j] = two of its
    # contacts move one body (then visited lane by lane). Pairs of lanes compared directly: 28 pairs of
    # 4 bodies, cheaper than marking bodies in a table the size of the model.
    for j in range(run):
        m = 0
        hit = False
        for q in range(W):
            cx = q * run + j
            if cx >= count:
                break
            m |= 1 << q
            for p in range(q):
                cy = p * run + j
                for sx in range(2):
                    if not _moves(pack, cx, sx):
                        continue
                    for sy in range(2):
                        if _moves(pack, cy, sy) and contact_body[cx, sx] == contact_body[cy, sy]:
                            hit = True
        gmask[j] = m
        clash[j] = hit


@njit(inline="always")
def pack_lanes(contact_body, pack, count, v, r):
    # The first stage's arrays, in group order (module doc):
    #   gmask, clash                        _groups
    #   v ← v_free + M⁻¹ H r_warm           scalar pushes in visit order (nlgs._push: supports get ±0)
    #   Q[(j·ROWS + row)·8 + q]             pack row and r of contact q·run + j (r_prev = r)
    #   IA, IB [j·8 + q]                    offsets 4a, 4b of its bodies in v4 (0 in absent lanes)
    #   v4[4b … 4b + 2] = v[b], v4[4b + 3] = 0
    # Returns (Q, IA, IB, gmask, clash, v4).
    run = (count + W - 1) // W
    gmask = np.empty(run, np.int64)
    clash = np.empty(run, np.bool_)
    _groups(contact_body, pack, count, run, gmask, clash)
    for j in range(run):  # visit order: the reference sweeps push the warm start in it
        for q in range(W):
            c = q * run + j
            if c >= count:
                break
            _push(v, contact_body[c, 0], contact_body[c, 1], pack, np.uint64(c), r[c, 0], r[c, 1])
    # np.empty and a fill, not np.zeros (_jit's rule): np.zeros compiled 2 signatures and a fill of its own,
    # 0.1 s of a first run's CPU (benchmarks/README.md, "Cold start"); absent lanes keep these zeros
    Q = np.empty(run * ROWS * W, np.float64)
    IA = np.empty(run * W, np.int64)
    IB = np.empty(run * W, np.int64)
    for i in range(Q.shape[0]):
        Q[i] = 0.0
    for i in range(IA.shape[0]):
        IA[i] = 0
        IB[i] = 0
    for c in range(count):
        j = c % run
        q = c // run
        base = j * ROWS * W + q
        for row in range(PACK_WIDTH):
            Q[base + row * W] = pack[c, row]
        Q[base + R_XT * W] = r[c, 0]
        Q[base + R_PT * W] = r[c, 0]
        Q[base + R_XN * W] = r[c, 1]
        Q[base + R_PN * W] = r[c, 1]
        IA[j * W + q] = 4 * contact_body[c, 0]
        IB[j * W + q] = 4 * contact_body[c, 1]
    bodies = v.shape[0]
    v4 = np.empty(4 * bodies, np.float64)
    for b in range(bodies):
        v4[4 * b] = v[b, 0]
        v4[4 * b + 1] = v[b, 1]
        v4[4 * b + 2] = v[b, 2]
        v4[4 * b + 3] = 0.0
    return Q, IA, IB, gmask, clash, v4


@njit(inline="always")
def unpack_lanes(Q, count, v4, v, r, status):
    # Back from group order: v[b] ← v4[4b … 4b + 2]; r, status of contact c ← its lane's rows.
    run = (count + W - 1) // W
    for b in range(v.shape[0]):
        v[b, 0] = v4[4 * b]
        v[b, 1] = v4[4 * b + 1]
        v[b, 2] = v4[4 * b + 2]
    for c in range(count):
        base = (c % run) * ROWS * W + c // run
        r[c, 0] = Q[base + R_XT * W]
        r[c, 1] = Q[base + R_XN * W]
        status[c] = np.int8(Q[base + R_ST * W])
