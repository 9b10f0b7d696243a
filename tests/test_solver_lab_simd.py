"""The coloured SIMD sweeps of the solver lab (benchmarks/solver_lab/simd_sweep.py).

References: the engine's own local solve and sweep (nlgs._local_solve, dispatch.first_stage), the
colouring's definition checked by brute force, and the tight solve the lab's capture keeps per problem.
"""

import functools

import numpy as np
import pytest
from solver_lab_helpers import tiny_cold_problem
from test_engine_nlgs import _packed_row, _random_problem, _stack_problem

from benchmarks.solver_lab import law, simd_sweep
from benchmarks.solver_lab.outcome import Context
from masonrycli.engine import interleaved, lanes, momentum, nlgs
from masonrycli.engine.tuning import TUNING


@pytest.fixture(scope="module")
def problem():
    return tiny_cold_problem()


def _movable(pack, c, side):
    im, ii = (nlgs.P_IMA, nlgs.P_IIA) if side == 0 else (nlgs.P_IMB, nlgs.P_IIB)
    return pack[c, im] > 0.0 or pack[c, ii] > 0.0


def test_branch_free_local_solve_is_the_engines_bit_for_bit(problem):
    pack = problem.pack()
    rng = np.random.default_rng(7)
    n = 20_000
    rows = rng.integers(0, problem.count, n)
    big = np.repeat(pack[rows], 1, axis=0)
    # u_free over open, stick and both sliding directions; one in eight rows with a W_tn large enough to
    # reverse the free sliding direction (the second candidate of _local_solve)
    ut = rng.normal(0.0, 0.5, n) * rng.choice([0.0, 1e-3, 1.0, 10.0], n)
    un = rng.normal(-0.2, 0.3, n)
    flip = rng.random(n) < 0.125
    big[flip, nlgs.P_WTN] *= 5.0
    mu = problem.mu
    r_ref, s_ref = np.empty((n, 2)), np.empty(n, np.int8)
    r_bf, s_bf = np.empty((n, 2)), np.empty(n, np.int8)
    simd_sweep.local_solve_many(ut, un, big, mu, r_ref, s_ref)
    simd_sweep.local_solve_bf_many(ut, un, big, mu, r_bf, s_bf)
    assert set(np.unique(s_ref)) >= {nlgs.STATUS_OPEN, nlgs.STATUS_STICK, nlgs.STATUS_SLIP}
    assert np.array_equal(r_ref.view(np.int64), r_bf.view(np.int64)) and np.array_equal(s_ref, s_bf)


def test_no_two_contacts_of_a_colour_share_a_movable_body(problem):
    pack = problem.pack()
    count, bodies = problem.count, problem.inv_mass.shape[0]
    order, start = np.empty(count, np.int64), np.empty(simd_sweep.MASK_WORDS * 64 + 1, np.int64)
    colours = simd_sweep.colour(problem.body, pack, count, bodies, order, start)
    assert sorted(order) == list(range(count)) and start[0] == 0 and start[colours] == count
    for k in range(colours):
        seen = set()
        for c in order[start[k] : start[k + 1]]:
            for side in (0, 1):
                if _movable(pack, c, side):
                    body = int(problem.body[c, side])
                    assert body not in seen, (k, c, body)
                    seen.add(body)
    # greedy: a contact in colour k > 0 meets every lower colour on one of its movable bodies
    colour_of = np.empty(count, np.int64)
    for k in range(colours):
        colour_of[order[start[k] : start[k + 1]]] = k
    for c in range(count):
        mine = {int(problem.body[c, s]) for s in (0, 1) if _movable(pack, c, s)}
        met = {
            colour_of[d]
            for d in range(count)
            if d != c and mine & {int(problem.body[d, s]) for s in (0, 1) if _movable(pack, d, s)}
        }
        assert set(range(colour_of[c])) <= met


def _solve(problem, variant, tolerance, cap=200_000):
    v, r = problem.v_free.copy(), problem.r_warm.copy()
    status = np.zeros(problem.count, np.int8)
    out = simd_sweep.solve(problem.body, problem.pack(), problem.count, problem.mu, tolerance, cap, v, r, status,
                           cap, variant)  # fmt: skip
    return out, v, r


