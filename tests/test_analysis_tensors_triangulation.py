"""masonrycli.analysis.triangulation: cell fans over the contact neighbours, chain neighbours (and the chain strain
rate of tensors over them), isolated blocks."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tensor_helpers import running_bond, star, star_is_closed, state_arrays, triangulated_wall

from masonrycli.analysis import tensors as T
from masonrycli.analysis import triangulation


@pytest.fixture(scope="module")
def wall():
    return triangulated_wall()


# ---------------------------------------------------------------------------------------------------
# Triangulation
# ---------------------------------------------------------------------------------------------------


def test_build_triangles_running_bond(wall):
    centroids, _, pairs, triangles = wall
    n = len(centroids)
    assert triangles.dtype == np.int64 and triangles.ndim == 2 and triangles.shape[1] == 3
    assert len(triangles) > 0
    touching = {(min(a, b), max(a, b)) for a, b in pairs.tolist()}
    for t in triangles.tolist():
        for j in t[1:]:
            assert (min(t[0], j), max(t[0], j)) in touching  # the apex touches both other blocks
        p = centroids[t]
        e1, e2 = p[1] - p[0], p[2] - p[0]
        assert 0.5 * (e1[0] * e2[1] - e1[1] * e2[0]) > 1e-6  # counter-clockwise, non-degenerate
    assert [tuple(t) for t in triangles.tolist()] == sorted(tuple(t) for t in triangles.tolist())
    # blocks away from the wall's edge: 6 triangles (2 below, 2 above, 1 each side pair); a full block
    # at the end of a course closes its fan over the two half blocks beside it (5 triangles)
    interior = [i for i in range(n) if star_is_closed(triangles, i)]
    assert len(interior) >= 9
    assert all(len(star(triangles, i)) in (5, 6) for i in interior)
    assert sum(len(star(triangles, i)) == 6 for i in interior) >= 9
    # a triangle of three mutually touching blocks is in the fan of each of them
    from shapely.geometry import Polygon
    from shapely.ops import unary_union

    keys = [tuple(sorted(t)) for t in triangles.tolist()]
    for t, key in zip(triangles.tolist(), keys):
        if all((min(a, b), max(a, b)) in touching for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))):
            assert keys.count(key) == 3
    for fan in (star(triangles, i) for i in range(n)):  # a cell's fan never overlaps itself
        fan_polys = [Polygon(centroids[t]) for t in fan]
        assert unary_union(fan_polys).area == pytest.approx(sum(p.area for p in fan_polys), rel=1e-12)


def test_build_triangles_is_deterministic_and_ignores_pair_order_repeats_and_supports(wall):
    centroids, _, pairs, triangles = wall
    n = len(centroids)
    rng = np.random.default_rng(0)
    messy = np.concatenate([pairs[:, ::-1], pairs, [[0, n], [n + 1, 3]]])
    messy = messy[rng.permutation(len(messy))]
    np.testing.assert_array_equal(triangulation.build_triangles(centroids, messy), triangles)


def test_build_triangles_fans_over_consecutive_neighbours_and_drops_slivers():
    # square of 4 blocks touching only along its sides: each corner's fan has one triangle over its two
    # neighbours (they need not touch each other, Fig. I.1); a gap of 180° or more is a free edge
    c = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    sides = np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    assert triangulation.build_triangles(c, sides).tolist() == [[0, 1, 3], [1, 2, 0], [2, 3, 1], [3, 0, 2]]
    # collinear, fewer than 3, no pairs
    line = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    assert triangulation.build_triangles(line, [[0, 1], [1, 2], [0, 2]]).shape == (0, 3)
    assert triangulation.build_triangles(c[:2], [[0, 1]]).shape == (0, 3)
    assert triangulation.build_triangles(c, np.zeros((0, 2))).shape == (0, 3)
    # a ring: each voussoir touches its two neighbours only; the fan over them is a sliver (smallest
    # angle 6° here) and is dropped, while a 12° triangle is kept
    for half_angle, kept in ((6.0, 0), (12.0, 1)):
        a = math.radians(half_angle)
        ring = np.array([[-math.cos(a), -math.sin(a)], [0.0, 0.0], [math.cos(a), -math.sin(a)]])
        assert len(triangulation.build_triangles(ring, [[0, 1], [1, 2]])) == kept


def test_fan_triangle_angles_are_at_least_the_minimum_in_the_paper_structures():
    """Every kept triangle's smallest angle (measured with numpy.linalg, independently) ≥ MIN_ANGLE."""
    boxes, centroids, _, pairs = running_bond(6, 5)
    tri = triangulation.build_triangles(centroids, pairs)
    p = centroids[tri]
    for k in range(3):
        u, w = p[:, (k + 1) % 3] - p[:, k], p[:, (k + 2) % 3] - p[:, k]
        cos = (u * w).sum(1) / np.linalg.norm(u, axis=1) / np.linalg.norm(w, axis=1)
        assert np.all(np.arccos(cos) >= triangulation.MIN_ANGLE - 1e-12)


