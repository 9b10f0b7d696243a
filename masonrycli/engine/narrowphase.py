"""Narrow phase: contact points between two convex polygons (separating axes + edge clipping).

For a candidate pair (a, b) of convex counter-clockwise polygons:

1. **Separating axes.** For each edge i of a, with outward unit normal n_i and start vertex v_i, the
   separation of b along n_i is ``min_{w ∈ b} n_i · (w − v_i)``; ``sep_a`` is the largest over a's
   edges (first edge on ties), ``sep_b`` likewise with the roles swapped. If either exceeds the alert
   distance, the polygons are farther apart than ``alert``: no contact.
2. **Reference face.** The face of larger separation, preferring a's face unless
   ``sep_b > sep_a + tol`` with ``tol = 1e-9 m + 1e-6 · size`` (size = the smaller of the two
   polygons' bounding-box extents). Coincident faces (a joint) then always pick a's face, whatever
   the rounding of the world vertices.
3. **Incident edge.** The edge of the other polygon whose outward normal is most anti-parallel to the
   reference normal n (first edge on ties).
4. **Clipping.** The incident segment is clipped against the two side planes of the reference edge
   (the lines through its end vertices, along n). An end within ``tol`` outside a side plane is kept
   as it is (not clipped): perfectly aligned corners (a column of blocks) then give the same points
   whatever the rounding.
5. **Points.** Each clipped end p with separation ``g = n · (p − v_ref) ≤ alert`` gives a contact:
   point ``p − ½ g n`` (midway between p and its projection on the reference face), normal n
   oriented from a to b, gap g (< 0 = penetration). At most two per pair, ordered along the reference
   edge (from its start vertex to its end vertex). Two ends closer than ``tol`` (corner against
   corner) are one contact: the one at an incident vertex is kept.

Two blocks sharing a joint give exactly the two ends of the overlapping segment with gap 0; a block
on a wide ground gives its two bottom corners; a corner on a face gives one point.

6. **Rounded corners.** A pair with a single contact takes the normal of the two blocks' corners rounded by
   2 cm (:mod:`.rounded`): a corner on a corner's normal no longer turns with a survey's last millimetre; a
   corner on a face keeps step 5's normal bit for bit.

Each contact carries a key naming the touching features (vertex of one body against edge of the other),
the same from one step to the next: see :mod:`.contact_key`.

The work is split in three functions per pair, called by :func:`_collide_pair`: :func:`_choose_faces`
(steps 1–3, with :func:`_max_face_separation`), :func:`_clip_incident` (step 4) and
:func:`_write_pair_contacts` (step 5). numba inlines the four into :func:`_collide_pair`
(``inline="always"``), which stays a kernel of its own (:func:`~._jit.kernel_only`): as four kernels of
their own, each call (arrays and tuples passed through numba's calling convention) cost ~5 ns, 19 µs of
the 126 µs the narrow phase took on a step of the 248-block wall (645 pairs; 107 µs inlined, the same
contacts; benchmarks/JOURNAL.md, "Solver", "Where a wall-248 step goes at the lane sweeps"). Inlining
:func:`_collide_pair` into the loop as well saves 7 µs more but costs 1.5 s of CPU of a first run's
compilation (its code is then optimised again inside each caller of :func:`_narrowphase`); inlining the
four costs none (bench_cold).
"""

from __future__ import annotations

import math

import numpy as np

from ._arrays import check_array, check_vertices
from ._jit import kernel_only, njit
from .contact_key import _end_label, _make_key, check_topology
from .rounded import SCRATCH_ROWS, _round_single, scratch_polygons

__all__ = ["REF_TOL_ABS", "REF_TOL_REL", "collide_polygons", "edge_normals", "narrowphase"]

REF_TOL_ABS = 1e-9
"""Absolute part of the face-choice / clipping / merging tolerance, m."""
REF_TOL_REL = 1e-6
"""Relative part of the tolerance, times the smaller polygon extent of the pair."""


