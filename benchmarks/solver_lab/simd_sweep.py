"""Coloured momentum sweeps: Gauss–Seidel with Nesterov momentum in colour order, the visit's arithmetic
vectorised across the contacts of a colour (Box2D v3's "wide" solver, issue 10).

Per step the contacts are coloured greedily so that no two contacts of one colour share a movable body
(a support, zero inverse mass and inertia, receives nothing, so contacts through it never conflict).
Within a colour the visits touch disjoint bodies: doing them "at once" is exactly Gauss–Seidel, so a
sweep is NLGS in colour order — the engine's law, local solve, residual (e_α = W_αα Δr, RMS over the
contacts), stopping test, momentum and restart (momentum._momentum_sweeps), in another visit order.

One sweep = for each colour
    phase A (no writes to v, so LLVM can vectorise it): gather v of a and b, u = H_αᵀ v, the
        extrapolated start r_y, u_free = u − W r_y, the branch-free exact local solve (open, stick and
        slide± candidates all computed, then selected in _local_solve's order), Δr and |e_α|² into
        small buffers;
    phase B (scalar: the scatter into v): v += M⁻¹ H Δr for each contact that moved, Σ|e_α|².

Lab prototype: timed on captured steps against the engine's accelerated sweep by
``python -m benchmarks.solver_lab.simd_bench`` (benchmarks/JOURNAL.md, "Coloured SIMD sweeps").
"""

from __future__ import annotations

import numpy as np

from benchmarks.solver_lab.simd_schedule import MASK_WORDS, colour, lanes, levels  # noqa: F401 (re-exported)
from masonrycli.engine import lane_sweeps, momentum, nlgs
from masonrycli.engine import lanes as lanes_  # "lanes" is simd_schedule's schedule here
from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import (
    P_BIAS,
    P_IIA,
    P_IIB,
    P_IMA,
    P_IMB,
    P_INN,
    P_ISM,
    P_ISP,
    P_ITN,
    P_ITT,
    P_NA,
    P_NB,
    P_NX,
    P_NY,
    P_TA,
    P_TB,
    P_WNN,
    P_WTN,
    P_WTT,
    STATUS_OPEN,
    STATUS_SLIP,
    STATUS_STICK,
)
from masonrycli.engine.tuning import TUNING

RESTART_GROWTH = momentum.RESTART_GROWTH

# Rows of the colour-sorted constant array K (one row per quantity, one column per contact: SoA).
K_NX, K_NY, K_TA, K_NA, K_TB, K_NB = 0, 1, 2, 3, 4, 5
K_WTT, K_WTN, K_WNN, K_BIAS, K_ITT, K_ITN, K_INN, K_ISP, K_ISM = 6, 7, 8, 9, 10, 11, 12, 13, 14
K_IMA, K_IIA, K_IMB, K_IIB = 15, 16, 17, 18
K_ROWS = 19
_PACK_OF_K = (P_NX, P_NY, P_TA, P_NA, P_TB, P_NB, P_WTT, P_WTN, P_WNN, P_BIAS, P_ITT, P_ITN, P_INN, P_ISP, P_ISM,
              P_IMA, P_IIA, P_IMB, P_IIB)  # fmt: skip


