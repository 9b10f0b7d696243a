"""Independent, slow reference for contact detection (tests only).

Written plainly in Python (lists, loops) and with shapely for the geometric operations (distance,
clipping by intersection), never calling the engine. It restates the *specification* of the narrow
phase (``masonrycli/engine/narrowphase.py`` docstring):

- separation of Q along the outward normals of P's edges; the reference face is a's unless b's
  separation is larger by more than ``tol = 1e-9 + 1e-6 · min extent``;
- incident edge = the other polygon's edge whose normal is most anti-parallel;
- the incident segment is clipped by the slab of the reference edge (here: shapely intersection of the
  segment with a long rectangle built on the reference edge);
- ends with separation ≤ alert give contact points midway to the reference face.

Also: brute-force O(N²) bounding-box pairs, world vertices with numpy, random convex polygons, and a
running-bond wall builder.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
import shapely.ops
from shapely.geometry import LineString, Point, Polygon

REF_TOL_ABS = 1e-9
REF_TOL_REL = 1e-6


# ----------------------------------------------------------------------------------------------
# Polygons
# ----------------------------------------------------------------------------------------------


def as_list(verts):
    return [(float(x), float(y)) for x, y in verts]


def polygon(verts) -> Polygon:
    return Polygon(as_list(verts))


def random_convex_polygon(rng, n_max=8, radius=0.5, aspect=1.0):
    """CCW convex polygon (n, 2) around the origin, 3..n_max vertices, size ~2·radius."""
    while True:
        n = int(rng.integers(3, n_max + 1))
        ang = np.sort(rng.uniform(0.0, 2 * math.pi, n))
        r = radius * rng.uniform(0.5, 1.0, n)
        pts = np.column_stack([aspect * r * np.cos(ang), r * np.sin(ang)])
        hull = shapely.convex_hull(shapely.MultiPoint([tuple(p) for p in pts]))
        if hull.geom_type != "Polygon" or hull.area < 0.05 * radius * radius * aspect:
            continue
        hull = shapely.geometry.polygon.orient(hull, 1.0)
        coords = np.asarray(hull.exterior.coords)[:-1]
        edges = np.roll(coords, -1, axis=0) - coords
        if np.min(np.hypot(edges[:, 0], edges[:, 1])) < 0.02 * radius:
            continue  # keep edges of reasonable length (well-conditioned normals)
        return coords - coords.mean(axis=0)


def rotate(verts, angle, centre=(0.0, 0.0)):
    c, s = math.cos(angle), math.sin(angle)
    out = []
    for x, y in verts:
        dx, dy = x - centre[0], y - centre[1]
        out.append((centre[0] + c * dx - s * dy, centre[1] + s * dx + c * dy))
    return np.array(out)


def rect(x0, y0, x1, y1):
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)


def extent(verts):
    xs = [p[0] for p in as_list(verts)]
    ys = [p[1] for p in as_list(verts)]
    return max(max(xs) - min(xs), max(ys) - min(ys))


def tolerance(P, Q):
    return REF_TOL_ABS + REF_TOL_REL * min(extent(P), extent(Q))


# ----------------------------------------------------------------------------------------------
# Separating axes, brute force
# ----------------------------------------------------------------------------------------------


def edge(P, i):
    P = as_list(P)
    return P[i], P[(i + 1) % len(P)]


def outward_normal(P, i):
    (x1, y1), (x2, y2) = edge(P, i)
    length = math.hypot(x2 - x1, y2 - y1)
    return ((y2 - y1) / length, -(x2 - x1) / length)


def face_separations(P, Q):
    """Separation of Q along each outward edge normal of P: list over P's edges."""
    seps = []
    for i in range(len(P)):
        n = outward_normal(P, i)
        v = edge(P, i)[0]
        seps.append(min(n[0] * (w[0] - v[0]) + n[1] * (w[1] - v[1]) for w in as_list(Q)))
    return seps


def max_separation(P, Q):
    """(largest separation, first edge reaching it)."""
    seps = face_separations(P, Q)
    best = max(seps)
    return best, seps.index(best)