@njit
def _edge_normals(vert_world, body_vert_start, edge_normal, body_size):
    # for each body b, each edge k (vertex k → vertex k+1, wrapping around):
    #     edge_normal[k] = (dy, −dx) / |(dx, dy)|      outward unit normal of a CCW polygon's edge
    #                      (0, 0) for a zero-length edge: the narrow phase ignores it
    #     body_size[b]   = largest side of the bounding box of b's vertices (scale of tolerances)
    # Done once per body and step rather than once per pair: the square roots and divisions were
    # most of the narrow phase's cost.
    for b in range(body_vert_start.shape[0] - 1):
        s = body_vert_start[b]
        n = body_vert_start[b + 1] - s
        xmin = vert_world[s, 0]
        xmax = xmin
        ymin = vert_world[s, 1]
        ymax = ymin
        for i in range(n):
            j = i + 1 if i + 1 < n else 0
            x = vert_world[s + i, 0]
            y = vert_world[s + i, 1]
            dx = vert_world[s + j, 0] - x
            dy = vert_world[s + j, 1] - y
            length = math.sqrt(dx * dx + dy * dy)
            if length > 0.0:
                edge_normal[s + i, 0] = dy / length
                edge_normal[s + i, 1] = 0.0 - dx / length
            else:
                edge_normal[s + i, 0] = 0.0
                edge_normal[s + i, 1] = 0.0
            xmin = min(xmin, x)
            xmax = max(xmax, x)
            ymin = min(ymin, y)
            ymax = max(ymax, y)
        body_size[b] = max(xmax - xmin, ymax - ymin)


def edge_normals(vert_world, body_vert_start, edge_normal=None, body_size=None):
    """Outward unit normal of every polygon edge, and the size of every body.

    Parameters
    ----------
    vert_world : (V, 2) float64
        World vertices [m], CCW per body.
    body_vert_start : (B+1,) int64
        CSR offsets of the vertices.
    edge_normal : (V, 2) float64, optional
        Out: row k is the unit outward normal of the edge from vertex k to the next vertex of the same
        body ((0, 0) for a zero-length edge). Allocated if None.
    body_size : (B,) float64, optional
        Out: largest side of each body's bounding box [m]. Allocated if None.

    Returns
    -------
    (edge_normal, body_size)
    """
    vertex_count, body_count = check_vertices("edge_normals", "vert_world", vert_world, body_vert_start)
    if edge_normal is None:
        edge_normal = np.empty((vertex_count, 2), dtype=np.float64)
    if body_size is None:
        body_size = np.empty(body_count, dtype=np.float64)
    check_array("edge_normals", "edge_normal", edge_normal, (vertex_count, 2), np.float64)
    check_array("edge_normals", "body_size", body_size, (body_count,), np.float64)
    _edge_normals(vert_world, body_vert_start, edge_normal, body_size)
    return edge_normal, body_size


@njit(inline="always")
def _max_face_separation(vert, normal, s1, n1, s2, n2, alert):
    # Largest separation of polygon 2 along the outward edge normals of polygon 1:
    #     for each edge i of 1:  sep_i = min_{w ∈ 2} n_i · (w − v_i)
    #     return (max_i sep_i, argmax_i)          (strict '>' : the first edge wins ties)
    # Stops as soon as an edge separates by more than alert: the pair is then dropped anyway.
    # Returns edge -1 if no separation is a number (NaN coordinates): the caller skips the pair.
    best = -math.inf
    best_edge = -1
    for i in range(n1):
        nx = normal[s1 + i, 0]
        ny = normal[s1 + i, 1]
        if nx == 0.0 and ny == 0.0:
            continue  # degenerate edge: no normal (input checks should have refused it)
        x1 = vert[s1 + i, 0]
        y1 = vert[s1 + i, 1]
        sep = math.inf
        for k in range(n2):
            sep = min(sep, nx * (vert[s2 + k, 0] - x1) + ny * (vert[s2 + k, 1] - y1))  # branch-free
        if sep > best:
            best = sep
            best_edge = i
            if best > alert:
                break
    return best, best_edge


