"""A corner on a corner in limit analysis: the normal of the two blocks' rounded corners, and no friction.

Where a corner of one block touches a corner of another (a voussoir's extrados corner on the corner of the
spandrel block beside it), the engine's detection gives the normal of whichever edge separates the two
polygons most; at a corner on a corner several do (every line through the point between the two blocks
separates them), and which one wins turns on the last digit: on the aqueduct a survey's 1 mm rounding turned
ten such normals by 47–87° and, with them, the friction cones the LP gave them: λ 0.1122 exact, 0.1327 rounded
at the origin, 0.1053 rounded in Lambert-93.

* **Normal.** Real arrises are never sharp. As in UDEC's corner rounding (each corner an arc of radius r; a
  vertex-to-vertex contact's normal along the line joining the two arcs' centres), a block is here its polygon
  eroded by r (each edge moved inwards by r) with a disc of radius r swept over it, and a single-point contact's
  normal is the direction between the closest points of the two eroded polygons. A corner on a face, away from
  the face's ends, gives an eroded vertex against an eroded edge: the face's normal, and the detected one is
  kept bit for bit. A corner on a corner gives eroded vertex against eroded vertex: the line between them, which
  lies inside the range of normals the sharp corners admit and which a millimetre of rounding turns by
  ~1 mm / r (a few degrees), not by up to 90°.
* **No friction.** Two sharp corners can pass each other on either side; which face they would rub along is
  the survey's last digit, so a corner on a corner carries a push along that normal and no shear (the brief
  the heritage walk-through gave: no strong frictional joint at a spurious orientation). Its force stays one
  the sharp corners admit, so the statics is not made stronger than the stones; kinematically the two blocks
  may slide past each other either way. A corner landing on a face within r of its rounded end keeps the share
  inset / r of μ (0 at the end, μ at r in), so that μ does not jump where a millimetre moves the point off the
  end. On the aqueduct λ is then 0.0995 exact and 0.0994 rounded, at origin or
  in Lambert-93, against the engine's collapse between 0.090 and 0.095 (docs/limit.md).

Pseudo-code for one single-point joint (a, b)::

    A = eroded(a, r), B = eroded(b, r)        # half-planes n_i · x <= n_i · v_i - r, clipped one by one
    (p, q) = closest points of A and B        # every vertex of one against every edge of the other
    A and B overlap (or one vanishes)        -> keep the detected contact as it is
    n = (q - p) / |q - p|                    # a corner on a face: that face's normal
    grip = min(1, inset / r)                 # inset: q's distance along its edge from the edge's nearer end
    grip < 1, or n not the detected normal   -> n and μ × grip (0 for a corner on a corner)
    else                                      -> the detected normal and μ, bit for bit
"""

from __future__ import annotations

import numpy as np

from geometry_library.trim import clip_half_plane

CORNER_RADIUS = 0.02
"""m: the rounding radius of a block's corners (a chipped arris of a dressed stone; UDEC's rounding length is
of this order, ~1 % of a block's size). A survey's 1 mm error then turns a corner-to-corner normal by ≲ 3°."""


def eroded(vertices: np.ndarray, radius: float) -> np.ndarray:
    """The convex CCW polygon ``vertices`` with each edge moved inwards by ``radius`` (empty (0, 2) when
    nothing is left): clipped by each inward-shifted edge's half-plane in turn (Sutherland–Hodgman)."""
    poly = np.asarray(vertices, dtype=np.float64)
    edges = np.roll(poly, -1, axis=0) - poly
    length = np.hypot(edges[:, 0], edges[:, 1])
    keep = length > 0.0
    normal = np.stack([edges[keep, 1], -edges[keep, 0]], axis=1) / length[keep, None]
    offset = np.einsum("ij,ij->i", normal, poly[keep]) - radius
    out = poly
    for n, c in zip(normal, offset):
        if out.shape[0] == 0:
            break
        out = clip_half_plane(out, -n, -c).reshape(-1, 2)  # keep n·x ≤ c: inside the shifted edge
    return out


def _closest_pair(points: np.ndarray, poly: np.ndarray):
    """The closest pair of (a vertex in ``points``, a point on an edge of ``poly``): (distance², vertex, foot,
    inset), ``inset`` the foot's distance along its edge from the nearer end (m; 0 at a vertex of ``poly``)."""
    ends = np.roll(poly, -1, axis=0)
    d = ends - poly
    dd = np.einsum("ij,ij->i", d, d)
    best = (np.inf, None, None, 0.0)
    for p in points:
        t = np.clip(np.einsum("ij,ij->i", p - poly, d) / np.where(dd > 0.0, dd, 1.0), 0.0, 1.0)
        foot = poly + t[:, None] * d
        dist2 = np.einsum("ij,ij->i", foot - p, foot - p)
        k = int(np.argmin(dist2))
        if dist2[k] < best[0]:
            best = (float(dist2[k]), p, foot[k], float(min(t[k], 1.0 - t[k]) * np.sqrt(dd[k])))
    return best


def _apart(pa: np.ndarray, pb: np.ndarray) -> bool:
    """True when an edge of one convex CCW polygon separates the other from it (separating axes)."""
    for p, q in ((pa, pb), (pb, pa)):
        e = np.roll(p, -1, axis=0) - p
        n = np.stack([e[:, 1], -e[:, 0]], axis=1)
        if np.any(np.min(q @ n.T - np.einsum("ij,ij->i", n, p)[None, :], axis=0) > 0.0):
            return True
    return False


def rounded_corner_normal(verts_a: np.ndarray, verts_b: np.ndarray, radius: float = CORNER_RADIUS):
    """(normal, grip) of a single-point contact between the convex CCW polygons ``verts_a`` and ``verts_b``
    with their corners rounded by ``radius`` (module doc): the unit direction from a to b between the closest
    points of the two polygons eroded by ``radius``, and the share of μ it keeps, inset / radius up to 1 (0 for a
    corner on a corner). None when the eroded polygons overlap or one vanishes (a block thinner than 2 r): the
    detected contact is then kept as it is."""
    ea, eb = eroded(verts_a, radius), eroded(verts_b, radius)
    if ea.shape[0] < 3 or eb.shape[0] < 3 or not _apart(ea, eb):
        return None
    d_ab, p_a, q_b, inset_b = _closest_pair(ea, eb)  # a's vertices against b's edges
    d_ba, p_b, q_a, inset_a = _closest_pair(eb, ea)  # b's vertices against a's edges
    v, inset = (q_b - p_a, inset_b) if d_ab <= d_ba else (p_b - q_a, inset_a)
    length = float(np.hypot(*v))
    return (v / length, min(inset / radius, 1.0)) if length > 0.0 else None
