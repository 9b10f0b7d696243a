"""Cell stress and strain tensors of Chetouane et al. (2003) and their invariants.

Python front of ``masonrycli.engine.tensor_kernels``: launchers, and ``TensorComputer``, which the time loop
calls once per step. The cells' triangles and chains, built once at set-up: :mod:`masonrycli.analysis.triangulation`.

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
* **Strain rate** (eqs. 1–5): the cell of block i is the fan of triangles with apex G_i and opposite
  edge G_j G_k over i's neighbours (Fig. I.1), fixed at set-up (``build_triangles``); in each, the
  centroid velocities are interpolated linearly over the *current* centroid positions, giving a constant
  gradient L_T (L_ij = ∂v_i/∂x_j) and D_T = sym(L_T). Cell strain rate of i = Σ_{T of i} A_T D_T /
  Σ_{T of i} A_T with A_T the current area (signed with respect to the initial counter-clockwise
  orientation, so equal to the area until a triangle inverts). NaN for a block without a triangle, and
  for a step in which its fan has folded (Σ A_T ≤ ``FOLDED_FRACTION`` of its initial area).
  For a closed fan (an interior block), Σ_T A_T ∇N_i^T = 0, so i's own cell strain rate does not
  depend on v_i — only on its ring of neighbours.
* **Chain strain rate**: a block with exactly two neighbouring blocks and no support (a voussoir of a
  bare ring) has a fan of at most one triangle, a sliver across the ring that ``build_triangles``
  drops; its 1-D strain rate along the chain, d(l_ij + l_ik)/dt / (l_ij + l_ik) over its two links to
  the neighbours' centroids, carries the hinge-opening signal instead (NaN for other blocks).
* **Cumulated strain**: ε ← ε + dt · D each ``step`` (explicit, with the rate at the state passed
  in). Starts at 0 (NaN for blocks in no triangle, which stay NaN); a step whose rate is NaN leaves
  the strain unchanged.
* **Invariants** of the symmetric part [[a, b], [b, d]], b = (t_xy + t_yx)/2: principal values
  λ1 ≥ λ2 (closed form, c = (a+d)/2, r = hypot((a−d)/2, b), λ = c ± r) and the angle of the major
  (λ1) direction from x, counter-clockwise, in (−π/2, π/2] rad, φ = ½ atan2(2b, a−d); an isotropic
  tensor (r ≤ 1e-14 (|c| + r)) gets φ = 0. Stress: spherical p = (σ1+σ2)/2, deviatoric
  q = (σ1−σ2)/2, skew |σ_xy − σ_yx|/2. Strain (rate): volumetric = trace = ε1+ε2, deviatoric
  (ε1−ε2)/2. Compression and contraction are negative.
* The joint states (sliding ratio, joint opening, hinges) are in ``masonrycli.analysis.mechanism``.
* **Which point of a block**: the strain rate, the cumulated strain, the chain strain rate and the
  triangulation take each block's own centroid (its polygon's, ``centroid_offset`` from the body's centre),
  the paper's G: a bridge's fill, carried as a mass on the blocks under it (``Block.carried_mass``), pulls
  the body's centre of mass up to 1.2 m into the fill, and fans between those points were not the
  masonry's cells. The block stress keeps the body's centre of mass as G: about it the inertia and the
  weight (the fill's included) have no moment, so the stress of a block at rest is symmetric (the filled
  bridge's voussoirs: skew ≤ 7e-4 |p|); about the stone's own centroid the contacts' moment of the fill's
  weight showed as a skew part up to 0.25 |p| (8.6 kPa). For a block that carries nothing the two agree.

Units: SI. Forces in N acting on the block's whole thickness (as the solver's, m = ρ·A·e); with the
default e = 1 m these are N/m and σ is in Pa either way.
"""

from __future__ import annotations

import numpy as np

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
    "chain_strain_rate": ((), "1/s", "1-D strain rate along a one-block chain, d(l_ij + l_ik)/dt / (l_ij + l_ik)"),
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
    "chain_strain_rate": ("chain", 0),
}
assert list(_LAYOUT) == list(TENSOR_FIELDS)

