"""Kernels for the cell stress and strain tensors of Chetouane et al. (2003), eqs. 1–12.

Private kernels only; the documented launchers are in ``masonrycli.analysis.tensors``. Index and sign conventions
follow ``docs/architecture.md``: blocks 0..N-1 then supports N..; ``contact_force`` is the force on
body b of ``contact_body[c] = (a, b)`` in world coordinates, body a gets the opposite. A tensor
``t[i, j]`` is stored row-major, ``(GI ⊗ F)_ij = GI_i F_j`` and ``L_ij = ∂v_i/∂x_j``.

Every kernel writes into arrays the caller owns; the small scratch arrays whose size follows the
contact count are allocated inside (a numba allocation costs ~0.1 µs).
"""

from __future__ import annotations

import math

import numpy as np

from masonrycli.engine._jit import kernel_only, njit

ISOTROPY_TOLERANCE = 1e-14
"""A 2×2 tensor whose anisotropy r = √(((a−d)/2)² + b²) is at most this fraction of |c| + r
(c = (a+d)/2) is treated as isotropic: its principal angle is reported as 0 instead of a direction
that would only reflect round-off (and flicker from one step to the next)."""

# Rows of the packed outputs of ``_strain_step`` / ``_stress_step`` (see ``masonrycli.analysis.tensors.TensorComputer``).
T_BLOCK_STRESS, T_CELL_STRESS, T_CELL_STRAIN_RATE, T_CELL_STRAIN = 0, 1, 2, 3
TENSOR_ROWS = 4
P_STRESS, P_STRAIN_RATE, P_STRAIN = 0, 1, 2
PAIR_ROWS = 3
(
    S_STRESS_SKEW,
    S_STRESS_ANGLE,
    S_STRESS_SPHERICAL,
    S_STRESS_DEVIATORIC,
    S_STRAIN_RATE_ANGLE,
    S_STRAIN_RATE_VOLUMETRIC,
    S_STRAIN_RATE_DEVIATORIC,
    S_STRAIN_ANGLE,
    S_STRAIN_VOLUMETRIC,
    S_STRAIN_DEVIATORIC,
) = range(10)
SCALAR_ROWS = 10


# ---------------------------------------------------------------------------------------------------
# Stress (eqs. 8 and 12)
# ---------------------------------------------------------------------------------------------------


# for each contact c = (a, b) at point I with force F on b:
#     if a is a block: σ_a += (I − G_a) ⊗ (−F)
#     if b is a block: σ_b += (I − G_b) ⊗ (+F)
# σ_i /= V_i
# (with G as the reference point the inertia term of eq. 7 vanishes, so eq. 8 holds in dynamics too)
@njit(inline="always")
def _block_stress(block_count, block_q, block_volume, contact_body, contact_point, contact_force, out):
    # Inputs: block_q (>=N,3) m, block_volume (N,) m³, contact_* (C,...) ; Outputs: out (N,2,2) Pa
    out[:] = 0.0
    for c in range(contact_body.shape[0]):
        px = contact_point[c, 0]
        py = contact_point[c, 1]
        fx = contact_force[c, 0]
        fy = contact_force[c, 1]
        for side in range(2):
            body = contact_body[c, side]
            if body < 0 or body >= block_count:
                continue  # supports carry no stress
            sign = -1.0 if side == 0 else 1.0
            gx = px - block_q[body, 0]
            gy = py - block_q[body, 1]
            out[body, 0, 0] += sign * gx * fx
            out[body, 0, 1] += sign * gx * fy
            out[body, 1, 0] += sign * gy * fx
            out[body, 1, 1] += sign * gy * fy
    for i in range(block_count):
        inv = 1.0 / block_volume[i]
        out[i, 0, 0] *= inv
        out[i, 0, 1] *= inv
        out[i, 1, 0] *= inv
        out[i, 1, 1] *= inv


