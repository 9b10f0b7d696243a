"""A corner on a corner in limit analysis: the normal of the two blocks' rounded corners, and no friction.

Where a corner of one block touches a corner of another (a voussoir's extrados corner on the corner of the
spandrel block beside it), the sharp polygons' detection gives the normal of whichever edge separates the two
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
  ~1 mm / r (a few degrees), not by up to 90°. The geometry is the engine's own (its narrow phase gives a
  single contact this normal too): :func:`masonrycli.engine.rounded.rounded_normal`, one definition for both.
* **No friction.** Two sharp corners can pass each other on either side; which face they would rub along is
  the survey's last digit, so a corner on a corner carries a push along that normal and no shear (the brief
  the heritage walk-through gave: no strong frictional joint at a spurious orientation). Its force stays one
  the sharp corners admit, so the statics is not made stronger than the stones; kinematically the two blocks
  may slide past each other either way. A corner landing on a face within r of its rounded end keeps the share
  inset / r of μ (0 at the end, μ at r in), so that μ does not jump where a millimetre moves the point off the
  end. On the aqueduct λ is then 0.0995 exact and 0.0994 rounded, at origin or
  in Lambert-93, against the engine's collapse near 0.095 (docs/limit.md).
  Keeping μ there (the engine's contact model) was measured against the engine and lost: with μ kept the LP's
  associative sliding makes a corner dilate by μ × its slip to pass the other, nearly a pin at μ = 10, where the
  engine's corner slips past: λ 0.1328 on the aqueduct (the engine falls at 0.95 λ), 0.9192 on the segmental
  bridge at μ = 10 (falls at 0.95 λ) and its ring's least thickness 0.0587 m at μ = 10 against the four-hinge
  reference's 0.07195 (the engine brings 0.065 m down). The rule's cost: on that bridge at μ = 0.6, whose
  voussoirs' corners sit on the piers' corners, λ = 0.0955 where the engine carries 0.95 × 0.1739 (safe side).

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

from masonrycli.engine.rounded import CORNER_RADIUS, rounded_normal

__all__ = ["CORNER_RADIUS", "rounded_corner_normal"]


def rounded_corner_normal(verts_a, verts_b, radius: float = CORNER_RADIUS):
    """(normal, grip) of a single-point contact between the convex CCW polygons ``verts_a`` and ``verts_b``
    with their corners rounded by ``radius`` (module doc): the unit direction from a to b between the closest
    points of the two polygons eroded by ``radius`` (the engine's :func:`~masonrycli.engine.rounded.rounded_normal`),
    and the share of μ it keeps, inset / radius up to 1 (0 for a corner on a corner). None when the eroded
    polygons overlap or one vanishes (a block thinner than 2 r): the detected contact is then kept as it is."""
    found = rounded_normal(verts_a, verts_b, radius)
    if found is None:
        return None
    normal, inset = found
    return normal, min(inset / radius, 1.0)
