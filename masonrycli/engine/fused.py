"""The small kernels of a time step fused into one call before the contact solve and one after.

On the 51-block wall a step outside the solve made a dozen launcher calls of 1–5 µs each (argument
unboxing, shape checks, the Python between them) around kernels of a few µs: the calls cost more than
the work. The kernels are the same (:mod:`.integrate`, :mod:`.collision`, :mod:`.warmstart`), called in
the same order on the same arrays, so a step's numbers do not change. The contact constants, the solve
and the contact powers keep their own launchers (nlgs.prepare_contacts, dispatch.solve,
power.contact_power). Whatever the fused call does not handle (the first detection, a capacity exceeded, a
pose not finite) it hands back, and the step goes through the launchers one by one as before (:meth:`masonrycli.engine.solver.Solver.step`).
"""

from __future__ import annotations

from masonrycli.engine._jit import njit
from masonrycli.engine.collision import _detect
from masonrycli.engine.integrate import _begin_step, _free_velocity, _update_q
from masonrycli.engine.warmstart import _remember, _warm_start


@njit
def _before_solve(
    body_q, body_v, body_radius, dt, theta, gravity, alert, body_vert_start, vert_local, body_dynamic,
    support_v_next, block_count, q_m, v_old, applied,
    vert_world, body_aabb, axis, body_order, pair_body, pair_scratch, counter, edge_normal, body_size,
    contact_body, contact_point, contact_normal, contact_gap, contact_key,
    prev_key, prev_r, r,
):  # fmt: skip
    # q_m = q_n + (1 − θ) dt v_n, v_old = v_n, top point speed       _begin_step
    # distance = alert + 2·dt·top                                   (Solver.detection_distance)
    # contacts at q_m within distance                                _detect → (P, C)
    #     C < 0 or C beyond the capacity of r: return, the launchers take over from here
    # r ← the previous step's impulses by contact key                _warm_start → hits
    # v ← v_free                                                     _free_velocity
    # Returns (P, C, hits, distance).
    top = _begin_step(body_q, body_v, body_radius, dt, theta, q_m, v_old)
    distance = alert + 2.0 * dt * top
    pairs, count = _detect(
        q_m, body_vert_start, vert_local, body_dynamic, distance,
        vert_world, body_aabb, axis, body_order, pair_body, pair_scratch, counter, edge_normal, body_size,
        contact_body, contact_point, contact_normal, contact_gap, contact_key,
    )  # fmt: skip
    if count < 0 or count > r.shape[0]:
        return pairs, -1, 0, distance
    hits = _warm_start(contact_key, count, prev_key, prev_r, r)
    _free_velocity(v_old, body_dynamic, gravity, dt, support_v_next, block_count, body_v, body_q, applied)
    return pairs, count, hits, distance


@njit
def _after_solve(body_q, v_old, body_v, dt, theta, block_count, contact_key, r, contact_gap, count, out_key, out_r):
    # q_n+1 = q_n + dt (θ v_n+1 + (1 − θ) v_n), top block speed (NaN if not finite)    _update_q
    # keys and impulses kept, sorted by key, for the next step                          _remember
    # penetration = max(0, −min gap) (0 without contacts, or if a gap is NaN, as max(0.0, nan))
    # Returns (top block speed, penetration).
    speed = _update_q(body_q, v_old, body_v, dt, theta, block_count)
    _remember(contact_key, r, count, out_key, out_r)
    if count == 0:
        return speed, 0.0
    lowest = contact_gap[0]
    for c in range(1, count):
        g = contact_gap[c]
        if g != g:
            return speed, 0.0
        if g < lowest:
            lowest = g
    depth = -lowest
    return speed, depth if depth > 0.0 else 0.0


def before_solve(m, bf, warm, state, support_v_next, q_m, v_old, r) -> tuple[int, int, float] | None:
    """Begin a step of model ``m`` on ``state`` up to the solve: q_m, contacts, warm start, v_free.

    In: the Solver's arrays — ``bf`` its ContactBuffers (contacts written, count set), ``warm`` its
    warmstart.WarmStart (the previous step's keys and impulses), ``q_m`` (B, 3) out: the detection
    configuration, ``v_old`` (B, 3) out: v_n, ``r`` (C_cap, 2) N·s out: the warm start. Returns (contacts,
    warm-started contacts, detection distance), or None when the launchers must detect (the first
    detection, new arrays, a capacity exceeded, a pose not finite): q_m is then written and the distance is
    Solver.detection_distance of it."""
    if not bf.checked_for(m.vert_local, m.body_dynamic, m.body_vert_start):
        return None
    pairs = bf.pairs
    pair_count, count, hits, distance = _before_solve(
        state.body_q, state.body_v, m.body_radius, m.dt, m.theta, m.gravity, m.alert_distance,
        m.body_vert_start, m.vert_local, m.body_dynamic, support_v_next, m.block_count,
        q_m, v_old, m.block_applied,
        bf.vert_world, bf.body_aabb, pairs.axis, pairs.body_order, pairs.pair_body, pairs.pair_scratch,
        pairs.body_counter, bf.edge_normal, bf.body_size,
        bf.contact_body, bf.contact_point, bf.contact_normal, bf.contact_gap, bf.contact_key,
        warm.key, warm.r, r,
    )  # fmt: skip
    if count < 0:
        return None
    pairs.pair_count = pair_count
    bf.contact_count = count
    return count, hits, distance


def after_solve(m, bf, warm, state, count: int, v_old, r) -> tuple[float, float]:
    """End a step of model ``m`` after the solve: q_n+1 in ``state`` (θ-method from ``v_old``, v_n), the
    ``count`` contacts' keys (``bf``) and impulses ``r`` kept in ``warm`` for the next warm start. Returns (top
    block speed m/s, NaN if a block's q or v is not finite; largest penetration m, ≥ 0)."""
    keep_key, keep_r = warm.reserve(count)  # what the next step's warm start reads
    speed, depth = _after_solve(
        state.body_q, v_old, state.body_v, m.dt, m.theta, m.block_count,
        bf.contact_key, r, bf.contact_gap, count, keep_key, keep_r,
    )  # fmt: skip
    return speed, depth