@njit(inline="always")
def _local_solve_bf(ut, un, bias, wtt, wtn, wnn, itt, itn, inn, isp, ism, mu):
    # nlgs._local_solve without branches: every candidate computed, then the first valid one in
    # _local_solve's order (open, stick, slide in the free direction, slide the other way, the
    # projected fallback) selected. Same operations on the same operands as _local_solve, so the same
    # bits. Returns (r_t, r_n, status).
    target = -bias - un
    # stick: r = W⁻¹(−u_t, target)
    rts = -itt * ut + itn * target
    rns = -itn * ut + inn * target
    stick = (inn > 0.0) & (rns >= 0.0) & (abs(rts) <= mu * rns)
    # slide with s = +1: r_t = −μ r_n, valid if slip ≥ 0; s = −1: r_t = μ r_n, valid if slip ≤ 0
    rnp = target * isp
    rtp = -mu * rnp
    okp = (isp > 0.0) & (ut + wtt * rtp + wtn * rnp >= 0.0)
    rnm = target * ism
    rtm = mu * rnm
    okm = (ism > 0.0) & (-(ut + wtt * rtm + wtn * rnm) >= 0.0)
    # fallback (unreachable for a positive definite W): normal solve, friction projected
    rnf = target / wnn
    rtf = -ut / wtt
    lim = mu * rnf
    rtf = lim if rtf > lim else (-lim if rtf < -lim else rtf)
    # select: the free direction first (s0 = +1 if u_t ≥ 0)
    pos = ut >= 0.0
    first_ok = okp if pos else okm
    second_ok = okm if pos else okp
    rt1 = rtp if pos else rtm
    rn1 = rnp if pos else rnm
    rt2 = rtm if pos else rtp
    rn2 = rnm if pos else rnp
    rt = rt1 if first_ok else (rt2 if second_ok else rtf)
    rn = rn1 if first_ok else (rn2 if second_ok else rnf)
    st = STATUS_SLIP
    rt = rts if stick else rt
    rn = rns if stick else rn
    st = STATUS_STICK if stick else st
    is_open = un + bias >= 0.0
    rt = 0.0 if is_open else rt
    rn = 0.0 if is_open else rn
    st = STATUS_OPEN if is_open else st
    return rt, rn, st


@njit(cache=False)
def local_solve_bf_many(ut, un, pack, mu, out_r, out_status):
    # Test helper: the branch-free local solve on rows of a pack (column c: u_free of contact c).
    for c in range(ut.shape[0]):
        rt, rn, st = _local_solve_bf(ut[c], un[c], pack[c, P_BIAS], pack[c, P_WTT], pack[c, P_WTN],
                                     pack[c, P_WNN], pack[c, P_ITT], pack[c, P_ITN], pack[c, P_INN],
                                     pack[c, P_ISP], pack[c, P_ISM], mu)  # fmt: skip
        out_r[c, 0] = rt
        out_r[c, 1] = rn
        out_status[c] = st


@njit(cache=False)
def local_solve_many(ut, un, pack, mu, out_r, out_status):
    # Test helper: the engine's nlgs._local_solve on the same inputs.
    for c in range(ut.shape[0]):
        rt, rn, st = nlgs._local_solve(ut[c], un[c], pack, c, mu)
        out_r[c, 0] = rt
        out_r[c, 1] = rn
        out_status[c] = st


@njit(cache=False)
def _phase_b_levels(lo, hi, ia, ib, K, v, D, pos, e2):
    # _phase_b for the level schedule: |e_α|² goes to the visit's position, summed in visit order later
    # (the engine's summation order, so the same residual to the bit).
    for k in range(hi - lo):
        i = np.uint64(lo + k)
        drt = D[0, i]
        drn = D[1, i]
        if drt != 0.0 or drn != 0.0:
            _push_k(v, ia[i], ib[i], K, i, drt, drn)
        e2[pos[i]] = D[2, i]


@njit(inline="always")
def _u(i, ia, ib, K, v):
    # u = H_αᵀ v of sorted row i (nlgs._relative_velocity on the SoA rows; a, b flat offsets into v).
    a = ia[i]
    b = ib[i]
    nx = K[K_NX, i]
    ny = K[K_NY, i]
    dvx = v[b] - v[a]
    dvy = v[b + np.uint64(1)] - v[a + np.uint64(1)]
    wa = v[a + np.uint64(2)]
    wb = v[b + np.uint64(2)]
    return dvx * ny - dvy * nx + wb * K[K_TB, i] - wa * K[K_TA, i], dvx * nx + dvy * ny + wb * K[K_NB, i] - wa * K[
        K_NA, i
    ]


