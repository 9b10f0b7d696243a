"""The lab's course-slip coarse correction (benchmarks/solver_lab/methods/slip.py and slip_realise.py).

The coarse solve (chain_dual) against scipy's bounded minimisation of the same dual written with one variable per
joint and class, and against its primal (strong duality, and no random perturbation doing better); then, on the
cold step of a 7-block, 3-course wall shaken as the lab's walls (1 m/s, so that bed joints slide): the courses
against the blocks' heights, the step against the tight reference (a no-op there), each realisation's pair
(v, r) against v = v_free + M⁻¹ Hᵀ r and the Coulomb cones, the tangential realisation against the courses'
momentum, and the solve against the target and the reference.
"""

import numpy as np
import pytest
from scipy.optimize import minimize

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import slip as S
from benchmarks.solver_lab.methods import slip_oracle as O
from benchmarks.solver_lab.methods import slip_realise as R
from benchmarks.solver_lab.methods.accelerated import accelerated
from benchmarks.solver_lab.outcome import Context
from masonrycli.engine import nlgs as N
from tests.solver_lab_helpers import tiny_cold_problem


def _random_chain(rng, n):
    m = rng.uniform(1.0, 5.0, n)
    a = rng.normal(size=n)
    lam = rng.uniform(0.0, 2.0, (n, 3)) * (rng.uniform(size=(n, 3)) > 0.2)  # some classes empty
    slopes = np.sort(rng.normal(size=(n, 3)), axis=1)
    B = np.concatenate([-lam.sum(1)[:, None], -lam.sum(1)[:, None] + 2 * np.cumsum(lam, axis=1)], axis=1)
    return m, a, lam, slopes, B


def _dual(F, X, m, a, slopes, lam):
    d = F - np.append(F[1:], 0.0)
    return 0.5 * ((d + m * a) ** 2 / m).sum() + (slopes * (X + lam)).sum()


def _allocation(F, B, lam):
    # each class's share of F, the cheapest (lowest slope) first: ψ's minimiser
    return np.clip(F[:, None] - B[:, :3], 0.0, 2 * lam) - lam


@pytest.mark.parametrize("n", [1, 2, 5, 12])
def test_chain_dual_matches_a_bounded_minimisation_by_scipy(n):
    rng = np.random.default_rng(n)
    for _ in range(5):
        m, a, lam, slopes, B = _random_chain(rng, n)
        F, its = S.chain_dual(m, a, B, slopes)
        assert its < 4 * n + 20  # finished by its own test, not the cap

        def f(x, m=m, a=a, slopes=slopes, lam=lam):
            X = x.reshape(n, 3)
            F_ = X.sum(1)
            d = F_ - np.append(F_[1:], 0.0)
            g_d = (d + m * a) / m
            g_F = g_d.copy()
            g_F[1:] -= g_d[:-1]
            return _dual(F_, X, m, a, slopes, lam), (g_F[:, None] + slopes).ravel()

        bounds = list(zip((-lam).ravel(), lam.ravel(), strict=True))
        res = minimize(
            f,
            np.zeros(3 * n),
            jac=True,
            bounds=bounds,
            method="L-BFGS-B",
            options={"ftol": 1e-15, "gtol": 1e-12, "maxiter": 5000},
        )
        X_ours = _allocation(F, B, lam)
        ours = _dual(F, X_ours, m, a, slopes, lam)
        assert ours <= res.fun + 1e-9 * max(1.0, abs(res.fun))
        np.testing.assert_allclose(F, res.x.reshape(n, 3).sum(1), atol=1e-5 * max(1.0, float(lam.max())))


def test_chain_dual_is_the_dual_of_the_course_problem():
    # primal: Σ ½ m_c (δu_c − a_c)² + Σ_kj λ_kj |δu_k − δu_{k−1} + S_kj|, δu_{−1} = 0
    rng = np.random.default_rng(7)
    for n in (1, 3, 8):
        m, a, lam, slopes, B = _random_chain(rng, n)

        def primal(u, m=m, a=a, slopes=slopes, lam=lam):
            z = u - np.append(0.0, u[:-1])
            return 0.5 * (m * (u - a) ** 2).sum() + (lam * np.abs(z[:, None] + slopes)).sum()

        F, _ = S.chain_dual(m, a, B, slopes)
        d = F - np.append(F[1:], 0.0)
        u = a + d / m
        X = _allocation(F, B, lam)
        dual_value = -0.5 * ((d + m * a) ** 2 / m).sum() + 0.5 * (m * a * a).sum() - (slopes * X).sum()
        assert primal(u) == pytest.approx(dual_value, rel=1e-9, abs=1e-9)
        for _ in range(50):
            assert primal(u) <= primal(u + 1e-3 * rng.normal(size=n)) + 1e-12


