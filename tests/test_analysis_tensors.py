"""masonrycli.analysis.tensors: DESIGN §6 cases 3–5 with exact references and the TensorComputer."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tensor_helpers import deformed, star, star_is_closed, state_arrays, triangulated_wall

from masonrycli.analysis import tensors as T
from masonrycli.analysis import triangulation

RHO, G = 2000.0, 9.81

# ---------------------------------------------------------------------------------------------------
# DESIGN §6 case 4: stress algebra
# ---------------------------------------------------------------------------------------------------

CASE4_POINTS = np.array(
    [[0.2, 0.1], [-0.2, 0.1], [0.2, -0.1], [-0.2, -0.1], [0.2, 0.1], [0.2, -0.1], [-0.2, 0.1], [-0.2, -0.1]]
)
CASE4_FORCES = np.array([[-150.0, -500.0]] * 2 + [[150.0, 500.0]] * 2 + [[-150.0, -75.0]] * 2 + [[150.0, 75.0]] * 2)
CASE4_SIGMA = np.array([[-1500.0, -750.0], [-750.0, -2500.0]])
CASE4_S1 = -2000.0 + math.sqrt(500.0**2 + 750.0**2)  # c ± hypot((a − d)/2, b)
CASE4_S2 = -2000.0 - math.sqrt(500.0**2 + 750.0**2)
CASE4_ANGLE = 0.5 * math.atan2(-1500.0, 1000.0)


def test_case4_principal_stresses_are_the_design_numbers():
    # The code on DESIGN.md §6 case 4, against the numbers printed there (3 decimals) and, to 1e-10,
    # against numpy: σ = Σ x ⊗ F / A and the eigen-decomposition of σ (symmetric here).
    body = np.tile([0, 1], (8, 1)).astype(np.int32)
    sigma = T.block_stress(1, np.zeros((2, 3)), np.array([0.08]), body, CASE4_POINTS, -CASE4_FORCES)[0]
    values, angle = T.principal(sigma)
    np.testing.assert_allclose(values, [-1098.612, -2901.388], rtol=0, atol=5e-4)
    assert math.degrees(angle) == pytest.approx(-28.155, abs=5e-4)
    reference = np.einsum("ki,kj->ij", CASE4_POINTS, CASE4_FORCES) / 0.08
    np.testing.assert_allclose(sigma, reference, rtol=1e-12)
    w, v = np.linalg.eigh(reference)
    np.testing.assert_allclose(values, w[::-1], rtol=1e-10)
    assert math.tan(angle) == pytest.approx(v[1, 1] / v[0, 1], rel=1e-10)
    # The module's constants, used by the tests below, are these numbers.
    np.testing.assert_allclose([CASE4_S1, CASE4_S2, CASE4_ANGLE], [*values, angle], rtol=1e-10)
    np.testing.assert_allclose(CASE4_SIGMA, reference, rtol=1e-12)


def test_case4_block_against_support():
    # block 0 (centred at the origin, 0.4 × 0.2 × 1 m), support 1: contact (0, 1) carries the force on
    # the support, so the block (body a) receives CASE4_FORCES.
    body = np.tile([0, 1], (8, 1)).astype(np.int32)
    q = np.zeros((2, 3))
    sigma = T.block_stress(1, q, np.array([0.08]), body, CASE4_POINTS, -CASE4_FORCES)
    np.testing.assert_allclose(sigma[0], CASE4_SIGMA, rtol=1e-10)
    values, angle = T.principal(sigma)
    np.testing.assert_allclose(values[0], [CASE4_S1, CASE4_S2], rtol=1e-10)
    assert angle[0] == pytest.approx(CASE4_ANGLE, rel=1e-10)


def test_case4_block_as_body_b_and_translated():
    # the block is body b = 1 of pairs with a far block 0, and sits at (5, 3): same stress
    offset = np.array([5.0, 3.0])
    body = np.tile([0, 1], (8, 1))
    q = np.array([[-20.0, 0.0, 0.0], [5.0, 3.0, 0.3]])
    sigma = T.block_stress(2, q, np.array([1.0, 0.08]), body, CASE4_POINTS + offset, CASE4_FORCES)
    np.testing.assert_allclose(sigma[1], CASE4_SIGMA, rtol=1e-10)


def test_case4_through_tensor_computer():
    tc = T.TensorComputer(1, np.array([0.08]), np.zeros((0, 3), np.int64))
    q = np.zeros((2, 3))
    body = np.tile([0, 1], (8, 1)).astype(np.int32)
    tc.step(q, q.copy(), body, CASE4_POINTS, -CASE4_FORCES, 1e-3)
    f = tc.fields()
    np.testing.assert_allclose(f["block_stress"][0], CASE4_SIGMA, rtol=1e-10)
    np.testing.assert_allclose(f["cell_stress"][0], CASE4_SIGMA, rtol=1e-10)  # cell = the block alone
    np.testing.assert_allclose(f["cell_principal_stress"][0], [CASE4_S1, CASE4_S2], rtol=1e-10)
    assert f["cell_principal_angle"][0] == pytest.approx(CASE4_ANGLE, rel=1e-10)
    assert f["cell_spherical_stress"][0] == pytest.approx(-2000.0, rel=1e-12)
    assert f["cell_deviatoric_stress"][0] == pytest.approx(math.sqrt(812500.0), rel=1e-12)
    assert f["cell_stress_skew"][0] == 0.0


def test_rotation_makes_stress_non_symmetric_and_skew_is_reported():
    # a couple of tangential forces: Σ GI ⊗ F has σ_xy ≠ σ_yx
    body = np.array([[0, 1], [0, 1]])
    points = np.array([[0.0, 0.1], [0.0, -0.1]])
    forces = np.array([[10.0, 0.0], [-10.0, 0.0]])  # on the block: −forces
    tc = T.TensorComputer(1, np.array([0.08]), np.zeros((0, 3)))
    tc.step(np.zeros((2, 3)), np.zeros((2, 3)), body, points, forces, 0.0)
    f = tc.fields()
    # σ_yx = (0.1 · (−10) + (−0.1) · 10) / 0.08 = −25, σ_xy = 0
    np.testing.assert_allclose(f["cell_stress"][0], [[0.0, 0.0], [-25.0, 0.0]], atol=1e-12)
    assert f["cell_stress_skew"][0] == pytest.approx(12.5, rel=1e-14)


# ---------------------------------------------------------------------------------------------------
# DESIGN §6 case 3: column of 5 blocks at rest, hand-computed static contact forces
# ---------------------------------------------------------------------------------------------------


def column_of_five():
    """Blocks 0..4 from the bottom, 0.4 × 0.2, support 5 = ground; two contact points per joint, at the
    joint's ends, each carrying half the weight above (static equilibrium)."""
    n, w, h = 5, 0.4, 0.2
    weight = RHO * G * w * h  # N (thickness 1 m)
    centroids = np.array([[0.0, h / 2 + k * h] for k in range(n)])
    body, point, force = [], [], []
    for x in (-w / 2, w / 2):
        body.append([0, n])  # ground under block 0: the block is body a, gets -force
        point.append([x, 0.0])
        force.append([0.0, -n * weight / 2])
    for k in range(n - 1):  # joint between k (a, below) and k + 1 (b, above): force on k + 1
        for x in (-w / 2, w / 2):
            body.append([k, k + 1])
            point.append([x, (k + 1) * h])
            force.append([0.0, (n - 1 - k) * weight / 2])
    return centroids, np.full(n, w * h), np.array(body, np.int32), np.array(point), np.array(force)


