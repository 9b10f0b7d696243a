"""Cell stress and strain tensors of Chetouane et al. (2003) and their invariants.

Python front of ``masonrycli.engine.tensor_kernels``: triangulation (once, at set-up), launchers, and
``TensorComputer``, which the time loop calls once per step.

Definitions (DESIGN §3; paper eqs. 1–12)
-----------------------------------------
* **Block stress** (eq. 8): σ_b = (1/V_b) Σ_contacts GI ⊗ F, (GI ⊗ F)_ij = GI_i F_j, with G the
  current centroid, I the contact point and F the contact force *on* block b (``contact_force`` is
  the force on body b of the pair (a, b), body a gets −F). Contacts with supports count (the ground
  reaction acts on the block); supports get no stress. V_b = area · thickness. Taking G as the
  reference point removes the inertia term of eq. 7, so the formula holds in dynamics; rotations make
  σ non-symmetric (eq. 6 discussion).
* **Cell** of block i: block i plus the distinct *blocks* (not supports) having at least one contact
  with i in the current contact list — every listed contact counts, open ones (inside the alert
  distance) included. Cell stress (eq. 12): Σ V_b σ_b / Σ V_b over the cell.
* **Strain rate** (eqs. 1–5): triangles of centroids fixed at set-up (``build_triangles``); in each,
  the centroid velocities are interpolated linearly over the *current* centroid positions, giving a
  constant gradient L_T (L_ij = ∂v_i/∂x_j) and D_T = sym(L_T). Cell strain rate of i =
  Σ_{T∋i} A_T D_T / Σ_{T∋i} A_T with A_T the current area (signed with respect to the initial
  counter-clockwise orientation, so equal to the area until a triangle inverts). NaN for a block in
  no triangle, and for a step in which the star of i has folded (Σ A_T ≤ 0).
  For a vertex i whose star of triangles is closed (an interior vertex), Σ_{T∋i} A_T ∇N_i^T = 0, so
  i's own cell strain rate does not depend on v_i — only on its ring of neighbours.
* **Cumulated strain**: ε ← ε + dt · D each ``step`` (explicit, with the rate at the state passed
  in). Starts at 0 (NaN for blocks in no triangle, which stay NaN); a step whose rate is NaN leaves
  the strain unchanged.
* **Invariants** of the symmetric part [[a, b], [b, d]], b = (t_xy + t_yx)/2: principal values
  λ1 ≥ λ2 (closed form, c = (a+d)/2, r = hypot((a−d)/2, b), λ = c ± r) and the angle of the major
  (λ1) direction from x, counter-clockwise, in (−π/2, π/2] rad, φ = ½ atan2(2b, a−d); an isotropic
  tensor (r ≤ 1e-14 (|c| + r)) gets φ = 0. Stress: spherical p = (σ1+σ2)/2, deviatoric
  q = (σ1−σ2)/2, skew |σ_xy − σ_yx|/2. Strain (rate): volumetric = trace = ε1+ε2, deviatoric
  (ε1−ε2)/2. Compression and contraction are negative.
* The joint states (sliding ratio, joint opening, hinges) are in ``masonrycli.mechanism``.

Units: SI. Forces in N acting on the block's whole thickness (as the solver's, m = ρ·A·e); with the
default e = 1 m these are N/m and σ is in Pa either way.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import Delaunay

from masonrycli.engine import tensor_kernels as _k

TENSOR_FIELDS: dict[str, tuple[tuple[int, ...], str, str]] = {
    "block_stress": ((2, 2), "Pa", "block stress (1/V) Σ GI ⊗ F, eq. 8; row i, column j = GI_i F_j"),
    "cell_stress": ((2, 2), "Pa", "cell stress Σ V σ / Σ V over the block and its contacting blocks, eq. 12"),
    "cell_stress_skew": ((), "Pa", "size of the skew part of the cell stress |σ_xy − σ_yx| / 2"),
    "cell_strain_rate": ((2, 2), "1/s", "cell strain rate, area-weighted mean of sym(grad v), eqs. 1–5"),
    "cell_strain": ((2, 2), "1", "cumulated cell strain, time integral of the cell strain rate"),
    "cell_principal_stress": ((2,), "Pa", "principal cell stresses σ1 ≥ σ2 (compression negative)"),
    "cell_principal_angle": ((), "rad", "direction of σ1 from x, counter-clockwise, in (−π/2, π/2]"),
    "cell_spherical_stress": ((), "Pa", "2-D spherical stress p = (σ1 + σ2) / 2"),
    "cell_deviatoric_stress": ((), "Pa", "deviatoric stress q = (σ1 − σ2) / 2 ≥ 0"),
    "cell_principal_strain_rate": ((2,), "1/s", "principal strain rates ε̇1 ≥ ε̇2"),
    "cell_principal_strain_rate_angle": ((), "rad", "direction of ε̇1 from x, counter-clockwise, in (−π/2, π/2]"),
    "cell_volumetric_strain_rate": ((), "1/s", "volumetric strain rate ε̇1 + ε̇2 (trace)"),
    "cell_deviatoric_strain_rate": ((), "1/s", "deviatoric strain rate (ε̇1 − ε̇2) / 2 ≥ 0"),
    "cell_principal_strain": ((2,), "1", "principal cumulated strains ε1 ≥ ε2"),
    "cell_principal_strain_angle": ((), "rad", "direction of ε1 from x, counter-clockwise, in (−π/2, π/2]"),
    "cell_volumetric_strain": ((), "1", "volumetric cumulated strain ε1 + ε2 (trace)"),
    "cell_deviatoric_strain": ((), "1", "deviatoric cumulated strain (ε1 − ε2) / 2 ≥ 0"),
}
"""Every per-block field of ``TensorComputer.fields()``, in order: name → (shape after the leading
block axis N, unit, description)."""

# name → (packed buffer, row) in TensorComputer
_LAYOUT: dict[str, tuple[str, int]] = {
    "block_stress": ("tensor", _k.T_BLOCK_STRESS),
    "cell_stress": ("tensor", _k.T_CELL_STRESS),
    "cell_stress_skew": ("scalar", _k.S_STRESS_SKEW),
    "cell_strain_rate": ("tensor", _k.T_CELL_STRAIN_RATE),
    "cell_strain": ("tensor", _k.T_CELL_STRAIN),
    "cell_principal_stress": ("pair", _k.P_STRESS),
    "cell_principal_angle": ("scalar", _k.S_STRESS_ANGLE),
    "cell_spherical_stress": ("scalar", _k.S_STRESS_SPHERICAL),
    "cell_deviatoric_stress": ("scalar", _k.S_STRESS_DEVIATORIC),
    "cell_principal_strain_rate": ("pair", _k.P_STRAIN_RATE),
    "cell_principal_strain_rate_angle": ("scalar", _k.S_STRAIN_RATE_ANGLE),
    "cell_volumetric_strain_rate": ("scalar", _k.S_STRAIN_RATE_VOLUMETRIC),
    "cell_deviatoric_strain_rate": ("scalar", _k.S_STRAIN_RATE_DEVIATORIC),
    "cell_principal_strain": ("pair", _k.P_STRAIN),
    "cell_principal_strain_angle": ("scalar", _k.S_STRAIN_ANGLE),
    "cell_volumetric_strain": ("scalar", _k.S_STRAIN_VOLUMETRIC),
    "cell_deviatoric_strain": ("scalar", _k.S_STRAIN_DEVIATORIC),
}
assert list(_LAYOUT) == list(TENSOR_FIELDS)

FOLDED_FRACTION = 0.25
"""A cell whose star of triangles has shrunk to this fraction of its initial area (the structure is
falling apart there) gets NaN strain rate and keeps its cumulated strain: the gradient of a nearly flat
triangle is not a strain of the masonry (a collapsing aqueduct gave −342 1/s without this guard)."""

DEGENERATE_AREA = 1e-12
"""``build_triangles`` drops triangles whose area is below this times scale², scale being the diagonal
of the bounding box of the initial centroids."""


# ---------------------------------------------------------------------------------------------------
# Triangulation (set-up, once)
# ---------------------------------------------------------------------------------------------------


def build_triangles(centroids0: np.ndarray, touching_pairs: np.ndarray) -> np.ndarray:
    """Triangles of block centroids for the strain rate, fixed for the whole run.

    Delaunay triangulation of the initial centroids, keeping only the triangles whose three edges join
    blocks that touch; where that leaves a hole because Delaunay chose an edge between blocks that do
    not touch, the hole is filled with triangles of mutually touching blocks that overlap no kept
    triangle (``_complete_with_cliques``); degenerate ones (area < ``DEGENERATE_AREA`` · scale²) are
    dropped.

    Args:
        centroids0: (N, 2) initial block centroids, m.
        touching_pairs: (P, 2) int, pairs of bodies in contact in the initial configuration (e.g. the
            distinct ``contact_body`` rows of the first detection). Order within a pair, repeats, and
            pairs involving supports (index ≥ N) are allowed; the latter are ignored.

    Returns:
        (T, 3) int64 block indices, each row counter-clockwise in the initial configuration and
        starting with its smallest index, rows sorted lexicographically (deterministic). (0, 3) when
        fewer than three blocks or all centroids collinear (e.g. a column).
    """
    points = np.asarray(centroids0, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 2:
        raise ValueError(f"centroids0 must have shape (N, 2), got {points.shape}")
    n = points.shape[0]
    empty = np.zeros((0, 3), np.int64)
    pairs = np.asarray(touching_pairs, dtype=np.int64).reshape(-1, 2)
    if n < 3 or pairs.shape[0] == 0:
        return empty
    scale = float(np.hypot(*np.ptp(points, axis=0)))
    if scale == 0.0:
        return empty
    # All collinear (Qhull would refuse): distance of every point to the line through p0 and the
    # point farthest from it.
    rel = points - points[0]
    far = rel[np.argmax(np.einsum("ij,ij->i", rel, rel))]
    off_line = np.abs(rel[:, 0] * far[1] - rel[:, 1] * far[0]) / np.hypot(far[0], far[1])
    if off_line.max() <= DEGENERATE_AREA * scale:
        return empty

    tri = Delaunay(points).simplices.astype(np.int64)

    lo, hi = np.minimum(pairs[:, 0], pairs[:, 1]), np.maximum(pairs[:, 0], pairs[:, 1])
    valid = (lo >= 0) & (hi < n) & (lo != hi)
    touch_keys = np.unique(lo[valid] * n + hi[valid])
    e_lo = np.minimum(tri, np.roll(tri, -1, axis=1))
    e_hi = np.maximum(tri, np.roll(tri, -1, axis=1))
    keep = np.isin(e_lo * n + e_hi, touch_keys).all(axis=1)
    tri = _complete_with_cliques(points, tri[keep], touch_keys, n, DEGENERATE_AREA * scale * scale)

    p0, p1, p2 = points[tri[:, 0]], points[tri[:, 1]], points[tri[:, 2]]
    area2 = (p1[:, 0] - p0[:, 0]) * (p2[:, 1] - p0[:, 1]) - (p1[:, 1] - p0[:, 1]) * (p2[:, 0] - p0[:, 0])
    tri[area2 < 0] = tri[area2 < 0][:, [0, 2, 1]]
    tri = tri[0.5 * np.abs(area2) >= DEGENERATE_AREA * scale * scale]
    if tri.shape[0] == 0:
        return empty

    first = np.argmin(tri, axis=1)
    tri = tri[np.arange(tri.shape[0])[:, None], (first[:, None] + np.arange(3)) % 3]
    order = np.lexsort((tri[:, 2], tri[:, 1], tri[:, 0]))
    return np.ascontiguousarray(tri[order])


def _complete_with_cliques(points, tri, touch_keys, n, min_area) -> np.ndarray:
    """Fill the holes Delaunay leaves where its edge joins two blocks that do not touch.

    Where four blocks touch each other (two courses of a two-block pier, say), Delaunay may pick the
    diagonal between the two that do not touch, and the filter then drops both triangles. Every triple
    of mutually touching blocks is a candidate; candidates are added, smallest first, when they overlap
    no triangle kept so far. Set-up only (once per run); the result stays deterministic.
    """
    lo, hi = touch_keys // n, touch_keys % n
    neighbours = [set() for _ in range(n)]
    for i, j in zip(lo.tolist(), hi.tolist()):
        neighbours[i].add(j)
        neighbours[j].add(i)
    cliques = [
        (i, j, k) for i, j in zip(lo.tolist(), hi.tolist()) for k in sorted(neighbours[i] & neighbours[j]) if k > j
    ]
    if not cliques:
        return tri
    cand = np.array(cliques, dtype=np.int64)
    have = {tuple(sorted(t)) for t in tri.tolist()}
    cand = cand[[tuple(c) not in have for c in cand.tolist()]]
    p = points[cand]
    area = 0.5 * np.abs(
        (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
    )
    cand = cand[area >= min_area]
    area = area[area >= min_area]
    order = np.lexsort((cand[:, 2], cand[:, 1], cand[:, 0], area))
    kept = [t for t in tri]
    kept_pts = [points[t] for t in tri]
    for c in cand[order]:
        pc = points[c]
        if kept_pts and _overlaps_any(pc, np.array(kept_pts), min_area):
            continue
        kept.append(c)
        kept_pts.append(pc)
    return np.array(kept, dtype=np.int64).reshape(-1, 3)


def _overlaps_any(tri_pts: np.ndarray, others: np.ndarray, min_area: float) -> bool:
    """Does triangle ``tri_pts`` (3, 2) overlap any of ``others`` (M, 3, 2) with positive area?

    Separating axes of two triangles: the six edge normals. They overlap when every axis shows an
    overlap of the projections longer than a tolerance (triangles sharing an edge or a vertex touch
    but do not overlap).
    """
    tol = np.sqrt(min_area)
    both = [np.broadcast_to(tri_pts, others.shape), others]
    separated = np.zeros(others.shape[0], dtype=bool)
    for shape in both:
        edges = np.roll(shape, -1, axis=1) - shape  # (M, 3, 2)
        normals = np.stack([-edges[..., 1], edges[..., 0]], -1)  # (M, 3, 2)
        normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
        pa = np.einsum("mkd,mvd->mkv", normals, both[0])  # (M, 3 axes, 3 vertices)
        pb = np.einsum("mkd,mvd->mkv", normals, both[1])
        overlap = np.minimum(pa.max(-1), pb.max(-1)) - np.maximum(pa.min(-1), pb.min(-1))
        separated |= (overlap <= tol).any(axis=1)
    return not separated.all()


# ---------------------------------------------------------------------------------------------------
# Launchers (one quantity each; TensorComputer.step runs them all in one dispatch)
# ---------------------------------------------------------------------------------------------------


def block_stress(block_count, block_q, block_volume, contact_body, contact_point, contact_force) -> np.ndarray:
    """Block stress σ_b = (1/V_b) Σ GI ⊗ F (eq. 8).

    Args:
        block_count: N.
        block_q: (B ≥ N, 3) centroid x, y (m) and θ (rad); only the first N rows are read.
        block_volume: (N,) area · thickness, m³.
        contact_body: (C, 2) int bodies (a, b); indices ≥ N are supports.
        contact_point: (C, 2) world contact points, m.
        contact_force: (C, 2) force on body b, world, N (body a gets the opposite).

    Returns:
        (N, 2, 2) Pa, ``[i, j] = Σ GI_i F_j / V``.
    """
    out = np.empty((block_count, 2, 2))
    _k._block_stress(
        block_count,
        _f64(block_q),
        _f64(block_volume),
        np.asarray(contact_body),
        _f64(contact_point),
        _f64(contact_force),
        out,
    )
    return out


def cell_average(block_count, block_tensor, block_volume, contact_body) -> np.ndarray:
    """Volume-weighted mean of a (N, 2, 2) block tensor over each block's cell (eq. 12).

    The cell of i is i plus the distinct blocks sharing at least one contact with i in ``contact_body``
    (supports excluded). Returns (N, 2, 2) in the unit of ``block_tensor``.
    """
    start, neighbour = _k._cell_neighbours(block_count, np.asarray(contact_body))
    out = np.empty((block_count, 2, 2))
    _k._cell_average(block_count, start, neighbour, _f64(block_volume), _f64(block_tensor), out)
    return out


def cell_strain_rate(block_count, block_q, block_v, triangles, min_area=None) -> np.ndarray:
    """Cell strain rate (eqs. 1–5): area-weighted mean of sym(grad v) over the triangles of each block.

    Args:
        block_count: N.
        block_q: (B ≥ N, 3) current centroid x, y (m), θ; block_v: (B ≥ N, 3) vx, vy (m/s), ω.
        triangles: (T, 3) int block indices from ``build_triangles``.
        min_area: (N,) m², optional: a star whose area is not above it gives NaN (default 0).

    Returns:
        (N, 2, 2) symmetric, 1/s; NaN rows for blocks in no triangle.
    """
    out = np.empty((block_count, 2, 2))
    floor = np.zeros(block_count) if min_area is None else _f64(min_area)
    _k._cell_strain_rate(block_count, _f64(block_q), _f64(block_v), _triangles(triangles, block_count), floor, out)
    return out


def principal(tensor) -> tuple[np.ndarray, np.ndarray]:
    """Principal values and major direction of the symmetric part of (..., 2, 2) tensors.

    Returns:
        values (..., 2) with values[..., 0] ≥ values[..., 1], and the angle (...) in rad of the
        direction of values[..., 0] from x, counter-clockwise, in (−π/2, π/2] (0 if isotropic).
    """
    t = _f64(tensor)
    if t.shape[-2:] != (2, 2):
        raise ValueError(f"tensor must have shape (..., 2, 2), got {t.shape}")
    batch = t.shape[:-2]
    flat = np.ascontiguousarray(t.reshape(-1, 2, 2))
    m = flat.shape[0]
    values = np.empty((m, 2))
    angle = np.empty(m)
    _k._principal(flat, values, angle, np.empty(m), np.empty(m), 1.0)
    return values.reshape(batch + (2,)), angle.reshape(batch)


# ---------------------------------------------------------------------------------------------------
# Per-step computer
# ---------------------------------------------------------------------------------------------------


class TensorComputer:
    """All ``TENSOR_FIELDS`` for one assembly, updated once per time step into preallocated arrays.

    Owns the cumulated-strain state. One numba dispatch per ``step``; no Python loop over blocks,
    contacts or triangles.
    ``step`` stores the tensors and the cumulated strain; ``fields`` derives the
    invariants from them on demand.

    Args:
        block_count: N.
        block_volume: (N,) block area · thickness, m³ (> 0).
        triangles: (T, 3) int block indices, from ``build_triangles`` on the initial configuration.
    """

    def __init__(
        self, block_count: int, block_volume: np.ndarray, triangles: np.ndarray, centroids0: np.ndarray | None = None
    ):
        n = int(block_count)
        if n < 0:
            raise ValueError("block_count must be >= 0")
        volume = np.ascontiguousarray(block_volume, dtype=np.float64)
        if volume.shape != (n,):
            raise ValueError(f"block_volume must have shape ({n},), got {volume.shape}")
        if n and not np.all(volume > 0):
            raise ValueError("block_volume must be positive")
        self.block_count = n
        self.block_volume = volume
        """(N,) m³."""
        self.triangles = _triangles(triangles, n)
        """(T, 3) int64 block indices."""
        self.has_triangle = np.zeros(n, bool)
        """(N,) True for the blocks with at least one triangle (finite strain rate and strain)."""
        self.has_triangle[self.triangles.ravel()] = True
        self.min_star_area = np.zeros(n)
        """(N,) m²: a cell whose star of triangles is not larger than this has no strain rate that step
        (``FOLDED_FRACTION`` of its initial area when ``centroids0`` is given, else 0)."""
        if centroids0 is not None and self.triangles.size:
            p = np.asarray(centroids0, dtype=np.float64)[self.triangles]
            area = 0.5 * (
                (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
            )
            star = np.zeros(n)
            for m in range(3):
                np.add.at(star, self.triangles[:, m], area)
            self.min_star_area = FOLDED_FRACTION * star
        self._tensor = np.full((_k.TENSOR_ROWS, n, 2, 2), np.nan)
        self._pair = np.full((_k.PAIR_ROWS, n, 2), np.nan)
        self._scalar = np.full((_k.SCALAR_ROWS, n), np.nan)
        self._buffers = {"tensor": self._tensor, "pair": self._pair, "scalar": self._scalar}
        self._invariants_stale = False
        self.reset_strain()

    def reset_strain(self) -> None:
        """Cumulated strain back to 0 (NaN for blocks in no triangle)."""
        strain = self._tensor[_k.T_CELL_STRAIN]
        strain[:] = 0.0
        strain[~self.has_triangle] = np.nan
        self._invariants_stale = True

    def step(
        self,
        block_q: np.ndarray,
        block_v: np.ndarray,
        contact_body: np.ndarray,
        contact_point: np.ndarray,
        contact_force: np.ndarray,
        dt: float,
    ) -> None:
        """Compute every field for the state passed in and add dt · (its strain rate) to the strain.

        Args:
            block_q: (B ≥ N, 3) float64 centroid x, y (m), θ (rad) — body or block array; rows ≥ N ignored.
            block_v: (B ≥ N, 3) float64 vx, vy (m/s), ω (rad/s).
            contact_body: (C, 2) int bodies (a, b); indices ≥ N are supports.
            contact_point: (C, 2) float64 world contact points, m.
            contact_force: (C, 2) float64 force on body b in world coordinates, N (impulse / dt).
            dt: time step, s (0 computes the fields without integrating, e.g. for the initial frame).

        Before the first call every field except ``cell_strain`` and its invariants is NaN.
        """
        n = self.block_count
        c = contact_body.shape[0]
        if block_q.shape[0] < n or block_v.shape[0] < n or contact_point.shape[0] != c or contact_force.shape[0] != c:
            raise ValueError(
                f"inconsistent shapes: N={n}, block_q {block_q.shape}, block_v {block_v.shape}, "
                f"contact_body {contact_body.shape}, contact_point {contact_point.shape}, "
                f"contact_force {contact_force.shape}"
            )
        _k._tensor_step(
            n,
            block_q,
            block_v,
            self.block_volume,
            self.triangles,
            self.min_star_area,
            contact_body,
            contact_point,
            contact_force,
            float(dt),
            self._tensor,
        )
        self._invariants_stale = True

    def fields(self) -> dict[str, np.ndarray]:
        """Copies of all ``TENSOR_FIELDS``, name → (N, *shape) float64 array, in ``TENSOR_FIELDS`` order.

        The invariants (principal values and angles, p, q, volumetric, deviatoric, skew) are pure
        functions of the stored tensors; they are derived here, once per ``step``, rather than in
        every ``step`` — the values are the same, and steps that are not recorded skip ~20 µs.
        """
        if self._invariants_stale:
            _k._tensor_invariants(self._tensor, self._pair, self._scalar)
            self._invariants_stale = False
        return {name: self._buffers[kind][row].copy() for name, (kind, row) in _LAYOUT.items()}


def _f64(a) -> np.ndarray:
    return np.asarray(a, dtype=np.float64)


def _triangles(triangles, block_count: int) -> np.ndarray:
    tri = np.ascontiguousarray(np.asarray(triangles, dtype=np.int64).reshape(-1, 3))
    if tri.size and (tri.min() < 0 or tri.max() >= block_count):
        raise ValueError(f"triangle indices must lie in [0, {block_count})")
    return tri
