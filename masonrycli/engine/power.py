"""Contact forces and power of a solved step, and the contacts' tangential velocities (for joint states).

Split from :mod:`masonrycli.engine.nlgs` (module size): the same kernels on the same packed rows
(``nlgs.prepare_contacts``), using the sweeps' one compiled ``_relative_velocity`` so the values are the sweeps' own.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import P_NX, P_NY, _relative_velocity


@njit
def _contact_power(
    contact_body,
    pack,
    r,
    count,
    v_old,
    v_new,
    body_dynamic,
    block_count,
    dt,
    out_force,
    out_support_force,
):
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
        nx = pack[c, P_NX]
        ny = pack[c, P_NY]
        px = r[c, 0] * ny + r[c, 1] * nx  # r_t t + r_n n, t = (n_y, −n_x)
        py = -r[c, 0] * nx + r[c, 1] * ny
        out_force[c, 0] = px / dt
        out_force[c, 1] = py / dt
        # unsigned as in the sweeps: one compiled _relative_velocity serves them all (a second for int32 /
        # int64 was 0.09 s of a first run's CPU); the same rows, so the same values
        ua, ub, uc = np.uint32(a), np.uint32(b), np.uint64(c)
        u0t, u0n = _relative_velocity(v_old, ua, ub, pack, uc)
        u1t, u1n = _relative_velocity(v_new, ua, ub, pack, uc)
        dissipated -= r[c, 0] * 0.5 * (u0t + u1t) + r[c, 1] * 0.5 * (u0n + u1n)
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


@njit
def _tangential_velocity(contact_body, pack, count, v, out):
    # u_t of every contact for velocities v (the same helper as the sweep).
    for c in range(count):
        a, b = np.uint32(contact_body[c, 0]), np.uint32(contact_body[c, 1])  # unsigned: as _contact_power
        ut, _ = _relative_velocity(v, a, b, pack, np.uint64(c))
        out[c] = ut


def contact_power(
    contact_body, pack, r, count, v_old, v_new, model, out_force, out_support_force
) -> tuple[float, float]:
    """World contact forces on body b (C,2) N, support forces (S,2) N; returns (dissipated, support work) J."""
    return _contact_power(
        contact_body,
        pack,
        r,
        count,
        v_old,
        v_new,
        model.body_dynamic,
        model.block_count,
        model.dt,
        out_force,
        out_support_force,
    )


def tangential_velocity(contact_body, pack, count, v) -> np.ndarray:
    """(C,) m/s: u_t of the contacts packed in ``pack`` for body velocities ``v`` (B, 3)."""
    out = np.empty(count)
    _tangential_velocity(contact_body, pack, count, v, out)
    return out