@njit(inline="always")
def _choose_faces(vert, normal, size_a, size_b, sa, na, sb, nb, alert):
    # Steps 1–3: separating axes, reference face, incident edge.
    #   sep_a, e_a = max face separation of b along a's normals   (> alert → no contact)
    #   sep_b, e_b = same with the roles swapped                   (> alert → no contact)
    #   reference R = b if sep_b > sep_a + tol else a ; incident I = the other polygon
    #   reference edge e (vertex e → e2) with outward normal n
    #   incident edge k (vertex k → k2) = argmin over I's edges of n · n_k
    # Returns (e, e2, k, k2, ref_is_b, rs, is_, tol) with rs / is_ the first vertex rows of R / I;
    # e = -1 when the pair has no contact.
    sep_a, e_a = _max_face_separation(vert, normal, sa, na, sb, nb, alert)
    if not (sep_a <= alert) or e_a < 0:
        return -1, -1, -1, -1, False, sa, sb, 0.0
    sep_b, e_b = _max_face_separation(vert, normal, sb, nb, sa, na, alert)
    if not (sep_b <= alert) or e_b < 0:
        return -1, -1, -1, -1, False, sa, sb, 0.0
    tol = REF_TOL_ABS + REF_TOL_REL * min(size_a, size_b)

    # Reference face: a's unless b's separates clearly more (deterministic on coincident faces).
    ref_is_b = sep_b > sep_a + tol
    if ref_is_b:
        rs, rn, e, is_, in_ = sb, nb, e_b, sa, na
    else:
        rs, rn, e, is_, in_ = sa, na, e_a, sb, nb
    e2 = e + 1 if e + 1 < rn else 0
    nx = normal[rs + e, 0]
    ny = normal[rs + e, 1]

    # Incident edge: outward normal most anti-parallel to n, i.e. smallest n · n_k (first on ties).
    k = 0
    best = math.inf
    for i in range(in_):
        mx = normal[is_ + i, 0]
        my = normal[is_ + i, 1]
        if mx == 0.0 and my == 0.0:
            continue
        d = nx * mx + ny * my
        if d < best:
            best = d
            k = i
    k2 = k + 1 if k + 1 < in_ else 0
    return e, e2, k, k2, ref_is_b, rs, is_, tol


@njit(inline="always")
def _clip_incident(vert, rs, e, e2, is_, k, k2, nx, ny, tol):
    # Step 4: clip the incident segment w1 = I[k] → w2 = I[k2] to the side planes of R's edge e.
    #   frame of the edge v1 = R[e] → v2 = R[e2]: u = (−n_y, n_x) (n is u turned by −90°), L = u·(v2 − v1);
    #   u is the CCW edge direction, the opposite of the contact tangent t = (n_y, −n_x) of .contact
    #   (t, g) = (u·(p − v1), n·(p − v1)) for each end p
    #   both ends beyond one side plane (by more than tol) → no contact
    #   an end beyond t = 0 or t = L (by more than tol) moves onto that plane, g interpolated;
    #   it is placed at v_side + g n rather than interpolated in x, y: on a joint (g = 0) it is then
    #   exactly the reference vertex. Ends within tol outside are kept as they are.
    # Returns (inside, L, end1, end2) with end = (p_x, p_y, g, t, t0, side): t0 is the incident
    # vertex's t before clipping, side the plane it was clipped at (0: through v1, 1: through v2,
    # -1: not clipped).
    v1x = vert[rs + e, 0]
    v1y = vert[rs + e, 1]
    v2x = vert[rs + e2, 0]
    v2y = vert[rs + e2, 1]
    ux = 0.0 - ny
    uy = nx
    length = ux * (v2x - v1x) + uy * (v2y - v1y)

    w1x = vert[is_ + k, 0]
    w1y = vert[is_ + k, 1]
    w2x = vert[is_ + k2, 0]
    w2y = vert[is_ + k2, 1]
    t1 = ux * (w1x - v1x) + uy * (w1y - v1y)
    t2 = ux * (w2x - v1x) + uy * (w2y - v1y)
    g1 = nx * (w1x - v1x) + ny * (w1y - v1y)
    g2 = nx * (w2x - v1x) + ny * (w2y - v1y)
    t01 = t1
    t02 = t2
    side1 = -1
    side2 = -1
    outside = (0.0, 0.0, 0.0, 0.0, 0.0, -1)

    # Side plane through v1 (t ≥ 0).
    if t1 < -tol and t2 < -tol:
        return False, length, outside, outside
    if t1 < -tol:
        lam = min(t1 / (t1 - t2), 1.0)  # ≤ 1: never beyond the other end (kept within tol)
        g1 = g1 + lam * (g2 - g1)
        t1 = 0.0
        side1 = 0
    elif t2 < -tol:
        lam = max(t1 / (t1 - t2), 0.0)
        g2 = g1 + lam * (g2 - g1)
        t2 = 0.0
        side2 = 0
    # Side plane through v2 (t ≤ L).
    d1 = length - t1
    d2 = length - t2
    if d1 < -tol and d2 < -tol:
        return False, length, outside, outside
    if d1 < -tol:
        lam = min(d1 / (d1 - d2), 1.0)
        g1 = g1 + lam * (g2 - g1)
        t1 = length
        side1 = 1
    elif d2 < -tol:
        lam = max(d1 / (d1 - d2), 0.0)
        g2 = g1 + lam * (g2 - g1)
        t2 = length
        side2 = 1

    if side1 < 0:
        p1x, p1y = w1x, w1y
    else:
        p1x = (v1x if side1 == 0 else v2x) + g1 * nx
        p1y = (v1y if side1 == 0 else v2y) + g1 * ny
    if side2 < 0:
        p2x, p2y = w2x, w2y
    else:
        p2x = (v1x if side2 == 0 else v2x) + g2 * nx
        p2y = (v1y if side2 == 0 else v2y) + g2 * ny
    return True, length, (p1x, p1y, g1, t1, t01, side1), (p2x, p2y, g2, t2, t02, side2)


