"""Broad phase (world vertices, boxes, sweep-and-prune) and detect_contacts vs brute force."""

from __future__ import annotations

import math

import numpy as np
import pytest

from masonrycli.engine.broadphase import PairBuffers, body_aabbs, candidate_pairs, world_vertices
from masonrycli.engine.collision import ContactBuffers, detect_contacts

import naive_collision as nv


def random_scene(rng, n, supports=3, spread=4.0, quantum=None):
    """n random convex polygons (the last `supports` are supports), random poses."""
    polys = [nv.random_convex_polygon(rng, radius=rng.uniform(0.05, 0.4), aspect=rng.uniform(0.3, 3)) for _ in range(n)]
    body_q = np.column_stack(
        [rng.uniform(0, spread, n), rng.uniform(0, spread / 2, n), rng.uniform(-math.pi, math.pi, n)]
    )
    if quantum:  # many equal box bounds: ties in the sort, touching boxes
        body_q[:, :2] = np.round(body_q[:, :2] / quantum) * quantum
        polys = [np.round(p / quantum) * quantum for p in polys]
        polys = [
            p if len(np.unique(p, axis=0)) == len(p) else nv.rect(-quantum, -quantum, quantum, quantum) for p in polys
        ]
        body_q[:, 2] = 0.0
    start = np.zeros(n + 1, dtype=np.int64)
    start[1:] = np.cumsum([len(p) for p in polys])
    vert_local = np.concatenate(polys)
    dynamic = np.ones(n, dtype=bool)
    dynamic[n - supports :] = False
    return body_q, start, vert_local, dynamic


def pairs_of(buffers: PairBuffers):
    return [tuple(p) for p in buffers.pair_body[: buffers.pair_count].tolist()]


# ----------------------------------------------------------------------------------------------
# world vertices and boxes
# ----------------------------------------------------------------------------------------------


def test_world_vertices_match_numpy():
    rng = np.random.default_rng(1)
    body_q, start, vert_local, _ = random_scene(rng, 200)
    body_q[:, :2] *= 10.0
    got = world_vertices(body_q, start, vert_local)
    np.testing.assert_allclose(got, nv.world_vertices_numpy(body_q, start, vert_local), rtol=0, atol=1e-14)
    # θ = 0: exactly x + local
    body_q[:, 2] = 0.0
    out = np.empty_like(got)
    assert world_vertices(body_q, start, vert_local, out) is out
    body_of_vertex = np.repeat(np.arange(len(body_q)), np.diff(start))
    np.testing.assert_array_equal(out, body_q[body_of_vertex, :2] + vert_local)


def test_broadphase_launchers_refuse_mismatched_arrays():
    body_q, start, vert_local, _ = random_scene(np.random.default_rng(3), 5)
    with pytest.raises(ValueError, match="world_vertices: body_q has shape \\(4, 3\\)"):
        world_vertices(body_q[:-1], start, vert_local)
    with pytest.raises(ValueError, match="world_vertices: body_vert_start .* int32"):
        world_vertices(body_q, start.astype(np.int32), vert_local)
    with pytest.raises(ValueError, match="world_vertices: out"):
        world_vertices(body_q, start, vert_local, np.empty((len(vert_local), 3)))
    vw = world_vertices(body_q, start, vert_local)
    with pytest.raises(ValueError, match="body_aabbs: vert_world"):
        body_aabbs(vw[1:], start, 1e-3)
    with pytest.raises(ValueError, match="body_aabbs: out"):
        body_aabbs(vw, start, 1e-3, np.empty((4, 4)))


def test_boxes_match_numpy():
    rng = np.random.default_rng(2)
    body_q, start, vert_local, _ = random_scene(rng, 100)
    vw = world_vertices(body_q, start, vert_local)
    np.testing.assert_array_equal(body_aabbs(vw, start, 1e-3), nv.aabbs_numpy(vw, start, 1e-3))


