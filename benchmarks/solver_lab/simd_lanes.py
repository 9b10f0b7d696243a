"""The 8-lane interleaved sweep written with explicit vectors (masonrycli.engine._vector): a lab measurement.

simd_sweep's "lanes+split" visits the engine's interleaved order with 8 runs, the 8 contacts of one
position (a group) at once — Gauss–Seidel in that order, since a group whose contacts share a movable
body is split into single visits — and converges like the engine (benchmarks/README.md, "Coloured SIMD
sweeps"); but LLVM's loop vectoriser left its 8-contact loops scalar (15.2 ns per contact·sweep). Here
one group's visit is written on ``<8 x double>`` vectors, one lane a contact:

    per sweep: v ← v + β (v − v_prev)  (momentum._extrapolate, as the reference)
    per group j (lanes = its contacts; a clashing group: one lane at a time, in order):
        gather v_a, v_b (6 vectors)  → u = H_αᵀ v
        extrapolated start r_y, u_free, the branch-free local solve (simd_sweep._local_solve_bf, every
        candidate computed in all lanes, then selected), Δr, |e_α|²   — vector arithmetic, no branch
        v_a −= M⁻¹…, v_b += M⁻¹… for the lanes that moved, movable bodies only (6 vectors scattered)
        Σ|e_α|²: the lanes added one by one, in lane order, to a group sum that starts at 0

A full group (8 lanes, no clash: all of wall-248's) gathers with 8 scalar loads a vector and scatters
with 8 scalar stores (every lane stores; where it does not push, the value it read); with ``rows``
("lanes+vec4") the sweeps' velocities are padded to 4 doubles a body and a full group reads and writes
one 256-bit row a lane (_vector.gather_rows / scatter_rows: a third of the memory operations). A
partial or split group uses the masked hardware gathers and scatters (vgatherqpd, vscatterqpd). On this
Zen 5 the hardware ones cost more: 5.6–6.2 ns per contact·sweep against 4.4 (benchmarks/README.md).
The local solve's fallback (two divisions) is computed only when a lane selects it (a singular W).

Every lane does the scalar code's IEEE operations on the same operands (no fast-math: nothing contracted
or reassociated), so the sweeps, residuals, v and r are those of "lanes+split" bit for bit. The one
difference of principle: the reference also adds its pushes ±0 into supports' velocities, which leaves
them unchanged unless one is −0.0 (then it may become +0.0); here supports are never written.

Per-contact data in one flat array of groups (AoSoA): row ``row`` of group j's lane q at
``(j · ROWS + row) · 8 + q`` (the constants K_* of simd_sweep, then r_t, r_n, r_prev,t, r_prev,n and the
status as a double), so every vector load and store is one contiguous 64-byte row. Velocities stay the
engine's flat (3 B) array, read and written by index (gathers and scatters).
"""

from __future__ import annotations

import numpy as np

from benchmarks.solver_lab.simd_schedule import lanes
from benchmarks.solver_lab.simd_sweep import (
    K_BIAS,
    K_IIA,
    K_IIB,
    K_IMA,
    K_IMB,
    K_INN,
    K_ISM,
    K_ISP,
    K_ITN,
    K_ITT,
    K_NA,
    K_NB,
    K_NX,
    K_NY,
    K_ROWS,
    K_TA,
    K_TB,
    K_WNN,
    K_WTN,
    K_WTT,
    _momentum_rule,
    _push_k,
    sorted_arrays,
)
from masonrycli.engine import _vector as V
from masonrycli.engine import momentum
from masonrycli.engine._jit import njit
from masonrycli.engine.lane_sweeps import _local_solve_v  # the engine's, which this lab code became

W = V.WIDTH
R_XT, R_XN, R_PT, R_PN, R_ST = K_ROWS, K_ROWS + 1, K_ROWS + 2, K_ROWS + 3, K_ROWS + 4
ROWS = K_ROWS + 5
FULL = (1 << W) - 1