@njit(inline="always")
def _write_pair_contacts(
    a, b, ref_is_b, e, e2, k, k2, nx, ny, length, tol, alert, end1, end2, c,
    contact_body, contact_point, contact_normal, contact_gap, contact_key,
):  # fmt: skip
    # Step 5: the clipped ends (see _clip_incident) → contacts of the pair, written from row c on.
    #   each end with g ≤ alert is a contact; two kept ends closer than tol are one (keep the end at an
    #   incident vertex)
    #   features → key (contact_key._end_label; snap = max(alert, tol) for aligned corners)
    #   rows ordered by t along the reference edge; point p − g n / 2, normal ±n from a to b, gap g
    # Rows beyond the capacity are counted, not written. Returns the next free row.
    p1x, p1y, g1, t1, t01, side1 = end1
    p2x, p2y, g2, t2, t02, side2 = end2
    keep1 = g1 <= alert
    keep2 = g2 <= alert
    if keep1 and keep2:
        ddx = p2x - p1x
        ddy = p2y - p1y
        if ddx * ddx + ddy * ddy <= tol * tol:
            # One physical contact (corner against corner): keep the end at an incident vertex.
            if side1 >= 0 and side2 < 0:
                keep1 = False
            else:
                keep2 = False

    # Features → keys. snap: corners closer than this along the edge count as aligned.
    snap = max(alert, tol)
    own1, vtx1, edg1 = _end_label(side1, t01, k, e, e2, k, length, snap, ref_is_b)
    own2, vtx2, edg2 = _end_label(side2, t02, k2, e, e2, k, length, snap, ref_is_b)
    if keep1 and keep2 and own1 == own2 and vtx1 == vtx2 and edg1 == edg2:
        # Both ends near the same aligned corner (a very short overlap): the raw labels differ.
        own1, vtx1, edg1 = _end_label(side1, t01, k, e, e2, k, length, -1.0, ref_is_b)
        own2, vtx2, edg2 = _end_label(side2, t02, k2, e, e2, k, length, -1.0, ref_is_b)

    # Order along the reference edge (t increasing), so the order does not depend on the direction
    # in which the incident edge runs.
    swap = t2 < t1
    out_normal_x = 0.0 - nx if ref_is_b else nx  # from a to b
    out_normal_y = 0.0 - ny if ref_is_b else ny
    capacity = contact_gap.shape[0]
    for m in range(2):
        first = (m == 0) != swap
        if first:
            if not keep1:
                continue
            px, py, g, own, vtx, edg = p1x, p1y, g1, own1, vtx1, edg1
        else:
            if not keep2:
                continue
            px, py, g, own, vtx, edg = p2x, p2y, g2, own2, vtx2, edg2
        if c < capacity:
            contact_body[c, 0] = a
            contact_body[c, 1] = b
            contact_point[c, 0] = px - 0.5 * g * nx
            contact_point[c, 1] = py - 0.5 * g * ny
            contact_normal[c, 0] = out_normal_x
            contact_normal[c, 1] = out_normal_y
            contact_gap[c] = g
            contact_key[c] = _make_key(a, b, own, vtx, edg)
        c += 1
    return c


