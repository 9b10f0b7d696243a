"""Banded LU without pivoting (masonrycli.engine.banded) against numpy's dense solve (LAPACK, partial
pivoting), and the body order against the bandwidth it promises."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.engine import banded, newton
from tests.test_engine_nlgs import _random_problem, _stack_problem


def _to_band(a, w):
    n = a.shape[0]
    band = np.zeros((n, 2 * w + 1))
    for i in range(n):
        for j in range(max(0, i - w), min(n, i + w + 1)):
            band[i, j - i + w] = a[i, j]
    return band


def _random_banded(rng, n, w, nonsymmetric):
    # A diagonally dominant band matrix, with a non-symmetric part and negative off-diagonal entries
    a = rng.normal(size=(n, n))
    a = a + a.T if not nonsymmetric else a
    i, j = np.indices((n, n))
    a[np.abs(i - j) > w] = 0.0
    a += np.diag(np.abs(a).sum(axis=1) + 1.0)
    return a


@pytest.mark.parametrize(
    ("n", "w", "nonsymmetric"), [(1, 0, False), (7, 1, True), (40, 6, True), (90, 50, False), (200, 17, True)]
)
def test_band_lu_solves_like_a_dense_solve(n, w, nonsymmetric):
    rng = np.random.default_rng(n + w)
    a = _random_banded(rng, n, w, nonsymmetric)
    b = rng.normal(size=n)
    band = _to_band(a, w)
    assert banded.band_lu(band, n, w) == -1
    x = b.copy()
    banded.band_solve(band, n, w, x)
    np.testing.assert_allclose(x, np.linalg.solve(a, b), rtol=1e-10, atol=1e-12)


def test_band_lu_factors_are_l_and_u():
    rng = np.random.default_rng(3)
    n, w = 30, 4
    a = _random_banded(rng, n, w, True)
    band = _to_band(a, w)
    banded.band_lu(band, n, w)
    full = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - w), min(n, i + w + 1)):
            full[i, j] = band[i, j - i + w]
    lower = np.tril(full, -1) + np.eye(n)
    upper = np.triu(full)
    np.testing.assert_allclose(lower @ upper, a, rtol=1e-12, atol=1e-12)


def test_a_zero_pivot_is_reported_not_divided_by():
    a = np.array([[1.0, 2.0, 0.0], [2.0, 4.0, 1.0], [0.0, 1.0, 3.0]])  # second pivot 4 − 2·2 = 0
    band = _to_band(a, 1)
    assert banded.band_lu(band, 3, 1) == 1


def test_body_order_keeps_the_promised_bandwidth():
    rng = np.random.default_rng(0)
    bodies = 60
    # a chain numbered at random: its own numbering is wide, reverse Cuthill–McKee's is 1 apart
    chain = rng.permutation(bodies)
    pairs = np.sort(np.column_stack([chain[:-1], chain[1:]]), axis=1)
    position, width = banded.body_order(pairs, np.ones(len(pairs), bool), bodies)
    assert sorted(position) == list(range(bodies))
    assert width == np.abs(position[pairs[:, 0]] - position[pairs[:, 1]]).max() == 1
    # already banded (a strip: each body touches the next two, no numbering does better): the own numbering
    k = np.arange(bodies - 2)
    pairs = np.r_[np.column_stack([k, k + 1]), np.column_stack([k, k + 2])]
    position, width = banded.body_order(pairs, np.ones(len(pairs), bool), bodies)
    assert (position == np.arange(bodies)).all() and width == 2
    # contacts that do not couple two moving bodies do not widen it
    position, width = banded.body_order(np.array([[0, 59]]), np.array([False]), bodies)
    assert width == 0


@pytest.mark.parametrize("seed", [5, 17, 41])
def test_the_newton_matrix_solved_in_the_band_matches_a_dense_solve(seed):
    # The engine's own Newton matrices (generic impulses: stick, slide and open contacts mixed), whose
    # diagonal can be negative: the banded solve without pivoting against LAPACK with pivoting.
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _random_problem(seed)
    count, bodies = body.shape[0], v0.shape[0]
    rng = np.random.default_rng(seed)
    r = np.abs(rng.normal(scale=0.05, size=(count, 2)))
    f, jac, _ = newton.phi(body, pack, count, mu, v0, r)
    dense, rhs = newton.newton_matrix(body, pack, count, bodies, f, jac)
    band = newton.Band(body, pack, count, bodies)
    newton._system(body, pack, count, newton.LAMBDA, f, jac, bodies, band.position, band.w, band.band, band.rhs)
    n = 3 * bodies
    assert banded.band_lu(band.band, n, band.w) == -1
    banded.band_solve(band.band, n, band.w, band.rhs)
    dofs = (3 * band.position[:, None] + np.arange(3)).ravel()
    ref = np.linalg.solve(dense, rhs)
    np.testing.assert_allclose(band.rhs[dofs], ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max())


def test_the_newton_matrix_of_a_stack_is_banded_as_promised():
    # 10 blocks stacked: each touches the one above and below, so one body apart, 3 + 2 dofs
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _stack_problem(10)
    count, bodies = body.shape[0], v0.shape[0]
    f, jac, _ = newton.phi(body, pack, count, mu, v0, r0)
    dense, _ = newton.newton_matrix(body, pack, count, bodies, f, jac)
    band = newton.Band(body, pack, count, bodies)
    assert band.w == 5
    dofs = (3 * band.position[:, None] + np.arange(3)).ravel()
    permuted = np.empty_like(dense)
    permuted[np.ix_(dofs, dofs)] = dense
    i, j = np.nonzero(permuted)
    assert np.abs(i - j).max() <= band.w
