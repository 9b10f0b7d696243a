"""The default solver's first stage in lane groups (engine/lanes.py, engine/lane_sweeps.py).

Reference: a plain-Python implementation in this file of the same sweeps, one contact at a time —
Gauss–Seidel with momentum (momentum.py's rule) in the interleaved order with 8 runs, a clashing group's
lanes sub-group by sub-group, the residual summed per (sub-)group as the vector code does — and, where no
group clashes, the solver lab's scalar lane sweep ("lanes+split"). Bit for bit: every lane does the scalar
visit's IEEE operations on the same operands.
"""

import math
import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from test_engine_nlgs import _stack_problem

from masonrycli.engine import dispatch, lane_sweeps, lanes, momentum, nlgs
from masonrycli.engine.nlgs import STATUS_OPEN, STATUS_SLIP, STATUS_STICK
from masonrycli.engine.tuning import TUNING

ROOT = Path(__file__).resolve().parent.parent
N = nlgs


def _local_solve(ut, un, p, mu):
    # nlgs._local_solve's cases, in its order (p: the contact's packed row as Python floats)
    bias = p[N.P_BIAS]
    if un + bias >= 0.0:
        return 0.0, 0.0, STATUS_OPEN
    target = -bias - un
    if p[N.P_INN] > 0.0:
        rt = -p[N.P_ITT] * ut + p[N.P_ITN] * target
        rn = -p[N.P_ITN] * ut + p[N.P_INN] * target
        if rn >= 0.0 and abs(rt) <= mu * rn:
            return rt, rn, STATUS_STICK
    s0 = 1.0 if ut >= 0.0 else -1.0
    for s in (s0, -s0):
        inv = p[N.P_ISP] if s > 0.0 else p[N.P_ISM]
        if inv <= 0.0:
            continue
        rn = target * inv
        rt = -s * mu * rn
        if s * (ut + p[N.P_WTT] * rt + p[N.P_WTN] * rn) >= 0.0:
            return rt, rn, STATUS_SLIP
    raise AssertionError("a singular W_αα: not in these problems")


