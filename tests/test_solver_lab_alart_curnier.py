"""The lab's globalised Alart–Curnier Newton (benchmarks/solver_lab/methods/alart_curnier.py).

Φ is checked against closed-form solutions of one block built here by hand (resting: stick; sliding on a
slope: slide; falling towards the ground across a gap: open); the Newton matrix against finite differences of
Φ and a dense solve; the method against the lab's tight reference on a tiny wall's cold step.
"""

from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import alart_curnier as A
from benchmarks.solver_lab.outcome import Context
from masonrycli.engine import nlgs as N
from tests.solver_lab_helpers import tiny_cold_problem

G, DT, MASS, WIDTH, HEIGHT, MU = 9.81, 1e-3, 2.0, 0.4, 0.2, 0.6


def _block(v_free, gap=0.0):
    """One block (body 1) on the support (body 0) by its two bottom corners, in the frame of the bed: n = y,
    t = x. A context with just what ``Residual`` reads; W_αα from a dense H M⁻¹ Hᵀ built here."""
    inertia = MASS * (WIDTH**2 + HEIGHT**2) / 12.0
    corners = np.array([[-WIDTH / 2, -HEIGHT / 2], [WIDTH / 2, -HEIGHT / 2]])
    # u_t = v_x − ω r_y, u_n = v_y + ω r_x (body 1 minus the fixed support)
    H = np.zeros((4, 6))
    for k, (x, y) in enumerate(corners):
        H[2 * k, 3:] = (1.0, 0.0, -y)
        H[2 * k + 1, 3:] = (0.0, 1.0, x)
    minv = np.array([0.0, 0.0, 0.0, 1 / MASS, 1 / MASS, 1 / inertia])
    W = H @ np.diag(minv) @ H.T
    pack = np.zeros((2, N.PACK_WIDTH))
    pack[:, N.P_WTT] = np.diag(W)[0::2]
    pack[:, N.P_WNN] = np.diag(W)[1::2]
    pack[:, N.P_BIAS] = gap / DT
    p = SimpleNamespace(count=2, mu=MU, v_free=np.vstack([np.zeros(3), v_free]))
    return SimpleNamespace(p=p, pack=pack, H=sp.csr_matrix(H), minv=minv), W


def _phi(ctx, r):
    F, _ = A.Residual(ctx).evaluate(np.asarray(r, float).ravel())
    return F


def test_phi_vanishes_on_a_resting_block_and_only_there():
    ctx, _ = _block(np.array([0.0, -G * DT, 0.0]))
    rn = MASS * G * DT / 2  # each corner carries half the weight; no friction needed
    assert np.abs(_phi(ctx, [[0.0, rn], [0.0, rn]])).max() < 1e-14
    assert np.abs(_phi(ctx, [[0.0, 1.01 * rn], [0.0, 0.99 * rn]])).max() > 1e-4  # tilts it: not a solution
    assert np.abs(_phi(ctx, [[0.1 * rn, rn], [-0.1 * rn, rn]])).max() < 1e-14  # inner stress: stick, still one


def test_phi_vanishes_on_a_block_sliding_down_a_slope():
    theta = np.arctan(0.8)  # steeper than μ = 0.6: it keeps sliding
    gx, gy = -G * np.sin(theta), -G * np.cos(theta)  # gravity in the bed's frame
    v0 = -0.1
    ctx, _ = _block(np.array([v0 + gx * DT, gy * DT, 0.0]))
    rn_total = -MASS * gy * DT  # stops the normal velocity
    # friction μ R_n up the slope (+x, against the slip), at the bed, h/2 below the centroid: the corners
    # share the normal load so that the moments about the centroid, Σ x r_n − y r_t, cancel:
    # (w/2)(r_n2 − r_n1) + (h/2) μ R_n = 0 (the downhill corner, x < 0, carries more)
    diff = MU * rn_total * HEIGHT / WIDTH
    rn1, rn2 = (rn_total + diff) / 2, (rn_total - diff) / 2
    r = np.array([[MU * rn1, rn1], [MU * rn2, rn2]])
    v = law.velocity_from_impulse(
        SimpleNamespace(v_free=ctx.p.v_free, inv_mass=np.array([0, 1 / MASS]), inv_inertia=ctx.minv[[2, 5]]),
        ctx.H,
        r,
    )
    assert v[1, 0] < 0 and abs(v[1, 1]) < 1e-15 and abs(v[1, 2]) < 1e-12  # slides, stays on, no rotation
    assert np.abs(_phi(ctx, r)).max() < 1e-14
    r_stuck = r.copy()
    r_stuck[:, 0] *= 0.9  # less than the full friction while it slides: violates Coulomb
    assert np.abs(_phi(ctx, r_stuck)).max() > 1e-4