# ----------------------------------------------------------------------------------------------
# sweep and prune
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed,quantum", [(3, None), (4, None), (5, 1 / 16), (6, 1 / 8)])
def test_random_scenes_match_brute_force_over_steps(seed, quantum):
    rng = np.random.default_rng(seed)
    n = 150
    body_q, start, vert_local, dynamic = random_scene(rng, n, quantum=quantum)
    buffers = PairBuffers(n)
    touching = 0
    for step in range(6):
        vw = world_vertices(body_q, start, vert_local)
        # quantized on a binary grid with no alert: many boxes exactly touching (equal bounds)
        boxes = body_aabbs(vw, start, 0.0 if quantum else 0.02)
        if quantum:
            touching += np.sum(boxes[:, None, 0] == boxes[None, :, 2])
        count = candidate_pairs(boxes, dynamic, buffers)
        expected = nv.aabb_pairs_bruteforce(boxes.tolist(), dynamic)
        assert count == len(expected) and pairs_of(buffers) == expected
        # a fresh buffer (no history) gives the same answer
        fresh = PairBuffers(n)
        candidate_pairs(boxes, dynamic, fresh)
        assert pairs_of(fresh) == expected
        # move: small steps, and once a shuffle (the kept order is then far from sorted)
        if step == 3:
            body_q = body_q[rng.permutation(n)].copy()
        else:
            body_q = body_q + rng.normal(0, 0.05, body_q.shape)
        if quantum:
            body_q[:, :2] = np.round(body_q[:, :2] / quantum) * quantum
            body_q[:, 2] = 0.0
    assert count > 50
    assert touching > 20 or not quantum


def test_capacity_grows_and_supports_never_pair():
    rng = np.random.default_rng(7)
    body_q, start, vert_local, dynamic = random_scene(rng, 80, supports=10, spread=1.0)
    boxes = body_aabbs(world_vertices(body_q, start, vert_local), start, 0.01)
    buffers = PairBuffers(80, pair_capacity=1)
    count = candidate_pairs(boxes, dynamic, buffers)
    expected = nv.aabb_pairs_bruteforce(boxes.tolist(), dynamic)
    assert count == len(expected) > 100 and pairs_of(buffers) == expected
    assert buffers.pair_capacity >= count and buffers.pair_capacity & (buffers.pair_capacity - 1) == 0
    assert all(dynamic[a] or dynamic[b] for a, b in expected)
    # all supports: no pairs at all
    none = PairBuffers(80)
    assert candidate_pairs(boxes, np.zeros(80, dtype=bool), none) == 0


def test_wall_pairs_match_brute_force_and_stay_local():
    body_q, start, vert_local, dynamic, polys = nv.running_bond_wall()
    assert len(polys) == 249  # 248 blocks + ground
    buffers = PairBuffers(len(polys))
    boxes = body_aabbs(world_vertices(body_q, start, vert_local), start, 1e-3)
    count = candidate_pairs(boxes, dynamic, buffers)
    expected = nv.aabb_pairs_bruteforce(boxes.tolist(), dynamic)
    assert pairs_of(buffers) == expected
    assert buffers.axis == 0  # the wall is longer than high
    ground = len(polys) - 1
    assert sum(b == ground for _, b in expected) == 15  # the bottom course only
    assert count < 4 * 248  # neighbours only: ~linear in the block count


def test_column_sweeps_along_y():
    polys = [nv.rect(0.0, 0.2 * i, 0.4, 0.2 * (i + 1)) for i in range(30)] + [nv.rect(-1, -1, 1, 0)]
    body_q, start, vert_local, dynamic = nv.model_from_polygons(polys, n_supports=1)
    buffers = PairBuffers(len(polys))
    boxes = body_aabbs(world_vertices(body_q, start, vert_local), start, 1e-3)
    candidate_pairs(boxes, dynamic, buffers)
    assert buffers.axis == 1
    assert pairs_of(buffers) == nv.aabb_pairs_bruteforce(boxes.tolist(), dynamic)
    assert len(pairs_of(buffers)) == 30


# ----------------------------------------------------------------------------------------------
# detect_contacts end to end
# ----------------------------------------------------------------------------------------------


def naive_contacts(polys_world, dynamic, alert):
    """Every pair's reference manifold (brute force over all pairs)."""
    out = {}
    boxes = [
        [p[:, 0].min() - alert, p[:, 1].min() - alert, p[:, 0].max() + alert, p[:, 1].max() + alert]
        for p in polys_world
    ]
    for a, b in nv.aabb_pairs_bruteforce(boxes, dynamic):  # (prefilter only: saves shapely calls)
        if nv.distance(polys_world[a], polys_world[b]) > alert + 1e-9:
            continue
        ref = nv.reference_manifold(polys_world[a], polys_world[b], alert, a=a, b=b)
        if ref["points"]:
            out[(a, b)] = ref
    return out


def split_world(vert_world, start):
    return [vert_world[start[i] : start[i + 1]] for i in range(len(start) - 1)]


