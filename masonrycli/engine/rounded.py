"""A corner on a corner: the normal of the two blocks' rounded corners.

Where one block's corner touches another's (a voussoir's extrados corner on the corner of the spandrel block
beside it, a rocking block's corner on the aligned corner of the course below), the separating-axis detection
(:mod:`.narrowphase`) gives the normal of whichever edge separates the two polygons most. At a corner on a
corner every line through the point between the two blocks separates them, and which edge wins turns on the
last digit: a survey's 1 mm rounding of the 346-block aqueduct turned ten such normals by 47–87°, and the
aqueduct tilted to 0.090 g stood exact and collapsed rounded (t = 1.20 s).

* **Normal.** Real arrises are never sharp. As in UDEC's corner rounding (each corner an arc of radius r; a
  vertex-to-vertex contact's normal along the line joining the two arcs' centres), a block is here its polygon
  eroded by r = :data:`CORNER_RADIUS` (each edge moved inwards by r) with a disc of radius r swept over it, and
  a pair's single contact takes the direction between the closest points of the two eroded polygons. A corner
  on a face, away from the face's ends, gives an eroded vertex against an eroded edge: that face's normal, and
  the detected one is kept bit for bit (a normal within ~1e-6 rad of it). A corner on a corner gives eroded
  vertex against eroded vertex: the line between them, which a millimetre of rounding turns by ~1 mm / r.
  Limit analysis (``masonrycli.limit.corners``) takes its normals from this same kernel
  (:func:`rounded_normal`).
* **Point and gap stay the detected ones.** The contact still sits at the sharp corner, with the sharp
  polygons' gap (≤ the alert distance): only the direction of the push and of the velocity it constrains
  change. The rounded shapes' own gap would let two sharp corners overlap by up to (√2 − 1) r each before
  touching, and their contact point would move a rocking block's pivot r inwards from its corner.
* **Friction: μ, as on every contact (DESIGN §2).** Limit analysis gives a corner on a corner no friction: its
  LP's associative sliding would otherwise make the corner dilate along a cone whose axis was the survey's last
  digit. In dynamics the Coulomb law stays: with the rounded normal the cone's axis no longer depends on that
  digit, a rounded arris on a rounded arris grips as any other stone contact does (UDEC keeps the joint's
  friction on its rounded corners), and a frictionless corner would let a voussoir's corner slip past a
  spandrel's for free, a weakness the stones do not have (and the engine has one μ for all contacts: a per-contact
  μ would touch every solver). Measured with μ (``limit.verify.run_check``, NLGS at 1e-6, 2 s): tilted to
  0.090 g the exact aqueduct and the ones rounded to 1 mm at the origin and at two Lambert-93 offsets all stand
  (0.017–0.021 mm; with the sharp normals the exact one stood, 0.036 mm, the rounded ones collapsed at t = 1.20
  and 0.195 s), at 0.0925 g too; near 0.095 g the verdicts scatter with the last bits, not with the survey
  (docs/limit.md).

The built-in wall and arch at rest have no such contact (their contacts are bit for bit the sharp detection's);
shaken, a wall's rocking end block on the aligned corner below and two blocks of a course touching at their top
corners are corners on corners, turned by ≤ 3° from the sharp normal (the golden histories' shaken walls).

Pseudo-code for a pair (a, b) with a single detected contact (normal n from a to b)::

    A = eroded(a, r), B = eroded(b, r)        # ∩ half-planes n_i · x <= n_i · v_i - r: adjacent shifted edges'
                                              # intersections, or clipped one by one where an edge vanishes
    A or B empty, or A and B not apart        -> keep n
    (p, q) = closest points of A and B        # every vertex of one against every edge of the other
    m = (q - p) / |q - p|
    m · n < 1 - 1e-12                         -> n := m          (else n is kept bit for bit)

It runs for single-contact pairs only (24 a step on the shaken 248-block wall).
"""

from __future__ import annotations

import math

import numpy as np

from ._jit import njit

__all__ = ["CORNER_RADIUS", "SAME_NORMAL", "rounded_normal"]

CORNER_RADIUS = 0.02
"""m: the rounding radius of a block's corners (a chipped arris of a dressed stone; UDEC's rounding length is
of this order, ~1 % of a block's size). A survey's 1 mm error then turns a corner-to-corner normal by ≲ 3°.
A block thinner than 2 r erodes to nothing and keeps its detected normals."""

SAME_NORMAL = 1e-12
"""1 − cos of the angle (~1.4e-6 rad) within which the rounded normal is the detected face's: kept bit for bit."""

SCRATCH_ROWS = 512
"""Rows of each scratch polygon: an eroded polygon's edges lie on its n edges and their n shifted copies, so
≤ 2 n ≤ 512 vertices for the 256 a body may have (:func:`.contact_key.check_topology`)."""