def _groups(body, pack, count):
    # [[contacts of each sub-group, in lane order]] of each group of the 8-run interleaved order: lane q
    # (contact q·run + j) joins the first sub-group with no contact on a body it moves (greedy colouring)
    run = -(-count // 8)
    out = []
    for j in range(run):
        subs = []
        for c in (q * run + j for q in range(8) if q * run + j < count):
            mine = {int(body[c, s]) for s in (0, 1) if _moves(pack[c], s)}
            for sub in subs:
                if not mine & {int(body[d, s]) for d in sub for s in (0, 1) if _moves(pack[d], s)}:
                    sub.append(c)
                    break
            else:
                subs.append([c])
        out.append(subs)
    return out


def _moves(p, side):
    return (p[N.P_IMA] > 0.0 or p[N.P_IIA] > 0.0) if side == 0 else (p[N.P_IMB] > 0.0 or p[N.P_IIB] > 0.0)


def _push(v, a, b, p, drt, drn, supports_too):
    px = drt * p[N.P_NY] + drn * p[N.P_NX]
    py = -drt * p[N.P_NX] + drn * p[N.P_NY]
    if supports_too or _moves(p, 0):
        v[a][0] -= p[N.P_IMA] * px
        v[a][1] -= p[N.P_IMA] * py
        v[a][2] -= p[N.P_IIA] * (p[N.P_TA] * drt + p[N.P_NA] * drn)
    if supports_too or _moves(p, 1):
        v[b][0] += p[N.P_IMB] * px
        v[b][1] += p[N.P_IMB] * py
        v[b][2] += p[N.P_IIB] * (p[N.P_TB] * drt + p[N.P_NB] * drn)


def slow_lane_sweeps(body, pack, count, mu, tolerance, cap, v0, r0, stall_after, near_level=0.0, stall_near=0):
    """Plain Python: momentum's sweeps (momentum._momentum_sweeps, flip omitted) visiting contact
    q·run + j for j = 0 …, q = 0 … 7, one at a time, a clashing group's lanes sub-group by sub-group;
    Σ|e_α|² summed per sub-group (from 0, in lane order). The warm start pushed group by group in lane
    order into every body, the sweeps' pushes into movable bodies only. Returns (iterations, residual, v,
    r, status). The stall window is stall_after sweeps without a new low, stall_near once the low is
    ≤ near_level (momentum.NEAR × the tolerance in the engine)."""
    P = [[float(x) for x in row] for row in pack[:count]]
    v = [[float(x) for x in row] for row in v0]
    x = [[float(r0[c, 0]), float(r0[c, 1])] for c in range(count)]
    prev = [list(xc) for xc in x]
    status = [0] * count
    groups = _groups(body, pack, count)
    for subs in groups:
        for c in sorted(c for sub in subs for c in sub):
            _push(v, int(body[c, 0]), int(body[c, 1]), P[c], x[c][0], x[c][1], True)
    v_prev = [list(row) for row in v]
    its, residual, best, best_at, last, j, beta = 0, 0.0, math.inf, 0, math.inf, 1, 0.0
    for it in range(cap):
        its = it + 1
        for i, row in enumerate(v):
            for k in range(3):
                xi = row[k]
                row[k] = xi + beta * (xi - v_prev[i][k])
                v_prev[i][k] = xi
        total = 0.0
        for sub in (sub for subs in groups for sub in subs):
            s = 0.0
            for c in sub:
                p, a, b = P[c], int(body[c, 0]), int(body[c, 1])
                dvx, dvy = v[b][0] - v[a][0], v[b][1] - v[a][1]
                ut = dvx * p[N.P_NY] - dvy * p[N.P_NX] + v[b][2] * p[N.P_TB] - v[a][2] * p[N.P_TA]
                un = dvx * p[N.P_NX] + dvy * p[N.P_NY] + v[b][2] * p[N.P_NB] - v[a][2] * p[N.P_NA]
                xt, xn = x[c]
                rt0 = xt + beta * (xt - prev[c][0])
                rn0 = xn + beta * (xn - prev[c][1])
                prev[c] = [xt, xn]
                wtt, wtn, wnn = p[N.P_WTT], p[N.P_WTN], p[N.P_WNN]
                ut -= wtt * rt0 + wtn * rn0
                un -= wtn * rt0 + wnn * rn0
                rt, rn, status[c] = _local_solve(ut, un, p, mu)
                x[c] = [rt, rn]
                drt, drn = rt - rt0, rn - rn0
                if drt != 0.0 or drn != 0.0:
                    _push(v, a, b, p, drt, drn, False)
                et, en = wtt * drt + wtn * drn, wtn * drt + wnn * drn
                s += et * et + en * en
            total += s
        residual = math.sqrt(total / count)
        if residual <= tolerance:
            break
        if residual < best:
            best, best_at = residual, it
        elif tolerance > 0.0 and it - best_at >= (stall_near if best <= near_level else stall_after):
            break
        if residual > momentum.RESTART_GROWTH * last:
            j = 1
        last = residual
        beta = (j - 1.0) / (j + 2.0)
        j += 1
    return its, residual, np.array(v), np.array(x), np.array(status, np.int8)


def _problem(n):
    body, pack, _, _, _, v0, r0, mu, _ = _stack_problem(n)
    return body, pack, v0, r0, mu


def _kinds(body, pack):
    groups = _groups(body, pack, body.shape[0])
    return {"full": sum(len(subs) == 1 and len(subs[0]) == 8 for subs in groups),
            "partial": sum(len(subs) == 1 and len(subs[0]) < 8 for subs in groups),
            "clash": sum(len(subs) > 1 for subs in groups),
            "multi": sum(any(len(sub) > 1 for sub in subs) for subs in groups if len(subs) > 1)}  # fmt: skip


def _same_bits(a, b):
    return np.array_equal(np.asarray(a, np.float64).view(np.int64), np.asarray(b, np.float64).view(np.int64))


def _run(body, pack, v0, r0, mu, tolerance, cap, stall=TUNING.first_stall):
    count = body.shape[0]
    v, r, st = v0.copy(), r0.copy(), np.full(count, -1, np.int8)
    its, res = lane_sweeps._lane_sweeps(body, pack, count, mu, tolerance, cap, v, r, st, stall)
    return its, res, v, r, st


# stack(6): 12 contacts, runs of 2: two partial groups that both clash (the bed joints of one block are
# 2 contacts apart), split into sub-groups of several lanes; stack(11): 22 contacts, runs of 3, clashing
# and partial groups; stack(39): 78 contacts, runs of 10, full groups and two partial ones (7 lanes).
@pytest.mark.parametrize(("n", "tolerance", "cap"), [(6, 0.0, 40), (11, 1e-9, 5000), (11, 0.0, 25), (39, 1e-9, 10_000),
                                                     (39, 0.0, 60)])  # fmt: skip
def test_lane_sweeps_are_the_plain_python_order_bit_for_bit(n, tolerance, cap):
    body, pack, v0, r0, mu = _problem(n)
    kinds = _kinds(body, pack)
    assert (kinds["full"] > 0 and kinds["partial"] > 0) if n == 39 else kinds["multi"] > 0, kinds
    for sweeps in (1, 2, 3, 7, cap) if tolerance == 0.0 else (cap,):
        its, res, v, r, st = _run(body, pack, v0, r0, mu, tolerance, sweeps, stall=sweeps)
        its_ref, res_ref, v_ref, r_ref, st_ref = slow_lane_sweeps(
            body, pack, body.shape[0], mu, tolerance, sweeps, v0, r0, sweeps
        )
        assert its == its_ref and res == res_ref, (sweeps, its, its_ref, res, res_ref)
        assert _same_bits(v, v_ref) and _same_bits(r, r_ref) and np.array_equal(st, st_ref)
        if tolerance > 0.0:
            assert res <= tolerance and its < cap


def test_a_stall_window_stops_the_sweeps_as_the_reference():
    body, pack, v0, r0, mu = _problem(39)
    its, res, v, r, _ = _run(body, pack, v0, r0, mu, 1e-30, 10_000, stall=3)
    ref = slow_lane_sweeps(body, pack, body.shape[0], mu, 1e-30, 10_000, v0, r0, 3)
    assert its == ref[0] < 10_000 and res == ref[1] and _same_bits(v, ref[2]) and _same_bits(r, ref[3])


def test_near_the_tolerance_the_stall_window_is_the_longer_one_as_the_reference():
    # Tolerance 1e-30 (never met): the sweeps end on a stall. With the low ≤ near_level the window is
    # stall_near instead of stall_after. near_level = inf: always the long window; 0: never; in between
    # (the low the short window stops at): the short window until the low reaches it, then the long one.
    body, pack, v0, r0, mu = _problem(39)
    count = body.shape[0]

    def kernel(near_level, stall_near):
        v, r, st = v0.copy(), r0.copy(), np.full(count, -1, np.int8)
        its, res = lane_sweeps._lane_sweeps(body, pack, count, mu, 1e-30, 10_000, v, r, st, 3, near_level, stall_near)
        return its, res, v, r

    short = kernel(0.0, 40)
    assert short[:2] == _run(body, pack, v0, r0, mu, 1e-30, 10_000, stall=3)[:2]  # the old window exactly
    long_ = kernel(np.inf, 40)
    assert long_[0] > short[0]
    for near_level in (np.inf, 1.5 * short[1], short[1]):
        its, res, v, r = kernel(near_level, 40)
        ref = slow_lane_sweeps(body, pack, count, mu, 1e-30, 10_000, v0, r0, 3, near_level, 40)
        assert its == ref[0] and res == ref[1] and _same_bits(v, ref[2]) and _same_bits(r, ref[3])
        assert its > short[0]  # the long window applied once the low was within near_level


def test_lane_sweeps_are_the_labs_scalar_lanes_bit_for_bit():
    from benchmarks.solver_lab import simd_sweep

    # without clashes (the stack of 39: full and partial groups) the order is the lab's "lanes+split"; a
    # clashing group there is visited lane by lane, here by sub-groups (lanes.py)
    for n in (39,):
        body, pack, v0, r0, mu = _problem(n)
        count = body.shape[0]
        assert _kinds(body, pack)["clash"] == 0
        its, res, v, r, st = _run(body, pack, v0, r0, mu, 1e-9, 10_000, stall=10_000)
        v2, r2, st2 = v0.copy(), r0.copy(), np.zeros(count, np.int8)
        its2, res2, _ = simd_sweep.solve(body, pack, count, mu, 1e-9, 10_000, v2, r2, st2, 10_000, "lanes+split")
        assert its == its2 and res == res2 and _same_bits(v, v2) and _same_bits(r, r2) and np.array_equal(st, st2)


def test_lane_sweeps_run_to_run_and_without_contacts():
    body, pack, v0, r0, mu = _problem(39)
    a, b = _run(body, pack, v0, r0, mu, 1e-9, 10_000), _run(body, pack, v0, r0, mu, 1e-9, 10_000)
    assert a[:2] == b[:2] and all(_same_bits(x, y) for x, y in zip(a[2:4], b[2:4])) and np.array_equal(a[4], b[4])
    v = v0.copy()
    assert lane_sweeps._lane_sweeps(body, pack, 0, mu, 1e-9, 100, v, r0.copy(), np.zeros(0, np.int8), 200) == (0, 0.0)
    assert _same_bits(v, v0)


def test_the_default_solve_starts_with_the_lane_sweeps():
    # dispatch.solve's first stage (nlgs-accel, tolerance > 0) is the lane sweeps while Tuning.lanes, the 4-run
    # scalar momentum sweep (interleaved._accelerated) without: the same converged step by both. Solver
    # "nlgs-accel": the float64 lane sweeps alone ("nlgs-accel32": test_engine_lane_sweeps32).
    body, pack, v0, r0, mu = _problem(39)
    count = body.shape[0]

    class Model:
        friction, tolerance, max_iterations, solver = mu, 1e-6, 10_000, "nlgs-accel"

    out = {}
    for flag in (True, False):
        v, r, st = v0.copy(), r0.copy(), np.zeros(count, np.int8)
        out[flag] = (*dispatch.solve(body, pack, count, Model, v, r, st, replace(TUNING, lanes=flag)), v, r)
    its, res, v, r, _ = _run(body, pack, v0, r0, mu, 1e-6, 10_000)
    assert res <= 1e-6 and out[True][:2] == (its, res) and _same_bits(out[True][2], v) and _same_bits(out[True][3], r)
    assert out[False][0] != its and out[False][1] <= 1e-6  # another order, another path to the tolerance
    assert np.abs(out[False][2] - v).max() < 1e-4  # the RMS tolerance bounds no velocity (nlgs.py doc)


def test_lane_sweeps_on_narrower_vectors(tmp_path):
    # Compiled for Haswell (AVX2: LLVM splits each <8 x double> into two ymm halves and scalarises the
    # masked gathers and scatters): the same bits as the plain-Python reference. A fresh process (numba
    # reads the CPU name at import) with an empty cache (numba shows no machine code of a cached kernel).
    env = dict(os.environ, NUMBA_CPU_NAME="haswell", NUMBA_CPU_FEATURES="", PYTHONPATH=str(ROOT),
               NUMBA_CACHE_DIR=str(tmp_path))  # fmt: skip
    code = (
        "import sys; sys.path.insert(0, 'tests'); import test_engine_lanes as t\n"
        "t.test_lane_sweeps_are_the_plain_python_order_bit_for_bit(11, 0.0, 25)\n"
        "t.test_lane_sweeps_are_the_plain_python_order_bit_for_bit(39, 1e-9, 10_000)\n"
        "from masonrycli.engine import lane_sweeps\n"
        "asm = ''.join(lane_sweeps._lane_sweeps.inspect_asm().values())\n"
        "assert 'zmm' not in asm and 'ymm' in asm, 'not compiled for AVX2'\n"
        "print('ok')\n"
    )
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr[-2000:]


def test_group_layout_puts_each_contact_in_its_lane():
    # lanes.py's AoSoA rows: contact q·run + j's packed row at Q[(j·ROWS + row)·8 + q] (read back here
    # through a 0-sweep solve: r, status and v come back from the rows unchanged).
    body, pack, v0, r0, mu = _problem(11)
    r0 = np.arange(2.0 * body.shape[0]).reshape(-1, 2) * 1e-3
    count = body.shape[0]
    its, res, v, r, st = _run(body, pack, v0, r0, mu, 1e-9, 0)
    assert (its, res) == (0, 0.0) and _same_bits(r, r0) and np.all(st == 0)
    ref = slow_lane_sweeps(body, pack, count, mu, 1e-9, 0, v0, r0, 200)
    assert _same_bits(v, ref[2])
    assert lanes.ROWS == nlgs.PACK_WIDTH + 5 and lanes.LANES == 8
