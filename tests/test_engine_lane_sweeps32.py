"""The default solver's float32 first stage (engine/lane_sweeps32.py, engine/_vector32.py).

References: numpy's float32 operations (the same IEEE single-precision operations) lane by lane for the
vector type; a plain-Python implementation in this file of the float32 sweeps, one contact at a time on
numpy float32 scalars — Gauss–Seidel with momentum in the 16-run order (the staggered layout where it
clashes less), a clashing group's lanes sub-group by sub-group, each lane's |e_α|² summed over the groups
in float32 and the lanes' sums in float64 — bit for bit; and for the whole first stage, the float64 test
it ends on, checked on velocities re-derived here from its impulses.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_engine_lanes import _local_solve, _moves, _same_bits
from test_engine_nlgs import _dense_h, _stack_problem

from masonrycli.engine import _vector32 as V
from masonrycli.engine import dispatch, lane_sweeps, lane_sweeps32, momentum, nlgs
from masonrycli.engine._jit import njit
from masonrycli.engine.tuning import TUNING

N = nlgs
F = np.float32
W = 16


@njit(cache=False)
def _arithmetic(a, b, out):
    # rows of out: a + b, a − b, a · b, a / b, −a, |a|, splat(b[0]), select(a < b, a, b)
    x = V.load(a, 0)
    y = V.load(b, 0)
    m = V.mask_bits(0xFFFF)
    V.masked_store(out, 0, x + y, m)
    V.masked_store(out, 16, x - y, m)
    V.masked_store(out, 32, x * y, m)
    V.masked_store(out, 48, x / y, m)
    V.masked_store(out, 64, -x, m)
    V.masked_store(out, 80, V.vabs(x), m)
    V.masked_store(out, 96, V.splat(b[0]), m)
    V.masked_store(out, 112, V.select(x < y, x, y), m)


@njit(cache=False)
def _masks(a, b, bits, out_bits, out_lanes, out_masked):
    # bits of ≥ > ≤ < == ≠, (≥ & ≠) | ~(<); lanes of a widened; a stored in the lanes of mask bits
    x = V.load(a, 0)
    y = V.load(b, 0)
    out_bits[0] = V.bits_of(x >= y)
    out_bits[1] = V.bits_of(x > y)
    out_bits[2] = V.bits_of(x <= y)
    out_bits[3] = V.bits_of(x < y)
    out_bits[4] = V.bits_of(x == y)
    out_bits[5] = V.bits_of(x != y)
    out_bits[6] = V.bits_of(((x >= y) & (x != y)) | ~(x < y))
    for k in range(16):
        out_lanes[k] = V.lane(x, k)
    V.masked_store(out_masked, 0, x, V.mask_bits(bits))


@njit(cache=False)
def _rows(src, idx, at, dst, out):
    # gather_rows of src's 4-float rows idx[at + k] into out (x, y, w); scatter_rows of (x + 1, y, w) to dst
    x, y, w = V.gather_rows(src, idx, at)
    m = V.mask_bits(0xFFFF)
    V.masked_store(out, 0, x, m)
    V.masked_store(out, 16, y, m)
    V.masked_store(out, 32, w, m)
    V.scatter_rows(dst, idx, at, x + V.splat(1.0), y, w)


def _random(rng):
    a, b = rng.normal(size=W).astype(F), rng.normal(size=W).astype(F)
    a[rng.random(W) < 0.15] = rng.choice([0.0, -0.0, np.inf, -np.inf, np.nan])
    b[rng.random(W) < 0.15] = rng.choice([0.0, -0.0, np.inf, np.nan])
    tie = rng.random(W) < 0.2
    b[tie] = a[tie]
    return a, b


def _same32(x, y):
    return np.array_equal(np.asarray(x, F).view(np.int32), np.asarray(y, F).view(np.int32))


def _bits(mask):
    return int(np.sum(mask.astype(np.int64) << np.arange(W)))


@pytest.mark.parametrize("seed", range(10))
def test_vector_operations_are_numpys_float32_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    a, b = _random(rng)
    out = np.empty(128, F)
    _arithmetic(a, b, out)
    with np.errstate(all="ignore"):
        expected = [a + b, a - b, a * b, a / b, -a, np.abs(a), np.full(W, b[0]), np.where(a < b, a, b)]
    for k, e in enumerate(expected):
        assert _same32(out[16 * k : 16 * k + 16], e), k
    bits = int(rng.integers(0, 1 << W))
    out_bits, lanes, masked = np.empty(7, np.int64), np.empty(W), np.full(W, F(7.0))
    _masks(a, b, bits, out_bits, lanes, masked)
    with np.errstate(invalid="ignore"):
        m = [a >= b, a > b, a <= b, a < b, a == b, a != b, ((a >= b) & (a != b)) | ~(a < b)]
    assert out_bits.tolist() == [_bits(x) for x in m]
    assert _same_bits(lanes, a.astype(np.float64))
    assert _same32(masked, np.where((bits >> np.arange(W)) & 1 == 1, a, F(7.0)))


@pytest.mark.parametrize("seed", range(5))
def test_rows_are_numpys(seed):
    rng = np.random.default_rng(seed)
    bodies = 40
    src, dst = rng.normal(size=4 * bodies).astype(F), rng.normal(size=4 * bodies).astype(F)
    before = dst.copy()
    pick = rng.choice(bodies, W, replace=False)
    idx = np.r_[np.zeros(3), 4 * pick].astype(np.int64)
    out = np.empty(48, F)
    _rows(src, idx, 3, dst, out)
    rows = src.reshape(bodies, 4)[pick]
    assert _same32(out, np.r_[rows[:, 0], rows[:, 1], rows[:, 2]])
    expect = before.reshape(bodies, 4).copy()
    expect[pick] = np.column_stack([rows[:, 0] + F(1.0), rows[:, 1], rows[:, 2], np.zeros(W, F)])
    assert _same32(dst, expect.ravel())


def _columns(k, h, count=None):
    """k columns of h unit blocks (1 kg, inertia 1/6 kg·m²) 2 m apart on one support, one contact point a
    bed joint, contact c = q·k + column (block q of its column on the one below, or on the support),
    falling at g·dt, sheared by random horizontal velocities. In 16 runs of k contacts (h = 16), lanes q
    and q + 1 hold the same column's joints q and q + 1: every group clashes unless staggered."""
    rng = np.random.default_rng(k * 100 + h)
    n = k * h
    q = np.zeros((n + 1, 3))
    q[:n, 0] = 2.0 * (np.arange(n) % k)
    q[:n, 1] = np.arange(n) // k + 0.5
    q[n, 1] = -0.5
    inv_mass, inv_inertia = np.r_[np.full(n, 1.0), 0.0], np.r_[np.full(n, 6.0), 0.0]
    body = np.array([(i, n) if i < k else (i - k, i) for i in range(n)], dtype=np.int32)
    point = np.array([(q[i, 0], float(i // k)) for i in range(n)])
    normal = np.array([(0.0, -1.0) if i < k else (0.0, 1.0) for i in range(n)])
    count = n if count is None else count
    body, point, normal = body[:count], point[:count], normal[:count]
    mu, dt = 0.5, 1e-3
    pack = np.zeros((count, nlgs.PACK_WIDTH))
    nlgs._prepare(body, point, normal, np.zeros(count), count, q, inv_mass, inv_inertia, mu, dt, pack)
    v0 = np.zeros((n + 1, 3))
    v0[:n, 0] = rng.normal(scale=0.01, size=n)
    v0[:n, 1] = -9.81 * dt
    return body, pack, q, point, normal, v0, np.zeros((count, 2)), mu


def _problem(name):
    if name.startswith("stack"):
        body, pack, _, _, _, v0, r0, mu, _ = _stack_problem(int(name[5:]))
        return body, pack, v0, r0, mu
    k, h, count = (int(x) for x in name[7:].split("x"))
    body, pack, _, _, _, v0, r0, mu = _columns(k, h, count)
    return body, pack, v0, r0, mu


def _operators(name):
    # (H, M⁻¹) of a problem, dense (test_engine_nlgs._dense_h)
    if name.startswith("stack"):
        _, _, h, m_inv, *_ = _stack_problem(int(name[5:]))
        return h, m_inv
    k, h_, count = (int(x) for x in name[7:].split("x"))
    body, _, q, point, normal, *_ = _columns(k, h_, count)
    inv = np.r_[np.tile([1.0, 1.0, 6.0], q.shape[0] - 1), np.zeros(3)]
    return _dense_h(q, body, point, normal), np.diag(inv)


def _layout(body, pack, count, stagger):
    # [[contacts of each sub-group in lane order]] of each group: lane q holds q·run + (j + s_q) mod run
    run = -(-count // W)
    out = []
    for j in range(run):
        subs = []
        for q in range(W):
            s = run // 2 if stagger and q % 2 else 0
            c = q * run + (j + s) % run
            if c >= count:
                continue
            mine = {int(body[c, i]) for i in (0, 1) if _moves(pack[c], i)}
            for sub in subs:
                if not mine & {int(body[d, i]) for d in sub for i in (0, 1) if _moves(pack[d], i)}:
                    sub.append(c)
                    break
            else:
                subs.append([c])
        out.append(subs)
    return out


def _stagger(body, pack, count):
    # the layout rule: staggered when more than an eighth of the plain layout's groups clash and the
    # staggered one has fewer clashing groups
    clashing = [sum(len(subs) > 1 for subs in _layout(body, pack, count, s)) for s in (False, True)]
    run = -(-count // W)
    return 8 * clashing[0] > run and clashing[1] < clashing[0]


def _v_of_r(body, pack, v0, order, r):
    # float32(v_free + M⁻¹ H r): nlgs._push's float64 operations, contacts in ``order``, every body
    v64 = [[float(x) for x in row] for row in v0]
    for c in order:
        p = pack[c]
        drt, drn = float(r[c][0]), float(r[c][1])
        a, b = int(body[c, 0]), int(body[c, 1])
        px, py = drt * p[N.P_NY] + drn * p[N.P_NX], -drt * p[N.P_NX] + drn * p[N.P_NY]
        v64[a][0] -= p[N.P_IMA] * px
        v64[a][1] -= p[N.P_IMA] * py
        v64[a][2] -= p[N.P_IIA] * (p[N.P_TA] * drt + p[N.P_NA] * drn)
        v64[b][0] += p[N.P_IMB] * px
        v64[b][1] += p[N.P_IMB] * py
        v64[b][2] += p[N.P_IIB] * (p[N.P_TB] * drt + p[N.P_NB] * drn)
    return [[F(x) for x in row] for row in v64]


def _lane_order(count, stagger):
    # the contacts group by group, lane by lane (absent lanes skipped)
    run = -(-count // W)
    out = []
    for j in range(run):
        for q in range(W):
            c = q * run + (j + (run // 2 if stagger and q % 2 else 0)) % run
            if c < count:
                out.append(c)
    return out


def slow_sweeps32(body, pack, count, mu, tolerance, cap, v0, r0, stall_after, resync=0):
    """Plain Python on float32 scalars: the float32 stage's sweeps (lane_sweeps32's module doc), one contact
    at a time. v starts as float32(v_free + M⁻¹ H r0) (the pushes in float64, contact order); the sweeps
    push movable bodies only; every ``resync`` sweeps v and v_prev are re-derived from r and r_prev (the
    pushes in float64, group by group in lane order). Returns (iterations, residual, r as float64,
    status)."""
    v = _v_of_r(body, pack, v0, range(count), [[float(x) for x in row] for row in r0[:count]])
    P = [[F(x) for x in row] for row in pack[:count]]
    x = [[F(r0[c, 0]), F(r0[c, 1])] for c in range(count)]
    prev = [list(xc) for xc in x]
    status = [0] * count
    stagger = _stagger(body, pack, count)
    groups = _layout(body, pack, count, stagger)
    lane_of = {c: q for subs in groups for sub in subs for c in sub for q in [_lane(count, c)]}
    v_prev = [list(row) for row in v]
    f32mu = F(mu)
    its, residual, best, best_at, last, j, beta = 0, 0.0, math.inf, 0, math.inf, 1, 0.0
    for it in range(cap):
        its = it + 1
        if resync and it and it % resync == 0:
            v = _v_of_r(body, pack, v0, _lane_order(count, stagger), x)
            v_prev = _v_of_r(body, pack, v0, _lane_order(count, stagger), prev)
        fb = F(beta)
        for i, row in enumerate(v):
            for k in range(3):
                xi = row[k]
                row[k] = xi + fb * (xi - v_prev[i][k])
                v_prev[i][k] = xi
        acc = [F(0.0)] * W
        for sub in (sub for subs in groups for sub in subs):
            for c in sub:
                p, a, b = P[c], int(body[c, 0]), int(body[c, 1])
                dvx, dvy = v[b][0] - v[a][0], v[b][1] - v[a][1]
                ut = dvx * p[N.P_NY] - dvy * p[N.P_NX] + v[b][2] * p[N.P_TB] - v[a][2] * p[N.P_TA]
                un = dvx * p[N.P_NX] + dvy * p[N.P_NY] + v[b][2] * p[N.P_NB] - v[a][2] * p[N.P_NA]
                xt, xn = x[c]
                rt0 = xt + fb * (xt - prev[c][0])
                rn0 = xn + fb * (xn - prev[c][1])
                prev[c] = [xt, xn]
                wtt, wtn, wnn = p[N.P_WTT], p[N.P_WTN], p[N.P_WNN]
                ut = ut - (wtt * rt0 + wtn * rn0)
                un = un - (wtn * rt0 + wnn * rn0)
                rt, rn, status[c] = _local_solve(ut, un, p, f32mu)
                x[c] = [rt, rn]
                drt, drn = rt - rt0, rn - rn0
                if drt != 0.0 or drn != 0.0:
                    px, py = drt * p[N.P_NY] + drn * p[N.P_NX], -drt * p[N.P_NX] + drn * p[N.P_NY]
                    if _moves(p, 0):
                        v[a][0] = v[a][0] - p[N.P_IMA] * px
                        v[a][1] = v[a][1] - p[N.P_IMA] * py
                        v[a][2] = v[a][2] - p[N.P_IIA] * (p[N.P_TA] * drt + p[N.P_NA] * drn)
                    if _moves(p, 1):
                        v[b][0] = v[b][0] + p[N.P_IMB] * px
                        v[b][1] = v[b][1] + p[N.P_IMB] * py
                        v[b][2] = v[b][2] + p[N.P_IIB] * (p[N.P_TB] * drt + p[N.P_NB] * drn)
                et, en = wtt * drt + wtn * drn, wtn * drt + wnn * drn
                q = lane_of[c]
                acc[q] = acc[q] + (et * et + en * en)
        total = 0.0
        for q in range(W):
            total += float(acc[q])
        residual = math.sqrt(total / count)
        if residual <= tolerance:
            break
        if residual < best:
            best, best_at = residual, it
        elif tolerance > 0.0 and it - best_at >= stall_after:
            break
        if residual > momentum.RESTART_GROWTH * last:
            j = 1
        last = residual
        beta = (j - 1.0) / (j + 2.0)
        j += 1
    return its, residual, np.array(x, np.float64), np.array(status, np.int8)


def _lane(count, c):
    return c // -(-count // W)


def _run32(body, pack, v0, r0, mu, tolerance, cap, stall=TUNING.first_stall, resync=lane_sweeps32.RESYNC):
    count = body.shape[0]
    v, r, st = v0.copy(), r0.copy(), np.full(count, -1, np.int8)
    its, res = lane_sweeps32.lane_sweeps32(body, pack, count, mu, tolerance, cap, v, r, st, stall, -1, resync)
    assert _same_bits(v, v0)  # v_free is only read
    return its, res, r, st


# columns4x16x64: 64 contacts, runs of 4, full groups that all clash unless staggered (staggered: none);
# columns4x16x62: the same with two contacts fewer, partial groups; stack11: 22 contacts, runs of 2, every
# group clashing, split into sub-groups (no stagger helps a single column); stack39: 78 contacts, runs of 5,
# no clash.
PROBLEMS = {"columns4x16x64": (True, False), "columns4x16x62": (True, False), "stack11": (False, True),
            "stack39": (False, False)}  # fmt: skip


@pytest.mark.parametrize("resync", [0, 3])
@pytest.mark.parametrize("name", list(PROBLEMS))
def test_float32_sweeps_are_the_plain_python_order_bit_for_bit(name, resync):
    body, pack, v0, r0, mu = _problem(name)
    count = body.shape[0]
    stagger, clashing = PROBLEMS[name]
    assert lane_sweeps32._choose_layout(body, pack, count, v0.shape[0]) == int(stagger) == _stagger(body, pack, count)
    assert any(len(subs) > 1 for subs in _layout(body, pack, count, stagger)) == clashing
    for tolerance, sweeps in ((0.0, 1), (0.0, 2), (0.0, 9), (1e-6, 3000)):
        its, res, r, st = _run32(body, pack, v0, r0, mu, tolerance, sweeps, stall=sweeps, resync=resync)
        ref = slow_sweeps32(body, pack, count, mu, tolerance, sweeps, v0, r0, sweeps, resync)
        assert its == ref[0] and res == ref[1], (tolerance, sweeps, its, ref[0], res, ref[1])
        assert _same_bits(r, ref[2]) and np.array_equal(st, ref[3])
        if tolerance > 0.0:
            assert res <= tolerance and its < sweeps


class _Model:
    tolerance, max_iterations, solver = 1e-6, 10_000, "nlgs-accel"


@pytest.mark.parametrize("name", ["columns4x16x64", "columns4x16x62", "stack39"])
def test_the_first_stage_ends_on_a_float64_sweep_from_the_float32_impulses(name):
    body, pack, v0, r0, mu = _problem(name)
    count = body.shape[0]
    model = type("M", (_Model,), {"friction": mu, "solver": "nlgs-accel32"})
    v, r, st = v0.copy(), r0.copy(), np.zeros(count, np.int8)
    its, res = dispatch.solve(body, pack, count, model, v, r, st)
    # by hand: the float32 sweeps to the tolerance, then the float64 lane sweeps from their impulses
    its32, _, r32, _ = _run32(body, pack, v0, r0, mu, 1e-6, 10_000)
    v2, r2, st2 = v0.copy(), r32.copy(), np.zeros(count, np.int8)
    its64, res64 = lane_sweeps._lane_sweeps(body, pack, count, mu, 1e-6, 10_000 - its32, v2, r2, st2, 200)
    assert its32 > 0 and its64 >= 1 and (its, res) == (its32 + its64, res64) and res <= 1e-6
    assert _same_bits(v, v2) and _same_bits(r, r2) and np.array_equal(st, st2)
    # v is v_free + M⁻¹ H r in float64 (re-derived, not the float32 sweeps' velocities)
    h, m_inv = _operators(name)
    assert np.abs(v.ravel() - (v0.ravel() + m_inv @ h @ r.ravel())).max() < 1e-12


def test_without_a_tolerance_or_float32_the_first_stage_is_the_float64_lane_sweeps():
    # tolerance 0 runs exactly the cap (nlgs.py doc): in float64 only, even for "nlgs-accel32"; solver
    # "nlgs-accel": the lane sweeps alone
    body, pack, v0, r0, mu = _problem("stack39")
    count = body.shape[0]
    for solver, tolerance in (("nlgs-accel32", 0.0), ("nlgs-accel", 1e-6)):
        model = type("M", (_Model,), {"friction": mu, "tolerance": tolerance, "max_iterations": 50, "solver": solver})
        v, r, st = v0.copy(), r0.copy(), np.zeros(count, np.int8)
        out = dispatch.solve(body, pack, count, model, v, r, st)
        v2, r2, st2 = v0.copy(), r0.copy(), np.zeros(count, np.int8)
        ref = lane_sweeps._lane_sweeps(body, pack, count, mu, tolerance, 50, v2, r2, st2, TUNING.first_stall)
        assert out == ref and _same_bits(v, v2) and _same_bits(r, r2)


def test_float32_sweeps_run_to_run_and_without_contacts():
    body, pack, v0, r0, mu = _problem("columns4x16x62")
    a, b = _run32(body, pack, v0, r0, mu, 1e-6, 3000), _run32(body, pack, v0, r0, mu, 1e-6, 3000)
    assert a[:2] == b[:2] and _same_bits(a[2], b[2]) and np.array_equal(a[3], b[3])
    out = lane_sweeps32.lane_sweeps32(body, pack, 0, mu, 1e-6, 100, v0, r0.copy(), np.zeros(0, np.int8), 200, -1)
    assert out == (0, 0.0)


@pytest.mark.parametrize("name", ["columns4x16x62", "stack39"])
def test_solver_nlgs_accel32_is_the_float32_first_stage_and_nlgs_accel_is_not(name):
    # solver "nlgs-accel32" runs lane_sweeps32.first_stage; "nlgs-accel" the float64 lane sweeps alone:
    # each against the first stage called by hand
    body, pack, v0, r0, mu = _problem(name)
    count = body.shape[0]
    for solver, first in (("nlgs-accel32", lane_sweeps32.first_stage), ("nlgs-accel", lane_sweeps._lane_sweeps)):
        model = type("M", (_Model,), {"friction": mu, "solver": solver})
        v, r, st = v0.copy(), r0.copy(), np.zeros(count, np.int8)
        out = dispatch.solve(body, pack, count, model, v, r, st)
        v2, r2, st2 = v0.copy(), r0.copy(), np.zeros(count, np.int8)
        ref = first(body, pack, count, mu, 1e-6, 10_000, v2, r2, st2, TUNING.first_stall)
        assert out == ref and out[1] <= 1e-6 and _same_bits(v, v2) and _same_bits(r, r2)


def test_the_first_stage_waits_near_the_tolerance_by_the_structures_depth(monkeypatch):
    # dispatch.solve hands lane_sweeps32.first_stage momentum.stall_near(model): 25 sweeps a block of depth, at
    # least Tuning.first_stall; first_stage's float64 part is _lane_sweeps with that window within NEAR × tol
    body, pack, v0, r0, mu = _problem("stack39")
    count = body.shape[0]
    seen = []
    first = lane_sweeps32.first_stage

    def spy(*args):
        seen.append(args[10])  # stall_near (args[11]: Tuning.lane_growth)
        assert args[11] == TUNING.lane_growth
        return first(*args)

    monkeypatch.setattr(lane_sweeps32, "first_stage", spy)
    for depth, window in ((0.0, TUNING.first_stall), (6.0, TUNING.first_stall), (64.0, 1600)):
        model = type("M", (_Model,), {"friction": mu, "solver": "nlgs-accel32", "block_depth": depth})
        assert momentum.stall_near(model) == window
        dispatch.solve(body, pack, count, model, v0.copy(), r0.copy(), np.zeros(count, np.int8))
        assert seen[-1] == window
    # by hand, on a step that stalls near its tolerance: the float32 stage, then the float64 one with both windows
    stalled = first(body, pack, count, mu, 1e-30, 5000, v0.copy(), r0.copy(), np.zeros(count, np.int8), 3, 3)
    tol = stalled[1] / 2  # where it stalled with window 3 is within NEAR × this tolerance
    v, r, st = v0.copy(), r0.copy(), np.zeros(count, np.int8)
    out = first(body, pack, count, mu, tol, 5000, v, r, st, 3, 40)
    its32, _, r32, _ = _run32(body, pack, v0, r0, mu, tol, 4999, stall=3)
    v2, r2, st2 = v0.copy(), r32.copy(), np.zeros(count, np.int8)
    its64, res64 = lane_sweeps._lane_sweeps(
        body, pack, count, mu, tol, 5000 - its32, v2, r2, st2, 3, momentum.NEAR * tol, 40
    )
    assert out == (its32 + its64, res64) and _same_bits(v, v2) and _same_bits(r, r2)
    short = first(body, pack, count, mu, tol, 5000, v0.copy(), r0.copy(), np.zeros(count, np.int8), 3, 3)
    assert out[0] > short[0]  # the longer window near the tolerance went on
