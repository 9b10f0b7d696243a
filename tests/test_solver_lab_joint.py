"""The lab's joint-block Gauss–Seidel (benchmarks/solver_lab/methods/joint.py), on a tiny wall's cold step.

Checked against references built here: the engine's own point sweeps (one point per joint and one round
must be them, bit for bit), a brute-force enumeration of a two-point joint's statuses with its dense 4×4
Delassus block (the joint solve must land on its velocities), and the lab's tight reference (a converged
solve satisfies the contact law and has the reference's velocities, which are unique).
"""

import itertools

import numpy as np
import pytest

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import joint as J
from benchmarks.solver_lab.outcome import Context
from masonrycli.engine import momentum, nlgs
from tests.solver_lab_helpers import tiny_cold_problem


@pytest.fixture(scope="module")
def cold():
    return tiny_cold_problem()


def test_joints_are_runs_of_one_body_pair():
    body = np.array([[0, 1], [0, 1], [0, 2], [1, 2], [1, 2], [1, 3]])
    assert J.joint_starts(body).tolist() == [0, 2, 3, 5, 6]
    assert J.joint_starts(np.zeros((0, 2), np.int64)).tolist() == [0]


@pytest.mark.parametrize("accelerate", [False, True])
def test_one_point_per_joint_is_the_engines_sweep(cold, accelerate):
    p, ctx = cold, Context(cold)
    n = 40
    starts = np.arange(p.count + 1, dtype=np.int64)
    v, r, sweeps, _, _ = J.joint_solve(p.body, ctx.pack, p.mu, p.v_free, p.r_warm, 0.0, n, 1, accelerate, False, starts)
    v_e, r_e = p.v_free.copy(), p.r_warm.copy()
    status = np.zeros(p.count, np.int8)
    body = p.body.astype(np.int64)
    if accelerate:
        momentum._nlgs_accelerated(body, ctx.pack, p.count, p.mu, 0.0, n, v_e, r_e, status, n)
    else:
        nlgs._nlgs(body, ctx.pack, p.count, p.mu, 0.0, n, v_e, r_e, status)
    assert sweeps == n
    assert np.array_equal(v, v_e) and np.array_equal(r, r_e)


def _enumerate(q, W, bias, mu, tol=1e-9):
    """Every solution u of a two-point joint's problem u = q + W r under Signorini–Coulomb, by brute force:
    each point open / stick / slip ±, the equalities of the combination solved by least squares (W may be
    singular: a face's two tangential rows coincide), the inequalities checked."""
    found = []
    for combo in itertools.product(("open", "stick", "+", "-"), repeat=2):
        rows, rhs = [], []
        for i, st in enumerate(combo):
            t, n = 2 * i, 2 * i + 1
            e = np.eye(4)
            if st == "open":
                rows += [e[t], e[n]]
                rhs += [0.0, 0.0]
            else:
                rows.append(W[n])  # u_n = −bias
                rhs.append(-bias[i] - q[n])
                if st == "stick":
                    rows.append(W[t])
                    rhs.append(-q[t])
                else:
                    s = 1.0 if st == "+" else -1.0
                    rows.append(e[t] + s * mu * e[n])  # r_t = −s μ r_n
                    rhs.append(0.0)
        r = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)[0]
        u = q + W @ r
        ok = np.allclose(np.array(rows) @ r, rhs, atol=tol)
        for i, st in enumerate(combo):
            t, n = 2 * i, 2 * i + 1
            if st == "open":
                ok &= u[n] + bias[i] >= -tol
            else:
                ok &= r[n] >= -tol and abs(r[t]) <= mu * r[n] + tol
                if st in "+-":
                    ok &= (1.0 if st == "+" else -1.0) * u[t] >= -tol
        if ok:
            found.append(u)
    return found


def test_a_joint_solve_lands_on_the_enumerated_solution(cold):
    # One two-point joint alone, its own impulses removed from the reference's velocities, then pushed by
    # random body velocities (some open it, some make it slide): the exact joint solve (one sweep of the
    # kernel on these two contacts) must give the velocities every feasible status combination gives.
    p, ctx = cold, Context(cold)
    starts = J.joint_starts(p.body)
    two = [(a, b) for a, b in zip(starts[:-1], starts[1:]) if b - a == 2]
    c0 = next(a for a, _ in two if (p.inv_mass[p.body[a]] > 0).all())  # two blocks, not a support
    idx = np.array([c0, c0 + 1])
    H = ctx.H.toarray()[np.r_[2 * idx, 2 * idx + 1][[0, 2, 1, 3]]]  # rows t0, n0, t1, n1
    Hj = H.reshape(2, 2, -1)
    minv = ctx.minv
    W = H @ np.diag(minv) @ H.T
    assert abs(np.linalg.det(W)) < 1e-6 * np.abs(W).max() ** 4  # the face's tangential rows coincide
    r_own = p.r_ref[idx].ravel()
    base = p.v_ref.ravel() - minv * (H.T @ r_own)
    rng = np.random.default_rng(3)
    kinds = set()
    for _ in range(40):
        v_free = (base + rng.normal(scale=0.05, size=base.size) * (minv > 0)).reshape(-1, 3)
        v, r, _, _, _ = J.joint_solve(
            p.body[idx], ctx.pack[idx], p.mu, v_free, np.zeros((2, 2)), 0.0, 1, J.ROUNDS_EXACT, False, False
        )
        u = np.einsum("ijk,k->ij", Hj, v.ravel()).ravel()
        q = H @ v_free.ravel()
        found = _enumerate(q, W, ctx.pack[idx, nlgs.P_BIAS], p.mu)
        assert found, "the enumeration finds no solution"
        for u_enum in found:
            np.testing.assert_allclose(u, u_enum, atol=1e-8)
        kinds.add((r[:, 1] > 0).sum() * 10 + (np.abs(r[:, 0]) >= p.mu * r[:, 1] * (1 - 1e-9)).sum())
    assert len(kinds) >= 3  # open, closed and sliding joints were all exercised


@pytest.mark.parametrize("method", ["joint-gs", "joint-accel", "joint-accel-r2"])
def test_a_converged_joint_solve_satisfies_the_law_and_has_the_reference_velocities(cold, method):
    ctx = Context(cold)
    ctx.sweep_s = 1e-6
    out = J.METHODS[method](ctx, 1e-10)
    assert out.converged and out.iterations > 1
    v_r = law.velocity_from_impulse(ctx.p, ctx.H, out.r)
    np.testing.assert_allclose(out.v, v_r, atol=1e-12)
    assert ctx.residual_max(v_r, out.r) <= 1e-9
    assert law.velocity_error(ctx.p, v_r) <= 1e-7


def test_every_joint_is_solved_within_the_rounds(cold):
    # A face in stick–stick has a (numerically) singular tangential pair: its impulses drift along the null
    # direction every round; the test on the points' velocities must still end the joint's rounds.
    p, ctx = cold, Context(cold)
    for accelerate in (False, True):
        _, _, sweeps, law_rms, stats = J.joint_solve(
            p.body, ctx.pack, p.mu, p.v_free, p.r_warm, 1e-10, 5000, J.ROUNDS_EXACT, accelerate, True
        )
        assert law_rms <= 1e-10 and stats[1] == 0
        assert stats[0] <= 20 * p.count * sweeps  # visits a contact and sweep: far from ROUNDS_EXACT
