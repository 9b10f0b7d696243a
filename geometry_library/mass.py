"""Mass properties of a polygonal block (exact shoelace formulas).

For a polygon with vertices p_0 … p_{k-1} (closed, p_k = p_0) and c_i = p_i × p_{i+1}:

    2A      = Σ c_i
    G       = Σ (p_i + p_{i+1}) c_i / (6A)
    J_O     = Σ c_i (x_i² + x_i x_{i+1} + x_{i+1}² + y_i² + y_i y_{i+1} + y_{i+1}²) / 12
    J_G     = J_O − A |G − O|²                     (polar second moment of area about G)
    m = ρ e A,   I = ρ e J_G

The sums are taken about the vertices' mean O to avoid cancellation far from the origin. Both
orientations are accepted: every sum above changes sign with the orientation, so dividing by the
signed area (and taking |A|) gives the same result for clockwise input.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .blocks import GeometryError


@dataclass(frozen=True, eq=False)
class MassProperties:
    """Mass properties of one block.

    Attributes
    ----------
    area : float, m².
    mass : float, kg — density · area · thickness.
    centroid : ndarray (2,), m.
    inertia : float, kg·m² — polar moment of inertia about the centroid (out-of-plane axis).
    """

    area: float
    mass: float
    centroid: np.ndarray
    inertia: float


def mass_properties(vertices, density: float = 2500.0, thickness: float = 1.0) -> MassProperties:
    """Area, mass, centroid and polar inertia about the centroid of a polygon.

    Parameters
    ----------
    vertices : array_like (k, 2), m — k ≥ 3, CCW or CW, closing repeat optional. Exact for any
        simple polygon (convex or not).
    density : float, kg/m³.
    thickness : float, m — out-of-plane depth.

    Raises
    ------
    GeometryError if the vertices are not finite (k, 2), the area is zero, or density/thickness are
    not positive.
    """
    xy = np.asarray(vertices, dtype=np.float64)
    if xy.ndim != 2 or xy.shape[1] != 2 or xy.shape[0] < 3:
        raise GeometryError(f"mass_properties: expected (k ≥ 3, 2) vertices, got shape {xy.shape}")
    if not np.all(np.isfinite(xy)):
        raise GeometryError("mass_properties: vertices contain NaN or infinite coordinates")
    for what, value in (("density", density), ("thickness", thickness)):
        if not (math.isfinite(value) and value > 0.0):
            raise GeometryError(f"mass_properties: {what} must be positive, got {value!r}")
    if np.array_equal(xy[0], xy[-1]):
        xy = xy[:-1]
    origin = xy.mean(axis=0)
    p = xy - origin
    q = np.roll(p, -1, axis=0)
    cross = p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]
    twice_area = float(cross.sum())
    if not abs(twice_area) > 0.0:
        raise GeometryError("mass_properties: polygon has zero area")
    cx = float(np.sum((p[:, 0] + q[:, 0]) * cross)) / (3.0 * twice_area)
    cy = float(np.sum((p[:, 1] + q[:, 1]) * cross)) / (3.0 * twice_area)
    j_origin = (
        float(
            np.sum(
                cross
                * (p[:, 0] ** 2 + p[:, 0] * q[:, 0] + q[:, 0] ** 2 + p[:, 1] ** 2 + p[:, 1] * q[:, 1] + q[:, 1] ** 2)
            )
        )
        / 12.0
    )
    area = 0.5 * abs(twice_area)
    j_origin = math.copysign(1.0, twice_area) * j_origin
    j_centroid = j_origin - area * (cx * cx + cy * cy)
    rho_e = density * thickness
    return MassProperties(
        area=area,
        mass=rho_e * area,
        centroid=np.array([origin[0] + cx, origin[1] + cy]),
        inertia=rho_e * j_centroid,
    )