@njit(inline="always")
def _group(j, act, Q, IA, IB, v, beta, mu, full, rows):
    # The visit of group j's lanes in mask act (module doc). Returns the group's Σ|e_α|², lane by lane.
    q0 = j * ROWS * W
    at = j * W
    if full and rows:  # all 8 lanes, no clash, 4 doubles a body: one 256-bit row a lane
        vax, vay, waa = V.gather_rows(v, IA, at)
        vbx, vby, wbb = V.gather_rows(v, IB, at)
    elif full:  # all 8 lanes, no clash: plain loads, one a double
        vax = V.gather_scalar(v, IA, at, 0)
        vay = V.gather_scalar(v, IA, at, 1)
        waa = V.gather_scalar(v, IA, at, 2)
        vbx = V.gather_scalar(v, IB, at, 0)
        vby = V.gather_scalar(v, IB, at, 1)
        wbb = V.gather_scalar(v, IB, at, 2)
    else:
        vax = V.gather(v, IA, at, 0, act)
        vay = V.gather(v, IA, at, 1, act)
        waa = V.gather(v, IA, at, 2, act)
        vbx = V.gather(v, IB, at, 0, act)
        vby = V.gather(v, IB, at, 1, act)
        wbb = V.gather(v, IB, at, 2, act)
    nx = V.load(Q, q0 + K_NX * W)
    ny = V.load(Q, q0 + K_NY * W)
    ta = V.load(Q, q0 + K_TA * W)
    na = V.load(Q, q0 + K_NA * W)
    tb = V.load(Q, q0 + K_TB * W)
    nb = V.load(Q, q0 + K_NB * W)
    dvx = vbx - vax
    dvy = vby - vay
    ut = dvx * ny - dvy * nx + wbb * tb - waa * ta  # simd_sweep._u
    un = dvx * nx + dvy * ny + wbb * nb - waa * na
    xt = V.load(Q, q0 + R_XT * W)  # simd_sweep._visit from here
    xn = V.load(Q, q0 + R_XN * W)
    rt0 = xt + beta * (xt - V.load(Q, q0 + R_PT * W))
    rn0 = xn + beta * (xn - V.load(Q, q0 + R_PN * W))
    V.masked_store(Q, q0 + R_PT * W, xt, act)
    V.masked_store(Q, q0 + R_PN * W, xn, act)
    wtt = V.load(Q, q0 + K_WTT * W)
    wtn = V.load(Q, q0 + K_WTN * W)
    wnn = V.load(Q, q0 + K_WNN * W)
    ut = ut - (wtt * rt0 + wtn * rn0)
    un = un - (wtn * rt0 + wnn * rn0)
    rt, rn, st = _local_solve_v(ut, un, V.load(Q, q0 + K_BIAS * W), wtt, wtn, wnn, V.load(Q, q0 + K_ITT * W),
                                V.load(Q, q0 + K_ITN * W), V.load(Q, q0 + K_INN * W), V.load(Q, q0 + K_ISP * W),
                                V.load(Q, q0 + K_ISM * W), mu)  # fmt: skip
    V.masked_store(Q, q0 + R_ST * W, st, act)
    V.masked_store(Q, q0 + R_XT * W, rt, act)
    V.masked_store(Q, q0 + R_XN * W, rn, act)
    drt = rt - rt0
    drn = rn - rn0
    zero = V.splat(0.0)
    moved = act & ((drt != zero) | (drn != zero))
    px = drt * ny + drn * nx  # simd_sweep._push_k
    py = -drt * nx + drn * ny
    ima = V.load(Q, q0 + K_IMA * W)
    iia = V.load(Q, q0 + K_IIA * W)
    imb = V.load(Q, q0 + K_IMB * W)
    iib = V.load(Q, q0 + K_IIB * W)
    push_a = moved & ((ima > zero) | (iia > zero))
    push_b = moved & ((imb > zero) | (iib > zero))
    nax = vax - ima * px
    nay = vay - ima * py
    naw = waa - iia * (ta * drt + na * drn)
    nbx = vbx + imb * px
    nby = vby + imb * py
    nbw = wbb + iib * (tb * drt + nb * drn)
    if full and rows:  # every lane stores, the old value where it does not push (a support: unchanged)
        V.scatter_rows(v, IA, at, V.select(push_a, nax, vax), V.select(push_a, nay, vay), V.select(push_a, naw, waa))
        V.scatter_rows(v, IB, at, V.select(push_b, nbx, vbx), V.select(push_b, nby, vby), V.select(push_b, nbw, wbb))
    elif full:
        V.scatter_scalar(v, IA, at, 0, V.select(push_a, nax, vax))
        V.scatter_scalar(v, IA, at, 1, V.select(push_a, nay, vay))
        V.scatter_scalar(v, IA, at, 2, V.select(push_a, naw, waa))
        V.scatter_scalar(v, IB, at, 0, V.select(push_b, nbx, vbx))
        V.scatter_scalar(v, IB, at, 1, V.select(push_b, nby, vby))
        V.scatter_scalar(v, IB, at, 2, V.select(push_b, nbw, wbb))
    else:
        V.scatter(v, IA, at, 0, nax, push_a)
        V.scatter(v, IA, at, 1, nay, push_a)
        V.scatter(v, IA, at, 2, naw, push_a)
        V.scatter(v, IB, at, 0, nbx, push_b)
        V.scatter(v, IB, at, 1, nby, push_b)
        V.scatter(v, IB, at, 2, nbw, push_b)
    et = wtt * drt + wtn * drn
    en = wtn * drt + wnn * drn
    e2 = V.select(act, et * et + en * en, zero)  # an unmoved lane's is +0: adding it changes no bit
    s = 0.0
    for q in range(W):
        s += V.lane(e2, q)
    return s