def reference_choice(A, B):
    """(ref_is_b, ref_edge, sep_a, sep_b, tol, ambiguous) per the specification.

    ``ambiguous``: b's separation exceeds a's by a positive amount within the tolerance (or sits on the
    threshold): the specification then picks a's face although b's separates more, and results that
    depend on the choice (gap = distance, a/b symmetry) are not expected to hold exactly.
    """
    sep_a, ea = max_separation(A, B)
    sep_b, eb = max_separation(B, A)
    tol = tolerance(A, B)
    ref_is_b = sep_b > sep_a + tol
    diff = sep_b - sep_a
    ambiguous = (1e-12 < diff <= tol + 1e-12) or abs(diff - tol) < 1e-12
    return ref_is_b, (eb if ref_is_b else ea), sep_a, sep_b, tol, ambiguous


def incident_edge(I, n):
    best, k = math.inf, 0
    for i in range(len(I)):
        ni = outward_normal(I, i)
        d = n[0] * ni[0] + n[1] * ni[1]
        if d < best:
            best, k = d, i
    return k


# ----------------------------------------------------------------------------------------------
# Reference manifold
# ----------------------------------------------------------------------------------------------


def reference_manifold(A, B, alert, a=0, b=1):
    """Contacts of the pair per the specification, or [] — clipping done by shapely.

    Returns a dict with ``points`` (list of (x, y)), ``gaps``, ``keys``, ``normal`` (from a to b),
    ``ref_is_b``, ``ref_edge``, ``incident_edge``, ``sep`` (separation of the chosen face),
    ``slab_margin`` (how far the incident vertices are from the side planes, min over both; small
    values mean a clipping decision at the tolerance), ``ambiguous`` (see reference_choice) and
    ``at_threshold`` (sep_b − sep_a is within rounding of the face-choice threshold).
    """
    A, B = as_list(A), as_list(B)
    ref_is_b, e, sep_a, sep_b, tol, ambiguous = reference_choice(A, B)
    out = dict(
        points=[],
        gaps=[],
        keys=[],
        normal=None,
        ref_is_b=ref_is_b,
        ref_edge=e,
        incident_edge=None,
        sep=max(sep_a, sep_b),
        ambiguous=ambiguous,
        slab_margin=math.inf,
        sep_a=sep_a,
        sep_b=sep_b,
        tol=tol,
        at_threshold=abs(sep_b - sep_a - tol) <= 1e-12,
    )
    if sep_a > alert or sep_b > alert:
        return out
    R, I = (B, A) if ref_is_b else (A, B)
    n = outward_normal(R, e)
    v1, v2 = edge(R, e)
    L = math.hypot(v2[0] - v1[0], v2[1] - v1[1])
    u = ((v2[0] - v1[0]) / L, (v2[1] - v1[1]) / L)
    k = incident_edge(I, n)
    w1, w2 = edge(I, k)
    out["incident_edge"] = k
    out["normal"] = (-n[0], -n[1]) if ref_is_b else n
    out["sep"] = sep_b if ref_is_b else sep_a

    def t_of(p):
        return u[0] * (p[0] - v1[0]) + u[1] * (p[1] - v1[1])

    out["slab_margin"] = min(min(abs(t_of(w)), abs(L - t_of(w))) for w in (w1, w2))

    big = 10.0 * (extent(A) + extent(B) + abs(out["sep"]) + alert)
    slab = Polygon(
        [
            (v1[0] - big * n[0], v1[1] - big * n[1]),
            (v2[0] - big * n[0], v2[1] - big * n[1]),
            (v2[0] + big * n[0], v2[1] + big * n[1]),
            (v1[0] + big * n[0], v1[1] + big * n[1]),
        ]
    )
    clipped = LineString([w1, w2]).intersection(slab)
    if clipped.is_empty:
        return out
    ends = list(clipped.coords) if clipped.geom_type in ("LineString", "Point") else []
    if clipped.geom_type == "LineString":
        ends = [ends[0], ends[-1]]
    snap = max(alert, tol)
    nI, nR = len(I), len(R)
    ivtx = {0: k, 1: (k + 1) % nI}

    def label(p, use_snap=True):
        """(owner_is_b, vertex, edge, at_incident_vertex) of a clipped end, per the specification."""
        s_ = snap if use_snap else -1.0
        for j, w in enumerate((w1, w2)):
            if math.dist(p, w) <= 1e-12:  # an incident vertex that survived clipping
                tw = t_of(w)
                side = 0 if tw <= L - tw else 1
                aligned = (tw <= s_) if side == 0 else (tw >= L - s_)
                rv = (e + side) % nR
                if aligned:
                    return (False, ivtx[j], e, True) if ref_is_b else (False, rv, k, True)
                return (not ref_is_b), ivtx[j], e, True
        side = 0 if abs(t_of(p)) < abs(L - t_of(p)) else 1  # cut at a side plane
        rv = (e + side) % nR
        cut = [j for j, w in enumerate((w1, w2)) if (t_of(w) < 0 if side == 0 else t_of(w) > L)]
        j = cut[0]
        tw = t_of((w1, w2)[j])
        aligned = (tw >= -s_) if side == 0 else (tw <= L + s_)
        if aligned:
            return (False, ivtx[j], e, False) if ref_is_b else (False, rv, k, False)
        return ref_is_b, rv, k, False

    cand = []
    for p in ends:
        g = n[0] * (p[0] - v1[0]) + n[1] * (p[1] - v1[1])
        if g <= alert:
            cand.append([t_of(p), p, g, label(p), label(p, use_snap=False)])
    cand.sort(key=lambda c: c[0])
    if len(cand) == 2 and math.dist(cand[0][1], cand[1][1]) <= tol:
        # one contact: keep the end at an incident vertex (else the first)
        cand = [cand[1]] if (cand[1][3][3] and not cand[0][3][3]) else [cand[0]]
    if len(cand) == 2 and cand[0][3][:3] == cand[1][3][:3]:
        for c in cand:
            c[3] = c[4]  # both ends labelled with the same aligned corner: raw labels
    for c in cand:
        owner_is_b, vertex, edg, _ = c[3]
        c[3] = (a << 40) | (b << 17) | (int(owner_is_b) << 16) | (vertex << 8) | edg
    for _, p, g, key, _ in cand:
        out["points"].append((p[0] - 0.5 * g * n[0], p[1] - 0.5 * g * n[1]))
        out["gaps"].append(g)
        out["keys"].append(key)
    return out