@njit(inline="always")
def _clip(src, count, nx, ny, c, dst):
    # Sutherland–Hodgman, one half-plane: keep the part of convex ring src[:count] where n·x ≤ c.
    #   s_i = c − n·x_i ;  keep x_i if s_i ≥ 0 ;  an edge whose ends' signs differ adds x_i + s_i/(s_i − s_j)(x_j − x_i)
    # Returns the vertex count written to dst.
    m = 0
    if count == 0:
        return 0
    si = c - (nx * src[0, 0] + ny * src[0, 1])
    for i in range(count):
        j = i + 1 if i + 1 < count else 0
        sj = c - (nx * src[j, 0] + ny * src[j, 1])
        if si >= 0.0:
            dst[m, 0] = src[i, 0]
            dst[m, 1] = src[i, 1]
            m += 1
        if (si >= 0.0) != (sj >= 0.0):
            t = si / (si - sj)
            dst[m, 0] = src[i, 0] + t * (src[j, 0] - src[i, 0])
            dst[m, 1] = src[i, 1] + t * (src[j, 1] - src[i, 1])
            m += 1
        si = sj
    return m


@njit(inline="always")
def _erode_corners(vert, normal, s, n, radius, out):
    # The eroded polygon when no edge vanishes (a block's usual case), without a division per clipped edge:
    #   w_i = v_i − r (n_{i−1} + n_i) / (1 + n_{i−1} · n_i)    on both shifted edges: n_{i−1}·w_i = n_{i−1}·v_i − r
    #   valid if every edge has a normal, no corner is a spike (1 + n_{i−1}·n_i > 1e-9) and every eroded edge
    #   w_i → w_{i+1} runs the way v_i → v_{i+1} does: then w is convex with the polygon's normals, i.e. the
    #   intersection of the shifted half-planes. Returns n, or 0 when not valid (the caller clips instead).
    for i in range(n):
        h = i - 1 if i > 0 else n - 1
        ax = normal[s + h, 0]
        ay = normal[s + h, 1]
        bx = normal[s + i, 0]
        by = normal[s + i, 1]
        den = 1.0 + (ax * bx + ay * by)
        if (bx == 0.0 and by == 0.0) or not den > 1e-9:
            return 0
        k = radius / den
        out[i, 0] = vert[s + i, 0] - k * (ax + bx)
        out[i, 1] = vert[s + i, 1] - k * (ay + by)
    for i in range(n):
        j = i + 1 if i + 1 < n else 0
        run = (out[j, 0] - out[i, 0]) * (vert[s + j, 0] - vert[s + i, 0]) + (out[j, 1] - out[i, 1]) * (
            vert[s + j, 1] - vert[s + i, 1]
        )
        if not run > 0.0:
            return 0
    return n


@njit(inline="always")
def _erode(vert, normal, s, n, radius, out, tmp):
    # The convex CCW polygon vert[s:s+n] with each edge (outward unit normal[s+i]) moved inwards by radius:
    #   _erode_corners when no edge vanishes; else
    #   out = polygon ; for each edge i with a normal: out = clip(out, n_i · x ≤ n_i · v_i − radius)
    # Returns the vertex count in out (0: nothing left; zero-length edges, normal (0, 0), are skipped).
    if _erode_corners(vert, normal, s, n, radius, out) > 0:
        return n
    for i in range(n):
        out[i, 0] = vert[s + i, 0]
        out[i, 1] = vert[s + i, 1]
    count = n
    src = out
    dst = tmp
    for i in range(n):
        nx = normal[s + i, 0]
        ny = normal[s + i, 1]
        if nx == 0.0 and ny == 0.0:
            continue
        c = nx * vert[s + i, 0] + ny * vert[s + i, 1] - radius
        count = _clip(src, count, nx, ny, c, dst)
        src, dst = dst, src  # ping-pong: the clipped ring is the next clip's input
        if count == 0:
            break
    if src is not out:
        for k in range(count):
            out[k, 0] = src[k, 0]
            out[k, 1] = src[k, 1]
    return count


@njit(inline="always")
def _separated(p, np_, q, nq):
    # True when an edge of convex CCW ring p (unnormalised outward normal (e_y, −e_x)) has all of q strictly
    # beyond it: min_w (n · (w − p_i)) > 0.
    for i in range(np_):
        j = i + 1 if i + 1 < np_ else 0
        nx = p[j, 1] - p[i, 1]
        ny = p[i, 0] - p[j, 0]
        low = math.inf
        for k in range(nq):
            low = min(low, nx * (q[k, 0] - p[i, 0]) + ny * (q[k, 1] - p[i, 1]))
        if low > 0.0:
            return True
    return False