@njit(inline="always")
def _visit(i, ut, un, K, beta, mu, X, D, status):
    # The visit of row i from its u, up to (not including) the push: the extrapolated start, the
    # branch-free local solve, Δr and |e_α|² into D. X rows: 0 r_t, 1 r_n (x_k in, x_k+1 out), 2 r_t,prev,
    # 3 r_n,prev; D rows: 0 Δr_t, 1 Δr_n, 2 |e_α|².
    xt = X[0, i]
    xn = X[1, i]
    rt0 = xt + beta * (xt - X[2, i])
    rn0 = xn + beta * (xn - X[3, i])
    X[2, i] = xt
    X[3, i] = xn
    wtt = K[K_WTT, i]
    wtn = K[K_WTN, i]
    wnn = K[K_WNN, i]
    ut -= wtt * rt0 + wtn * rn0
    un -= wtn * rt0 + wnn * rn0
    rt, rn, st = _local_solve_bf(ut, un, K[K_BIAS, i], wtt, wtn, wnn, K[K_ITT, i], K[K_ITN, i], K[K_INN, i],
                                 K[K_ISP, i], K[K_ISM, i], mu)  # fmt: skip
    status[i] = st
    X[0, i] = rt
    X[1, i] = rn
    drt = rt - rt0
    drn = rn - rn0
    D[0, i] = drt
    D[1, i] = drn
    et = wtt * drt + wtn * drn
    en = wtn * drt + wnn * drn
    D[2, i] = et * et + en * en


@njit(cache=False, error_model="numpy")  # numpy: a division by zero gives inf, no early exit to raise
def _phase_a(lo, hi, ia, ib, K, v, beta, mu, X, D, status):
    # "fused": the visits of rows lo … hi − 1 (one colour) up to the push in one loop: reads v, writes
    # only the per-contact buffers (LLVM cannot bound the indirect reads for its alias checks: scalar).
    for k in range(hi - lo):
        i = np.uint64(lo + k)  # unsigned: no wrap-around test per access (momentum.py), contiguous rows
        ut, un = _u(i, ia, ib, K, v)
        _visit(i, ut, un, K, beta, mu, X, D, status)


@njit(cache=False)
def _gather_u(lo, hi, ia, ib, K, v, U):
    # Split phase A, first half (scalar: indirect reads): U rows 0, 1 = u_t, u_n of rows lo … hi − 1.
    for k in range(hi - lo):
        i = np.uint64(lo + k)
        U[0, i], U[1, i] = _u(i, ia, ib, K, v)


@njit(cache=False, error_model="numpy")
def _solve_u(lo, hi, K, U, beta, mu, X, D, status):
    # Split phase A, second half (every access contiguous, so LLVM can bound them for its alias checks and
    # vectorises it 8-wide): from u in U, the rest of _phase_a.
    for k in range(hi - lo):
        i = np.uint64(lo + k)
        _visit(i, U[0, i], U[1, i], K, beta, mu, X, D, status)


@njit(inline="always")
def _momentum_rule(residual, tolerance, it, best, best_at, last, j, stall_after):
    # momentum._momentum_sweeps's rule after a sweep: stop at the tolerance or after stall_after sweeps
    # without a new lowest residual; else restart (j = 1) when the residual grew by more than
    # RESTART_GROWTH, and the next β = (j − 1)/(j + 2). Returns (stop, best, best_at, last, j, beta).
    if residual <= tolerance:
        return True, best, best_at, last, j, 0.0
    if residual < best:
        best = residual
        best_at = it
    elif tolerance > 0.0 and it - best_at >= stall_after:
        return True, best, best_at, last, j, 0.0
    if residual > RESTART_GROWTH * last:
        j = 1
    beta = (j - 1.0) / (j + 2.0)
    return False, best, best_at, residual, j + 1, beta


@njit(inline="always")
def _push_k(v, a, b, K, i, drt, drn):
    # nlgs._push on the sorted SoA constants (a, b: flat offsets 3·body into v).
    nx = K[K_NX, i]
    ny = K[K_NY, i]
    px = drt * ny + drn * nx
    py = -drt * nx + drn * ny
    ima = K[K_IMA, i]
    v[a] -= ima * px
    v[a + np.uint64(1)] -= ima * py
    v[a + np.uint64(2)] -= K[K_IIA, i] * (K[K_TA, i] * drt + K[K_NA, i] * drn)
    imb = K[K_IMB, i]
    v[b] += imb * px
    v[b + np.uint64(1)] += imb * py
    v[b + np.uint64(2)] += K[K_IIB, i] * (K[K_TB, i] * drt + K[K_NB, i] * drn)


