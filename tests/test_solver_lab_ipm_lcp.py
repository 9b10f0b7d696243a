"""The lab's interior-point method on the LCP form of the Coulomb law (benchmarks/solver_lab/methods/ipm_lcp.py),
on the tiny wall's cold step of tests/test_solver_lab_ipm.py: its condensed Newton direction against a dense
solve of the full linearised system built from the lab's H, and the full law against the engine's tight
NLGS reference.
"""

import numpy as np
import pytest

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import ipm as I
from benchmarks.solver_lab.methods import ipm_lcp as L
from benchmarks.solver_lab.outcome import Context
from tests.solver_lab_helpers import tiny_cold_problem
from tests.test_solver_lab_ipm import _dense


@pytest.fixture(scope="module")
def cold():
    return tiny_cold_problem()


def test_lcp_direction_matches_the_dense_newton_system(cold):
    # The condensed direction of ipm_lcp (velocity system, 4 × 4 contact blocks eliminated) against one dense
    # solve of the full linearised system in (dv, dy, dw): M dv = Hᵀ E dy, dw = G H dv + J_y dy + rp,
    # W dy + Y dw = −r_c.
    ctx = Context(cold)
    ops = I.Operators(ctx)
    ht, hn, _, m = _dense(ctx, ops)
    c, n, mu = cold.count, ops.n, cold.mu
    rng = np.random.default_rng(7)
    y = rng.uniform(0.1, 1.0, (c, 4))
    w = rng.uniform(0.1, 1.0, (c, 4))
    x = L._velocity(ops, y)
    rp = L._rows(ops, ops.contact_velocity(x), y) - w
    rc = w * y
    # dense: unknowns (dv (n), dy (4c), dw (4c)); y, w ordered contact-major
    e = np.zeros((2 * c, 4 * c))  # r = E y, rows (t, n) of each contact
    g = np.zeros((4 * c, n))  # ∂w/∂v
    jy = np.zeros((4 * c, 4 * c))
    for a in range(c):
        e[2 * a, 4 * a + 1], e[2 * a, 4 * a + 2], e[2 * a + 1, 4 * a] = 1.0, -1.0, 1.0
        g[4 * a], g[4 * a + 1], g[4 * a + 2] = hn[a], ht[a], -ht[a]
        jy[4 * a + 1, 4 * a + 3] = jy[4 * a + 2, 4 * a + 3] = 1.0
        jy[4 * a + 3, 4 * a : 4 * a + 3] = (mu, -1.0, -1.0)
    h = np.zeros((2 * c, n))
    h[0::2], h[1::2] = ht, hn
    big = np.zeros((n + 8 * c, n + 8 * c))
    big[:n, :n] = np.diag(m)
    big[:n, n : n + 4 * c] = -h.T @ e
    big[n : n + 4 * c, :n] = -g
    big[n : n + 4 * c, n : n + 4 * c] = -jy
    big[n : n + 4 * c, n + 4 * c :] = np.eye(4 * c)
    big[n + 4 * c :, n : n + 4 * c] = np.diag(w.ravel())
    big[n + 4 * c :, n + 4 * c :] = np.diag(y.ravel())
    rhs = np.concatenate([np.zeros(n), rp.ravel(), -rc.ravel()])
    sol = np.linalg.solve(big, rhs)
    dv = sol[:n]
    dy = sol[n : n + 4 * c].reshape(c, 4)
    np.testing.assert_allclose(m * dv, h.T @ e @ dy.ravel(), atol=1e-10)
    # the condensed velocity system, built and factored as iterate() does (predictor: r_c = w ∘ y)
    d = y / w
    b = np.linalg.inv(np.eye(4) + L._jy(mu, c) * d[:, None, :])
    q = rp - np.einsum("cij,cj->ci", L._jy(mu, c), rc / w)
    dbg = np.einsum("ij,cj,cjk,kl->cil", L._E, d, b, L._G)
    fac = ops.factor_blocks(np.concatenate([dbg[:, 0, 0], dbg[:, 0, 1], dbg[:, 1, 0], dbg[:, 1, 1]]))
    bq = np.einsum("cij,cj->ci", b, q)
    rhs_v = -(ops.HdT @ np.einsum("ij,cj->ci", L._E, rc / w + d * bq).ravel())
    np.testing.assert_allclose(ops.solve(fac, rhs_v), dv, atol=1e-9 * max(1.0, np.abs(dv).max()))
    _, y1, w1, alpha = L.iterate(ops, x, y, w, L._jy(mu, c))  # the full step stays interior
    assert 0 < alpha <= 1 and (y1 > 0).all() and (w1 > 0).all()


def test_lcp_ipm_meets_the_law_and_the_reference(cold):
    ctx = Context(cold)
    out = L.METHODS["ipm-lcp"](ctx, 1e-5)
    assert out.converged
    v = law.velocity_from_impulse(cold, ctx.H, out.r)
    assert ctx.residual(v, out.r) <= 1e-5
    assert law.velocity_error(cold, v) <= 2e-4