@njit(inline="always")
def _closest(p, np_, q, nq):
    # Closest (vertex of p, point on an edge of q): for each vertex w of p (in order), each edge q_k → q_k+1:
    #   t = clamp((w − q_k)·d / d·d, 0, 1), foot = q_k + t d (the end vertex at t = 0, 1);
    #   the first strict minimum of |foot − w|² wins.
    # Returns (distance², w_x, w_y, foot_x, foot_y, inset) with inset = min(t, 1 − t)·|d| (m from the edge's
    # nearer end; 0 at a vertex of q).
    best = math.inf
    wx = wy = fx = fy = inset = 0.0
    for i in range(np_):
        px = p[i, 0]
        py = p[i, 1]
        for k in range(nq):
            k2 = k + 1 if k + 1 < nq else 0
            dx = q[k2, 0] - q[k, 0]
            dy = q[k2, 1] - q[k, 1]
            dd = dx * dx + dy * dy
            along = (px - q[k, 0]) * dx + (py - q[k, 1]) * dy
            # clamped to an end: that vertex itself (q_k + 1·d need not be q_k+1 to the bit), so that a vertex
            # on a vertex gives the same pair whichever polygon comes first: swapping a and b flips m exactly.
            # Most tests end at a vertex: they skip the division (t = along / dd has the sign of along, and
            # t ≥ 1 where along ≥ dd or where the quotient rounds up to 1).
            t = 0.0
            if along > 0.0 and dd > 0.0:
                t = 1.0 if along >= dd else along / dd
            if t <= 0.0:
                t, gx, gy = 0.0, q[k, 0], q[k, 1]
            elif t >= 1.0:
                t, gx, gy = 1.0, q[k2, 0], q[k2, 1]
            else:
                gx, gy = q[k, 0] + t * dx, q[k, 1] + t * dy
            dist2 = (gx - px) * (gx - px) + (gy - py) * (gy - py)
            if dist2 < best:
                best = dist2
                wx, wy, fx, fy = px, py, gx, gy
                inset = min(t, 1.0 - t) * math.sqrt(dd)
    return best, wx, wy, fx, fy, inset


@njit
def _rounded_normal(vert, normal, sa, na, sb, nb, radius, scratch):
    # (found, m_x, m_y, inset) for bodies a = vert[sa:sa+na], b = vert[sb:sb+nb] (module doc's pseudo-code):
    #   A, B = eroded a, b (scratch[0], scratch[2]; scratch[1], [3] are clipping buffers)
    #   found = A, B both polygons and apart ; m = unit direction from A's closest point to B's
    #   inset: the closest point's distance along its edge from the edge's nearer end (0: vertex on vertex)
    ea = scratch[0]
    eb = scratch[2]
    ca = _erode(vert, normal, sa, na, radius, ea, scratch[1])
    cb = _erode(vert, normal, sb, nb, radius, eb, scratch[3])
    if ca < 3 or cb < 3 or not (_separated(ea, ca, eb, cb) or _separated(eb, cb, ea, ca)):
        return False, 0.0, 0.0, 0.0
    d_ab, pax, pay, qbx, qby, inset_b = _closest(ea, ca, eb, cb)  # a's vertices against b's edges
    d_ba, pbx, pby, qax, qay, inset_a = _closest(eb, cb, ea, ca)  # b's vertices against a's edges
    if d_ab <= d_ba:
        vx, vy, inset = qbx - pax, qby - pay, inset_b
    else:
        vx, vy, inset = pbx - qax, pby - qay, inset_a
    length = math.sqrt(vx * vx + vy * vy)
    if not length > 0.0:
        return False, 0.0, 0.0, 0.0
    return True, vx / length, vy / length, inset


@njit(inline="always")
def _round_single(vert, normal, sa, na, sb, nb, row, contact_normal, scratch):
    # The narrow phase's hook for a pair with one contact (row): its normal becomes the rounded corners' one
    # unless that is the detected normal to within SAME_NORMAL (then kept bit for bit).
    found, mx, my, _ = _rounded_normal(vert, normal, sa, na, sb, nb, CORNER_RADIUS, scratch)
    if found and mx * contact_normal[row, 0] + my * contact_normal[row, 1] < 1.0 - SAME_NORMAL:
        contact_normal[row, 0] = mx
        contact_normal[row, 1] = my


def scratch_polygons() -> np.ndarray:
    """The work array of :func:`_rounded_normal`: four polygons of :data:`SCRATCH_ROWS` vertices."""
    return np.empty((4, SCRATCH_ROWS, 2), np.float64)


def rounded_normal(verts_a, verts_b, radius: float = CORNER_RADIUS):
    """(normal, inset) of a single-point contact between the convex CCW polygons ``verts_a`` and ``verts_b``
    (world vertices, m) with their corners rounded by ``radius`` (module doc): the unit direction from a to b
    between the closest points of the two polygons eroded by ``radius``, and how far (m) the closest point lies
    along its eroded edge from that edge's nearer end (0 for a corner on a corner). None when the eroded
    polygons overlap or one vanishes (a block thinner than 2 r). The same kernel as the engine's (numpy in,
    numpy out) for limit analysis and tests."""
    from .narrowphase import edge_normals  # here: narrowphase imports this module's kernels

    a = np.ascontiguousarray(verts_a, dtype=np.float64)
    b = np.ascontiguousarray(verts_b, dtype=np.float64)
    vert = np.concatenate([a, b])
    start = np.array([0, len(a), len(vert)], dtype=np.int64)
    normal, _ = edge_normals(vert, start)
    found, mx, my, inset = _rounded_normal(vert, normal, 0, len(a), len(a), len(b), float(radius), scratch_polygons())
    return (np.array([mx, my]), float(inset)) if found else None
