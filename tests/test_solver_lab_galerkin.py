"""The lab's Galerkin coarse correction on interface resultants (benchmarks/solver_lab/methods/galerkin.py), on a
tiny wall's cold step: 7 blocks in 3 courses on a ground shaken gently (0.05 m/s), so that the joints stick and
the coarse space is not empty.

Checked against quantities built here independently: the courses from the blocks' heights (for the layers),
the dense Delassus matrix W = H M⁻¹ Hᵀ and a dense least-squares minimisation of E(r) = ½ rᵀWr + qᵀr over the
coarse subspace (for the coarse step), the Coulomb cone (for the step length), the lab's law residual (for the
monotone guard) and the lab's tight reference (for the solve).
"""

import numpy as np
import pytest

from benchmarks.solver_lab import law
from benchmarks.solver_lab.capture import capture_run, reference
from benchmarks.solver_lab.methods import galerkin as G
from benchmarks.solver_lab.outcome import Clock, Context
from masonrycli.engine import nlgs as N
from masonrycli.run import Simulation
from masonrycli.scenario.motion import Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder


@pytest.fixture(scope="module")
def cold():
    gentle = Sine(direction=(1.0, 0.0), amplitude=0.05, frequency=2.0)
    sc = scenario_from_builder(
        "wall", {"blocks": 7, "courses": 3}, RunConfig(duration=0.002), Material(), {"ground": gentle}
    )
    p = capture_run(Simulation(sc), typical_step=1)[0]["cold"]
    p.name = "tiny-stack"
    reference(p)
    assert p.ref_residual <= 1e-9
    return p


def _after_sweeps(ctx, n):
    r = ctx.p.r_warm.copy()
    v, _ = ctx.sweep(r, n)
    return v, r


def test_layers_are_the_courses(cold):
    p = cold
    dyn = p.inv_mass > 0
    heights = np.unique(np.round(p.q_m[dyn, 1], 6))
    course = 1 + np.searchsorted(heights, np.round(p.q_m[:, 1], 6))
    lay = G.layers(p)
    np.testing.assert_array_equal(lay[dyn], course[dyn])
    assert (lay[~dyn] == 0).all()
    g = G.interface_groups(p)
    a, b = p.body[:, 0], p.body[:, 1]
    same_course = dyn[a] & dyn[b] & (course[a] == course[b])
    assert (g.group[same_course] == -1).all()  # head joints are not aggregated
    assert set(g.group[~same_course]) == {0, 1, 2}  # ground–course 1, 1–2, 2–3