@pytest.fixture(scope="module")
def cold():
    return tiny_cold_problem(courses=3, name="tiny-slip")


def test_courses_and_bed_joints(cold):
    p = cold
    ctx = Context(p)
    chain = S.build_chain(p, ctx.pack)
    dyn = p.inv_mass > 0
    heights = np.unique(np.round(p.q_m[dyn, 1], 6))
    np.testing.assert_array_equal(chain.course[dyn], np.searchsorted(heights, np.round(p.q_m[dyn, 1], 6)))
    assert (chain.course[~dyn] == -1).all() and chain.n == 3
    a, b = p.body[:, 0], p.body[:, 1]
    lower = np.where(dyn[a], chain.course[a], -1)
    upper = np.where(dyn[b], chain.course[b], -1)
    bed = np.abs(p.normal[:, 1]) > 0.99
    np.testing.assert_array_equal(chain.joint >= 0, bed)  # head joints are held
    np.testing.assert_array_equal(chain.joint[bed], np.maximum(lower, upper)[bed])  # joint k under course k
    np.testing.assert_array_equal(np.abs(chain.tau[bed]), 1.0)
    m = np.bincount(chain.course[dyn], 1.0 / p.inv_mass[dyn])
    np.testing.assert_allclose(chain.mass, m)


@pytest.mark.parametrize("realise", ["tangential", "balance", "min-norm"])
def test_the_step_is_a_no_op_at_the_reference(cold, realise):
    p = cold
    ctx = Context(p)
    chain = S.build_chain(p, ctx.pack)
    st = S.joint_state(ctx, chain, p.v_ref, p.r_ref)
    assert (st.cls[chain.joint >= 0] != 1).sum() > 0  # some bed-joint contacts slide: the classes are exercised
    r2, v2, du = S.coarse_step(ctx, chain, p.v_ref, p.r_ref, realise)
    assert np.abs(du).max() < 1e-6
    assert np.abs(r2 - p.r_ref).max() < 1e-6 * np.abs(p.r_ref).max()


@pytest.mark.parametrize("realise", ["tangential", "balance", "min-norm"])
def test_realisations_keep_the_pair_consistent_and_in_the_cones(cold, realise):
    p = cold
    ctx = Context(p)
    chain = S.build_chain(p, ctx.pack)
    r = p.r_warm.copy()
    v, _ = ctx.sweep(r, 5)
    r2, v2, du = S.coarse_step(ctx, chain, v, r, realise)
    assert np.abs(du).max() > 1e-4  # the step does something here
    np.testing.assert_allclose(v2, law.velocity_from_impulse(p, ctx.H, r2), atol=1e-12)
    assert (r2[:, 1] >= 0).all()
    assert (np.abs(r2[:, 0]) <= p.mu * r2[:, 1] * (1 + 1e-12) + 1e-15).all()


def test_tangential_realisation_moves_each_course_by_its_correction(cold):
    p = cold
    ctx = Context(p)
    chain = S.build_chain(p, ctx.pack)
    r = p.r_warm.copy()
    v, _ = ctx.sweep(r, 5)
    r2, v2, du = S.coarse_step(ctx, chain, v, r, "tangential")
    np.testing.assert_allclose(S.course_means(p, chain, v2 - v), du, atol=1e-12 + 1e-9 * np.abs(du).max())


@pytest.mark.parametrize("reg, within", [(1e-10, 1e-3), (R.BALANCE_REG, 0.15)])
def test_min_norm_realises_a_translation_when_no_cone_binds(cold, monkeypatch, reg, within):
    # the reference's normals with no friction: every touching contact strictly inside its cone, so a small
    # translation needs no active set and is realised exactly but for the regularisation (BALANCE_REG on the
    # normal equations), which damps it by up to ~9 % here at the shipped 1e-4
    monkeypatch.setattr(R, "BALANCE_REG", reg)
    p = cold
    ctx = Context(p)
    chain = S.build_chain(p, ctx.pack)
    r = p.r_ref.copy()
    r[:, 0] = 0.0
    du = np.array([1e-6, -2e-6, 3e-6])
    dr = R.min_norm(ctx, chain.course, chain.joint, r, np.zeros(p.count, bool), du)
    dv = (ctx.minv * (ctx.H.T @ dr.ravel())).reshape(-1, 3)
    dyn = p.inv_mass > 0
    want = np.zeros_like(dv)
    want[dyn, 0] = du[chain.course[dyn]]
    assert np.abs(dv - want)[dyn].max() < within * np.abs(du).max()