# count the block–block contacts of each block → CSR start (N+1,)
# scatter the other block of each contact into neighbour (2·C_bb,)  (duplicates kept: a pair with two
# contact points appears twice; the cell average skips repeats with a stamp array)
@njit(inline="always")
def _cell_neighbours(block_count, contact_body):
    # Inputs: contact_body (C,2) ; Returns: start (N+1,) int64, neighbour (start[N],) int64
    start = np.empty(block_count + 1, np.int64)
    start[:] = 0
    for c in range(contact_body.shape[0]):
        a = contact_body[c, 0]
        b = contact_body[c, 1]
        if a == b or a < 0 or b < 0 or a >= block_count or b >= block_count:
            continue
        start[a + 1] += 1
        start[b + 1] += 1
    for i in range(block_count):
        start[i + 1] += start[i]
    fill = start[:-1].copy()
    neighbour = np.empty(start[block_count], np.int64)
    for c in range(contact_body.shape[0]):
        a = contact_body[c, 0]
        b = contact_body[c, 1]
        if a == b or a < 0 or b < 0 or a >= block_count or b >= block_count:
            continue
        neighbour[fill[a]] = b
        fill[a] += 1
        neighbour[fill[b]] = a
        fill[b] += 1
    return start, neighbour


# cell(i) = {i} ∪ {distinct blocks j listed as i's neighbours}
# out_i = Σ_{j ∈ cell(i)} V_j t_j / Σ_{j ∈ cell(i)} V_j
@njit(inline="always")
def _cell_average(block_count, start, neighbour, block_volume, block_tensor, out):
    # Inputs: CSR start/neighbour, block_volume (N,), block_tensor (N,2,2) ; Outputs: out (N,2,2)
    stamp = np.empty(block_count, np.int64)
    stamp[:] = -1
    for i in range(block_count):
        stamp[i] = i
        w = block_volume[i]
        s00 = w * block_tensor[i, 0, 0]
        s01 = w * block_tensor[i, 0, 1]
        s10 = w * block_tensor[i, 1, 0]
        s11 = w * block_tensor[i, 1, 1]
        vol = w
        for k in range(start[i], start[i + 1]):
            j = neighbour[k]
            if stamp[j] == i:
                continue
            stamp[j] = i
            w = block_volume[j]
            s00 += w * block_tensor[j, 0, 0]
            s01 += w * block_tensor[j, 0, 1]
            s10 += w * block_tensor[j, 1, 0]
            s11 += w * block_tensor[j, 1, 1]
            vol += w
        inv = 1.0 / vol
        out[i, 0, 0] = s00 * inv
        out[i, 0, 1] = s01 * inv
        out[i, 1, 0] = s10 * inv
        out[i, 1, 1] = s11 * inv


# ---------------------------------------------------------------------------------------------------
# Strain rate and cumulated strain (eqs. 1–5)
# ---------------------------------------------------------------------------------------------------


# per triangle T = (i, j, k) of the fan of cell i (apex i first, CCW in the initial configuration),
# current centroids x, velocities v:
#     E = [x_j − x_i, x_k − x_i]    W = [v_j − v_i, v_k − v_i]      (columns)
#     L_T = W E⁻¹,  A_T = det(E)/2  ⇒  A_T L_T = ½ W adj(E)          (no division: finite even when flat)
#     add A_T L_T and A_T to cell i only (the paper's cell: the triangles with apex G_i)
# cell i: D_i = sym(Σ A_T L_T) / Σ A_T ; NaN if i has no triangle or Σ A_T ≤ min_area_i (the fan has
# folded over or collapsed: the gradient of a nearly flat triangle says nothing about the masonry)
# A_T is signed (positive unless the triangle has inverted), which keeps Σ_T A_T ∇N_i = 0 around a
# closed fan exactly, whatever the current shape.
@njit
def _cell_strain_rate(block_count, block_q, block_v, triangles, min_area, out):
    # Inputs: block_q, block_v (>=N,3), triangles (T,3), min_area (N,) m² ; Outputs: out (N,2,2) 1/s
    area = np.empty(block_count, np.float64)
    area[:] = 0.0
    out[:] = 0.0
    for t in range(triangles.shape[0]):
        i = triangles[t, 0]
        j = triangles[t, 1]
        k = triangles[t, 2]
        e1x = block_q[j, 0] - block_q[i, 0]
        e1y = block_q[j, 1] - block_q[i, 1]
        e2x = block_q[k, 0] - block_q[i, 0]
        e2y = block_q[k, 1] - block_q[i, 1]
        w1x = block_v[j, 0] - block_v[i, 0]
        w1y = block_v[j, 1] - block_v[i, 1]
        w2x = block_v[k, 0] - block_v[i, 0]
        w2y = block_v[k, 1] - block_v[i, 1]
        a_t = 0.5 * (e1x * e2y - e1y * e2x)
        l00 = 0.5 * (w1x * e2y - w2x * e1y)
        l01 = 0.5 * (w2x * e1x - w1x * e2x)
        l10 = 0.5 * (w1y * e2y - w2y * e1y)
        l11 = 0.5 * (w2y * e1x - w1y * e2x)
        sym = 0.5 * (l01 + l10)
        area[i] += a_t
        out[i, 0, 0] += l00
        out[i, 0, 1] += sym
        out[i, 1, 0] += sym
        out[i, 1, 1] += l11
    for i in range(block_count):
        if area[i] > 0.0 and area[i] > min_area[i]:
            inv = 1.0 / area[i]
            out[i, 0, 0] *= inv
            out[i, 0, 1] *= inv
            out[i, 1, 0] *= inv
            out[i, 1, 1] *= inv
        else:
            out[i, :, :] = np.nan


