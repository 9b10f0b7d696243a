"""Narrow phase vs the independent reference (tests/naive_collision.py: plain Python SAT + shapely). Its
contacts' keys: test_engine_contact_key.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

from masonrycli.engine.contact_key import decode_contact_key
from masonrycli.engine.narrowphase import collide_polygons, edge_normals, narrowphase
from masonrycli.engine.rounded import CORNER_RADIUS

import naive_collision as nv

ALERT = 0.02  # random polygons are ~1 m across: a generous alert distance gives many near contacts


# ----------------------------------------------------------------------------------------------
# helpers
# ----------------------------------------------------------------------------------------------


def run_batch(pairs, alert):
    """All pairs through one narrowphase() call (bodies 2i, 2i+1); per pair (points, normals, gaps, keys)."""
    polys = [p for pair in pairs for p in pair]
    vert_world = np.ascontiguousarray(np.concatenate(polys), dtype=np.float64)
    body_vert_start = np.zeros(len(polys) + 1, dtype=np.int64)
    body_vert_start[1:] = np.cumsum([len(p) for p in polys])
    pair_body = np.arange(len(polys), dtype=np.int32).reshape(-1, 2)
    cap = 2 * len(pairs)
    body = np.full((cap, 2), -1, dtype=np.int32)
    point = np.full((cap, 2), np.nan)
    normal = np.full((cap, 2), np.nan)
    gap = np.full(cap, np.nan)
    key = np.full(cap, -1, dtype=np.int64)
    edge_normal, body_size = edge_normals(vert_world, body_vert_start)
    n = narrowphase(
        vert_world, edge_normal, body_size, body_vert_start, pair_body, len(pairs), alert, body, point, normal, gap, key
    )
    assert np.all(body[:n, 0] % 2 == 0) and np.all(body[:n, 1] == body[:n, 0] + 1)
    assert np.all(np.diff(body[:n, 0]) >= 0), "contacts grouped by pair, pairs in input order"
    out = []
    for i in range(len(pairs)):
        m = body[:n, 0] == 2 * i
        out.append((point[:n][m], normal[:n][m], gap[:n][m], key[:n][m]))
    return out


def face_frame(P, i):
    (x1, y1), (x2, y2) = nv.edge(P, i)
    n = np.array(nv.outward_normal(P, i))
    u = np.array([x2 - x1, y2 - y1]) / math.hypot(x2 - x1, y2 - y1)
    return np.array([x1, y1]), np.array([(x1 + x2) / 2, (y1 + y2) / 2]), n, u


def make_pair(rng, kind, alert=ALERT):
    """Random convex A, B with one face of A (or of B) at a prescribed separation from the other."""
    A = nv.random_convex_polygon(rng, aspect=float(rng.choice([0.6, 1.0, 1.7])))
    B = nv.random_convex_polygon(rng, aspect=float(rng.choice([0.6, 1.0, 1.7])))
    B = nv.rotate(B, rng.uniform(0, 2 * math.pi))
    target = {
        "touch": 0.0,
        "gap": rng.uniform(0.0, 1.5 * alert),
        "overlap": -rng.uniform(0.0, 0.05),
        "parallel": rng.choice([0.0, rng.uniform(-0.02, 1.5 * alert)]),
    }[kind]
    face_of_a = rng.random() < 0.5
    if kind == "parallel":
        # Turn B so that one of its edges faces A's edge f, within a tiny angle.
        f = int(rng.integers(len(A)))
        j = int(rng.integers(len(B)))
        nA = np.array(nv.outward_normal(A, f))
        nB = np.array(nv.outward_normal(B, j))
        delta = float(rng.choice([0.0, 1e-9, -1e-9, 1e-7, -1e-7, 1e-5]))
        turn = math.atan2(-nA[1], -nA[0]) - math.atan2(nB[1], nB[0]) + delta
        B = nv.rotate(B, turn)
        face_of_a = True
    if face_of_a:
        f = int(rng.integers(len(A))) if kind != "parallel" else f
        v, mid, n, u = face_frame(A, f)
        B = B - B.mean(axis=0) + mid + 1.0 * n + rng.uniform(-0.6, 0.6) * u
        sep = min(n @ (w - v) for w in B)
        B = B + (target - sep) * n
    else:
        f = int(rng.integers(len(B)))
        B = B - B.mean(axis=0)
        v, mid, n, u = face_frame(B, f)
        shift = A.mean(axis=0) - mid - 1.0 * n + rng.uniform(-0.6, 0.6) * u
        B = B + shift
        v = v + shift
        sep = min(n @ (w - v) for w in A)
        B = B + (sep - target) * n
    return A, B


@pytest.fixture(scope="module")
def random_cases():
    rng = np.random.default_rng(20240611)
    kinds = ["touch"] * 250 + ["gap"] * 300 + ["overlap"] * 300 + ["parallel"] * 250
    pairs = [make_pair(rng, k) for k in kinds]
    results = run_batch(pairs, ALERT)
    refs = [nv.reference_manifold(A, B, ALERT, a=2 * i, b=2 * i + 1) for i, (A, B) in enumerate(pairs)]
    return kinds, pairs, results, refs


def comparable(ref):
    """No decision of the specification sits within rounding of its thresholds (clipping, face choice)."""
    return not ref["at_threshold"] and ref["slab_margin"] > 1e-6


# ----------------------------------------------------------------------------------------------
# structured cases
# ----------------------------------------------------------------------------------------------


def test_block_on_wide_ground_gives_its_two_bottom_corners():
    block = nv.rect(1.0, 0.0, 1.3, 0.2)
    ground = nv.rect(-5.0, -1.0, 5.0, 0.0)
    for a_poly, b_poly, sign in ((block, ground, -1.0), (ground, block, 1.0)):
        point, normal, gap, key = collide_polygons(a_poly, b_poly, 1e-3)
        np.testing.assert_array_equal(gap, [0.0, 0.0])
        assert sorted(map(tuple, point)) == [(1.0, 0.0), (1.3, 0.0)]
        np.testing.assert_array_equal(normal, [[0.0, sign], [0.0, sign]])
        # both contacts sit at the block's vertices 0 and 1, against the ground's top edge (2)
        a, b, owner_is_b, vertex, edge = decode_contact_key(key)
        block_is_b = sign > 0
        assert list(owner_is_b) == [int(block_is_b)] * 2
        assert sorted(vertex) == [0, 1] and list(edge) == [2, 2]


def test_running_bond_joint_gives_the_two_ends_of_the_overlap():
    lower = nv.rect(0.0, 0.0, 0.3, 0.2)
    upper = nv.rect(0.15, 0.2, 0.45, 0.4)
    point, normal, gap, key = collide_polygons(lower, upper, 1e-3)
    np.testing.assert_array_equal(gap, [0.0, 0.0])
    assert sorted(map(tuple, point)) == [(0.15, 0.2), (0.3, 0.2)]
    np.testing.assert_array_equal(normal, [[0.0, 1.0], [0.0, 1.0]])
    # same row, vertical joint
    point, normal, gap, key = collide_polygons(lower, nv.rect(0.3, 0.0, 0.6, 0.2), 1e-3)
    assert sorted(map(tuple, point)) == [(0.3, 0.0), (0.3, 0.2)]
    np.testing.assert_array_equal(normal, [[1.0, 0.0], [1.0, 0.0]])
    np.testing.assert_array_equal(gap, [0.0, 0.0])


def test_open_joint_gap_and_alert():
    lower = nv.rect(0.0, 0.0, 0.3, 0.2)
    for g in (1e-4, 9.9e-4):
        _, _, gap, _ = collide_polygons(lower, nv.rect(0.15, 0.2 + g, 0.45, 0.4 + g), 1e-3)
        np.testing.assert_allclose(gap, [g, g], rtol=0, atol=1e-15)
    for g in (1.001e-3, 0.01):
        point, _, _, _ = collide_polygons(lower, nv.rect(0.15, 0.2 + g, 0.45, 0.4 + g), 1e-3)
        assert len(point) == 0


def test_corner_on_face_gives_one_point():
    base = nv.rect(0.0, 0.0, 1.0, 0.2)
    for g in (0.0, 3e-4, -2e-4):
        diamond = nv.rotate(nv.rect(-0.1, -0.1, 0.1, 0.1), math.pi / 4) + [0.4, 0.2 + 0.1 * math.sqrt(2) + g]
        point, normal, gap, key = collide_polygons(base, diamond, 1e-3)
        assert len(point) == 1
        np.testing.assert_allclose(gap, [g], atol=1e-15)
        np.testing.assert_allclose(point, [[0.4, 0.2 + g / 2]], atol=1e-15)
        np.testing.assert_array_equal(normal, [[0.0, 1.0]])


def test_corner_against_corner_is_one_contact():
    a = nv.rect(0.0, 0.0, 0.3, 0.2)
    b = nv.rect(0.3, 0.2, 0.6, 0.4)
    point, normal, gap, key = collide_polygons(a, b, 1e-3)
    assert len(point) == 1
    np.testing.assert_array_equal(point, [[0.3, 0.2]])
    np.testing.assert_array_equal(gap, [0.0])


@pytest.mark.parametrize("delta", [1e-7, -1e-7, 1e-9, 1e-4])
@pytest.mark.parametrize("swap", [False, True])
def test_nearly_parallel_faces(delta, swap):
    # 0.2-wide block on a 0.3-wide one, turned by delta about the middle of its bottom face.
    lower = nv.rect(0.0, 0.0, 0.3, 0.2)
    upper = nv.rotate(nv.rect(0.05, 0.2, 0.25, 0.4), delta, centre=(0.15, 0.2))
    a_poly, b_poly = (upper, lower) if swap else (lower, upper)
    point, normal, gap, key = collide_polygons(a_poly, b_poly, 1e-3)
    assert len(point) == 2
    # exact: the bottom corners of the upper block are at ±0.1 sin(delta) from y = 0.2 when the
    # lower block's face is the reference, and the lower block's face spans the upper one entirely
    ref = nv.reference_manifold(a_poly, b_poly, 1e-3)
    if ref["ref_is_b"] == swap:  # reference = lower block's top face
        np.testing.assert_allclose(
            sorted(gap), [-0.1 * math.sin(abs(delta)), 0.1 * math.sin(abs(delta))], rtol=1e-9, atol=1e-16
        )
    np.testing.assert_allclose(point, ref["points"], atol=1e-15)
    np.testing.assert_allclose(gap, ref["gaps"], atol=1e-15)
    np.testing.assert_allclose(normal, [ref["normal"]] * 2, atol=1e-15)
    if abs(delta) < 1e-6:  # within the tolerance: a's face, whichever it is
        assert not ref["ref_is_b"]


def test_rocking_block_on_ground():
    ground = nv.rect(-5.0, -1.0, 5.0, 0.0)
    for phi in (0.05, -0.3):
        corner = (0.0, 0.0) if phi > 0 else (0.3, 0.0)
        block = nv.rotate(nv.rect(0.0, 0.0, 0.3, 0.2), phi, centre=corner)
        point, normal, gap, key = collide_polygons(block, ground, 1e-3)
        assert len(point) == 1
        np.testing.assert_allclose(point, [corner], atol=1e-16)
        np.testing.assert_allclose(gap, [0.0], atol=1e-16)
        np.testing.assert_allclose(normal, [[0.0, -1.0]], atol=1e-16)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_coincident_faces_random_polygons(seed):
    """Random convex polygons sharing part of a straight joint: the two ends of the overlap, gap 0."""
    import shapely
    from shapely.geometry import LineString, box

    rng = np.random.default_rng(seed)
    checked = 0
    while checked < 40:
        P = nv.random_convex_polygon(rng, radius=0.4)
        Q = nv.random_convex_polygon(rng, radius=0.4)
        # cut P below y = 0 and Q above it: both get an edge on y = 0 exactly
        P = shapely.geometry.polygon.orient(nv.polygon(P).intersection(box(-9, -9, 9, 0.0)), 1.0)
        Q = shapely.geometry.polygon.orient(nv.polygon(Q).intersection(box(-9, 0.0, 9, 9)), 1.0)
        if P.is_empty or Q.is_empty or P.geom_type != "Polygon" or Q.geom_type != "Polygon":
            continue
        P = np.asarray(P.exterior.coords)[:-1]
        Q = np.asarray(Q.exterior.coords)[:-1]
        P[np.abs(P[:, 1]) < 1e-12, 1] = 0.0
        Q[np.abs(Q[:, 1]) < 1e-12, 1] = 0.0
        Q[:, 0] += rng.uniform(-0.3, 0.3)
        top = P[P[:, 1] == 0.0]
        bottom = Q[Q[:, 1] == 0.0]
        if len(top) != 2 or len(bottom) != 2:
            continue
        shared = LineString(top).intersection(LineString(bottom))
        if shared.geom_type != "LineString" or shared.length < 0.02:
            continue
        ends = sorted(np.asarray(shared.coords).tolist())
        # in place, then turned and moved: same contacts, turned and moved
        angle = rng.uniform(-math.pi, math.pi)
        offset = rng.uniform(-3, 3, 2)
        for turn in (0.0, angle):
            Pw = nv.rotate(P, turn) + (offset if turn else 0.0)
            Qw = nv.rotate(Q, turn) + (offset if turn else 0.0)
            expected = nv.rotate(np.array(ends), turn) + (offset if turn else 0.0)
            point, normal, gap, key = collide_polygons(Pw, Qw, 1e-3)
            assert len(point) == 2
            tol = 1e-15 if turn == 0.0 else 1e-12
            if np.linalg.norm(point[0] - expected[0]) > np.linalg.norm(point[0] - expected[1]):
                expected = expected[::-1]  # match the two points to the two ends
            np.testing.assert_allclose(point, expected, atol=tol)
            np.testing.assert_allclose(gap, [0.0, 0.0], atol=tol)
            np.testing.assert_allclose(normal, [[-math.sin(turn), math.cos(turn)]] * 2, atol=tol)
            # each end is a vertex of P or Q (the key says which): check it
            _, _, owner_is_b, vertex, _ = decode_contact_key(key)
            for p, own, vtx in zip(point, owner_is_b, vertex):
                np.testing.assert_allclose((Qw if own else Pw)[vtx], p, atol=tol)
        checked += 1


# ----------------------------------------------------------------------------------------------
# random pairs vs the independent reference
# ----------------------------------------------------------------------------------------------


def expected_normal(A, B, ref):
    """(normal, atol) of the pair's contacts per the specification (steps 1–6), or None within rounding of
    step 6's threshold: a single contact takes the rounded corners' normal unless that is the face's."""
    if len(ref["points"]) != 1:
        return ref["normal"], 1e-14
    rounded = nv.rounded_normal(A, B, CORNER_RADIUS)
    turn = 1.0 - float(rounded @ ref["normal"]) if rounded is not None else 0.0
    if 1e-13 < turn < 1e-10:
        return None
    return (rounded, 1e-10) if turn >= 1e-10 else (ref["normal"], 1e-14)


