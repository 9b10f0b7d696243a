"""Coloured momentum sweeps with every per-contact quantity in one flat array of 8-contact blocks (AoSoA).

simd_sweep.py's split phase A vectorises only while LLVM can bound every array it touches for its
run-time alias checks; computing the bodies' velocity changes there as well (variant "split2", measured and since removed, so that
phase B only adds them) made it "too many memory checks needed" (LLVM's remark), and it stayed scalar. Here each colour's contacts are
padded to whole blocks of LANES contacts, and every per-contact row (constants, u, momentum state,
velocity changes, |e|², status) of a block lies in one flat array at

    Q[(block · ROWS + row) · LANES + lane]

so the solve's accesses are one base plus compile-time offsets: no alias check at all, and the lane
loop (constant trip count LANES) is vectorised. Padding contacts have W = 1, everything else 0: they
are open, push 0, add |e|² = 0, and read and write scratch velocity slots of their own.

Per colour: gather (scalar: u_t, u_n from the bodies' velocities), solve (vector: momentum's
extrapolated start, the branch-free local solve, Δr, M⁻¹ H Δr for a and b, |e|²), push (scalar, no
branch: every contact adds its velocity changes; a support's go to a scratch slot of the contact).
"""

from __future__ import annotations

import numpy as np

from benchmarks.solver_lab.simd_schedule import MASK_WORDS, colour
from benchmarks.solver_lab.simd_sweep import _PACK_OF_K, K_ROWS, _local_solve_bf, _momentum_rule
from masonrycli.engine import momentum, nlgs
from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import P_IIA, P_IIB, P_IMA, P_IMB
from masonrycli.engine.tuning import TUNING

LANES = 8
"""Contacts a block: one AVX-512 vector of doubles."""
R_UT, R_UN, R_XT, R_XN, R_PT, R_PN = 19, 20, 21, 22, 23, 24  # rows after the K_* constants (simd_sweep)
R_DAX, R_DAY, R_DAW, R_DBX, R_DBY, R_DBW, R_E2, R_ST = 25, 26, 27, 28, 29, 30, 31, 32
ROWS = 33
_U = np.uint64
# offsets of the rows within a block (row · LANES), unsigned so index arithmetic stays unsigned
_ROW_OFFSETS = tuple(_U(r * LANES) for r in range(ROWS))
(O_NX, O_NY, O_TA, O_NA, O_TB, O_NB, O_WTT, O_WTN, O_WNN, O_BIAS, O_ITT, O_ITN, O_INN, O_ISP, O_ISM,
 O_IMA, O_IIA, O_IMB, O_IIB, O_UT, O_UN, O_XT, O_XN, O_PT, O_PN,
 O_DAX, O_DAY, O_DAW, O_DBX, O_DBY, O_DBW, O_E2, O_ST) = _ROW_OFFSETS  # fmt: skip
BLOCK = _U(ROWS * LANES)
ONE, TWO = _U(1), _U(2)


