"""The start of the default solver's first stage in single precision: :mod:`masonrycli.engine.lane_sweeps`'s
momentum sweeps in float32, 16 contacts visited at once on ``<16 x float>`` vectors
(:mod:`masonrycli.engine._vector32`), then the float64 lane sweeps from their impulses (iterative
refinement: the step ends on a float64 sweep and the float64 stopping test; solver "nlgs-accel32", chosen in dispatch.solve):

    groups: 16 runs of ⌈C/16⌉ contacts of detection order; group j's lane q holds contact
            q·run + (j + s_q) mod run, s_q = run/2 for odd q in the staggered layout, 0 in the plain one
            (_choose_layout); a clashing group's sub-groups visited in turn, as lanes.py
    v32 ← float32(v_free + M⁻¹ H r_warm)  (the pushes in float64); r32 ← float32(r_warm)
    repeat: the sweep of lane_sweeps._lane_sweeps in float32 (extrapolation, the visit); the residual
            sqrt(Σ|e_α|² / C), each lane's |e_α|² summed over the groups in float32, the 16 lane sums
            in float64; stop at the tolerance, the cap or the stall window
    r ← float64(r32); v is left as it came (v_free)
    first_stage: then lane_sweeps._lane_sweeps from r (v = v_free + M⁻¹ H r re-derived in float64)

Why: a float32 visit does the same operations as a float64 one on twice the lanes of a zmm register,
and the body rows it gathers are 16 bytes instead of 32: 2.5–2.7 ns per contact·sweep against 4.0–4.1 on
captured steps of the 248-block wall, and 1.279 → 0.919 CPU s per simulated s in bench_solver
(benchmarks/JOURNAL.md, "The float32 first stage"). Rounding does not decide the result: the float32 sweeps
stall where a sweep's rounding (~1e-7 m/s) accumulates in the slow modes (higher on taller walls), and the
float64 sweeps after them end the step on the float64 stopping test.

Why the staggered layout: with 16 runs on a wall of 16 courses a run is about a course, and lane q and
q + 1 (the same place in neighbouring courses) meet on the block between them: every group of the
248-block wall's steps clashed. Half a run's shift puts neighbouring runs' lanes half a course apart
(none clashed). On 32 courses (2 courses a run) the plain layout has no clash and the shift makes them,
so the layout with fewer clashing groups is taken (the plain one unless more than an eighth clash).
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine import _vector32, lane_sweeps, momentum
from masonrycli.engine._jit import njit
from masonrycli.engine.lanes import colour_lane
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
    PACK_WIDTH,
    STATUS_OPEN,
    STATUS_SLIP,
    STATUS_STICK,
    _push,
)

V = _vector32
LANES32 = 16
"""Lanes: contacts of a float32 group (``_vector32.WIDTH``). 16 on every CPU: on Zen 4, which runs a zmm
operation as two 256-bit halves, 8 lanes cost 1.04× per contact·sweep (another order: other bits), 4 lanes
1.64×, the 16 split into ymm halves 1.008× (benchmarks/JOURNAL.md, "Issue 10's aim on a Zen 4 CPU")."""
R_XT, R_XN, R_PT, R_PN, R_ST = PACK_WIDTH, PACK_WIDTH + 1, PACK_WIDTH + 2, PACK_WIDTH + 3, PACK_WIDTH + 4
ROWS = PACK_WIDTH + 5
FULL = (1 << LANES32) - 1
STALL32 = 200
"""Sweeps without a new low after which the float32 stage hands the step to the float64 sweeps (at most
the first stage's own stall window)."""
RESYNC = 32
"""Sweeps between the float32 stage's re-derivations of the velocities from the impulses (_resync)."""


@njit(inline="always")
def _local_solve32(ut, un, bias, wtt, wtn, wnn, itt, itn, inn, isp, ism, mu):
    # lane_sweeps._local_solve_v on <16 x float> (a copy: numba cannot take the vector module as an argument)
    # nlgs._local_solve in every lane without branches: all candidates computed, then the first valid one
    # in _local_solve's order (open; stick; slide in the free direction s0 = sign u_t; the other way; the
    # projected fallback). The same operations on the same operands as _local_solve, so the same bits.
    #   stick:  r = W⁻¹(−u_t, target), target = −bias − u_n; valid if r_n ≥ 0, |r_t| ≤ μ r_n
    #   slide±: r_n = target / (W_nn ∓ μ W_tn), r_t = ∓μ r_n; valid if ±(u_t + W_tt r_t + W_tn r_n) ≥ 0
    # The fallback's two divisions (a singular W only) are computed only when some lane selects it.
    zero = V.splat(0.0)
    target = -bias - un
    rts = -itt * ut + itn * target
    rns = -itn * ut + inn * target
    stick = (inn > zero) & (rns >= zero) & (V.vabs(rts) <= mu * rns)
    rnp = target * isp
    rtp = -mu * rnp
    okp = (isp > zero) & (ut + wtt * rtp + wtn * rnp >= zero)
    rnm = target * ism
    rtm = mu * rnm
    okm = (ism > zero) & (-(ut + wtt * rtm + wtn * rnm) >= zero)
    is_open = un + bias >= zero
    if V.bits_of(~(is_open | stick | okp | okm)) != 0:
        rnf = target / wnn
        rtf = -ut / wtt
        lim = mu * rnf
        rtf = V.select(rtf > lim, lim, V.select(rtf < -lim, -lim, rtf))
    else:
        rnf = zero
        rtf = zero
    pos = ut >= zero
    neg = ~pos
    first_ok = (pos & okp) | (neg & okm)
    second_ok = (pos & okm) | (neg & okp)
    rt1 = V.select(pos, rtp, rtm)
    rn1 = V.select(pos, rnp, rnm)
    rt2 = V.select(pos, rtm, rtp)
    rn2 = V.select(pos, rnm, rnp)
    rt = V.select(first_ok, rt1, V.select(second_ok, rt2, rtf))
    rn = V.select(first_ok, rn1, V.select(second_ok, rn2, rnf))
    rt = V.select(stick, rts, rt)
    rn = V.select(stick, rns, rn)
    st = V.select(stick, V.splat(STATUS_STICK), V.splat(STATUS_SLIP))
    rt = V.select(is_open, zero, rt)
    rn = V.select(is_open, zero, rn)
    st = V.select(is_open, V.splat(STATUS_OPEN), st)
    return rt, rn, st


@njit(inline="always")
def _contact(count, run, q, j, stagger):
    # the contact in lane q of group j (module doc), or -1 for an absent lane
    s = (run // 2) if (stagger and q & 1) else 0
    jj = j + s
    if jj >= run:
        jj -= run
    c = q * run + jj
    return c if c < count else -1


@njit(inline="always")
def _clashing_groups(contact_body, moves, count, run, stagger, seen):
    # The groups of a layout in which two lanes move the same body (seen: -1 for every body on entry).
    # moves[c]: bit 0 contact c moves body a, bit 1 body b (lanes._moves' test on the pack's rows, not Q's:
    # the layout is chosen before Q exists).
    n = 0
    for j in range(run):
        clash = 0
        for q in range(LANES32):
            c = _contact(count, run, q, j, stagger)
            if c < 0:
                continue
            for side in range(2):
                if moves[c] >> side & 1:
                    b = contact_body[c, side]
                    if seen[b] == j:
                        clash = 1
                    seen[b] = j
        n += clash
    return n


@njit
def _choose_layout(contact_body, pack, count, bodies):
    # 1 (staggered) when it has fewer clashing groups than the plain layout, else 0. The plain layout is
    # kept unless more than an eighth of its groups clash.
    # Which bodies a contact moves is read from its pack row once, in contact order: the two layouts'
    # passes read rows C/16 apart, four columns a side, and took ~20 µs a step on the 248-block wall.
    run = (count + LANES32 - 1) // LANES32
    moves = np.empty(count, np.uint8)
    for c in range(count):
        ma = pack[c, P_IMA] > 0.0 or pack[c, P_IIA] > 0.0
        mb = pack[c, P_IMB] > 0.0 or pack[c, P_IIB] > 0.0
        moves[c] = np.uint8(ma) | np.uint8(mb) << np.uint8(1)
    seen = np.empty(bodies, np.int64)
    for b in range(bodies):
        seen[b] = -1
    plain = _clashing_groups(contact_body, moves, count, run, False, seen)
    if 8 * plain <= run:
        return 0
    for b in range(bodies):
        seen[b] = -1
    return 1 if _clashing_groups(contact_body, moves, count, run, True, seen) < plain else 0


@njit(inline="always")
def pack_lanes32(contact_body, pack, count, v, r, stagger):
    # Q[(j·ROWS + row)·16 + q] = float32 of contact c's pack row and r (r_prev = r), c = _contact(q, j);
    # IA, IB [j·16 + q] = 4a, 4b (0 in absent lanes); lanes[j·16 + q] = c or -1
    # sub[j, k], nsub[j]: group j's clash-free sub-groups, greedy in lane order (lanes._sub_groups)
    # v4[4b … 4b + 2] = float32(v_free + M⁻¹ H r_warm), the pushes in float64 (v is not written)
    # Its own copy of lanes.pack_lanes but for colour_lane: float32 rows, the staggered layout, and the
    # pushes in contact order from the pack (lanes': in lane order from Q), so one kernel would change bits.
    run = (count + LANES32 - 1) // LANES32
    # every element of Q written once: an absent lane's rows and a present one's status 0 (the zeros a fill
    # of the whole of Q gave them before its rows were copied over it)
    Q = np.empty(run * ROWS * LANES32, np.float32)
    IA = np.empty(run * LANES32, np.int64)
    IB = np.empty(run * LANES32, np.int64)
    lanes = np.empty(run * LANES32, np.int64)
    for j in range(run):
        for q in range(LANES32):
            c = _contact(count, run, q, j, stagger)
            lanes[j * LANES32 + q] = c
            IA[j * LANES32 + q] = 0
            IB[j * LANES32 + q] = 0
            base = j * ROWS * LANES32 + q
            if c < 0:
                for row in range(ROWS):
                    Q[base + row * LANES32] = 0.0
                continue
            for row in range(PACK_WIDTH):
                Q[base + row * LANES32] = np.float32(pack[c, row])
            Q[base + R_XT * LANES32] = Q[base + R_PT * LANES32] = np.float32(r[c, 0])
            Q[base + R_XN * LANES32] = Q[base + R_PN * LANES32] = np.float32(r[c, 1])
            Q[base + R_ST * LANES32] = 0.0
            IA[j * LANES32 + q] = 4 * contact_body[c, 0]
            IB[j * LANES32 + q] = 4 * contact_body[c, 1]
    bodies = v.shape[0]
    sub = np.empty((run, LANES32), np.int64)
    nsub = np.empty(run, np.int64)
    seen = np.empty(bodies, np.int64)
    held = np.empty(bodies, np.int64)
    for b in range(bodies):
        seen[b] = -1
    for j in range(run):
        n = 0
        for q in range(LANES32):
            if lanes[j * LANES32 + q] >= 0:
                n = colour_lane(Q, IA, IB, j, q, LANES32, n, seen, held, sub)
        nsub[j] = n
    v64 = v.copy()
    for c in range(count):
        _push(v64, contact_body[c, 0], contact_body[c, 1], pack, np.uint64(c), r[c, 0], r[c, 1])
    v4 = np.empty(4 * bodies, np.float32)
    for b in range(bodies):
        v4[4 * b] = np.float32(v64[b, 0])
        v4[4 * b + 1] = np.float32(v64[b, 1])
        v4[4 * b + 2] = np.float32(v64[b, 2])
        v4[4 * b + 3] = 0.0
    return Q, IA, IB, lanes, sub, nsub, v4


@njit(inline="always")
def _group32(j, act, Q, IA, IB, v4, beta, mu, full):
    # lane_sweeps._group in float32 on 16 lanes; returns the lanes' |e_α|² (0 in lanes outside act)
    # A copy, not shared: numba cannot take the vector module (_vector32, <16 x float>) as an argument.
    q0 = j * ROWS * LANES32
    at = j * LANES32
    vax, vay, waa = V.gather_rows(v4, IA, at)
    vbx, vby, wbb = V.gather_rows(v4, IB, at)
    nx = V.load(Q, q0 + P_NX * LANES32)
    ny = V.load(Q, q0 + P_NY * LANES32)
    ta = V.load(Q, q0 + P_TA * LANES32)
    na = V.load(Q, q0 + P_NA * LANES32)
    tb = V.load(Q, q0 + P_TB * LANES32)
    nb = V.load(Q, q0 + P_NB * LANES32)
    dvx = vbx - vax
    dvy = vby - vay
    ut = dvx * ny - dvy * nx + wbb * tb - waa * ta
    un = dvx * nx + dvy * ny + wbb * nb - waa * na
    xt = V.load(Q, q0 + R_XT * LANES32)
    xn = V.load(Q, q0 + R_XN * LANES32)
    rt0 = xt + beta * (xt - V.load(Q, q0 + R_PT * LANES32))
    rn0 = xn + beta * (xn - V.load(Q, q0 + R_PN * LANES32))
    V.masked_store(Q, q0 + R_PT * LANES32, xt, act)
    V.masked_store(Q, q0 + R_PN * LANES32, xn, act)
    wtt = V.load(Q, q0 + P_WTT * LANES32)
    wtn = V.load(Q, q0 + P_WTN * LANES32)
    wnn = V.load(Q, q0 + P_WNN * LANES32)
    ut = ut - (wtt * rt0 + wtn * rn0)
    un = un - (wtn * rt0 + wnn * rn0)
    rt, rn, st = _local_solve32(ut, un, V.load(Q, q0 + P_BIAS * LANES32), wtt, wtn, wnn, V.load(Q, q0 + P_ITT * LANES32),
                                V.load(Q, q0 + P_ITN * LANES32), V.load(Q, q0 + P_INN * LANES32), V.load(Q, q0 + P_ISP * LANES32),
                                V.load(Q, q0 + P_ISM * LANES32), mu)  # fmt: skip
    V.masked_store(Q, q0 + R_ST * LANES32, st, act)
    V.masked_store(Q, q0 + R_XT * LANES32, rt, act)
    V.masked_store(Q, q0 + R_XN * LANES32, rn, act)
    drt = rt - rt0
    drn = rn - rn0
    zero = V.splat(0.0)
    moved = act & ((drt != zero) | (drn != zero))
    px = drt * ny + drn * nx
    py = -drt * nx + drn * ny
    ima = V.load(Q, q0 + P_IMA * LANES32)
    iia = V.load(Q, q0 + P_IIA * LANES32)
    imb = V.load(Q, q0 + P_IMB * LANES32)
    iib = V.load(Q, q0 + P_IIB * LANES32)
    push_a = moved & ((ima > zero) | (iia > zero))
    push_b = moved & ((imb > zero) | (iib > zero))
    nax = vax - ima * px
    nay = vay - ima * py
    naw = waa - iia * (ta * drt + na * drn)
    nbx = vbx + imb * px
    nby = vby + imb * py
    nbw = wbb + iib * (tb * drt + nb * drn)
    if full:
        V.scatter_rows(v4, IA, at, V.select(push_a, nax, vax), V.select(push_a, nay, vay), V.select(push_a, naw, waa))
        V.scatter_rows(v4, IB, at, V.select(push_b, nbx, vbx), V.select(push_b, nby, vby), V.select(push_b, nbw, wbb))
    else:
        pa = V.bits_of(push_a)
        pb = V.bits_of(push_b)
        for q in range(LANES32):
            if pa >> q & 1:
                o = IA[at + q]
                v4[o] = np.float32(V.lane(nax, q))
                v4[o + 1] = np.float32(V.lane(nay, q))
                v4[o + 2] = np.float32(V.lane(naw, q))
            if pb >> q & 1:
                o = IB[at + q]
                v4[o] = np.float32(V.lane(nbx, q))
                v4[o + 1] = np.float32(V.lane(nby, q))
                v4[o + 2] = np.float32(V.lane(nbw, q))
    et = wtt * drt + wtn * drn
    en = wtn * drt + wnn * drn
    return V.select(act, et * et + en * en, zero)


@njit(inline="always")
def _resync(contact_body, pack, Q, lanes, v_free, v64, vp64, v4, v_prev):
    # v4 ← float32(v_free + M⁻¹ H r), v_prev ← float32(v_free + M⁻¹ H r_prev), the pushes in float64 from
    # the rows' r and r_prev, group by group in lane order: the velocities the sweeps carry drift from
    # their impulses by a rounding a push, and that drift, not r's own rounding, is where the float32
    # sweeps stall (module doc).
    for b in range(v_free.shape[0]):
        for k in range(3):
            v64[b, k] = v_free[b, k]
            vp64[b, k] = v_free[b, k]
    for i in range(lanes.shape[0]):
        c = lanes[i]
        if c < 0:
            continue
        base = (i // LANES32) * ROWS * LANES32 + i % LANES32
        a = contact_body[c, 0]
        b = contact_body[c, 1]
        cc = np.uint64(c)
        _push(v64, a, b, pack, cc, np.float64(Q[base + R_XT * LANES32]), np.float64(Q[base + R_XN * LANES32]))
        _push(vp64, a, b, pack, cc, np.float64(Q[base + R_PT * LANES32]), np.float64(Q[base + R_PN * LANES32]))
    for b in range(v_free.shape[0]):
        for k in range(3):
            v4[4 * b + k] = np.float32(v64[b, k])
            v_prev[4 * b + k] = np.float32(vp64[b, k])


@njit(inline="always")
def _extrapolate32(x, x_prev, beta):
    # x ← x + β (x − x_prev), x_prev ← old x (float32)
    for i in range(x.shape[0]):
        xi = x[i]
        x[i] = xi + beta * (xi - x_prev[i])
        x_prev[i] = xi


@njit
def lane_sweeps32(
    contact_body,
    pack,
    count,
    mu,
    tolerance,
    max_iterations,
    v,
    r,
    status,
    stall_after,
    stagger,
    resync=0,
    growth=momentum.RESTART_GROWTH,
):
    # The float32 stage (module doc). v: v_free, read only; r: warm start in, float64 of the float32
    # impulses out; status out; growth: the restart's factor (Tuning.lane_growth). Returns (iterations, residual).
    if count == 0:
        return 0, 0.0
    if stagger < 0:
        stagger = _choose_layout(contact_body, pack, count, v.shape[0])
    Q, IA, IB, lanes, sub, nsub, v4 = pack_lanes32(contact_body, pack, count, v, r, stagger == 1)
    run = nsub.shape[0]
    v_prev = v4.copy()
    v64 = np.empty_like(v)
    vp64 = np.empty_like(v)
    vmu = V.splat(mu)
    iterations = 0
    residual = 0.0
    best = np.inf
    best_at = 0
    last = np.inf
    j_restart = 1
    beta = 0.0
    for it in range(max_iterations):
        iterations = it + 1
        if resync > 0 and it > 0 and it % resync == 0:
            _resync(contact_body, pack, Q, lanes, v, v64, vp64, v4, v_prev)
        _extrapolate32(v4, v_prev, np.float32(beta))
        vbeta = V.splat(beta)
        acc = V.splat(0.0)
        for j in range(run):
            if sub[j, 0] == FULL:
                acc = acc + _group32(j, V.mask_bits(FULL), Q, IA, IB, v4, vbeta, vmu, True)
                continue
            for k in range(nsub[j]):
                acc = acc + _group32(j, V.mask_bits(sub[j, k]), Q, IA, IB, v4, vbeta, vmu, False)
        sum_e2 = 0.0
        for q in range(LANES32):
            sum_e2 += V.lane(acc, q)
        residual = np.sqrt(sum_e2 / count)
        if residual <= tolerance:
            break
        if residual < best:
            best = residual
            best_at = it
        elif tolerance > 0.0 and it - best_at >= stall_after:
            break
        if residual > growth * last:
            j_restart = 1
        last = residual
        beta = (j_restart - 1.0) / (j_restart + 2.0)
        j_restart += 1
    for j in range(run):
        for q in range(LANES32):
            c = lanes[j * LANES32 + q]
            if c >= 0:
                base = j * ROWS * LANES32 + q
                r[c, 0] = np.float64(Q[base + R_XT * LANES32])
                r[c, 1] = np.float64(Q[base + R_XN * LANES32])
                status[c] = np.int8(Q[base + R_ST * LANES32])
    return iterations, residual


def first_stage(
    contact_body,
    pack,
    count,
    mu,
    tolerance,
    max_iterations,
    v,
    r,
    status,
    stall_after,
    stall_near=0,
    growth=momentum.RESTART_GROWTH,
):
    """The accelerated solve's first stage with a float32 start (module doc): :func:`lane_sweeps32` to
    ``tolerance`` (its own float32 test), then lane_sweeps._lane_sweeps from its impulses in float64 (v
    re-derived from v_free, at least one sweep: the step ends on a float64 sweep and test), whose stall
    window is ``stall_near`` once within momentum.NEAR × the tolerance (momentum.py, "Near the tolerance");
    both restart at ``growth`` (Tuning.lane_growth). Returns (iterations, residual): the sweeps of both, the float64 sweep's residual."""
    # max_iterations − 1: the float64 sweep the step ends on stays within the run's cap
    its32, _ = lane_sweeps32(
        contact_body, pack, count, mu, tolerance, max(max_iterations - 1, 0), v, r, status,
        min(stall_after, STALL32), -1, RESYNC, growth,
    )  # fmt: skip
    its, residual = lane_sweeps._lane_sweeps(
        contact_body, pack, count, mu, tolerance, max(max_iterations - its32, 1), v, r, status, stall_after,
        momentum.NEAR * tolerance, max(stall_near, stall_after), growth,
    )  # fmt: skip
    return its32 + its, residual