@njit(cache=False)
def pack_groups(count, order, start, groups, K, X):
    # The lanes schedule (simd_schedule.lanes: positions in order, groups start[g] … start[g + 1]) as
    # AoSoA groups of W slots: slot (j, q) = position j·W + q of the 8-run order's group j (lane q: run q).
    # Returns (Q, slot_of_position, gmask: lanes present in group j, clash: group j was split).
    run = (count + W - 1) // W
    Q = np.zeros(run * ROWS * W, np.float64)
    slot = np.empty(count, np.int64)
    gmask = np.zeros(run, np.int64)
    clash = np.zeros(run, np.bool_)
    p = 0
    g = 0
    for j in range(run):
        n = 0
        for q in range(W):
            if q * run + j < count:
                slot[p + n] = j * W + q
                gmask[j] |= 1 << q
                n += 1
        clash[j] = start[g + 1] - start[g] != n  # a split group: n groups of one
        g += 1 if not clash[j] else n
        p += n
    for p in range(count):
        j, q = slot[p] // W, slot[p] % W
        base = j * ROWS * W + q
        for row in range(K_ROWS):
            Q[base + row * W] = K[row, p]
        Q[base + R_XT * W] = Q[base + R_PT * W] = X[0, p]
        Q[base + R_XN * W] = Q[base + R_PN * W] = X[1, p]
    return Q, slot, gmask, clash


def _build(rows):
    @njit(cache=False, error_model="numpy")  # numpy: a division by zero gives inf (as the reference's)
    def lane_sweeps(contact_body, pack, count, mu, tolerance, max_iterations, v, v_flat, r, status, stall_after):
        # simd_sweep's "lanes+split" (momentum._momentum_sweeps, flip omitted, in the 8-run order's groups)
        # with each group's visit in vectors (_group). Returns (iterations, residual, groups).
        if count == 0:
            return 0, 0.0, 0
        body_count = v.shape[0]
        order = np.empty(count, np.int64)
        start = np.empty(count + 1, np.int64)
        groups = lanes(contact_body, pack, count, body_count, order, start)
        ia, ib, K, X = sorted_arrays(contact_body, pack, count, r, order)
        for i in range(count):  # v ← v_free + M⁻¹ H r_warm, in visit order (as the reference)
            _push_k(v_flat, ia[i], ib[i], K, i, X[0, i], X[1, i])
        Q, slot, gmask, clash = pack_groups(count, order, start, groups, K, X)
        run = gmask.shape[0]
        IA = np.zeros(run * W, np.int64)
        IB = np.zeros(run * W, np.int64)
        stride = 4 if rows else 3  # doubles a body in the sweeps' velocities v_work
        for p in range(count):
            IA[slot[p]] = ia[p] // 3 * stride
            IB[slot[p]] = ib[p] // 3 * stride
        if rows:  # body b at 4b … 4b + 2 (4b + 3: padding, never read into a result)
            v_work = np.zeros(4 * body_count, np.float64)
            v_work.reshape(body_count, 4)[:, :3] = v_flat.reshape(body_count, 3)
        else:
            v_work = v_flat
        v_prev_flat = v_work.copy()
        iterations = 0
        residual = 0.0
        best = np.inf
        best_at = 0
        last = np.inf
        j_restart = 1
        beta = 0.0
        for it in range(max_iterations):
            iterations = it + 1
            momentum._extrapolate(v_work, v_prev_flat, beta)  # the same per element
            vbeta = V.splat(beta)
            vmu = V.splat(mu)
            sum_e2 = 0.0
            for j in range(run):
                if clash[j]:  # the reference's groups of one, in lane order
                    for q in range(W):
                        if gmask[j] >> q & 1:
                            sum_e2 += _group(j, V.mask_bits(1 << q), Q, IA, IB, v_work, vbeta, vmu, False, rows)
                elif gmask[j] == FULL:
                    sum_e2 += _group(j, V.mask_bits(FULL), Q, IA, IB, v_work, vbeta, vmu, True, rows)
                else:
                    sum_e2 += _group(j, V.mask_bits(gmask[j]), Q, IA, IB, v_work, vbeta, vmu, False, rows)
            residual = np.sqrt(sum_e2 / count)
            stop, best, best_at, last, j_restart, beta = _momentum_rule(
                residual, tolerance, it, best, best_at, last, j_restart, stall_after
            )
            if stop:
                break
        if rows:
            v_flat.reshape(body_count, 3)[:, :] = v_work.reshape(body_count, 4)[:, :3]
        for p in range(count):
            c = order[p]
            base = slot[p] // W * ROWS * W + slot[p] % W
            r[c, 0] = Q[base + R_XT * W]
            r[c, 1] = Q[base + R_XN * W]
            status[c] = np.int8(Q[base + R_ST * W])
        return iterations, residual, groups

    return lane_sweeps


lane_sweeps = _build(rows=False)
lane_sweeps_rows = _build(rows=True)


def solve(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall_after=momentum.STALL_SWEEPS, rows=False):
    """The explicitly vectorised lane sweeps on one step's arrays (as simd_sweep.solve takes them); rows:
    velocities padded to 4 doubles a body, a full group's gathered and scattered a 256-bit row a lane.
    Returns (iterations, residual, groups)."""
    v_flat = v.reshape(-1)
    if not np.shares_memory(v, v_flat):
        raise ValueError("v must be C-contiguous: the sweeps write v through its flat view")
    return (lane_sweeps_rows if rows else lane_sweeps)(
        contact_body, pack, count, mu, tolerance, cap, v, v_flat, r, status, stall_after
    )