# block i in a one-block chain between blocks j and k (chain[i] = (j, k), −1 otherwise):
#     ε̇_i = d(l_ij + l_ik)/dt / (l_ij + l_ik),  dl_ij/dt = u_ij · (v_j − v_i),  u_ij = (x_j − x_i)/l_ij
# (the 1-D strain rate of the chain's two links: > 0 when the joints open, as at a hinge)
@njit(inline="always")
def _chain_strain_rate(block_count, block_q, block_v, chain, out):
    # Inputs: block_q, block_v (>=N,3), chain (N,2) int64 ; Outputs: out (N,) 1/s, NaN off chains
    for i in range(block_count):
        out[i] = np.nan
        if chain[i, 0] < 0:
            continue
        rate = 0.0
        length = 0.0
        for side in range(2):
            j = chain[i, side]
            dx = block_q[j, 0] - block_q[i, 0]
            dy = block_q[j, 1] - block_q[i, 1]
            lij = math.hypot(dx, dy)
            if lij > 0.0:
                rate += (dx * (block_v[j, 0] - block_v[i, 0]) + dy * (block_v[j, 1] - block_v[i, 1])) / lij
            length += lij
        if length > 0.0:
            out[i] = rate / length


# strain_i += dt · rate_i where rate_i is finite (a block without triangle has NaN strain from the
# start and keeps it; a transiently undefined rate — folded star — leaves the strain unchanged)
@kernel_only
def _integrate_strain(rate, dt, strain):
    # Inputs: rate (N,2,2) 1/s, dt s ; In/out: strain (N,2,2)
    for i in range(rate.shape[0]):
        if math.isfinite(rate[i, 0, 0]) and math.isfinite(rate[i, 0, 1]) and math.isfinite(rate[i, 1, 1]):
            strain[i, 0, 0] += dt * rate[i, 0, 0]
            strain[i, 0, 1] += dt * rate[i, 0, 1]
            strain[i, 1, 0] += dt * rate[i, 1, 0]
            strain[i, 1, 1] += dt * rate[i, 1, 1]


# ---------------------------------------------------------------------------------------------------
# Closed-form 2×2 symmetric eigen-decomposition and invariants
# ---------------------------------------------------------------------------------------------------


# [[a, b], [b, d]]:  c = (a+d)/2,  r = hypot((a−d)/2, b)  (no cancellation, no overflow)
#     λ1 = c + r ≥ λ2 = c − r,  φ = ½ atan2(2b, a−d) ∈ (−π/2, π/2]  (direction of λ1, CCW from x)
# atan2 gives −π only for b = −0.0 with a < d: fold it to +π (φ = π/2); isotropic (r ≈ 0) → φ = 0.
@kernel_only
def _sym_eig2(a, b, d):
    c = 0.5 * (a + d)
    h = 0.5 * (a - d)
    r = math.hypot(h, b)
    if r <= ISOTROPY_TOLERANCE * (abs(c) + r):
        phi = 0.0
    else:
        phi = 0.5 * math.atan2(2.0 * b, a - d)
        if phi <= -0.5 * math.pi:
            phi += math.pi
        phi += 0.0  # −0.0 → +0.0
    return c + r, c - r, phi, c, r


