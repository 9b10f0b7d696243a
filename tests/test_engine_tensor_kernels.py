"""Kernels of masonrycli.engine.tensor_kernels against slow, independent pure-Python/numpy references."""

from __future__ import annotations

import math

import numpy as np
import pytest

from masonrycli.engine import tensor_kernels as K

# ---------------------------------------------------------------------------------------------------
# Slow references (plain loops, numpy.linalg)
# ---------------------------------------------------------------------------------------------------


def ref_block_stress(n, q, volume, body, point, force):
    out = np.zeros((n, 2, 2))
    for (a, b), p, f in zip(body, point, force):
        for blk, fb in ((a, -f), (b, f)):
            if blk < n:
                out[blk] += np.outer(p - q[blk, :2], fb)
    return out / volume[:, None, None]


def ref_cell_average(n, tensor, volume, body):
    out = np.empty((n, 2, 2))
    for i in range(n):
        cell = {i}
        cell |= {int(b) for a, b in body if a == i and b < n}
        cell |= {int(a) for a, b in body if b == i and a < n}
        cell = sorted(cell)
        out[i] = sum(volume[j] * tensor[j] for j in cell) / sum(volume[j] for j in cell)
    return out


def ref_strain_rate(n, q, v, triangles):
    num = np.zeros((n, 2, 2))
    den = np.zeros(n)
    for tri in triangles:
        x = q[tri, :2]
        vel = v[tri, :2]
        # v(x) = L x + c through the three vertices: solve [x 1] [L^T; c^T] = vel
        a = np.hstack([x, np.ones((3, 1))])
        sol = np.linalg.solve(a, vel)
        grad = sol[:2].T  # L_ij = dv_i/dx_j
        area = 0.5 * np.linalg.det(np.array([x[1] - x[0], x[2] - x[0]]).T)
        num[tri[0]] += area * 0.5 * (grad + grad.T)  # the triangle belongs to the cell of its apex
        den[tri[0]] += area
    out = np.full((n, 2, 2), np.nan)
    has = den > 0
    out[has] = num[has] / den[has, None, None]
    return out


