"""The first stage of solver "nlgs-accel" (and the float64 end of "nlgs-accel32"'s, lane_sweeps32.first_stage):
momentum's sweeps with 8 contacts visited at once, in vectors.

The sweeps of :mod:`masonrycli.engine.momentum` (Nesterov extrapolation, adaptive restart, the stall
window after which dispatch.solve hands the step to :mod:`masonrycli.engine.stalled`) in the lane groups of
:mod:`masonrycli.engine.lanes`: the interleaved order with 8 runs, a group's 8 contacts visited side by
side on ``<8 x double>`` vectors (:mod:`masonrycli.engine._vector`), one lane a contact:

    per sweep: v ← v + β (v − v_prev)            (momentum._extrapolate)
    per group j (a clashing group: each of its sub-groups in turn, lanes.py):
        gather v_a, v_b → u = H_αᵀ v; the extrapolated start r_y, u_free = u − W r_y; the branch-free
        local solve (every candidate computed in all lanes, then the first valid one in
        nlgs._local_solve's order selected); Δr, e_α = W Δr
        v_a −= M⁻¹ H_a Δr, v_b += M⁻¹ H_b Δr for the lanes that moved, movable bodies only
        Σ|e_α|²: the lanes added one by one, in lane order, to a group sum that starts at 0

Why: the scalar sweep runs at the latency of its visits' chain (interleaved.py), and LLVM's own loop
vectoriser leaves 8-contact loops scalar. Measured on captured steps of the 248-block wall
(benchmarks/JOURNAL.md, explicit vectors addendum): 0.57× the CPU of the 4-run scalar sweep per step on
Zen 5 (AVX-512), 0.77× compiled for Haswell (AVX2), at the same sweep counts and error.

Exactness: every lane does the scalar visit's IEEE operations on the same operands (no fast-math), so
the sweeps are Gauss–Seidel with momentum in the 8-run order, bit for bit, on any vector width (LLVM
splits ``<8 x double>`` on narrower hardware: the same bits, less speed). It is not the 4-run order's
sweep: another visit order, another path to the same tolerance. A support's velocity is never written
by the sweeps (the scalar push adds ±0 to it).
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine import _vector, momentum
from masonrycli.engine._jit import njit
from masonrycli.engine.lanes import FULL, LANES, R_PN, R_PT, R_ST, R_XN, R_XT, ROWS, pack_lanes, unpack_lanes
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

V = _vector  # short name in the kernels (imported by module name: _jit stamps the cache with its source)


@njit(inline="always")
def _local_solve_v(ut, un, bias, wtt, wtn, wnn, itt, itn, inn, isp, ism, mu):
    # lane_sweeps32._local_solve32 is its copy on <16 x float>: numba cannot take the vector module as an argument.
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
def _group(j, act, Q, IA, IB, v4, beta, mu, full):
    # lane_sweeps32._group32 is its copy on <16 x float>: numba cannot take the vector module as an argument.
    # The visit of group j's lanes in mask act (module doc), on the AoSoA rows Q and the padded v4.
    #   read: one 256-bit row a body and lane (gather_rows; an absent lane reads body 0, offset 0, and
    #         its zero rows make it open: nothing computed from it is stored)
    #   full (8 lanes, no clash): written back the same way (scatter_rows; every lane writes, the value
    #         it read where it does not push); else (a partial group or a sub-group) the pushing lanes of
    #         act only, by scalar stores in lane order (on Zen 5 the masked hardware scatters cost more:
    #         benchmarks/JOURNAL.md, explicit vectors addendum).
    # Returns the group's Σ|e_α|², its lanes added in lane order.
    q0 = j * ROWS * LANES
    at = j * LANES
    vax, vay, waa = V.gather_rows(v4, IA, at)
    vbx, vby, wbb = V.gather_rows(v4, IB, at)
    nx = V.load(Q, q0 + P_NX * LANES)
    ny = V.load(Q, q0 + P_NY * LANES)
    ta = V.load(Q, q0 + P_TA * LANES)
    na = V.load(Q, q0 + P_NA * LANES)
    tb = V.load(Q, q0 + P_TB * LANES)
    nb = V.load(Q, q0 + P_NB * LANES)
    dvx = vbx - vax  # u = H_αᵀ v as nlgs._relative_velocity
    dvy = vby - vay
    ut = dvx * ny - dvy * nx + wbb * tb - waa * ta
    un = dvx * nx + dvy * ny + wbb * nb - waa * na
    xt = V.load(Q, q0 + R_XT * LANES)  # the extrapolated start as momentum._momentum_sweeps
    xn = V.load(Q, q0 + R_XN * LANES)
    rt0 = xt + beta * (xt - V.load(Q, q0 + R_PT * LANES))
    rn0 = xn + beta * (xn - V.load(Q, q0 + R_PN * LANES))
    V.masked_store(Q, q0 + R_PT * LANES, xt, act)
    V.masked_store(Q, q0 + R_PN * LANES, xn, act)
    wtt = V.load(Q, q0 + P_WTT * LANES)
    wtn = V.load(Q, q0 + P_WTN * LANES)
    wnn = V.load(Q, q0 + P_WNN * LANES)
    ut = ut - (wtt * rt0 + wtn * rn0)
    un = un - (wtn * rt0 + wnn * rn0)
    rt, rn, st = _local_solve_v(ut, un, V.load(Q, q0 + P_BIAS * LANES), wtt, wtn, wnn, V.load(Q, q0 + P_ITT * LANES),
                                V.load(Q, q0 + P_ITN * LANES), V.load(Q, q0 + P_INN * LANES), V.load(Q, q0 + P_ISP * LANES),
                                V.load(Q, q0 + P_ISM * LANES), mu)  # fmt: skip
    V.masked_store(Q, q0 + R_ST * LANES, st, act)
    V.masked_store(Q, q0 + R_XT * LANES, rt, act)
    V.masked_store(Q, q0 + R_XN * LANES, rn, act)
    drt = rt - rt0
    drn = rn - rn0
    zero = V.splat(0.0)
    moved = act & ((drt != zero) | (drn != zero))
    px = drt * ny + drn * nx  # the push as nlgs._push
    py = -drt * nx + drn * ny
    ima = V.load(Q, q0 + P_IMA * LANES)
    iia = V.load(Q, q0 + P_IIA * LANES)
    imb = V.load(Q, q0 + P_IMB * LANES)
    iib = V.load(Q, q0 + P_IIB * LANES)
    push_a = moved & ((ima > zero) | (iia > zero))  # movable bodies only: a support is never written
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
        for q in range(LANES):
            if pa >> q & 1:
                o = IA[at + q]
                v4[o] = V.lane(nax, q)
                v4[o + 1] = V.lane(nay, q)
                v4[o + 2] = V.lane(naw, q)
            if pb >> q & 1:
                o = IB[at + q]
                v4[o] = V.lane(nbx, q)
                v4[o + 1] = V.lane(nby, q)
                v4[o + 2] = V.lane(nbw, q)
    et = wtt * drt + wtn * drn
    en = wtn * drt + wnn * drn
    e2 = V.select(act, et * et + en * en, zero)  # an absent lane's is +0: adding it changes no bit
    s = 0.0
    for q in range(LANES):
        s += V.lane(e2, q)
    return s


@njit
def _lane_sweeps(
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
    near_level=0.0,
    stall_near=0,
    growth=momentum.RESTART_GROWTH,
):
    # v: v_free in, v_n+1 out; r: warm start in, impulses out (as momentum._momentum_sweeps, flip omitted).
    #   Q, IA, IB, groups, v4 ← lanes.pack_lanes (v ← v_free + M⁻¹ H r_warm on the way)
    #   repeat: _extrapolate(v4); for each group: _group on each of its sub-groups (one unless it clashes)
    #           residual = sqrt(Σ|e_α|² / C); stop at the tolerance, the cap or the stall window
    #           (stall_after sweeps without a new low; stall_near once the low is ≤ near_level m/s);
    #           restart (j = 1) when the residual grew by more than ``growth`` (Tuning.lane_growth; the
    #           shipped one by default); β = (j − 1)/(j + 2)
    #   v, r, status ← lanes.unpack_lanes
    # Returns (iterations, residual).
    if count == 0:
        return 0, 0.0
    Q, IA, IB, sub, nsub, v4 = pack_lanes(contact_body, pack, count, v, r)
    run = nsub.shape[0]
    v_prev = v4.copy()
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
        momentum._extrapolate(v4, v_prev, beta)  # the padding stays 0: 0 + β (0 − 0)
        vbeta = V.splat(beta)
        sum_e2 = 0.0
        for j in range(run):
            # all 8 lanes, no clash: full a constant in this inlined copy (one copy for both kinds, the flag
            # known at run time only, cost ~1.5 ns a contact·sweep: 4.1 -> 5.8 on a step of the 248-block wall)
            if sub[j, 0] == FULL:
                sum_e2 += _group(j, V.mask_bits(FULL), Q, IA, IB, v4, vbeta, vmu, True)
                continue
            # a partial group; a clashing one's sub-groups in turn (lanes.py). Two call sites in all: numba
            # inlines _group at each, and a third copy was 0.5 s of a first run's CPU (benchmarks/JOURNAL.md,
            # "Cold start")
            for k in range(nsub[j]):
                sum_e2 += _group(j, V.mask_bits(sub[j, k]), Q, IA, IB, v4, vbeta, vmu, False)
        residual = np.sqrt(sum_e2 / count)
        if residual <= tolerance:
            break
        if residual < best:
            best = residual
            best_at = it
        elif tolerance > 0.0 and it - best_at >= (stall_near if best <= near_level else stall_after):
            break
        if residual > growth * last:
            j_restart = 1
        last = residual
        beta = (j_restart - 1.0) / (j_restart + 2.0)
        j_restart += 1
    unpack_lanes(Q, count, v4, v, r, status)
    return iterations, residual