def test_coarse_step_is_the_dense_minimiser_of_the_energy_on_the_subspace(cold):
    ctx = Context(cold)
    p = ctx.p
    v, r = _after_sweeps(ctx, 5)
    g = G.interface_groups(p)
    P, Q, touched = G.prolongation(p, ctx.pack, r, g)
    assert Q is P and P.shape[1] >= 4 and touched.sum() >= 6
    assert set(np.flatnonzero(np.abs(P).sum(1).A1 > 0) // 2) <= set(np.flatnonzero(touched))
    H = ctx.H.toarray()
    W = H @ np.diag(ctx.minv) @ H.T
    q = H @ p.v_free.ravel()
    q[1::2] += ctx.pack[:, N.P_BIAS]
    x = r.ravel()
    Pd = P.toarray()
    c = np.linalg.lstsq(Pd.T @ W @ Pd, -Pd.T @ (W @ x + q), rcond=1e-12)[0]

    def energy(y):
        return 0.5 * y @ W @ y + q @ y

    dr, dv = G.coarse_solve(ctx, P, v)
    np.testing.assert_allclose(dr, Pd @ c, atol=1e-8 * np.abs(Pd @ c).max())
    np.testing.assert_allclose(dv, ctx.minv * (H.T @ dr), atol=1e-12)
    assert energy(x + dr) < energy(x) - 1e-12  # a descent, and the minimum along every column
    rng = np.random.default_rng(3)
    for _ in range(5):
        assert energy(x + dr + 1e-3 * Pd @ rng.normal(size=c.size)) >= energy(x + dr)
    # without the residual guard the step is still monotone in E (cone-limited α ≤ 1 on a convex parabola)
    r2, _, alpha, _ = G.correction(ctx, v, r, g, Clock(), guard=False)
    assert 0.0 < alpha <= 1.0 and energy(r2.ravel()) < energy(x)


def test_interface_columns_are_normal_force_shear_and_moment(cold):
    # The N column pushes the upper course up and the ground down by the same impulse, the T column
    # sideways, and the M column has no net force (a pure couple about the interface's centroid).
    ctx = Context(cold)
    p = ctx.p
    v, r = _after_sweeps(ctx, 5)
    g = G.interface_groups(p)
    P, _, touched = G.prolongation(p, ctx.pack, r, g)
    assert P.shape[1] == 9  # three interfaces × (N, T, M)
    f = (ctx.H.T @ P).toarray().reshape(-1, 3, P.shape[1])  # generalized impulse per body and column
    upper = g.layer == 2  # the course above interface 1
    for j in range(P.shape[1]):
        col = P[:, j].toarray().ravel().reshape(-1, 2)
        on = np.abs(col).sum(1) > 0
        assert touched[on].all()
        k = set(g.group[on])
        assert len(k) == 1
        if k != {1}:
            continue
        net = f[upper, :2, j].sum(0)
        if np.abs(col[:, 0]).max() > 0:  # T
            assert abs(net[0]) > 10 * abs(net[1])
        elif np.allclose(col[on, 1], 1.0):  # N
            assert net[1] > 10 * abs(net[0])
        else:  # M
            assert np.abs(net).max() < 1e-9 * np.abs(col).sum()


def test_step_keeps_touched_contacts_in_their_cone(cold):
    ctx = Context(cold)
    p = ctx.p
    for follow in (False, True):
        v, r = _after_sweeps(ctx, 10)
        g = G.interface_groups(p)
        P, Q, touched = G.prolongation(p, ctx.pack, r, g, follow)
        dr, _ = G.coarse_solve(ctx, P, v, Q)
        tied = touched & ~G.interior(p, r, g)
        a = G.cone_step(p, r, 50.0 * dr, touched, tied)  # a long direction: the cone must bind
        assert 0.0 < a < 1.0
        r2 = r + a * 50.0 * dr.reshape(-1, 2)
        assert (r2[:, 1] >= -1e-12).all()
        assert (np.abs(r2[:, 0]) <= p.mu * r2[:, 1] + 1e-12).all()
        np.testing.assert_allclose(np.abs(r2[tied, 0]) - p.mu * r2[tied, 1], np.abs(r[tied, 0]) - p.mu * r[tied, 1])


def test_monotone_guard(cold, monkeypatch):
    ctx = Context(cold)
    ctx.sweep_s = 1e-6
    kept = []
    for grouping in ("interface", "joint"):
        trace = []
        out = G.galerkin(ctx, 1e-8, sweeps=5, grouping=grouping, trace=trace)
        assert out.converged and out.corrections == len(trace)
        kept += [t for t in trace if t[2] is not None]
    # every kept correction lowered (or kept) the law residual it was judged on
    assert len(kept) >= 5 and all(t[3] <= t[1] for t in kept)
    v, r = _after_sweeps(ctx, 5)
    new = G.correction(ctx, v, r, G.joint_groups(ctx.p), Clock(), None)
    assert new is not None
    np.testing.assert_allclose(new[3], ctx.residual(new[1], new[0]))  # judged on the pair it hands back
    np.testing.assert_allclose(new[1], law.velocity_from_impulse(ctx.p, ctx.H, new[0]), atol=1e-12)
    # an uphill step (the Galerkin direction reversed) must be refused
    original = G.coarse_solve
    monkeypatch.setattr(G, "coarse_solve", lambda *a, **k: tuple(-x for x in original(*a, **k)))
    v, r = _after_sweeps(ctx, 5)
    res = ctx.residual(v, r)
    assert G.correction(ctx, v, r, G.interface_groups(ctx.p), Clock(), res) is None


def test_solve_reaches_the_target_and_the_reference(cold):
    ctx = Context(cold)
    ctx.sweep_s = 1e-6
    p = ctx.p
    for name in ("nlgs-galerkin", "nlgs-galerkin-follow", "nlgs-galerkin-joint"):
        out = G.METHODS[name](ctx, 1e-8)
        v = law.velocity_from_impulse(p, ctx.H, out.r)
        np.testing.assert_allclose(out.v, v, atol=1e-9)
        assert out.converged and ctx.residual(v, out.r) <= 1e-8, name
        assert law.velocity_error(p, v) < 1e-5, name


def test_layer_rigid_share(cold):
    # A rigid motion of each course (own translation and rotation about any point) is all "layer-rigid";
    # one block of a course moving alone is not.
    p = cold
    lay = G.layers(p)
    rng = np.random.default_rng(5)
    e = np.zeros((lay.size, 3))
    for k in range(1, lay.max() + 1):
        s = lay == k
        vx, vy, w = rng.normal(size=3)
        x0, y0 = rng.normal(size=2)
        e[s, 0] = vx - w * (p.q_m[s, 1] - y0)
        e[s, 1] = vy + w * (p.q_m[s, 0] - x0)
        e[s, 2] = w
    assert G.layer_rigid_share(p, e, lay) == pytest.approx(1.0, abs=1e-12)
    one = np.zeros_like(e)
    one[np.flatnonzero(lay == 2)[0], 0] = 1.0
    assert 0.0 < G.layer_rigid_share(p, one, lay) < 0.5