def test_random_pairs_match_reference_manifold(random_cases):
    kinds, pairs, results, refs = random_cases
    compared = rounded = 0
    for (A, B), (point, normal, gap, key), ref in zip(pairs, results, refs):
        expected = expected_normal(A, B, ref)
        if not comparable(ref) or expected is None:
            continue
        compared += 1
        assert len(point) == len(ref["points"])
        if len(point):
            np.testing.assert_allclose(point, ref["points"], atol=1e-12)
            np.testing.assert_allclose(gap, ref["gaps"], atol=1e-12)
            np.testing.assert_allclose(normal, [expected[0]] * len(point), atol=expected[1])
            np.testing.assert_array_equal(key, ref["keys"])
            np.testing.assert_allclose(np.hypot(normal[:, 0], normal[:, 1]), 1.0, atol=1e-15)
            rounded += expected[1] > 1e-14
    assert compared > 0.99 * len(pairs)
    assert sum(len(r[0]) == 2 for r in results) > 100 and sum(len(r[0]) == 1 for r in results) > 100
    assert rounded > 20, rounded  # corners on corners, given the rounded corners' normal


def test_no_contact_beyond_alert(random_cases):
    kinds, pairs, results, refs = random_cases
    far = 0
    for (A, B), (point, _, gap, _), ref in zip(pairs, results, refs):
        d = nv.distance(A, B)
        if d > ALERT + 1e-9:
            far += 1
            assert len(point) == 0
        if max(ref["sep_a"], ref["sep_b"]) > ALERT:
            assert len(point) == 0
        assert np.all(gap <= ALERT)
    assert far > 50


