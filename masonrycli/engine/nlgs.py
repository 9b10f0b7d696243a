"""Nonlinear Gauss–Seidel on the Signorini–Coulomb problem, with the exact 2×2 local solve.

Per contact α between bodies a < b, in the local frame (t, n) with t = (n_y, −n_x):

    u_α = H_αᵀ v             relative velocity of b with respect to a at the contact point
    v   = v_free + M⁻¹ H r   (impulse r_α acts on b, −r_α on a)

Contact law (inelastic shocks, the gap-predicted Signorini condition of DESIGN.md §2):

    r_n ≥ 0,  u_n + max(g_m, 0)/dt ≥ 0,  r_n · (u_n + max(g_m, 0)/dt) = 0
    |r_t| ≤ μ r_n,  u_t = 0 while |r_t| < μ r_n,  r_t = −μ r_n sign(u_t) when sliding

A contact already penetrating (g_m < 0) is only stopped, never pushed out: pushing out injects energy.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import njit

STATUS_OPEN, STATUS_STICK, STATUS_SLIP = 0, 1, 2


@njit
def _prepare(contact_body, contact_point, contact_normal, contact_gap, count, body_q, inv_mass, inv_inertia,
             dt, out_ra, out_rb, out_w, out_bias):
    # For each contact: lever arms from the centroids (at the detection configuration q_m) to the
    # contact point, the Delassus diagonal block W_αα = Σ_{a,b} (m⁻¹ dᵢ·dⱼ + I⁻¹ (r×dᵢ)(r×dⱼ)) in (t, n),
    # stored as (W_tt, W_tn, W_nn), and the Signorini bias max(g, 0)/dt.
    for c in range(count):
        a = contact_body[c, 0]
        b = contact_body[c, 1]
        nx = contact_normal[c, 0]
        ny = contact_normal[c, 1]
        tx = ny
        ty = -nx
        wtt = 0.0
        wtn = 0.0
        wnn = 0.0
        for k in range(2):
            body = a if k == 0 else b
            rx = contact_point[c, 0] - body_q[body, 0]
            ry = contact_point[c, 1] - body_q[body, 1]
            if k == 0:
                out_ra[c, 0] = rx
                out_ra[c, 1] = ry
            else:
                out_rb[c, 0] = rx
                out_rb[c, 1] = ry
            im = inv_mass[body]
            ii = inv_inertia[body]
            rt = rx * ty - ry * tx
            rn = rx * ny - ry * nx
            wtt += im + ii * rt * rt
            wtn += ii * rt * rn
            wnn += im + ii * rn * rn
        out_w[c, 0] = wtt
        out_w[c, 1] = wtn
        out_w[c, 2] = wnn
        g = contact_gap[c]
        out_bias[c] = g / dt if g > 0.0 else 0.0


@njit
def _local_solve(ut, un, wtt, wtn, wnn, mu, bias):
    # Exact solution of the 2×2 Signorini–Coulomb problem u = u_free + W r, enumerating the cases:
    #   open:   r = 0 if u_free_n + bias ≥ 0
    #   stick:  u = (0, −bias) → r = W⁻¹(−u_t, −bias − u_n), valid if r_n ≥ 0 and |r_t| ≤ μ r_n
    #   slide:  r_t = −s μ r_n (s = ±1, the sliding direction), u_n = −bias fixes r_n,
    #           valid if s·u_t ≥ 0 afterwards
    # Returns (r_t, r_n, status).
    if un + bias >= 0.0:
        return 0.0, 0.0, STATUS_OPEN
    target = -bias - un  # > 0: normal velocity change needed
    det = wtt * wnn - wtn * wtn
    if det > 0.0:
        rt = (-ut * wnn - wtn * target) / det
        rn = (wtt * target + wtn * ut) / det
        if rn >= 0.0 and abs(rt) <= mu * rn:
            return rt, rn, STATUS_STICK
    # Try the free sliding direction first; the t–n coupling W_tn can reverse it, so then the other.
    s0 = 1.0 if ut >= 0.0 else -1.0
    for k in range(2):
        s = s0 if k == 0 else -s0
        denom = wnn - s * mu * wtn
        if denom <= 0.0:
            continue
        rn = target / denom
        rt = -s * mu * rn
        slip = ut + wtt * rt + wtn * rn
        if s * slip >= 0.0:
            return rt, rn, STATUS_SLIP
    # Unreachable for μ ≥ 0 and a positive definite W; keep the normal solve and project friction.
    rn = target / wnn
    rt = -ut / wtt
    lim = mu * rn
    if rt > lim:
        rt = lim
    elif rt < -lim:
        rt = -lim
    return rt, rn, STATUS_SLIP


@njit
def _point_velocity(v, body, rx, ry, tx, ty, nx, ny):
    # Velocity of the material point at lever arm r of ``body``, projected on (t, n).
    px = v[body, 0] - v[body, 2] * ry
    py = v[body, 1] + v[body, 2] * rx
    return px * tx + py * ty, px * nx + py * ny


@njit
def _apply(v, body, inv_mass, inv_inertia, rx, ry, px, py, sign):
    # v_body += sign · M⁻¹ (P, r × P)
    im = inv_mass[body]
    if im == 0.0:
        return
    v[body, 0] += sign * im * px
    v[body, 1] += sign * im * py
    v[body, 2] += sign * inv_inertia[body] * (rx * py - ry * px)


@njit
def _nlgs(contact_body, contact_normal, ra, rb, w, bias, count, mu, inv_mass, inv_inertia,
          tolerance, max_iterations, v, r, status):
    # v enters as v_free and leaves as v_n+1; r enters as the warm start and leaves as the solution.
    #   v ← v_free + M⁻¹ H r_warm
    #   repeat: for α in order: u_free = H_αᵀ v − W_αα r_α ; r_α' = local_solve(u_free) ;
    #                           v += M⁻¹ H_α (r_α' − r_α)
    #           until sqrt(Σ|Δr|² / Σ|r|²) < tolerance (LMGC90's quadratic norm) or the cap.
    for c in range(count):
        a = contact_body[c, 0]
        b = contact_body[c, 1]
        nx = contact_normal[c, 0]
        ny = contact_normal[c, 1]
        px = r[c, 0] * ny + r[c, 1] * nx
        py = -r[c, 0] * nx + r[c, 1] * ny
        _apply(v, a, inv_mass, inv_inertia, ra[c, 0], ra[c, 1], px, py, -1.0)
        _apply(v, b, inv_mass, inv_inertia, rb[c, 0], rb[c, 1], px, py, 1.0)
    iterations = 0
    residual = 0.0
    for it in range(max_iterations):
        iterations = it + 1
        sum_dr2 = 0.0
        sum_r2 = 0.0
        for c in range(count):
            a = contact_body[c, 0]
            b = contact_body[c, 1]
            nx = contact_normal[c, 0]
            ny = contact_normal[c, 1]
            tx = ny
            ty = -nx
            ubt, ubn = _point_velocity(v, b, rb[c, 0], rb[c, 1], tx, ty, nx, ny)
            uat, uan = _point_velocity(v, a, ra[c, 0], ra[c, 1], tx, ty, nx, ny)
            rt0 = r[c, 0]
            rn0 = r[c, 1]
            ut = ubt - uat - (w[c, 0] * rt0 + w[c, 1] * rn0)
            un = ubn - uan - (w[c, 1] * rt0 + w[c, 2] * rn0)
            rt, rn, st = _local_solve(ut, un, w[c, 0], w[c, 1], w[c, 2], mu, bias[c])
            status[c] = st
            drt = rt - rt0
            drn = rn - rn0
            if drt != 0.0 or drn != 0.0:
                px = drt * tx + drn * nx
                py = drt * ty + drn * ny
                _apply(v, a, inv_mass, inv_inertia, ra[c, 0], ra[c, 1], px, py, -1.0)
                _apply(v, b, inv_mass, inv_inertia, rb[c, 0], rb[c, 1], px, py, 1.0)
                r[c, 0] = rt
                r[c, 1] = rn
            sum_dr2 += drt * drt + drn * drn
            sum_r2 += rt * rt + rn * rn
        if sum_r2 > 0.0:
            residual = np.sqrt(sum_dr2 / sum_r2)
        else:
            residual = 0.0 if sum_dr2 == 0.0 else np.inf
        if residual < tolerance:
            break
    return iterations, residual


@njit
def _contact_power(contact_body, contact_normal, ra, rb, r, count, v_old, v_new, body_dynamic, block_count,
                   dt, out_force, out_support_force):
    # Per contact: world force on body b (r/dt) and, over the step, the energy dissipated
    # D = −Σ r·ū (ū: relative velocity at the mean velocity (v_n + v_n+1)/2) and the work of the supports
    # W_s = Σ (force of the support on the block)·(support velocity)·dt. At θ = ½ these close the
    # discrete energy balance exactly: ΔK + ΔP = W_s − D.
    dissipated = 0.0
    support_work = 0.0
    for s in range(out_support_force.shape[0]):
        out_support_force[s, 0] = 0.0
        out_support_force[s, 1] = 0.0
    for c in range(count):
        a = contact_body[c, 0]
        b = contact_body[c, 1]
        nx = contact_normal[c, 0]
        ny = contact_normal[c, 1]
        tx = ny
        ty = -nx
        px = r[c, 0] * tx + r[c, 1] * nx
        py = r[c, 0] * ty + r[c, 1] * ny
        out_force[c, 0] = px / dt
        out_force[c, 1] = py / dt
        u0t, u0n = _point_velocity(v_old, b, rb[c, 0], rb[c, 1], tx, ty, nx, ny)
        u1t, u1n = _point_velocity(v_new, b, rb[c, 0], rb[c, 1], tx, ty, nx, ny)
        w0t, w0n = _point_velocity(v_old, a, ra[c, 0], ra[c, 1], tx, ty, nx, ny)
        w1t, w1n = _point_velocity(v_new, a, ra[c, 0], ra[c, 1], tx, ty, nx, ny)
        ut = 0.5 * (u0t + u1t - w0t - w1t)
        un = 0.5 * (u0n + u1n - w0n - w1n)
        dissipated -= r[c, 0] * ut + r[c, 1] * un
        for k in range(2):
            body = a if k == 0 else b
            if body_dynamic[body]:
                continue
            sign = -1.0 if k == 0 else 1.0  # force on this support: −P on a, +P on b
            vsx = 0.5 * (v_old[body, 0] + v_new[body, 0])
            vsy = 0.5 * (v_old[body, 1] + v_new[body, 1])
            # The support pushes the block with the opposite force.
            support_work -= sign * (px * vsx + py * vsy)
            out_support_force[body - block_count, 0] += sign * px / dt
            out_support_force[body - block_count, 1] += sign * py / dt
    return dissipated, support_work


def prepare_contacts(contact_body, contact_point, contact_normal, contact_gap, count, body_q, model,
                     out_ra, out_rb, out_w, out_bias) -> None:
    """Lever arms (C,2) m, Delassus blocks (C,3) = (W_tt, W_tn, W_nn) 1/kg, Signorini bias (C,) m/s."""
    _prepare(contact_body, contact_point, contact_normal, contact_gap, count, body_q, model.body_inv_mass,
             model.body_inv_inertia, model.dt, out_ra, out_rb, out_w, out_bias)


def solve(contact_body, contact_normal, ra, rb, w, bias, count, model, v, r, status) -> tuple[int, float]:
    """Run NLGS. ``v`` (B,3): v_free in, v_n+1 out. ``r`` (C,2): warm start in, (r_t, r_n) N·s out.

    Returns (sweeps, residual); residual is the relative quadratic norm of the last sweep's change.
    """
    return _nlgs(contact_body, contact_normal, ra, rb, w, bias, count, model.friction, model.body_inv_mass,
                 model.body_inv_inertia, model.tolerance, model.max_iterations, v, r, status)


def contact_power(contact_body, contact_normal, ra, rb, r, count, v_old, v_new, model, out_force,
                  out_support_force) -> tuple[float, float]:
    """World contact forces on body b (C,2) N, support forces (S,2) N; returns (dissipated, support work) J."""
    return _contact_power(contact_body, contact_normal, ra, rb, r, count, v_old, v_new, model.body_dynamic,
                          model.block_count, model.dt, out_force, out_support_force)