def test_chain_neighbours_and_chain_strain_rate_of_an_affine_field():
    """Blocks touching exactly two blocks and no support form a chain; for v = L x + c along a straight
    chain the rate is uᵀ L u, and along any chain it is Σ l (uᵀ L u) / Σ l (an independent formula)."""
    rng = np.random.default_rng(5)
    x = np.array([[0.0, 0.0], [1.0, 0.1], [2.0, 0.3], [2.8, 0.9], [3.0, 2.0]])
    n = len(x)
    pairs = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [0, n]])  # block 0 rests on support n
    chain = triangulation.chain_neighbours(n, pairs)
    assert chain[0].tolist() == [-1, -1] and chain[4].tolist() == [-1, -1]  # support / one neighbour
    assert [sorted(c) for c in chain[1:4].tolist()] == [[0, 2], [1, 3], [2, 4]]
    l0, c0 = rng.normal(size=(2, 2)), rng.normal(size=2)
    q, v = state_arrays(x)
    v[:n, :2] = x @ l0.T + c0
    rate = T.chain_strain_rate(n, q, v, chain)
    assert np.isnan(rate[[0, 4]]).all()
    for i in (1, 2, 3):
        links = x[chain[i]] - x[i]
        length = np.linalg.norm(links, axis=1)
        u = links / length[:, None]
        expected = sum(ln * (ui @ l0 @ ui) for ln, ui in zip(length, u)) / length.sum()
        assert rate[i] == pytest.approx(expected, rel=1e-12)
    straight = np.array([[0.0, 0.0], [1.0, 1.0], [2.5, 2.5]])
    q, v = state_arrays(straight)
    v[:3, :2] = straight @ l0.T
    u = np.array([1.0, 1.0]) / math.sqrt(2.0)
    assert T.chain_strain_rate(3, q, v, triangulation.chain_neighbours(3, [[0, 1], [1, 2]]))[1] == pytest.approx(
        u @ l0 @ u
    )


def test_isolated_block_gets_nan_strain(wall):
    centroids, areas, pairs, _ = wall
    n = len(centroids)
    far = np.concatenate([centroids, [[10.0, 0.1]]])  # block n touches nothing
    triangles = triangulation.build_triangles(far, pairs)
    assert not np.isin(n, triangles)
    tc = T.TensorComputer(n + 1, np.append(areas, 0.06), triangles)
    assert not tc.has_triangle[n] and tc.has_triangle[:n].any()
    q, v = state_arrays(far)
    v[: n + 1, 0] = 0.1 * far[:, 1]  # simple shear
    no = np.zeros((0, 2))
    tc.step(q, v, np.zeros((0, 2), np.int32), no, no, 1e-3)
    f = tc.fields()
    for name in (
        "cell_strain_rate",
        "cell_strain",
        "cell_principal_strain_rate",
        "cell_principal_strain",
        "cell_volumetric_strain",
        "cell_deviatoric_strain_rate",
        "cell_principal_strain_angle",
    ):
        assert np.all(np.isnan(f[name][n])), name
        assert np.all(np.isfinite(f[name][tc.has_triangle])), name
