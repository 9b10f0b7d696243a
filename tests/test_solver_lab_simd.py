"""The coloured SIMD sweeps of the solver lab (benchmarks/solver_lab/simd_sweep.py).

References: the engine's own local solve and sweep (nlgs._local_solve, nlgs._nlgs_interleaved), the
colouring's definition checked by brute force, and the tight solve the lab's capture keeps per problem.
"""

import numpy as np
import pytest
from solver_lab_helpers import tiny_cold_problem

from benchmarks.solver_lab import law, simd_sweep
from benchmarks.solver_lab.outcome import Context
from masonrycli.engine import momentum, nlgs


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


@pytest.mark.parametrize("variant", ["split", "fused", "split2", "blocks", "lanes+split"])
def test_coloured_sweeps_converge_to_the_tight_solution(problem, variant):
    (sweeps, residual, colours), v, r = _solve(problem, variant, 1e-10)
    assert residual <= 1e-10 and colours >= 2 and sweeps > 1
    ctx = Context(problem)
    # the lab's own law (numpy, written apart from the engine) holds, and v is the tight reference's
    assert ctx.residual(law.velocity_from_impulse(problem, ctx.H, r), r) <= 1e-8
    np.testing.assert_allclose(v, law.velocity_from_impulse(problem, ctx.H, r), atol=1e-10)
    assert np.abs(v - problem.v_ref).max() < 1e-6


def test_level_schedule_replays_the_engines_sweep_bit_for_bit(problem):
    # the "levels" variant runs the engine's interleaved visit order level by level: the same sweeps
    tol = 1e-7
    (sweeps, residual, _), v, r = _solve(problem, "levels", tol)
    v2, r2 = problem.v_free.copy(), problem.r_warm.copy()
    s2 = np.zeros(problem.count, np.int8)
    sweeps2, residual2 = nlgs._nlgs_interleaved(problem.body, problem.pack(), problem.count, problem.mu, tol,
                                                200_000, v2, r2, s2, True, momentum.STALL_SWEEPS)  # fmt: skip
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