def test_phi_vanishes_on_an_open_contact():
    gap = 1e-3  # 1 mm above the ground, falling at 0.5 m/s: within the step it does not reach it
    ctx, _ = _block(np.array([0.0, -0.5, 0.0]), gap=gap)
    assert np.abs(_phi(ctx, np.zeros((2, 2)))).max() < 1e-14
    assert np.abs(_phi(ctx, [[0.0, 1e-3], [0.0, 1e-3]])).max() > 1e-4  # pushing across a gap: not a solution
    ctx_close, _ = _block(np.array([0.0, -0.5, 0.0]), gap=1e-4)  # it would reach it: r = 0 is wrong
    assert np.abs(_phi(ctx_close, np.zeros((2, 2)))).max() > 1e-4


@pytest.fixture(scope="module")
def cold():
    return tiny_cold_problem()


@pytest.mark.parametrize("augmented", [False, True])
def test_newton_matrix_matches_finite_differences_and_a_dense_solve(cold, augmented):
    ctx = Context(cold)
    rng = np.random.default_rng(3)
    # a point away from the kinks: loaded contacts, a mix of statuses
    r = cold.r_ref.ravel() + rng.normal(scale=0.05, size=2 * cold.count) * np.abs(cold.r_ref.ravel()).max()
    lam = 1e-3
    res = A.Residual(ctx, "schur", augmented)
    F, state = res.evaluate(r)
    a, _, _, btn = state
    closed, stick, slide = a[1::2] > 0, a[0::2] > 0, btn != 0
    assert closed.any() and (~closed).any() and stick.any() and slide.any()
    J_fd = np.empty((r.size, r.size))
    h = 1e-7 * np.abs(r).max()
    for j in range(r.size):
        e = np.zeros_like(r)
        e[j] = h
        J_fd[:, j] = (res.evaluate(r + e)[0] - res.evaluate(r - e)[0]) / (2 * h)
    J = res.jacobian(state, 0.0)[0].toarray()
    np.testing.assert_allclose(J, J_fd, atol=1e-6 * np.abs(J_fd).max())
    dr_dense = np.linalg.solve(J_fd + lam * np.diag(res.wdiag), -F)
    for form in ("velocity", "saddle", "schur"):
        other = A.Residual(ctx, form, augmented)
        dr = other.direction(other.jacobian(state, lam), F)
        np.testing.assert_allclose(dr, dr_dense, atol=1e-6 * np.abs(dr_dense).max(), err_msg=form)


def test_method_reaches_the_target_and_the_reference(cold):
    ctx = Context(cold)
    for name in ("ac", "ac-m500"):
        out = A.METHODS[name](ctx, 1e-7)
        assert out.converged, name
        v = law.velocity_from_impulse(cold, ctx.H, out.r)
        np.testing.assert_allclose(out.v, v, atol=1e-9)
        assert ctx.residual(v, out.r) <= 1e-7, name
        assert law.velocity_error(cold, v) < 1e-5, name
    out = A.METHODS["ac"](ctx, 1e-7)
    assert out.iterations >= 1  # the Newton path ran from the warm start (r = 0)
    assert out.stats["law"][0] > 1e-3