# per block: symmetric part of t → λ1, λ2, φ, mean_factor·(a+d), (λ1−λ2)/2
@njit
def _principal(tensor, out_values, out_angle, out_isotropic, out_deviatoric, trace_factor):
    # Inputs: tensor (N,2,2), trace_factor (½ → spherical p, 1 → volumetric trace)
    # Outputs: out_values (N,2) λ1 ≥ λ2, out_angle (N,) rad, out_isotropic (N,), out_deviatoric (N,)
    for i in range(tensor.shape[0]):
        a = tensor[i, 0, 0]
        d = tensor[i, 1, 1]
        b = 0.5 * (tensor[i, 0, 1] + tensor[i, 1, 0])
        l1, l2, phi, c, r = _sym_eig2(a, b, d)
        out_values[i, 0] = l1
        out_values[i, 1] = l2
        out_angle[i] = phi
        out_isotropic[i] = trace_factor * (a + d)
        out_deviatoric[i] = r


# ---------------------------------------------------------------------------------------------------
# One dispatch per step, one per read
# ---------------------------------------------------------------------------------------------------


# strain rate → strain += dt·rate: every step (the cumulated strain needs each step's rate).
@njit
def _strain_step(block_count, block_q, block_v, triangles, min_area, dt, tensor_out):
    # Inputs: as the kernels above; Outputs: tensor_out[T_CELL_STRAIN_RATE], tensor_out[T_CELL_STRAIN] (in/out)
    rate = tensor_out[T_CELL_STRAIN_RATE]
    _cell_strain_rate(block_count, block_q, block_v, triangles, min_area, rate)
    if dt != 0.0:
        _integrate_strain(rate, dt, tensor_out[T_CELL_STRAIN])


# block stress → cell neighbours → cell stress, chain strain rate: only when the fields are read (the
# step's own inputs; nothing carries over from one step to the next). The stress about block_q (the bodies'
# centres of mass), the chain's links between point_q with velocities point_v (the blocks' own centroids).
@njit
def _stress_step(
    block_count,
    block_q,
    point_q,
    point_v,
    block_volume,
    chain,
    contact_body,
    contact_point,
    contact_force,
    tensor_out,
    chain_out,
):
    # Outputs: tensor_out[T_BLOCK_STRESS], tensor_out[T_CELL_STRESS], chain_out (N,) chain strain rate
    n = block_count
    block_stress = tensor_out[T_BLOCK_STRESS]
    _block_stress(n, block_q, block_volume, contact_body, contact_point, contact_force, block_stress)
    start, neighbour = _cell_neighbours(n, contact_body)
    _cell_average(n, start, neighbour, block_volume, block_stress, tensor_out[T_CELL_STRESS])
    _chain_strain_rate(n, point_q, point_v, chain, chain_out)


# cell stress: skew |t_xy − t_yx|/2, principal values/angle, p = (σ1+σ2)/2, q = (σ1−σ2)/2
# strain rate, strain: principal values/angle, volumetric = trace, deviatoric = (ε1−ε2)/2
@njit
def _tensor_invariants(tensor_out, pair_out, scalar_out):
    # Inputs: tensor_out (4,N,2,2) ; Outputs: pair_out (3,N,2) rows P_*, scalar_out (10,N) rows S_*
    cell_stress = tensor_out[T_CELL_STRESS]
    for i in range(cell_stress.shape[0]):
        scalar_out[S_STRESS_SKEW, i] = 0.5 * abs(cell_stress[i, 0, 1] - cell_stress[i, 1, 0])
    _principal(
        cell_stress,
        pair_out[P_STRESS],
        scalar_out[S_STRESS_ANGLE],
        scalar_out[S_STRESS_SPHERICAL],
        scalar_out[S_STRESS_DEVIATORIC],
        0.5,
    )
    _principal(
        tensor_out[T_CELL_STRAIN_RATE],
        pair_out[P_STRAIN_RATE],
        scalar_out[S_STRAIN_RATE_ANGLE],
        scalar_out[S_STRAIN_RATE_VOLUMETRIC],
        scalar_out[S_STRAIN_RATE_DEVIATORIC],
        1.0,
    )
    _principal(
        tensor_out[T_CELL_STRAIN],
        pair_out[P_STRAIN],
        scalar_out[S_STRAIN_ANGLE],
        scalar_out[S_STRAIN_VOLUMETRIC],
        scalar_out[S_STRAIN_DEVIATORIC],
        1.0,
    )