def vertex_face_distance(P, Q, margin=1e-9):
    """Smallest distance from a vertex of P to the interior of an edge of Q (projection strictly
    inside the edge), or inf."""
    best = math.inf
    for p in as_list(P):
        for i in range(len(Q)):
            (x1, y1), (x2, y2) = edge(Q, i)
            dx, dy = x2 - x1, y2 - y1
            lam = ((p[0] - x1) * dx + (p[1] - y1) * dy) / (dx * dx + dy * dy)
            if margin < lam < 1 - margin:
                best = min(best, math.hypot(p[0] - x1 - lam * dx, p[1] - y1 - lam * dy))
    return best


def closest_is_vertex_face(A, B, d, tol=1e-12):
    """True if the distance d between A and B is reached between a vertex and an edge interior."""
    return min(vertex_face_distance(A, B), vertex_face_distance(B, A)) <= d + tol


def distance(A, B):
    return polygon(A).distance(polygon(B))


def rounded_normal(A, B, radius):
    """Unit direction from A to B between the closest points of A and B eroded by ``radius`` (the rounded
    corners of engine/rounded.py), or None when the eroded polygons touch or one vanishes. shapely does the
    work: a mitred inward buffer of a convex polygon moves each edge inwards by ``radius``."""
    ea = polygon(A).buffer(-radius, join_style="mitre")
    eb = polygon(B).buffer(-radius, join_style="mitre")
    if ea.is_empty or eb.is_empty or ea.area <= 0.0 or eb.area <= 0.0 or ea.distance(eb) <= 0.0:
        return None
    p, q = shapely.ops.nearest_points(ea, eb)
    v = np.array([q.x - p.x, q.y - p.y])
    return v / np.hypot(*v)