def test_solve_reaches_the_target_and_the_reference(cold):
    p = cold
    ctx = Context(p)
    ctx.sweep_s, ctx.accel_cost = 1e-6, 1.0
    # the momentum sweeps alone end 1.4e-4 m/s from this reference at a 7e-9 m/s residual (another solution of
    # the Coulomb step): the "-accel" variant is held to their answer, the others to the reference
    alone = accelerated(ctx, 1e-8)
    v_alone = law.velocity_from_impulse(p, ctx.H, alone.r)
    for name in ("nlgs-slip", "nlgs-slip-once", "nlgs-slip-balance", "nlgs-slip-tangential", "nlgs-slip-accel"):
        out = S.METHODS[name](ctx, 1e-8)
        v = law.velocity_from_impulse(p, ctx.H, out.r)
        np.testing.assert_allclose(out.v, v, atol=1e-9)
        assert out.converged and ctx.residual(v, out.r) <= 1e-8, name
        if name.endswith("-accel"):
            assert law.velocity_error(p, v) < law.velocity_error(p, v_alone) + 1e-5, name
        else:
            assert law.velocity_error(p, v) < 1e-5, name


def test_course_rigid_fit(cold):
    # a rigid motion of each course (own translation and rotation about any point) is its own fit; one block
    # moving alone is not
    p = cold
    chain = S.build_chain(p, Context(p).pack)
    rng = np.random.default_rng(3)
    e = np.zeros((p.inv_mass.size, 3))
    for c in range(chain.n):
        s = chain.course == c
        vx, vy, w = rng.normal(size=3)
        x0, y0 = rng.normal(size=2)
        e[s] = np.stack([vx - w * (p.q_m[s, 1] - y0), vy + w * (p.q_m[s, 0] - x0), np.full(s.sum(), w)], axis=1)
    np.testing.assert_allclose(O.course_rigid_fit(p, chain, e), e, atol=1e-12)
    one = np.zeros_like(e)
    one[np.flatnonzero(chain.course == 1)[0], 0] = 1.0
    assert np.abs(O.course_rigid_fit(p, chain, one) - one).max() > 0.5


def test_oracle_counts_sweeps_to_the_target(cold):
    ctx = Context(cold)
    for kind in ("rigid", "full", "joint-NMT", "pair-NM+slip-tangential"):
        o = O.oracle(ctx, kind, sweeps=5, target=1e-8, steps=3)
        assert 0 < o["alone"] < S.CAP and 5 <= o["once"] < S.CAP and 0 < o["repeated"] < S.CAP
        assert o["steps"] <= 3


def test_with_resultants_sets_each_bed_joints_resultants(cold):
    # where nothing is clipped, N, the moment about the contacts' mean x and the friction total of every bed joint
    # are the reference's, and nothing else changes
    p = cold
    ctx = Context(p)
    chain = S.build_chain(p, ctx.pack)
    inj = chain.joint >= 0
    r = p.r_ref.copy()
    touching = (r[:, 1] > 0) | (ctx.pack[:, N.P_BIAS] <= 0)
    r[touching, 1] += 1.0  # 1 N·s more on every touching contact: the change back is uniform, nothing clipped
    r[:, 0] *= 0.5
    out = O.with_resultants(ctx, chain, r, "NMT")
    k, x = chain.joint[inj], p.point[inj, 0]
    xi = x - (np.bincount(k, x) / np.bincount(k))[k]
    for q in (lambda z: z[inj, 1], lambda z: z[inj, 1] * xi, lambda z: chain.tau[inj] * z[inj, 0]):
        np.testing.assert_allclose(np.bincount(k, q(out)), np.bincount(k, q(p.r_ref)), atol=1e-9)
    np.testing.assert_array_equal(out[~inj], r[~inj])


def test_with_resultants_per_pair(cold):
    # the same for every body pair, head joints included: N, the moment along the pair's tangent and Σ r_t
    p = cold
    ctx = Context(p)
    chain = S.build_chain(p, ctx.pack)
    r = p.r_ref.copy()
    touching = (r[:, 1] > 0) | (ctx.pack[:, N.P_BIAS] <= 0)
    r[touching, 1] += 1.0
    r[:, 0] *= 0.5
    out = O.with_resultants(ctx, chain, r, "NMT", pairs=True)
    pair = np.unique(p.body[:, 0] * 1000 + p.body[:, 1], return_inverse=True)[1].ravel()
    t = np.stack([p.normal[:, 1], -p.normal[:, 0]], axis=1)
    mean = np.stack([np.bincount(pair, p.point[:, j]) / np.bincount(pair) for j in (0, 1)], axis=1)
    xi = ((p.point - mean[pair]) * t).sum(1)
    for q in (lambda z: z[:, 1], lambda z: z[:, 1] * xi, lambda z: z[:, 0]):
        np.testing.assert_allclose(np.bincount(pair, q(out)), np.bincount(pair, q(p.r_ref)), atol=1e-9)
