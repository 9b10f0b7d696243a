"""Per-step collapse indicators in one pass over blocks and contacts (read by :mod:`masonrycli.analysis.collapse`).

After each step the collapse monitor needs a handful of maxima: the fastest turning block, the
fastest sliding closed contact, the deepest fall below the supports' settlement and the largest turn
relative to each block's own height, and the mean horizontal displacement of the top blocks. One kernel computes them all so the
watch costs a few microseconds a step.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import _relative_velocity


@njit
def _watch(body_q, body_v, q0, height, n, top, contact_body, pack, status, count):
    # settlement s = max(0, max over supports i ≥ n of y0_i − y_i)   (0 if a support's is NaN, or none)
    # for each block i < n:   rock = max |ω_i|,  fall = max ((y0_i − s) − y_i) / h_i,  turn = max |θ_i|
    # for each closed contact: u_t = (v_b(I) − v_a(I)) · t (nlgs._relative_velocity);  slide = max |u_t|
    # top_dx = mean over the top blocks of x_i − x0_i
    # The settlement was numpy's in CollapseMonitor.update (a slice, a difference, a max: ~6 µs a step on
    # the 248-block wall, the kernel's whole work took as long); the same operations, so the same bits.
    low = -np.inf
    nan = False
    for i in range(n, body_q.shape[0]):
        d = q0[i, 1] - body_q[i, 1]
        if d != d:
            nan = True
        elif d > low:
            low = d
    settlement = low if (low > 0.0 and not nan) else 0.0
    rock = 0.0
    fall = -np.inf
    turn = 0.0
    for i in range(n):
        rock = max(rock, abs(body_v[i, 2]))
        fall = max(fall, ((q0[i, 1] - settlement) - body_q[i, 1]) / height[i])
        turn = max(turn, abs(body_q[i, 2]))
    slide = 0.0
    for c in range(count):
        if status[c] == 0:  # open
            continue
        a, b = np.uint32(contact_body[c, 0]), np.uint32(contact_body[c, 1])  # unsigned: power._contact_power
        ut, _ = _relative_velocity(body_v, a, b, pack, np.uint64(c))
        slide = max(slide, abs(ut))
    top_dx = 0.0
    for k in range(top.shape[0]):
        top_dx += body_q[top[k], 0] - q0[top[k], 0]
    if top.shape[0]:
        top_dx /= top.shape[0]
    return rock, slide, fall, turn, top_dx


def watch_step(solver, body_q, body_v, q0, height, top) -> tuple[float, float, float, float, float]:
    """Collapse indicators after ``solver``'s last step.

    body_q, body_v : (B, 3) state after the step.  q0 : (B, 3) initial configuration.
    height : (N,) m, block heights as built.  top : (K,) int64 indices of the top blocks.
    Returns (max |ω| rad/s, max |u_t| of closed contacts m/s, max fall / height, max |θ| rad,
    mean x displacement of the top blocks m). The fall is measured from q0 lowered by the supports'
    settlement (max(0, max of y0 − y over the supports, rows N: of body_q), 0 if one is NaN): a block
    riding a settling support has not fallen.
    """
    # the step's contacts through the Solver's public views (rows [:C], C-contiguous: the kernel's types)
    body, pack, status = solver.contact_body, solver.contact_pack, solver.contact_status
    return _watch(body_q, body_v, q0, height, height.shape[0], top, body, pack, status, status.shape[0])