@njit(cache=False)
def build_blocks(contact_body, pack, count, r, body_count):
    # Colour (simd_sweep.colour), pad each colour to whole blocks, fill Q; read offsets ia, ib (3·body)
    # and write offsets wa, wb (a support's: the slot's scratch 3·(B + slot)); slot_contact (−1: padding).
    # Returns (n_colours, block_start, Q, ia, ib, wa, wb, slot_contact).
    order = np.empty(count, np.int64)
    start = np.empty(MASK_WORDS * 64 + 1, np.int64)
    n_colours = colour(contact_body, pack, count, body_count, order, start)
    block_start = np.empty(n_colours + 1, np.int64)
    block_start[0] = 0
    for k in range(n_colours):
        block_start[k + 1] = block_start[k] + (start[k + 1] - start[k] + LANES - 1) // LANES
    n_slots = block_start[n_colours] * LANES
    Q = np.zeros(block_start[n_colours] * ROWS * LANES, np.float64)
    ia = np.empty(n_slots, np.uint64)
    ib = np.empty(n_slots, np.uint64)
    wa = np.empty(n_slots, np.uint64)
    wb = np.empty(n_slots, np.uint64)
    slot_contact = np.full(n_slots, -1, np.int64)
    for k in range(n_colours):
        for s in range(block_start[k] * LANES, block_start[k + 1] * LANES):
            q = (s // LANES) * ROWS * LANES + s % LANES
            scratch = 3 * (body_count + s)
            m = s - block_start[k] * LANES
            if m < start[k + 1] - start[k]:
                c = order[start[k] + m]
                slot_contact[s] = c
                a = contact_body[c, 0]
                b = contact_body[c, 1]
                ia[s] = 3 * a
                ib[s] = 3 * b
                wa[s] = 3 * a if (pack[c, P_IMA] > 0.0 or pack[c, P_IIA] > 0.0) else scratch
                wb[s] = 3 * b if (pack[c, P_IMB] > 0.0 or pack[c, P_IIB] > 0.0) else scratch
                for j in range(K_ROWS):
                    Q[q + j * LANES] = pack[c, _PACK_OF_K[j]]
                Q[q + R_XT * LANES] = Q[q + R_PT * LANES] = r[c, 0]
                Q[q + R_XN * LANES] = Q[q + R_PN * LANES] = r[c, 1]
            else:  # padding: open, pushes nothing, its own scratch velocities (zeros)
                ia[s] = ib[s] = wa[s] = wb[s] = scratch
                Q[q + 6 * LANES] = 1.0  # W_tt
                Q[q + 8 * LANES] = 1.0  # W_nn
    return n_colours, block_start, Q, ia, ib, wa, wb, slot_contact


@njit(cache=False)
def _gather(b0, b1, ia, ib, Q, v):
    # u = H_αᵀ v (nlgs._relative_velocity) of the slots of blocks b0 … b1 − 1 into rows UT, UN.
    for blk in range(b1 - b0):
        base = _U(b0 + blk) * BLOCK
        for lane in range(LANES):
            s = _U((b0 + blk) * LANES + lane)
            o = base + _U(lane)
            a = ia[s]
            b = ib[s]
            nx = Q[o + O_NX]
            ny = Q[o + O_NY]
            dvx = v[b] - v[a]
            dvy = v[b + ONE] - v[a + ONE]
            wa = v[a + TWO]
            wb = v[b + TWO]
            Q[o + O_UT] = dvx * ny - dvy * nx + wb * Q[o + O_TB] - wa * Q[o + O_TA]
            Q[o + O_UN] = dvx * nx + dvy * ny + wb * Q[o + O_NB] - wa * Q[o + O_NA]


@njit(cache=False, error_model="numpy")  # numpy: the fallback's division by zero gives inf, no early exit
def _solve(b0, b1, Q, beta, mu):
    # Blocks b0 … b1 − 1, all lanes at once: momentum's visit from u (simd_sweep._visit's arithmetic, then nlgs._push's products).
    for blk in range(b1 - b0):
        base = _U(b0 + blk) * BLOCK
        for lane in range(LANES):
            o = base + _U(lane)
            ut = Q[o + O_UT]
            un = Q[o + O_UN]
            xt = Q[o + O_XT]
            xn = Q[o + O_XN]
            rt0 = xt + beta * (xt - Q[o + O_PT])
            rn0 = xn + beta * (xn - Q[o + O_PN])
            Q[o + O_PT] = xt
            Q[o + O_PN] = xn
            wtt = Q[o + O_WTT]
            wtn = Q[o + O_WTN]
            wnn = Q[o + O_WNN]
            ut -= wtt * rt0 + wtn * rn0
            un -= wtn * rt0 + wnn * rn0
            rt, rn, st = _local_solve_bf(ut, un, Q[o + O_BIAS], wtt, wtn, wnn, Q[o + O_ITT], Q[o + O_ITN],
                                         Q[o + O_INN], Q[o + O_ISP], Q[o + O_ISM], mu)  # fmt: skip
            Q[o + O_ST] = st
            Q[o + O_XT] = rt
            Q[o + O_XN] = rn
            drt = rt - rt0
            drn = rn - rn0
            nx = Q[o + O_NX]
            ny = Q[o + O_NY]
            px = drt * ny + drn * nx
            py = -drt * nx + drn * ny
            ima = Q[o + O_IMA]
            Q[o + O_DAX] = ima * px
            Q[o + O_DAY] = ima * py
            Q[o + O_DAW] = Q[o + O_IIA] * (Q[o + O_TA] * drt + Q[o + O_NA] * drn)
            imb = Q[o + O_IMB]
            Q[o + O_DBX] = imb * px
            Q[o + O_DBY] = imb * py
            Q[o + O_DBW] = Q[o + O_IIB] * (Q[o + O_TB] * drt + Q[o + O_NB] * drn)
            et = wtt * drt + wtn * drn
            en = wtn * drt + wnn * drn
            Q[o + O_E2] = et * et + en * en


@njit(cache=False)
def _push(b0, b1, wa, wb, Q, v):
    # v_a −= Δv_a, v_b += Δv_b for every slot (no branch); returns Σ |e|² of the blocks.
    sum_e2 = 0.0
    for blk in range(b1 - b0):
        base = _U(b0 + blk) * BLOCK
        for lane in range(LANES):
            s = _U((b0 + blk) * LANES + lane)
            o = base + _U(lane)
            a = wa[s]
            b = wb[s]
            v[a] -= Q[o + O_DAX]
            v[a + ONE] -= Q[o + O_DAY]
            v[a + TWO] -= Q[o + O_DAW]
            v[b] += Q[o + O_DBX]
            v[b + ONE] += Q[o + O_DBY]
            v[b + TWO] += Q[o + O_DBW]
            sum_e2 += Q[o + O_E2]
    return sum_e2


@njit(cache=False)
def block_sweeps(contact_body, pack, count, mu, tolerance, max_iterations, v, v_flat, r, status, stall_after):
    # momentum._momentum_sweeps (flip omitted) in colour order on the blocks. Returns (iterations,
    # residual, colours).
    if count == 0:
        return 0, 0.0, 0
    body_count = v.shape[0]
    n_colours, block_start, Q, ia, ib, wa, wb, slot_contact = build_blocks(contact_body, pack, count, r, body_count)
    n_slots = ia.shape[0]
    n3 = 3 * body_count
    vw = np.zeros(3 * (body_count + n_slots), np.float64)  # v, then the slots' scratch velocities
    for p in range(count):  # v ← v_free + M⁻¹ H r_warm
        nlgs._push(v, contact_body[p, 0], contact_body[p, 1], pack, np.uint64(p), r[p, 0], r[p, 1])
    vw[:n3] = v_flat
    v_prev = vw[:n3].copy()
    iterations = 0
    residual = 0.0
    best = np.inf
    best_at = 0
    last = np.inf
    j = 1
    beta = 0.0
    for it in range(max_iterations):
        iterations = it + 1
        momentum._extrapolate(vw[:n3], v_prev, beta)
        sum_e2 = 0.0
        for k in range(n_colours):
            b0 = block_start[k]
            b1 = block_start[k + 1]
            _gather(b0, b1, ia, ib, Q, vw)
            _solve(b0, b1, Q, beta, mu)
            sum_e2 += _push(b0, b1, wa, wb, Q, vw)
        residual = np.sqrt(sum_e2 / count)
        stop, best, best_at, last, j, beta = _momentum_rule(
            residual, tolerance, it, best, best_at, last, j, stall_after
        )
        if stop:
            break
    v_flat[:] = vw[:n3]
    for s in range(n_slots):
        c = slot_contact[s]
        if c >= 0:
            q = (s // LANES) * ROWS * LANES + s % LANES
            r[c, 0] = Q[q + R_XT * LANES]
            r[c, 1] = Q[q + R_XN * LANES]
            status[c] = np.int8(Q[q + R_ST * LANES])
    return iterations, residual, n_colours


def solve(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall_after=TUNING.first_stall):
    """The block-coloured first stage on one step's arrays (as dispatch.first_stage takes them)."""
    return block_sweeps(contact_body, pack, count, mu, tolerance, cap, v, v.reshape(-1), r, status, stall_after)