@njit(cache=False)
def _phase_b(lo, hi, ia, ib, K, v, D):
    # Pushes of one colour into v (disjoint bodies); returns Σ|e_α|² over the contacts that moved.
    sum_e2 = 0.0
    for k in range(hi - lo):
        i = np.uint64(lo + k)
        drt = D[0, i]
        drn = D[1, i]
        if drt != 0.0 or drn != 0.0:
            _push_k(v, ia[i], ib[i], K, i, drt, drn)
            sum_e2 += D[2, i]
    return sum_e2


@njit(cache=False)
def sorted_arrays(contact_body, pack, count, r, order):
    # Colour-sorted SoA copies: flat offsets 3a, 3b into v, constants K, momentum state X (x = x_prev = r).
    ia = np.empty(count, np.uint64)
    ib = np.empty(count, np.uint64)
    K = np.empty((K_ROWS, count), np.float64)
    X = np.empty((4, count), np.float64)
    for i in range(count):
        c = order[i]
        ia[i] = 3 * contact_body[c, 0]
        ib[i] = 3 * contact_body[c, 1]
        for k in range(K_ROWS):
            K[k, i] = pack[c, _PACK_OF_K[k]]
        X[0, i] = X[2, i] = r[c, 0]
        X[1, i] = X[3, i] = r[c, 1]
    return ia, ib, K, X


def build(variant: str):
    """The coloured first stage with phase A as ``variant``: "fused" (one loop, indirect reads of v: LLVM
    cannot bound them for its alias checks and leaves it scalar), "split" (_gather_u scalar, then
    _solve_u vectorised), "split4" (split on velocities padded to 4 doubles a body), "levels" /
    "levels+fused", "lanes+split", "sym+split" (benchmarks/JOURNAL.md). Measured and removed: a "noalias"
    phase A (fused, compiled with numba's private noalias flag; only the engine may import numba) and
    "split2" (split with the push's products computed in the vector loop: not vectorised, 15.8 ns). Returns the kernel
    (contact_body, pack, count, mu, tolerance, cap, v, v_flat, r, status, stall) → (iterations,
    residual, colours)."""
    schedule, _, phase = variant.rpartition("+")  # "levels+fused": the level schedule, phase A fused
    if phase == "levels":
        schedule, phase = "levels", "split"
    phase_a = _phase_a
    split = phase in ("split", "split4")
    pad4 = phase == "split4"  # bodies' velocities padded to 4 doubles: a body's (vx, vy, ω) one 256-bit row
    exact = schedule == "levels"
    by_lanes = schedule == "lanes"  # "lanes+split": groups of the 8-run interleaved order (simd_schedule.lanes)
    symmetric = schedule == "sym"  # "sym+split": the colours' order turns every sweep (symmetric GS)

    @njit(cache=False)
    def coloured_sweeps(contact_body, pack, count, mu, tolerance, max_iterations, v, v_flat, r, status, stall_after):
        # momentum._momentum_sweeps (flip omitted) in colour order, each colour a phase A and a phase B
        # (module doc). Returns (iterations, residual, colours).
        if count == 0:
            return 0, 0.0, 0
        body_count = v.shape[0]
        order = np.empty(count, np.int64)
        if exact:
            start = np.empty(count + 1, np.int64)
            n_colours, visit = levels(contact_body, pack, count, body_count, order, start)
            pos = order.copy()  # visit position of each sorted row
            for i in range(count):
                order[i] = visit[pos[i]]
        elif by_lanes:
            start = np.empty(count + 1, np.int64)
            n_colours = lanes(contact_body, pack, count, body_count, order, start)
            pos = order
        else:
            start = np.empty(MASK_WORDS * 64 + 1, np.int64)
            n_colours = colour(contact_body, pack, count, body_count, order, start)
            pos = order
        ia, ib, K, X = sorted_arrays(contact_body, pack, count, r, order)
        e2 = np.zeros(count, np.float64)
        D = np.empty((3, count), np.float64)
        U = np.empty((2, count), np.float64)
        st_s = np.empty(count, np.int8)
        if exact:  # v ← v_free + M⁻¹ H r_warm, in the engine's order
            for p in range(count):
                c = visit[p]
                nlgs._push(v, contact_body[c, 0], contact_body[c, 1], pack, np.uint64(c), r[c, 0], r[c, 1])
        else:
            for i in range(count):
                _push_k(v_flat, ia[i], ib[i], K, i, X[0, i], X[1, i])
        n3 = v_flat.shape[0]
        if pad4:  # the sweeps work on v4: body b at 4b … 4b + 2, offsets 4·body
            v_work = np.zeros(4 * body_count, np.float64)
            v_work.reshape(body_count, 4)[:, :3] = v_flat.reshape(body_count, 3)
            for i in range(count):
                ia[i] = ia[i] // np.uint64(3) * np.uint64(4)
                ib[i] = ib[i] // np.uint64(3) * np.uint64(4)
            n3 = 4 * body_count
        else:
            v_work = v_flat
        v_prev_flat = v_work[:n3].copy()
        iterations = 0
        residual = 0.0
        best = np.inf
        best_at = 0
        last = np.inf
        j = 1
        beta = 0.0
        for it in range(max_iterations):
            iterations = it + 1
            momentum._extrapolate(v_work[:n3], v_prev_flat, beta)
            sum_e2 = 0.0
            for kc in range(n_colours):
                k = n_colours - 1 - kc if symmetric and it % 2 == 1 else kc
                lo = start[k]
                hi = start[k + 1]
                if split:
                    _gather_u(lo, hi, ia, ib, K, v_work, U)
                    _solve_u(lo, hi, K, U, beta, mu, X, D, st_s)
                else:
                    phase_a(lo, hi, ia, ib, K, v_work, beta, mu, X, D, st_s)
                if exact:
                    _phase_b_levels(lo, hi, ia, ib, K, v_work, D, pos, e2)
                else:
                    sum_e2 += _phase_b(lo, hi, ia, ib, K, v_work, D)
            if exact:
                for p in range(count):
                    sum_e2 += e2[p]
            residual = np.sqrt(sum_e2 / count)
            stop, best, best_at, last, j, beta = _momentum_rule(
                residual, tolerance, it, best, best_at, last, j, stall_after
            )
            if stop:
                break
        if pad4:
            v_flat.reshape(body_count, 3)[:, :] = v_work.reshape(body_count, 4)[:, :3]
        for i in range(count):
            c = order[i]
            r[c, 0] = X[0, i]
            r[c, 1] = X[1, i]
            status[c] = st_s[i]
        return iterations, residual, n_colours

    return coloured_sweeps