@kernel_only
def _collide_pair(
    vert, normal, size_a, size_b, sa, na, sb, nb, a, b, alert, c,
    contact_body, contact_point, contact_normal, contact_gap, contact_key,
):  # fmt: skip
    # Contacts of the pair (a, b) written from row c on; returns the next free row.
    #   faces    = _choose_faces(...)          reference edge e of R, incident edge k of I (or none)
    #   clipped  = _clip_incident(...)         the incident segment within the reference side planes
    #   c        = _write_pair_contacts(...)   0..2 contacts with their keys
    e, e2, k, k2, ref_is_b, rs, is_, tol = _choose_faces(vert, normal, size_a, size_b, sa, na, sb, nb, alert)
    if e < 0:
        return c
    nx = normal[rs + e, 0]
    ny = normal[rs + e, 1]
    inside, length, end1, end2 = _clip_incident(vert, rs, e, e2, is_, k, k2, nx, ny, tol)
    if not inside:
        return c
    return _write_pair_contacts(
        a, b, ref_is_b, e, e2, k, k2, nx, ny, length, tol, alert, end1, end2, c,
        contact_body, contact_point, contact_normal, contact_gap, contact_key,
    )  # fmt: skip


@njit
def _narrowphase(
    vert_world, edge_normal, body_size, body_vert_start, pair_body, pair_count, alert,
    contact_body, contact_point, contact_normal, contact_gap, contact_key,
):  # fmt: skip
    # for each candidate pair p (in the given order): append its 0..2 contacts (see _collide_pair);
    # one contact: its normal is the rounded corners' (step 6, .rounded._round_single).
    # Contacts beyond the capacity are counted, not written. Returns the number of contacts.
    c = np.int64(0)  # not 0: numba would compile _collide_pair for the literal 0 as well (broadphase.py)
    scratch = np.empty((4, SCRATCH_ROWS, 2), np.float64)
    for p in range(pair_count):
        a = pair_body[p, 0]
        b = pair_body[p, 1]
        sa = body_vert_start[a]
        sb = body_vert_start[b]
        na = body_vert_start[a + 1] - sa
        nb = body_vert_start[b + 1] - sb
        after = _collide_pair(
            vert_world, edge_normal, body_size[a], body_size[b], sa, na, sb, nb, a, b, alert, c,
            contact_body, contact_point, contact_normal, contact_gap, contact_key,
        )  # fmt: skip
        if after == c + 1 and c < contact_gap.shape[0]:
            _round_single(vert_world, edge_normal, sa, na, sb, nb, c, contact_normal, scratch)
        c = after
    return c