@pytest.mark.parametrize("variant", ["split", "fused", "blocks", "lanes+split", "split4", "lanes+vec"])
def test_coloured_sweeps_converge_to_the_tight_solution(problem, variant):
    (sweeps, residual, colours), v, r = _solve(problem, variant, 1e-10)
    assert residual <= 1e-10 and colours >= 2 and sweeps > 1
    ctx = Context(problem)
    # the lab's own law (numpy, written apart from the engine) holds, and v is the tight reference's
    assert ctx.residual(law.velocity_from_impulse(problem, ctx.H, r), r) <= 1e-8
    np.testing.assert_allclose(v, law.velocity_from_impulse(problem, ctx.H, r), atol=1e-10)
    assert np.abs(v - problem.v_ref).max() < 1e-6


def test_level_schedule_replays_the_engines_sweep_bit_for_bit(problem):
    # the "levels" variant runs the engine's interleaved visit order (INTERLEAVE runs: the scalar momentum
    # sweep, alternate passed so that it is not the lane sweeps' first stage) level by level: the same sweeps
    tol = 1e-7
    (sweeps, residual, _), v, r = _solve(problem, "levels", tol)
    v2, r2 = problem.v_free.copy(), problem.r_warm.copy()
    s2 = np.zeros(problem.count, np.int8)
    sweeps2, residual2 = interleaved.sweeps(problem.body, problem.pack(), problem.count, problem.mu, tol,
                                            200_000, v2, r2, s2, interleaved.MOMENTUM, TUNING.first_stall)  # fmt: skip
    assert sweeps == sweeps2 and residual == residual2
    assert np.array_equal(v, v2) and np.array_equal(r, r2)


@pytest.mark.parametrize("variant", ["split", "blocks"])
def test_the_same_step_gives_the_same_bits(problem, variant):
    a = _solve(problem, variant, 1e-8)
    b = _solve(problem, variant, 1e-8)
    assert a[0] == b[0] and np.array_equal(a[1], b[1]) and np.array_equal(a[2], b[2])