@pytest.mark.parametrize("perturb", [0.0, 2e-4])
def test_wall_contacts_match_reference(perturb):
    rng = np.random.default_rng(11)
    body_q, start, vert_local, dynamic, polys = nv.running_bond_wall()
    if perturb:
        body_q[:-1] += rng.uniform(-perturb, perturb, (len(polys) - 1, 3))
    alert = 1e-3
    buffers = ContactBuffers(start)
    n = detect_contacts(body_q, start, vert_local, dynamic, alert, buffers)
    c = buffers.view()
    assert n == len(c.contact_gap) == buffers.contact_count
    world = split_world(nv.world_vertices_numpy(body_q, start, vert_local), start)
    ref = naive_contacts(world, dynamic, alert)
    got_pairs = sorted({tuple(p) for p in c.contact_body.tolist()})
    assert got_pairs == sorted(ref)
    # sorted by pair, each pair's contacts equal to the reference (which implements the spec)
    assert np.all(np.diff(c.contact_body[:, 0].astype(np.int64) * 1000 + c.contact_body[:, 1]) >= 0)
    for (a, b), r in ref.items():
        m = (c.contact_body[:, 0] == a) & (c.contact_body[:, 1] == b)
        np.testing.assert_allclose(c.contact_point[m], r["points"], atol=1e-12)
        np.testing.assert_allclose(c.contact_gap[m], r["gaps"], atol=1e-12)
        np.testing.assert_allclose(c.contact_normal[m], [r["normal"]] * m.sum(), atol=1e-14)
        if perturb:
            np.testing.assert_array_equal(c.contact_key[m], r["keys"])
    assert len(np.unique(c.contact_key)) == n
    if not perturb:
        # every joint has exactly its two ends, at gap 0 (up to the rounding of centre + local)
        assert np.all(np.abs(c.contact_gap) <= 1e-15)
        # 232 joints within the courses, 15 × 30 between courses, 15 on the ground
        assert len(ref) == 232 + 450 + 15 and n == 2 * len(ref)
        for a, b in ref:  # the two ends of the shared segment of the two rectangles
            lo = np.maximum(polys[a].min(axis=0), polys[b].min(axis=0))
            hi = np.minimum(polys[a].max(axis=0), polys[b].max(axis=0))
            m = (c.contact_body[:, 0] == a) & (c.contact_body[:, 1] == b)
            np.testing.assert_allclose(sorted(c.contact_point[m].tolist()), [lo, hi], atol=1e-15)
        bottom = c.contact_body[:, 1] == len(polys) - 1
        assert bottom.sum() == 30 and np.all(c.contact_normal[bottom] == [0.0, -1.0])


def test_detect_contacts_is_deterministic_and_grows_buffers():
    rng = np.random.default_rng(12)
    body_q, start, vert_local, dynamic, polys = nv.running_bond_wall()
    big = ContactBuffers(start)
    small = ContactBuffers(start, pair_capacity=1, contact_capacity=1)
    for step in range(4):
        q = body_q.copy()
        q[:-1] += rng.uniform(-3e-4, 3e-4, (len(polys) - 1, 3))
        n1 = detect_contacts(q, start, vert_local, dynamic, 1e-3, big)
        n2 = detect_contacts(q, start, vert_local, dynamic, 1e-3, small)
        fresh = ContactBuffers(start)
        n3 = detect_contacts(q, start, vert_local, dynamic, 1e-3, fresh)
        assert n1 == n2 == n3 > 600
        for x, y, z in zip(big.view(), small.view(), fresh.view()):
            np.testing.assert_array_equal(x, y)
            np.testing.assert_array_equal(x, z)
    assert small.contact_capacity >= small.contact_count and small.pairs.pair_capacity >= small.pair_count


def test_detect_contacts_checks_its_inputs():
    body_q, start, vert_local, dynamic, polys = nv.running_bond_wall(rows=2, full_per_row=3)
    buffers = ContactBuffers(start)
    with pytest.raises(ValueError, match="world_vertices: body_q has shape"):
        detect_contacts(body_q[:-1], start, vert_local, dynamic, 1e-3, buffers)
    with pytest.raises(ValueError, match="candidate_pairs"):
        detect_contacts(body_q, start, vert_local, dynamic[:-1], 1e-3, buffers)
    q = body_q.copy()
    q[2, 1] = np.nan
    with pytest.raises(FloatingPointError, match="body 2"):
        detect_contacts(q, start, vert_local, dynamic, 1e-3, buffers)
    with pytest.raises(ValueError, match="alert"):
        detect_contacts(body_q, start, vert_local, dynamic, -1.0, buffers)
    with pytest.raises(ValueError, match="vertices"):
        ContactBuffers(np.array([0, 3, 5], dtype=np.int64))