def test_separated_gap_is_the_distance(random_cases):
    """Vertex-face or face-face closest features: the smallest gap is shapely's distance."""
    kinds, pairs, results, refs = random_cases
    checked = 0
    for (A, B), (point, _, gap, _), ref in zip(pairs, results, refs):
        d = nv.distance(A, B)
        if not (1e-9 < d <= ALERT) or ref["ambiguous"] or not nv.closest_is_vertex_face(A, B, d):
            continue
        checked += 1
        assert len(gap) > 0
        assert abs(gap.min() - d) <= 1e-9
    assert checked > 150


def test_touching_and_overlapping_gap_is_the_sat_separation(random_cases):
    """min gap = largest separation over the face normals (−penetration depth along the reference
    normal) whenever the deepest incident vertex lies within the reference face's slab; never less."""
    kinds, pairs, results, refs = random_cases
    exact = {"touch": 0, "overlap": 0}
    for (A, B), (point, _, gap, _), ref in zip(pairs, results, refs):
        if ref["ambiguous"] or max(ref["sep_a"], ref["sep_b"]) > ALERT:
            continue
        if len(gap):
            assert gap.min() >= ref["sep"] - 1e-12
        if ref["sep"] <= 1e-12 and deepest_in_slab(A, B, ref):
            assert abs(gap.min() - ref["sep"]) <= 1e-12
            if abs(ref["sep"]) <= 1e-12:
                exact["touch"] += 1
                assert nv.distance(A, B) <= 1e-12
            else:
                exact["overlap"] += 1
                assert nv.polygon(A).intersection(nv.polygon(B)).area > 0
    assert exact["touch"] > 80 and exact["overlap"] > 80