def test_case3_column_block_and_cell_stress():
    centroids, volume, body, point, force = column_of_five()
    n = len(centroids)
    triangles = triangulation.build_triangles(centroids, body)  # collinear centroids: no triangle
    assert triangles.shape == (0, 3)
    tc = T.TensorComputer(n, volume, triangles)
    q, v = state_arrays(centroids)
    tc.step(q, v, body, point, force, 1e-3)
    f = tc.fields()
    expected_from_top = np.array([-1962.0, -5886.0, -9810.0, -13734.0, -17658.0])
    k_from_top = np.arange(1, 6)
    np.testing.assert_allclose(expected_from_top, -RHO * G * 0.2 * (k_from_top - 0.5), rtol=1e-14)
    sigma = f["block_stress"]
    np.testing.assert_allclose(sigma[::-1, 1, 1], expected_from_top, rtol=1e-12)
    assert np.all(np.abs(sigma[:, 0, 1]) <= 1e-12 * np.abs(sigma[:, 1, 1]))
    assert np.all(np.abs(sigma[:, 1, 0]) <= 1e-12 * np.abs(sigma[:, 1, 1]))
    assert np.all(np.abs(sigma[:, 0, 0]) <= 1e-12 * np.abs(sigma[:, 1, 1]))
    # interior blocks: cell = {k−1, k, k+1}, equal volumes, σ_yy linear in k → cell stress = block stress
    np.testing.assert_allclose(f["cell_stress"][1:4], sigma[1:4], rtol=1e-12, atol=1e-9)
    # end blocks: two-block cells
    np.testing.assert_allclose(f["cell_stress"][4], 0.5 * (sigma[3] + sigma[4]), rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(f["cell_stress"][0], 0.5 * (sigma[0] + sigma[1]), rtol=1e-12, atol=1e-9)
    # principal: σ1 = σ_xx = 0 along x, σ2 = σ_yy; p = σ_yy/2, q = |σ_yy|/2
    np.testing.assert_allclose(f["cell_principal_stress"][2], [0.0, -9810.0], rtol=1e-12, atol=1e-9)
    assert f["cell_principal_angle"][2] == 0.0
    assert f["cell_spherical_stress"][2] == pytest.approx(-4905.0, rel=1e-12)
    assert f["cell_deviatoric_stress"][2] == pytest.approx(4905.0, rel=1e-12)
    # no triangle anywhere: strain rate and strain are NaN, not 0
    for name in ("cell_strain_rate", "cell_strain", "cell_principal_strain", "cell_volumetric_strain_rate"):
        assert np.all(np.isnan(f[name])), name


# ---------------------------------------------------------------------------------------------------
# DESIGN §6 case 5: strain rate of an affine field
# ---------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def wall():
    return triangulated_wall()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_case5_affine_velocity_recovers_sym_l0(wall, seed):
    centroids, _, _, triangles = wall
    n = len(centroids)
    rng = np.random.default_rng(100 + seed)
    l0 = rng.normal(size=(2, 2))
    c0 = rng.normal(size=2)
    x = deformed(centroids, seed)
    q, v = state_arrays(x)
    v[:n, :2] = x @ l0.T + c0
    v[:n, 2] = rng.normal(size=n)  # block spins do not enter the centroid interpolation
    rate = T.cell_strain_rate(n, q, v, triangles)
    has = np.isin(np.arange(n), triangles)
    assert has.sum() > n // 2
    np.testing.assert_allclose(
        rate[has], np.broadcast_to(0.5 * (l0 + l0.T), (has.sum(), 2, 2)), rtol=0, atol=1e-12 * np.abs(l0).max()
    )


def test_case5_rigid_rotation_gives_zero(wall):
    centroids, _, _, triangles = wall
    n = len(centroids)
    x = deformed(centroids, 7)
    omega, x0, c0 = 3.7, np.array([0.4, -1.2]), np.array([0.5, -0.25])
    q, v = state_arrays(x)
    r = x - x0
    v[:n, 0] = c0[0] - omega * r[:, 1]
    v[:n, 1] = c0[1] + omega * r[:, 0]
    rate = T.cell_strain_rate(n, q, v, triangles)
    has = np.isin(np.arange(n), triangles)
    assert np.all(np.abs(rate[has]) <= 1e-12 * omega)


def test_case5_interior_block_own_velocity_does_not_change_its_cell_rate(wall):
    """What holds exactly: around an interior block i (closed fan), Σ_{T of i} A_T ∇N_i^T = 0, so the
    cell strain rate *of block i* does not depend on v_i — for any velocity field and any current
    shape. The neighbours' cell rates do depend on v_i, and so does a boundary block's own rate."""
    centroids, _, _, triangles = wall
    n = len(centroids)
    interior = [i for i in range(n) if star_is_closed(triangles, i)]
    boundary = [i for i in range(n) if len(star(triangles, i)) and not star_is_closed(triangles, i)]
    assert interior and boundary
    rng = np.random.default_rng(3)
    x = deformed(centroids, 11)
    q, v = state_arrays(x)
    v[:n] = rng.normal(size=(n, 3))  # arbitrary, non-affine
    base = T.cell_strain_rate(n, q, v, triangles)
    for i in interior:
        v2 = v.copy()
        v2[i, :2] += rng.normal(size=2)
        rate = T.cell_strain_rate(n, q, v2, triangles)
        np.testing.assert_allclose(rate[i], base[i], rtol=0, atol=1e-12 * np.abs(base).max())
        ring = np.unique(star(triangles, i))
        ring = ring[ring != i]
        assert np.abs(rate[ring] - base[ring]).max() > 1e-3  # the neighbours see it
    i = boundary[0]
    v2 = v.copy()
    v2[i, :2] += [1.0, -1.0]
    assert np.abs(T.cell_strain_rate(n, q, v2, triangles)[i] - base[i]).max() > 1e-3


# ---------------------------------------------------------------------------------------------------
# TensorComputer
# ---------------------------------------------------------------------------------------------------


def wall_contacts(centroids, pairs, rng):
    """Two contact points per touching pair and random forces, plus ground contacts."""
    n = len(centroids)
    bottom = np.nonzero(centroids[:, 1] < 0.15)[0]
    ground = np.stack([np.repeat(bottom, 2), np.full(2 * len(bottom), n)], 1)
    body = np.concatenate([np.repeat(pairs, 2, axis=0), ground])
    c = len(body)
    point = 0.5 * (centroids[body[:, 0]] + centroids[np.minimum(body[:, 1], n - 1)])
    point += rng.normal(scale=0.05, size=(c, 2))
    return body.astype(np.int32), point, rng.normal(size=(c, 2)) * 1e3


def test_fields_names_shapes_units(wall):
    centroids, areas, pairs, triangles = wall
    n = len(centroids)
    tc = T.TensorComputer(n, areas, triangles)
    q, v = state_arrays(centroids)
    tc.step(q, v, *wall_contacts(centroids, pairs, np.random.default_rng(0)), 1e-3)
    f = tc.fields()
    assert list(f) == list(T.TENSOR_FIELDS)
    for name, (suffix, unit, desc) in T.TENSOR_FIELDS.items():
        assert f[name].shape == (n, *suffix), name
        assert f[name].dtype == np.float64
        assert isinstance(unit, str) and unit and desc
    # copies: mutating them does not touch the computer
    f["cell_stress"][:] = 1e99
    assert np.all(tc.fields()["cell_stress"] < 1e99)


def test_fields_are_consistent_with_independent_references(wall):
    centroids, areas, pairs, triangles = wall
    n = len(centroids)
    rng = np.random.default_rng(1)
    tc = T.TensorComputer(n, areas, triangles)
    x = deformed(centroids, 2)
    q, v = state_arrays(x)
    v[:n] = rng.normal(size=(n, 3))
    contacts = wall_contacts(x, pairs, rng)
    tc.step(q, v, *contacts, 1e-3)
    f = tc.fields()
    body, point, force = contacts
    np.testing.assert_allclose(f["block_stress"], T.block_stress(n, q, areas, body, point, force), rtol=1e-14)
    np.testing.assert_allclose(f["cell_strain_rate"], T.cell_strain_rate(n, q, v, triangles), rtol=1e-14)
    for tensor, values, angle in (
        ("cell_stress", "cell_principal_stress", "cell_principal_angle"),
        ("cell_strain_rate", "cell_principal_strain_rate", "cell_principal_strain_rate_angle"),
        ("cell_strain", "cell_principal_strain", "cell_principal_strain_angle"),
    ):
        t = f[tensor][tc.has_triangle]
        sym = 0.5 * (t + np.swapaxes(t, 1, 2))
        w, vec = np.linalg.eigh(sym)
        scale = np.abs(sym).max()
        np.testing.assert_allclose(f[values][tc.has_triangle], w[:, ::-1], rtol=0, atol=1e-12 * scale)
        phi = f[angle][tc.has_triangle]
        cross = np.cos(phi) * vec[:, 1, 1] - np.sin(phi) * vec[:, 0, 1]
        assert np.all(np.abs(cross) < 1e-9)
        assert np.all((phi > -np.pi / 2) & (phi <= np.pi / 2))
    s = f["cell_principal_stress"]
    np.testing.assert_allclose(f["cell_spherical_stress"], 0.5 * (s[:, 0] + s[:, 1]), rtol=1e-12)
    np.testing.assert_allclose(f["cell_deviatoric_stress"], 0.5 * (s[:, 0] - s[:, 1]), rtol=1e-12)
    cs = f["cell_stress"]
    np.testing.assert_allclose(f["cell_stress_skew"], 0.5 * np.abs(cs[:, 0, 1] - cs[:, 1, 0]), rtol=1e-15)
    for rate in ("_rate", ""):
        e = f["cell_principal_strain" + rate][tc.has_triangle]
        volumetric = f["cell_volumetric_strain" + rate][tc.has_triangle]
        deviatoric = f["cell_deviatoric_strain" + rate][tc.has_triangle]
        np.testing.assert_allclose(volumetric, e[:, 0] + e[:, 1], rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(deviatoric, 0.5 * (e[:, 0] - e[:, 1]), rtol=1e-12, atol=1e-15)


def test_cumulated_strain_integrates_the_rate(wall):
    centroids, areas, pairs, triangles = wall
    n = len(centroids)
    tc = T.TensorComputer(n, areas, triangles)
    l0 = np.array([[0.3, -0.2], [0.5, -0.1]])
    q, v = state_arrays(centroids)
    v[:n, :2] = centroids @ l0.T
    no = np.zeros((0, 2))
    args = (np.zeros((0, 2), np.int32), no, no)
    tc.step(q, v, *args, 0.0)  # initial frame: no integration
    assert np.all(tc.fields()["cell_strain"][tc.has_triangle] == 0.0)
    dt, steps = 1e-3, 40
    for _ in range(steps):
        tc.step(q, v, *args, dt)
    f = tc.fields()
    expected = steps * dt * 0.5 * (l0 + l0.T)
    got = f["cell_strain"][tc.has_triangle]
    np.testing.assert_allclose(got, np.broadcast_to(expected, got.shape), rtol=1e-10, atol=1e-15)
    assert f["cell_volumetric_strain"][tc.has_triangle] == pytest.approx(steps * dt * 0.2, rel=1e-10)
    tc.reset_strain()
    assert np.all(tc.fields()["cell_strain"][tc.has_triangle] == 0.0)


def test_step_accepts_block_or_body_arrays_and_int64_bodies(wall):
    centroids, areas, pairs, triangles = wall
    n = len(centroids)
    rng = np.random.default_rng(4)
    body, point, force = wall_contacts(centroids, pairs, rng)
    q, v = state_arrays(centroids, n_supports=3)
    v[:n] = rng.normal(size=(n, 3))
    a, b = T.TensorComputer(n, areas, triangles), T.TensorComputer(n, areas, triangles)
    a.step(q, v, body, point, force, 1e-3)
    b.step(q[:n].copy(), v[:n].copy(), body.astype(np.int64), point, force, 1e-3)
    for name, value in a.fields().items():
        np.testing.assert_array_equal(value, b.fields()[name])


def test_constructor_and_step_validation():
    with pytest.raises(ValueError):
        T.TensorComputer(2, np.ones(3), np.zeros((0, 3)))
    with pytest.raises(ValueError):
        T.TensorComputer(2, np.array([1.0, 0.0]), np.zeros((0, 3)))
    with pytest.raises(ValueError):
        T.TensorComputer(3, np.ones(3), np.array([[0, 1, 3]]))
    tc = T.TensorComputer(2, np.ones(2), np.zeros((0, 3)))
    with pytest.raises(ValueError):
        tc.step(
            np.zeros((1, 3)), np.zeros((2, 3)), np.zeros((0, 2), np.int32), np.zeros((0, 2)), np.zeros((0, 2)), 1e-3
        )
    with pytest.raises(ValueError):
        tc.step(
            np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((1, 2), np.int32), np.zeros((1, 2)), np.zeros((2, 2)), 1e-3
        )


def test_principal_launcher_batches():
    rng = np.random.default_rng(8)
    t = rng.normal(size=(4, 5, 2, 2))
    values, angle = T.principal(t)
    assert values.shape == (4, 5, 2) and angle.shape == (4, 5)
    w = np.linalg.eigvalsh(0.5 * (t + np.swapaxes(t, -1, -2)))
    np.testing.assert_allclose(values, w[..., ::-1], atol=1e-13)


def test_tensor_computer_floors_the_star_area_from_the_initial_centroids():
    centroids0 = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    tc = T.TensorComputer(3, np.ones(3), np.array([[0, 1, 2], [1, 2, 0], [2, 0, 1]]), centroids0=centroids0)
    np.testing.assert_allclose(tc.min_star_area, T.FOLDED_FRACTION * 0.5)
    q = np.zeros((3, 3))
    q[:, :2] = [[0.0, 0.0], [1.0, 0.0], [0.0, 0.05]]  # squashed to 5 % of its area
    v = np.zeros((3, 3))
    v[2, 1] = -1.0
    no = np.zeros((0, 2))
    tc.step(q, v, np.zeros((0, 2), np.int32), no, no, 1e-3)
    f = tc.fields()
    assert np.all(np.isnan(f["cell_strain_rate"]))
    assert np.all(f["cell_strain"] == 0.0)  # the cumulated strain keeps its value


def test_fields_read_at_the_last_step_only_are_those_read_every_step(wall):
    """Stress and chain strain rate are made when read, from the last step's arrays: reading the fields
    after every step or only after the last gives the same bits (the strain still sums every step)."""
    centroids, areas, pairs, triangles = wall
    n = len(centroids)
    rng = np.random.default_rng(7)
    every, last = T.TensorComputer(n, areas, triangles), T.TensorComputer(n, areas, triangles)
    for k in range(4):
        q, v = state_arrays(deformed(centroids, k))
        v += rng.normal(scale=1e-3, size=v.shape)
        contacts = wall_contacts(centroids, pairs, rng)
        every.step(q, v, *contacts, 1e-3)
        seen = every.fields()
        last.step(q.copy(), v.copy(), *(a.copy() for a in contacts), 1e-3)
    for name, value in last.fields().items():
        assert value.tobytes() == seen[name].tobytes(), name
    assert np.isfinite(seen["cell_stress"]).any() and np.isfinite(seen["cell_strain"]).any()