def test_lane_groups_are_the_8_run_interleaved_order_in_independent_groups(problem):
    pack = problem.pack()
    count, bodies = problem.count, problem.inv_mass.shape[0]
    order, start = np.empty(count, np.int64), np.empty(count + 1, np.int64)
    groups = simd_sweep.lanes(problem.body, pack, count, bodies, order, start)
    run = -(-count // 8)
    expected = [q * run + j for j in range(run) for q in range(8) if q * run + j < count]
    assert list(order) == expected and start[0] == 0 and start[groups] == count
    assert all(0 < start[k + 1] - start[k] <= 8 for k in range(groups))
    for k in range(groups):
        seen = set()
        for c in order[start[k] : start[k + 1]]:
            for side in (0, 1):
                if _movable(pack, c, side):
                    assert int(problem.body[c, side]) not in seen
                    seen.add(int(problem.body[c, side]))
    # on this 7-block wall the runs are short and meet: some groups had to be split into single visits
    assert groups > run


def test_branch_free_local_solve_on_edge_inputs():
    # each branch at its boundary, a W_tn that reverses the free direction, degenerate rows as _prepare
    # writes them (W⁻¹ zeroed; then also both sliding denominators): the engine's bits and statuses
    mu, w_diag, w_coupled = 0.5, (1.0, 0.0, 1.0), (1.0, 0.9, 1.0)
    cases = [  # (u_t, u_n, W, bias, the status _local_solve's definition gives)
        (0.3, 0.2, w_diag, 0.0, nlgs.STATUS_OPEN),
        (0.0, 0.0, w_diag, 0.0, nlgs.STATUS_OPEN),  # u_n + bias = 0 is open
        (0.1, -1.0, w_diag, 0.0, nlgs.STATUS_STICK),
        (-0.0, -1.0, w_diag, 0.0, nlgs.STATUS_STICK),
        (2.0, -1.0, w_diag, 0.0, nlgs.STATUS_SLIP),
        (-2.0, -1.0, w_diag, 0.0, nlgs.STATUS_SLIP),
        (0.5, -1.0, w_diag, 0.2, nlgs.STATUS_SLIP),
        (0.6, -1.0, w_coupled, 0.0, nlgs.STATUS_SLIP),
        (-0.6, -1.0, w_coupled, 0.0, nlgs.STATUS_SLIP),
    ]
    rows = [_packed_row(w, bias, mu)[0] for _, _, w, bias, _ in cases]
    degenerate = _packed_row(w_diag, 0.0, mu)[0]
    degenerate[[nlgs.P_ITT, nlgs.P_ITN, nlgs.P_INN]] = 0.0
    no_slide = degenerate.copy()
    no_slide[[nlgs.P_ISP, nlgs.P_ISM]] = 0.0
    pack = np.vstack(rows + [degenerate, no_slide, no_slide])
    ut = np.array([c[0] for c in cases] + [0.3, 0.3, -0.3])
    un = np.array([c[1] for c in cases] + [-1.0, -1.0, -1.0])
    out = []
    for kernel in (simd_sweep.local_solve_many, simd_sweep.local_solve_bf_many):
        r, st = np.empty((len(ut), 2)), np.empty(len(ut), np.int8)
        kernel(ut, un, pack, mu, r, st)
        out.append((r, st))
    (r_ref, s_ref), (r_bf, s_bf) = out
    assert s_ref[: len(cases)].tolist() == [c[4] for c in cases]
    assert np.array_equal(r_ref.view(np.int64), r_bf.view(np.int64)) and np.array_equal(s_ref, s_bf)


@pytest.mark.parametrize("seed", range(4))
def test_colouring_of_random_joints_through_supports(seed):
    # 40 blocks and 3 supports, 300 contacts in joints of 1–3 points between random pairs
    rng = np.random.default_rng(seed)
    inv_mass, inv_inertia = np.r_[rng.uniform(0.5, 2, 40), np.zeros(3)], np.r_[rng.uniform(1, 5, 40), np.zeros(3)]
    pairs = []
    while len(pairs) < 300:
        a, b = sorted(rng.choice(43, 2, replace=False))
        pairs += [(a, b)] * int(rng.integers(1, 4)) if a < 40 else []
    body = np.array(pairs[:300], np.int32)
    pack = np.zeros((300, nlgs.PACK_WIDTH))
    pack[:, nlgs.P_IMA], pack[:, nlgs.P_IIA] = inv_mass[body[:, 0]], inv_inertia[body[:, 0]]
    pack[:, nlgs.P_IMB], pack[:, nlgs.P_IIB] = inv_mass[body[:, 1]], inv_inertia[body[:, 1]]
    order, start = np.empty(300, np.int64), np.empty(simd_sweep.MASK_WORDS * 64 + 1, np.int64)
    n = simd_sweep.colour(body, pack, 300, 43, order, start)
    assert np.array_equal(np.sort(order), np.arange(300)) and (np.diff(start[: n + 1]) > 0).all()
    for k in range(n):
        rows = order[start[k] : start[k + 1]]
        movable = [x for c in rows for x in body[c] if x < 40]
        assert len(movable) == len(set(movable)), k
    assert n <= 2 * np.bincount(body[body < 40], minlength=40).max() - 1  # greedy's bound
    # contacts of five blocks on one support: one colour
    on_support = np.zeros((5, nlgs.PACK_WIDTH))
    on_support[:, nlgs.P_IMA] = on_support[:, nlgs.P_IIA] = 1.0
    n = simd_sweep.colour(np.array([(i, 40) for i in range(5)], np.int32), on_support, 5, 43, order, start)
    assert n == 1


@pytest.mark.parametrize(("problem", "sweeps"), [(("random", 5), 30), (("random", 41), 12), (("stack", 6), 60)])
def test_coloured_sweeps_are_momentum_gauss_seidel_in_colour_order(problem, sweeps):
    # No two visits of a colour share a movable body, so the coloured sweeps must give what the engine's
    # sequential momentum sweeps give on the contacts renumbered in colour order (tolerance 0: the cap).
    kind, arg = problem
    body, pack, _, _, _, v0, r0, mu, _ = _random_problem(arg) if kind == "random" else _stack_problem(arg)
    count = body.shape[0]
    order, start = np.empty(count, np.int64), np.empty(simd_sweep.MASK_WORDS * 64 + 1, np.int64)
    assert simd_sweep.colour(body, pack, count, v0.shape[0], order, start) > 1
    v, r, status = v0.copy(), r0.copy(), np.zeros(count, np.int8)
    its, res, _ = simd_sweep.solve(body, pack, count, mu, 0.0, sweeps, v, r, status, sweeps)
    v_s, r_s, st_s = v0.copy(), r0[order].copy(), np.zeros(count, np.int8)
    its_s, res_s = momentum._nlgs_accelerated(np.ascontiguousarray(body[order]), np.ascontiguousarray(pack[order]),
                                              count, mu, 0.0, sweeps, v_s, r_s, st_s, TUNING.first_stall)  # fmt: skip
    assert its == its_s == sweeps
    assert res == pytest.approx(res_s, rel=1e-12, abs=1e-18)  # only the residual's summation order differs
    np.testing.assert_allclose(v, v_s, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(r[order], r_s, rtol=1e-12, atol=1e-15)
    assert np.array_equal(status[order], st_s)


def _lane_groups(body, pack, count, bodies):
    # The engine's lane groups (engine/lanes.py) by kind: (full groups of 8, partial groups, clashing groups)
    _, _, _, sub, nsub, _ = lanes.pack_lanes(body, pack, count, np.zeros((bodies, 3)), np.zeros((count, 2)))
    one = nsub == 1
    return int((one & (sub[:, 0] == lanes.FULL)).sum()), int((one & (sub[:, 0] != lanes.FULL)).sum()), int((~one).sum())


@functools.cache
def _lane_problem(name):
    if name == "tiny":
        tiny = tiny_cold_problem()
        return tiny.body, tiny.pack(), tiny.v_free, tiny.r_warm, tiny.mu
    stack = _stack_problem(39)  # 78 contacts: runs of 10, the last of 8, so groups 8 and 9 have 7 lanes
    return stack[0], stack[1], stack[5], stack[6], stack[7]


def _lanes_run(name, variant, tolerance, sweeps):
    body, pack, v0, r0, mu = _lane_problem(name)
    v, r, st = v0.copy(), r0.copy(), np.zeros(body.shape[0], np.int8)
    its, res, groups = simd_sweep.solve(body, pack, body.shape[0], mu, tolerance, sweeps, v, r, st, sweeps, variant)
    return its, res, groups, v, r, st


@pytest.mark.parametrize(("tolerance", "cap"), [(1e-9, 10_000), (0.0, 60)])
def test_lanes_vec_is_the_engines_first_stage_and_the_scalar_lanes_without_clashes(tolerance, cap):
    # "lanes+vec" is the engine's lane sweeps (engine/lane_sweeps.py); on a problem whose lane groups do
    # not clash (the stack: full and 7-lane groups) their order is simd_sweep's scalar "lanes+split", so
    # the same sweeps, residual, v, r and statuses to the bit, and as many visits a sweep. Tolerance 0:
    # after every sweep count up to cap.
    body, pack, v0, _, _ = _lane_problem("stack")
    full, partial, clashing = _lane_groups(body, pack, body.shape[0], v0.shape[0])
    assert full > 0 and partial > 0 and clashing == 0
    for sweeps in range(1, cap + 1) if tolerance == 0.0 else [cap]:
        its, res, groups, v, r, st = _lanes_run("stack", "lanes+split", tolerance, sweeps)
        its2, res2, groups2, v2, r2, st2 = _lanes_run("stack", "lanes+vec", tolerance, sweeps)
        assert (its == sweeps) == (tolerance == 0.0) and (res <= tolerance or tolerance == 0.0)
        assert its == its2 and res == res2 and groups == groups2 == full + partial
        assert _same_bits(v, v2) and _same_bits(r, r2) and np.array_equal(st, st2)


def test_lanes_vec_splits_clashing_groups_by_colour():
    # On the tiny wall every group clashes: "lanes+split" visits such a group lane by lane, the engine
    # (greedy colouring, lanes.py) in fewer sub-groups; both reach the tolerance.
    body, pack, v0, _, _ = _lane_problem("tiny")
    count = body.shape[0]
    full, partial, clashing = _lane_groups(body, pack, count, v0.shape[0])
    assert clashing > 0
    scalar, engine = (_lanes_run("tiny", variant, 1e-9, 10_000) for variant in ("lanes+split", "lanes+vec"))
    assert scalar[2] > engine[2] >= full + partial + 2 * clashing
    assert scalar[1] <= 1e-9 and engine[1] <= 1e-9


def _same_bits(a, b):
    return np.array_equal(a.view(np.int64), b.view(np.int64))