def deepest_in_slab(A, B, ref, margin=1e-9):
    R, I = (B, A) if ref["ref_is_b"] else (A, B)
    n = nv.outward_normal(R, ref["ref_edge"])
    v1, v2 = (np.array(v) for v in nv.edge(R, ref["ref_edge"]))
    u = (v2 - v1) / np.linalg.norm(v2 - v1)
    depth = [n[0] * (w[0] - v1[0]) + n[1] * (w[1] - v1[1]) for w in I]
    w = np.array(I[int(np.argmin(depth))])
    t = u @ (w - v1)
    return margin < t < np.linalg.norm(v2 - v1) - margin


def test_contact_points_lie_near_both_polygons(random_cases):
    kinds, pairs, results, refs = random_cases
    for (A, B), (point, _, gap, _), ref in zip(pairs, results, refs):
        for p, g in zip(point, gap):
            bound = 0.5 * abs(g) + ref["tol"] + 1e-12
            assert nv.point_distance(A, p) <= min(bound, ALERT)
            assert nv.point_distance(B, p) <= min(bound, ALERT)


def test_swapping_bodies_flips_the_normal_only(random_cases):
    kinds, pairs, results, refs = random_cases
    swapped = run_batch([(B, A) for A, B in pairs], ALERT)
    checked = 0
    for i, ((point, normal, gap, key), (point2, normal2, gap2, key2), ref) in enumerate(zip(results, swapped, refs)):
        if abs(ref["sep_a"] - ref["sep_b"]) <= ref["tol"] + 1e-9:
            continue  # the specification prefers body a's face: the choice changes with the order
        checked += len(point)
        np.testing.assert_array_equal(point2, point)
        np.testing.assert_array_equal(gap2, gap)
        np.testing.assert_array_equal(normal2, 0.0 - normal)
        # same physical features (A's or B's vertex, against the other's edge), except at aligned
        # corners, labelled with body a's corner: the label then changes with the order, but both
        # labelled vertices are within snap of the contact point
        _, _, own, vtx, edg = decode_contact_key(key)
        _, _, own2, vtx2, edg2 = decode_contact_key(key2)
        A, B = pairs[i]
        for j in range(len(point)):
            first = ("B" if own[j] else "A", vtx[j], edg[j])
            second = ("A" if own2[j] else "B", vtx2[j], edg2[j])
            if first != second:
                for body, v, _ in (first, second):
                    corner = (B if body == "B" else A)[v]
                    assert np.linalg.norm(corner - point[j]) <= max(ALERT, ref["tol"]) + abs(gap[j]) + 1e-12
    assert checked > 500