_KERNELS: dict = {}


def _engine_lanes(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall_after):
    # The engine's first stage, and its visits a sweep: lanes.pack_lanes' sub-groups, Σ nsub over the groups
    # (the same count as "lanes+split"'s colours where no group clashes; fewer where one does: split by
    # colour there, lane by lane in "lanes+split").
    its, residual = lane_sweeps._lane_sweeps(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall_after)
    if count == 0:
        return its, residual, 0
    nsub = lanes_.pack_lanes(contact_body, pack, count, np.zeros_like(v), np.zeros((count, 2)))[4]
    return its, residual, int(nsub.sum())


def solve(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall_after=TUNING.first_stall, variant="split"):
    """The coloured first stage on one step's arrays (as dispatch.first_stage takes them).
    Returns (iterations, residual, colours). Variant "blocks": simd_blocks.py's layout in 8-contact blocks;
    "lanes+vec": the engine's lane sweeps (engine/lane_sweeps.py, the default's first stage; the lab's
    explicit-vector prototype, simd_lanes.py, became them), the lane groups' visits (sub-groups of a
    clashing group counted one each) as colours."""
    if variant == "lanes+vec":
        return _engine_lanes(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall_after)
    if variant == "blocks":
        from benchmarks.solver_lab import simd_blocks  # it builds on this module

        return simd_blocks.solve(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall_after)
    if variant not in _KERNELS:
        _KERNELS[variant] = build(variant)
    return _KERNELS[variant](contact_body, pack, count, mu, tolerance, cap, v, v.reshape(-1), r, status, stall_after)