def narrowphase(
    vert_world, edge_normal, body_size, body_vert_start, pair_body, pair_count, alert,
    contact_body, contact_point, contact_normal, contact_gap, contact_key,
) -> int:  # fmt: skip
    """Contact points of the candidate pairs, written into preallocated arrays.

    Parameters
    ----------
    vert_world : (V, 2) float64
        World vertices [m], CCW per body (``broadphase.world_vertices``).
    edge_normal : (V, 2) float64
        Outward unit edge normals (:func:`edge_normals`).
    body_size : (B,) float64
        Largest bounding-box side of each body [m] (:func:`edge_normals`).
    body_vert_start : (B+1,) int64
        CSR offsets of the vertices (3..256 per body, see :func:`check_topology`).
    pair_body : (P_cap, 2) int32
        Candidate pairs (a, b), a < b; rows ``[:pair_count]`` are used, in that order.
    pair_count : int
        Number of pairs.
    alert : float
        Alert distance [m]: contacts with gap ≤ alert are kept.
    contact_body : (C_cap, 2) int32
        Out: bodies a, b of each contact (normal from a to b).
    contact_point : (C_cap, 2) float64
        Out: contact point, world [m].
    contact_normal : (C_cap, 2) float64
        Out: unit normal from a to b (tangent t = (n_y, −n_x), see :mod:`.contact`).
    contact_gap : (C_cap,) float64
        Out: gap [m], < 0 = penetration.
    contact_key : (C_cap,) int64
        Out: stable contact key (layout in the module docstring).

    Returns
    -------
    contact_count : int
        Rows ``[:contact_count]`` of the outputs are written; contacts of one pair are consecutive,
        pairs in input order. At most 2 per pair: the capacity C_cap must be ≥ 2·pair_count.
    """
    where = "narrowphase"
    vertex_count, body_count = check_vertices(where, "vert_world", vert_world, body_vert_start)
    check_array(where, "edge_normal", edge_normal, (vertex_count, 2), np.float64)
    check_array(where, "body_size", body_size, (body_count,), np.float64)
    check_array(where, "pair_body", pair_body, (None, 2), np.int32)
    if not 0 <= pair_count <= pair_body.shape[0]:
        raise ValueError(f"{where}: pair_count {pair_count} outside 0..{pair_body.shape[0]} (rows of pair_body)")
    capacity = contact_gap.shape[0]
    for name, array, shape, dtype in (
        ("contact_body", contact_body, (capacity, 2), np.int32),
        ("contact_point", contact_point, (capacity, 2), np.float64),
        ("contact_normal", contact_normal, (capacity, 2), np.float64),
        ("contact_gap", contact_gap, (capacity,), np.float64),
        ("contact_key", contact_key, (capacity,), np.int64),
    ):
        check_array(where, name, array, shape, dtype)
    if capacity < 2 * pair_count:
        raise ValueError(f"{where}: capacity {capacity} < 2 x {pair_count} pairs")
    return _narrowphase(
        vert_world, edge_normal, body_size, body_vert_start, pair_body, int(pair_count), float(alert),
        contact_body, contact_point, contact_normal, contact_gap, contact_key,
    )  # fmt: skip


def collide_polygons(verts_a, verts_b, alert, a: int = 0, b: int = 1):
    """Contacts between two convex CCW polygons given by their world vertices (tests, tools).

    Allocates; the time loop uses :func:`masonrycli.engine.collision.detect_contacts` instead.

    Parameters
    ----------
    verts_a, verts_b : (n, 2) float64
        World vertices of body a and body b [m], CCW, without repeating the first vertex.
    alert : float
        Alert distance [m].
    a, b : int
        Body indices written into the keys and ``contact_body``.

    Returns
    -------
    (contact_point (c, 2), contact_normal (c, 2), contact_gap (c,), contact_key (c,)) with c ≤ 2.
    """
    verts_a = np.ascontiguousarray(verts_a, dtype=np.float64)
    verts_b = np.ascontiguousarray(verts_b, dtype=np.float64)
    vert = np.concatenate([verts_a, verts_b])
    body_vert_start = np.array([0, len(verts_a), len(vert)], dtype=np.int64)
    check_topology(body_vert_start)
    normal, size = edge_normals(vert, body_vert_start)
    contact_body = np.zeros((2, 2), dtype=np.int32)
    contact_point = np.zeros((2, 2))
    contact_normal = np.zeros((2, 2))
    contact_gap = np.zeros(2)
    contact_key = np.zeros(2, dtype=np.int64)
    c = _collide_pair(
        vert, normal, size[0], size[1], 0, len(verts_a), len(verts_a), len(verts_b), a, b, float(alert), 0,
        contact_body, contact_point, contact_normal, contact_gap, contact_key,
    )  # fmt: skip
    if c == 1:
        _round_single(vert, normal, 0, len(verts_a), len(verts_a), len(verts_b), 0, contact_normal, scratch_polygons())
    return contact_point[:c].copy(), contact_normal[:c].copy(), contact_gap[:c].copy(), contact_key[:c].copy()