FOLDED_FRACTION = 0.25
"""A cell whose fan of triangles has shrunk to this fraction of its initial area (the structure is
falling apart there) gets NaN strain rate and keeps its cumulated strain: the gradient of a nearly flat
triangle is not a strain of the masonry (a collapsing aqueduct gave −342 1/s without this guard)."""

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
    """Cell strain rate (eqs. 1–5): area-weighted mean of sym(grad v) over the fan of each block.

    Args:
        block_count: N.
        block_q: (B ≥ N, 3) current centroid x, y (m), θ; block_v: (B ≥ N, 3) vx, vy (m/s), ω.
        triangles: (T, 3) int block indices (apex first) from ``build_triangles``.
        min_area: (N,) m², optional: a fan whose area is not above it gives NaN (default 0).

    Returns:
        (N, 2, 2) symmetric, 1/s; NaN rows for blocks in no triangle.
    """
    out = np.empty((block_count, 2, 2))
    floor = np.zeros(block_count) if min_area is None else _f64(min_area)
    _k._cell_strain_rate(block_count, _f64(block_q), _f64(block_v), _triangles(triangles, block_count), floor, out)
    return out


def chain_strain_rate(block_count, block_q, block_v, chain) -> np.ndarray:
    """(N,) 1/s: the 1-D strain rate of each block's two links in a one-block chain (NaN off chains).

    ``chain``: (N, 2) int from ``chain_neighbours``; block_q, block_v as for ``cell_strain_rate``.
    """
    out = np.empty(block_count)
    _k._chain_strain_rate(block_count, _f64(block_q), _f64(block_v), _chain(chain, block_count), out)
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
        triangles: (T, 3) int block indices (apex first), from ``build_triangles`` on the initial
            configuration.
        centroids0: (N, 2) m, optional: the initial centroids, for the folded-fan floor.
        chain: (N, 2) int, optional: ``chain_neighbours`` (default: no block in a chain).
        centroid_offset: (N, 2) m, optional: each block's own centroid relative to its body's centre at
            θ = 0 (a carried fill's blocks'; module doc "Which point of a block"); None or all zero: the
            body's centre is the centroid, and ``step`` hands the kernels the arrays it is given.
    """

    def __init__(
        self,
        block_count: int,
        block_volume: np.ndarray,
        triangles: np.ndarray,
        centroids0: np.ndarray | None = None,
        chain: np.ndarray | None = None,
        centroid_offset: np.ndarray | None = None,
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
        self.has_triangle[self.triangles[:, 0]] = True
        self.chain = _chain(np.full((n, 2), -1) if chain is None else chain, n)
        """(N, 2) int64 neighbours of the blocks in a one-block chain, −1 elsewhere."""
        self.min_star_area = np.zeros(n)
        """(N,) m²: a cell whose fan of triangles is not larger than this has no strain rate that step
        (``FOLDED_FRACTION`` of its initial area when ``centroids0`` is given, else 0)."""
        if centroids0 is not None and self.triangles.size:
            p = np.asarray(centroids0, dtype=np.float64)[self.triangles]
            area = 0.5 * (
                (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
            )
            self.min_star_area = FOLDED_FRACTION * np.bincount(self.triangles[:, 0], weights=area, minlength=n)
        self._tensor = np.full((_k.TENSOR_ROWS, n, 2, 2), np.nan)
        self._pair = np.full((_k.PAIR_ROWS, n, 2), np.nan)
        self._scalar = np.full((_k.SCALAR_ROWS, n), np.nan)
        self._chain_rate = np.full((1, n), np.nan)
        self._buffers = {"tensor": self._tensor, "pair": self._pair, "scalar": self._scalar, "chain": self._chain_rate}
        self._invariants_stale = False
        self._stress_inputs: tuple | None = None  # the last step's arrays until fields() reads them
        offset = None if centroid_offset is None else np.asarray(centroid_offset, dtype=np.float64).reshape(n, 2)
        self.centroid_offset = None if offset is None or not offset.any() else offset
        """(N, 2) m, or None: every block's centroid is its body's centre (no carried mass)."""
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
        """Add dt · (the strain rate of the state passed in) to the strain; the other fields of that state
        are computed when :meth:`fields` reads them, from these same arrays (kept by reference: leave them
        as they are until then, as the time loop does with its buffers between a step and its frame).

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
        point_q, point_v = self.centroids(block_q, block_v)
        _k._strain_step(n, point_q, point_v, self.triangles, self.min_star_area, float(dt), self._tensor)
        # Stress and chain strain rate are read at recorded frames only: computed then (fields).
        self._stress_inputs = (block_q, point_q, point_v, contact_body, contact_point, contact_force)
        self._invariants_stale = True

    def centroids(self, block_q: np.ndarray, block_v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(N, 3) the blocks' own centroids (x, y, θ) and their velocities (vx, vy, ω) from the bodies' poses
        and velocities; the arrays given when no block carries a mass (``centroid_offset`` None)."""
        if self.centroid_offset is None:
            return block_q, block_v
        # r = R(θ) offset;  x_c = x + r;  v_c = v + ω × r = (vx − ω r_y, vy + ω r_x)
        n = self.block_count
        q, v = block_q[:n], block_v[:n]
        c, s = np.cos(q[:, 2]), np.sin(q[:, 2])
        ox, oy = self.centroid_offset.T
        rx, ry = c * ox - s * oy, s * ox + c * oy
        point_q = np.stack([q[:, 0] + rx, q[:, 1] + ry, q[:, 2]], axis=1)
        point_v = np.stack([v[:, 0] - v[:, 2] * ry, v[:, 1] + v[:, 2] * rx, v[:, 2]], axis=1)
        return point_q, point_v

    def fields(self) -> dict[str, np.ndarray]:
        """Copies of all ``TENSOR_FIELDS``, name → (N, *shape) float64 C-contiguous array, in ``TENSOR_FIELDS``
        order (rows of one copy of each packed buffer: a later ``step`` leaves them as they are).

        The invariants (principal values and angles, p, q, volumetric, deviatoric, skew) are pure
        functions of the stored tensors; they are derived here, once per ``step``, rather than in
        every ``step`` — the values are the same, and steps that are not recorded skip ~20 µs.
        """
        if self._stress_inputs is not None:
            q, point_q, point_v, body, point, force = self._stress_inputs
            _k._stress_step(
                self.block_count,
                q,
                point_q,
                point_v,
                self.block_volume,
                self.chain,
                body,
                point,
                force,
                self._tensor,
                self._chain_rate[0],
            )
            self._stress_inputs = None
        if self._invariants_stale:
            _k._tensor_invariants(self._tensor, self._pair, self._scalar)
            self._invariants_stale = False
        # One copy of each packed buffer (4 copies, not 18): each field is a contiguous row of its copy.
        copies = {kind: buffer.copy() for kind, buffer in self._buffers.items()}
        return {name: copies[kind][row] for name, (kind, row) in _LAYOUT.items()}


def _f64(a) -> np.ndarray:
    return np.asarray(a, dtype=np.float64)


def _chain(chain, block_count: int) -> np.ndarray:
    out = np.ascontiguousarray(np.asarray(chain, dtype=np.int64).reshape(-1, 2))
    if out.shape[0] != block_count or out.max(initial=-1) >= block_count:
        raise ValueError(f"chain must have shape ({block_count}, 2) with indices < {block_count}")
    return out


def _triangles(triangles, block_count: int) -> np.ndarray:
    tri = np.ascontiguousarray(np.asarray(triangles, dtype=np.int64).reshape(-1, 3))
    if tri.size and (tri.min() < 0 or tri.max() >= block_count):
        raise ValueError(f"triangle indices must lie in [0, {block_count})")
    return tri