def point_distance(P, p):
    return polygon(P).distance(Point(p))


# ----------------------------------------------------------------------------------------------
# Broad phase, brute force
# ----------------------------------------------------------------------------------------------


def world_vertices_numpy(body_q, body_vert_start, vert_local):
    body_of_vertex = np.repeat(np.arange(len(body_q)), np.diff(body_vert_start))
    q = body_q[body_of_vertex]
    c, s = np.cos(q[:, 2]), np.sin(q[:, 2])
    x = q[:, 0] + c * vert_local[:, 0] - s * vert_local[:, 1]
    y = q[:, 1] + s * vert_local[:, 0] + c * vert_local[:, 1]
    return np.column_stack([x, y])


def aabbs_numpy(vert_world, body_vert_start, alert):
    boxes = []
    for b in range(len(body_vert_start) - 1):
        v = vert_world[body_vert_start[b] : body_vert_start[b + 1]]
        boxes.append(
            [v[:, 0].min() - alert / 2, v[:, 1].min() - alert / 2, v[:, 0].max() + alert / 2, v[:, 1].max() + alert / 2]
        )
    return np.array(boxes).reshape(-1, 4)


def aabb_pairs_bruteforce(boxes, body_dynamic):
    """All (i, j), i < j, whose closed boxes overlap and not both supports — O(N²), sorted."""
    pairs = []
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            if not (body_dynamic[i] or body_dynamic[j]):
                continue
            if (
                boxes[i][0] <= boxes[j][2]
                and boxes[j][0] <= boxes[i][2]
                and boxes[i][1] <= boxes[j][3]
                and boxes[j][1] <= boxes[i][3]
            ):
                pairs.append((i, j))
    return pairs


# ----------------------------------------------------------------------------------------------
# Models
# ----------------------------------------------------------------------------------------------


def course_edges(row: int, full_per_row: int, w: float) -> list[float]:
    """x of the vertical joints of course ``row`` of a straight-ended running bond: even courses
    ``full_per_row`` full blocks, odd ones a half block at each end."""
    if row % 2 == 0:
        return [i * w for i in range(full_per_row + 1)]
    return [0.0] + [w / 2 + i * w for i in range(full_per_row)] + [full_per_row * w]


def running_bond_wall(rows=16, full_per_row=15, block=(0.3, 0.2), ground_margin=0.5):
    """A running-bond wall on a ground support, as flat model arrays.

    Even rows: ``full_per_row`` full blocks; odd rows: a half block, ``full_per_row - 1`` full blocks,
    a half block (16 rows of 15 / 16 blocks = 248 blocks). The ground (last body, a support) is a
    rectangle under the whole wall, its top at y = 0.

    Returns body_q (B, 3), body_vert_start (B+1,), vert_local (V, 2), body_dynamic (B,), polygons.
    """
    w, h = block
    polys = []
    for r in range(rows):
        y0 = r * h
        xs = course_edges(r, full_per_row, w)
        for x0, x1 in zip(xs[:-1], xs[1:]):
            polys.append(rect(x0, y0, x1, y0 + h))
    length = full_per_row * w
    polys.append(rect(-ground_margin, -0.5, length + ground_margin, 0.0))
    return model_from_polygons(polys, n_supports=1) + (polys,)


def model_from_polygons(polys, n_supports=0):
    """Flat arrays (body_q, body_vert_start, vert_local, body_dynamic) with θ = 0 and the body
    reference point at the vertex mean (any interior point works for the collision code)."""
    centres = np.array([p.mean(axis=0) for p in polys])
    body_q = np.column_stack([centres, np.zeros(len(polys))])
    body_vert_start = np.zeros(len(polys) + 1, dtype=np.int64)
    body_vert_start[1:] = np.cumsum([len(p) for p in polys])
    vert_local = np.concatenate([p - c for p, c in zip(polys, centres)])
    body_dynamic = np.ones(len(polys), dtype=bool)
    if n_supports:
        body_dynamic[-n_supports:] = False
    return body_q, body_vert_start, vert_local, body_dynamic