def test_batch_matches_single_pair_launcher(random_cases):
    kinds, pairs, results, refs = random_cases
    for (A, B), (point, normal, gap, key) in list(zip(pairs, results))[:200]:
        p2, n2, g2, k2 = collide_polygons(A, B, ALERT)
        np.testing.assert_array_equal(p2, point)
        np.testing.assert_array_equal(g2, gap)
        np.testing.assert_array_equal(n2, normal)
        np.testing.assert_array_equal(decode_contact_key(k2)[2:], decode_contact_key(key)[2:])


# ----------------------------------------------------------------------------------------------
# limits
# ----------------------------------------------------------------------------------------------


def test_narrowphase_refuses_too_small_output():
    vert = np.concatenate([nv.rect(0, 0, 1, 1), nv.rect(1, 0, 2, 1)])
    start = np.array([0, 4, 8], dtype=np.int64)
    pairs = np.array([[0, 1]], dtype=np.int32)
    small = (np.zeros((1, 2), np.int32), np.zeros((1, 2)), np.zeros((1, 2)), np.zeros(1), np.zeros(1, np.int64))
    with pytest.raises(ValueError, match="capacity"):
        narrowphase(vert, *edge_normals(vert, start), start, pairs, 1, 1e-3, *small)


def test_launchers_refuse_mismatched_arrays():
    vert = np.concatenate([nv.rect(0, 0, 1, 1), nv.rect(1, 0, 2, 1)])
    start = np.array([0, 4, 8], dtype=np.int64)
    with pytest.raises(ValueError, match="edge_normals: vert_world has shape \\(7, 2\\)"):
        edge_normals(vert[:-1], start)
    with pytest.raises(ValueError, match="edge_normals: body_size"):
        edge_normals(vert, start, body_size=np.zeros(3))
    pairs = np.array([[0, 1]], dtype=np.int32)
    out = (np.zeros((2, 2), np.int32), np.zeros((2, 2)), np.zeros((2, 2)), np.zeros(2), np.zeros(2, np.int64))
    with pytest.raises(ValueError, match="pair_count 2"):
        narrowphase(vert, *edge_normals(vert, start), start, pairs, 2, 1e-3, *out)
    with pytest.raises(ValueError, match="pair_body has shape \\(1, 2\\) int64"):
        narrowphase(vert, *edge_normals(vert, start), start, pairs.astype(np.int64), 1, 1e-3, *out)
    with pytest.raises(ValueError, match="contact_key"):
        narrowphase(vert, *edge_normals(vert, start), start, pairs, 1, 1e-3, *out[:4], np.zeros(2))
    assert narrowphase(vert, *edge_normals(vert, start), start, pairs, 1, 1e-3, *out) == 2