def random_contacts(rng, n_blocks, n_supports, count):
    a = rng.integers(0, n_blocks, count)
    b = rng.integers(0, n_blocks + n_supports, count)
    keep = a != b
    a, b = a[keep], b[keep]
    body = np.stack([np.minimum(a, b), np.maximum(a, b)], 1).astype(np.int32)
    # repeat some rows (two contact points per pair), shuffled so that repeats are not adjacent
    body = np.concatenate([body, body[: len(body) // 2]])
    body = body[rng.permutation(len(body))]
    c = len(body)
    return body, rng.normal(size=(c, 2)), rng.normal(size=(c, 2)) * 100.0


# ---------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_block_stress_matches_reference(seed):
    rng = np.random.default_rng(seed)
    n, s = 30, 3
    q = rng.normal(size=(n + s, 3))
    volume = rng.uniform(0.02, 0.2, n)
    body, point, force = random_contacts(rng, n, s, 120)
    out = np.empty((n, 2, 2))
    K._block_stress(n, q, volume, body, point, force, out)
    np.testing.assert_allclose(out, ref_block_stress(n, q, volume, body, point, force), rtol=1e-12, atol=1e-9)


def test_block_stress_no_contact_is_zero():
    out = np.full((3, 2, 2), 7.0)
    K._block_stress(
        3, np.zeros((3, 3)), np.ones(3), np.zeros((0, 2), np.int64), np.zeros((0, 2)), np.zeros((0, 2)), out
    )
    assert np.all(out == 0.0)


def test_block_stress_of_balanced_forces_does_not_depend_on_reference_point():
    # Σ F = 0 on the block ⇒ Σ (I − G) ⊗ F is the same for any G.
    rng = np.random.default_rng(5)
    point = rng.normal(size=(6, 2))
    force = rng.normal(size=(6, 2))
    force[-1] = -force[:-1].sum(axis=0)
    body = np.tile([0, 1], (6, 1))
    out1, out2 = np.empty((1, 2, 2)), np.empty((1, 2, 2))
    K._block_stress(1, np.array([[0.0, 0.0, 0.0]]), np.array([0.5]), body, point, -force, out1)
    K._block_stress(1, np.array([[3.0, -2.0, 0.0]]), np.array([0.5]), body, point, -force, out2)
    np.testing.assert_allclose(out1, out2, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("seed", [0, 1])
def test_cell_average_matches_reference(seed):
    rng = np.random.default_rng(seed)
    n, s = 25, 2
    body, _, _ = random_contacts(rng, n, s, 60)
    tensor = rng.normal(size=(n, 2, 2))
    volume = rng.uniform(0.02, 0.2, n)
    start, neighbour = K._cell_neighbours(n, body)
    out = np.empty((n, 2, 2))
    K._cell_average(n, start, neighbour, volume, tensor, out)
    np.testing.assert_allclose(out, ref_cell_average(n, tensor, volume, body), rtol=1e-12, atol=1e-14)


def test_cell_neighbours_ignore_supports_and_keep_repeats():
    body = np.array([[0, 1], [0, 1], [1, 3], [0, 2]], np.int32)  # body 3 is a support for n = 3
    start, neighbour = K._cell_neighbours(3, body)
    assert start.tolist() == [0, 3, 5, 6]
    assert sorted(neighbour[start[0] : start[1]].tolist()) == [1, 1, 2]
    assert neighbour[start[1] : start[2]].tolist() == [0, 0]
    assert neighbour[start[2] : start[3]].tolist() == [0]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_cell_strain_rate_matches_reference(seed):
    rng = np.random.default_rng(seed)
    # perturbed grid, triangulated by hand (two triangles per square, CCW), one isolated block
    nx, ny = 5, 4
    gx, gy = np.meshgrid(np.arange(nx) * 0.3, np.arange(ny) * 0.2)
    n = nx * ny + 1
    q = np.zeros((n + 1, 3))
    q[: nx * ny, 0] = gx.ravel()
    q[: nx * ny, 1] = gy.ravel()
    q[: nx * ny, :2] += rng.normal(scale=0.02, size=(nx * ny, 2))
    q[nx * ny] = [10.0, 10.0, 0.0]
    tris = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            p = j * nx + i
            for a, b, c in ((p, p + 1, p + nx + 1), (p, p + nx + 1, p + nx)):  # each in its 3 cells
                tris += [[a, b, c], [b, c, a], [c, a, b]]
    tris = np.array(tris, np.int64)
    v = rng.normal(size=(n + 1, 3))
    out = np.empty((n, 2, 2))
    K._cell_strain_rate(n, q, v, tris, np.zeros(n), out)
    ref = ref_strain_rate(n, q, v, tris)
    assert np.all(np.isnan(out[nx * ny]))
    np.testing.assert_allclose(out, ref, rtol=1e-10, atol=1e-12)


def test_integrate_strain_keeps_nan_and_skips_nan_rate():
    rate = np.array([[[1.0, 2.0], [2.0, 3.0]], [[1.0, 1.0], [1.0, 1.0]], [[np.nan] * 2] * 2])
    strain = np.array([[[0.5, 0.0], [0.0, 0.0]], [[np.nan] * 2] * 2, [[1.0, 0.0], [0.0, 1.0]]])
    K._integrate_strain(rate, 0.25, strain)
    np.testing.assert_array_equal(strain[0], [[0.75, 0.5], [0.5, 0.75]])
    assert np.all(np.isnan(strain[1]))
    np.testing.assert_array_equal(strain[2], [[1.0, 0.0], [0.0, 1.0]])


# ---------------------------------------------------------------------------------------------------
# Closed-form 2×2 eigen vs numpy.linalg.eigh
# ---------------------------------------------------------------------------------------------------


def check_against_eigh(a, b, d):
    l1, l2, phi, c, r = K._sym_eig2(a, b, d)
    w, vecs = np.linalg.eigh(np.array([[a, b], [b, d]]))
    scale = max(abs(a), abs(b), abs(d), 1e-300)
    assert abs(l1 - w[1]) <= 1e-13 * scale
    assert abs(l2 - w[0]) <= 1e-13 * scale
    assert l1 >= l2
    assert -math.pi / 2 < phi <= math.pi / 2
    assert c == pytest.approx(0.5 * (a + d), rel=1e-15, abs=1e-300)
    if w[1] - w[0] > 1e-6 * scale:  # the direction is defined
        u = vecs[:, 1]
        cross = math.cos(phi) * u[1] - math.sin(phi) * u[0]
        assert abs(cross) <= 1e-10  # parallel up to sign


def test_sym_eig2_random_against_eigh():
    rng = np.random.default_rng(42)
    scales = 10.0 ** rng.uniform(-6, 6, 1000)
    abd = rng.normal(size=(1000, 3)) * scales[:, None]
    for a, b, d in abd:
        check_against_eigh(a, b, d)


@pytest.mark.parametrize(
    "a, b, d, phi",
    [
        (3.0, 0.0, 1.0, 0.0),  # zero shear, a > d
        (1.0, 0.0, 3.0, math.pi / 2),  # zero shear, a < d → +90°, never −90°
        (1.0, -0.0, 3.0, math.pi / 2),  # negative zero shear
        (2.0, -1.0, 2.0, -math.pi / 4),  # negative shear, a = d
        (2.0, 1.0, 2.0, math.pi / 4),
        (-1500.0, -750.0, -2500.0, -0.5 * math.atan(1.5)),  # negative shear (DESIGN §6 case 4)
        (5.0, 0.0, 5.0, 0.0),  # isotropic
        (-5.0, 0.0, -5.0, 0.0),
        (0.0, 0.0, 0.0, 0.0),  # zero tensor
    ],
)
def test_sym_eig2_special_cases(a, b, d, phi):
    l1, l2, got, _, _ = K._sym_eig2(a, b, d)
    assert got == pytest.approx(phi, rel=1e-14, abs=1e-15)
    if phi == 0.0:
        assert math.copysign(1.0, got) == 1.0  # +0, never −0
    check_against_eigh(a, b, d)


def test_sym_eig2_nearly_isotropic_round_off_gives_zero_angle():
    # anisotropy at the round-off level: the direction is noise, reported as 0
    _, _, phi, _, _ = K._sym_eig2(1.0, 1e-17, 1.0 + 2e-16)
    assert phi == 0.0


def test_sym_eig2_nan_propagates():
    l1, l2, phi, _, _ = K._sym_eig2(np.nan, np.nan, np.nan)
    assert math.isnan(l1) and math.isnan(l2) and math.isnan(phi)


def test_principal_uses_symmetric_part_and_factors():
    t = np.array([[[1.0, 3.0], [1.0, -1.0]]])  # symmetric part [[1, 2], [2, -1]]
    values, angle, iso, dev = np.empty((1, 2)), np.empty(1), np.empty(1), np.empty(1)
    K._principal(t, values, angle, iso, dev, 0.5)
    np.testing.assert_allclose(values[0], [math.sqrt(5.0), -math.sqrt(5.0)], rtol=1e-15)
    assert angle[0] == pytest.approx(0.5 * math.atan2(4.0, 2.0), rel=1e-15)
    assert iso[0] == 0.0 and dev[0] == pytest.approx(math.sqrt(5.0), rel=1e-15)
    K._principal(t + np.eye(2), values, angle, iso, dev, 1.0)
    assert iso[0] == pytest.approx(2.0, rel=1e-15)


def test_cell_strain_rate_flat_or_inverted_star_is_nan():
    # one triangle (0, 1, 2), CCW at set-up, in the fan of each of its blocks; flattened now (area 0)
    # → NaN; inverted (area < 0) → NaN
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    tri = np.array([[0, 1, 2], [1, 2, 0], [2, 0, 1]])
    out = np.empty((3, 2, 2))
    flat = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]
    inverted = [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
    for q in (flat, inverted):
        K._cell_strain_rate(3, np.array(q), v, tri, np.zeros(3), out)
        assert np.all(np.isnan(out))
    K._cell_strain_rate(3, np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), v, tri, np.zeros(3), out)
    np.testing.assert_allclose(out, np.broadcast_to([[1.0, 0.0], [0.0, 2.0]], (3, 2, 2)), rtol=1e-15)


def test_cell_strain_rate_collapsed_star_below_floor_is_nan():
    # The same triangle squashed to 10 % of its area: finite without a floor, NaN with a floor of 25 %
    # of the initial area (0.5 m²), as TensorComputer sets it from the initial centroids.
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    tri = np.array([[0, 1, 2], [1, 2, 0], [2, 0, 1]])
    q = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.1, 0.0]])
    out = np.empty((3, 2, 2))
    K._cell_strain_rate(3, q, v, tri, np.zeros(3), out)
    assert np.all(np.isfinite(out))
    K._cell_strain_rate(3, q, v, tri, np.full(3, 0.25 * 0.5), out)
    assert np.all(np.isnan(out))
