"""Nonlinear Gauss–Seidel on the Signorini–Coulomb problem, with the exact 2×2 local solve.

Per contact α between bodies a < b, in the contact frame (t, n) of :mod:`masonrycli.engine.contact`:

    u_α = H_αᵀ v             relative velocity of b with respect to a at the contact point
    v   = v_free + M⁻¹ H r   (impulse r_α acts on b, −r_α on a)

Contact law (inelastic shocks, the gap-predicted Signorini condition of DESIGN.md §2):

    r_n ≥ 0,  u_n + max(g_m, 0)/dt ≥ 0,  r_n · (u_n + max(g_m, 0)/dt) = 0
    |r_t| ≤ μ r_n,  u_t = 0 while |r_t| < μ r_n,  r_t = −μ r_n sign(u_t) when sliding

A contact already penetrating (g_m < 0) is only stopped, never pushed out: pushing out injects energy.

Stopping test (physical units). When the sweep reaches contact α, the local solve moves its relative
velocity by e_α = W_αα (r_α' − r_α): |e_α| is how far α violated the contact law (m/s) at that moment —
0 when its law already held. The residual of a sweep is the root mean square over the step's C
contacts,

    residual = sqrt(Σ_α |e_α|² / C)   (m/s)

and the solve stops after the first sweep with residual ≤ tolerance (default 1e-5 m/s, a thousandth of
the velocity gravity adds in a 1 ms step), or at the sweep cap (then the step is unconverged and is
counted as such). Measured on walls of 8–32 courses (benchmarks/JOURNAL.md, "Choosing the stopping test"): the old test, the relative
change of the impulses, stops on stagnation and is ~10x looser in tall walls than on one block; the
largest violation instead of the RMS plateaus near 1e-5 m/s on single corner contacts and never meets a
tight tolerance. The RMS is not a bound on the block velocities' error: Gauss–Seidel moves load about
one course per sweep, and a slow mode can keep velocities 1e-4 m/s off while each sweep corrects little.

Stagnation. On tall walls that slide (32 courses and more, shaken at 1 m/s) Gauss–Seidel can cycle: at
step 74 of the 32-course wall the residual wanders between 7.7e-5 and 2.3e-4 m/s for 50 000 sweeps while
hundreds of sliding bed-joint corners change status (benchmarks/JOURNAL.md, "Sweep order"), and sweeping
such steps to the cap cost half of that wall's run time. So when a solve with a tolerance > 0 goes
PLAIN_STALL sweeps without a new lowest residual, dispatch.solve continues it by faces (:mod:`masonrycli.engine.faces`:
the points of each face solved together, which does not cycle there) until the tolerance, the cap (counted
in sweep units), or the faces stall in turn; a step that still misses the tolerance is counted unconverged
as at the cap. A slowly converging step keeps reaching new lows and is not handed over. Tolerance 0 runs
exactly the cap.

The solve of a step (which sweeps, the faces after a stall, the accelerated solvers' first stage and
stalled steps) is :func:`masonrycli.engine.dispatch.solve`; this module holds the primitives every sweep is
made of (the packed constants, the local solve, one contact's visit) and the plain sweep.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import kernel_only, njit
from masonrycli.engine.contact import ContactStatus

PLAIN_STALL = 10_000
"""Point sweeps without a new lowest residual after which a solve with a tolerance > 0 continues by faces
(module doc, "Stagnation"); 2000 handed over slowly converging steps (golden histories changed)."""

# Plain ints for the kernels (the enum is for readers).
STATUS_OPEN, STATUS_STICK, STATUS_SLIP = int(ContactStatus.OPEN), int(ContactStatus.STICK), int(ContactStatus.SLIP)


# Columns of the packed per-contact array built by _prepare and read by every NLGS sweep. Packing the
# contact's constants in one row (instead of a dozen arrays) and precomputing inverses keeps the sweep
# free of divisions and of lever-arm rotations: ~3x faster than recomputing them per sweep.
P_NX, P_NY = 0, 1  # unit normal a → b (t from n as in masonrycli.engine.contact)
P_TA, P_NA = 2, 3  # r_a × t, r_a × n   (m): moment arms of a unit t / n impulse on body a
P_TB, P_NB = 4, 5  # r_b × t, r_b × n
P_WTT, P_WTN, P_WNN = 6, 7, 8  # Delassus block W_αα (1/kg)
P_BIAS = 9  # max(g_m, 0)/dt (m/s)
P_ITT, P_ITN, P_INN = 10, 11, 12  # W_αα⁻¹
P_ISP, P_ISM = 13, 14  # 1/(W_nn − μ W_tn), 1/(W_nn + μ W_tn): sliding with s = +1 / −1 (0 if ≤ 0)
P_IMA, P_IIA, P_IMB, P_IIB = 15, 16, 17, 18  # inverse masses and inertias of a and b
PACK_WIDTH = 19


@njit
def _prepare(
    contact_body,
    contact_point,
    contact_normal,
    contact_gap,
    count,
    body_q,
    inv_mass,
    inv_inertia,
    mu,
    dt,
    out_pack,
):
    # For each contact: lever arms from the centroids (at the detection configuration q_m) to the
    # contact point; their moments about t and n; the Delassus diagonal block
    #   W_ij = Σ_{a,b} (m⁻¹ dᵢ·dⱼ + I⁻¹ (r×dᵢ)(r×dⱼ)),  d = (t, n)
    # its inverse, the two sliding denominators, and the Signorini bias max(g, 0)/dt.
    for c in range(count):
        a = contact_body[c, 0]
        b = contact_body[c, 1]
        nx = contact_normal[c, 0]
        ny = contact_normal[c, 1]
        tx = ny  # the contact frame of masonrycli.engine.contact
        ty = -nx
        rax = contact_point[c, 0] - body_q[a, 0]
        ray = contact_point[c, 1] - body_q[a, 1]
        rbx = contact_point[c, 0] - body_q[b, 0]
        rby = contact_point[c, 1] - body_q[b, 1]
        ta = rax * ty - ray * tx
        na = rax * ny - ray * nx
        tb = rbx * ty - rby * tx
        nb = rbx * ny - rby * nx
        ima = inv_mass[a]
        iia = inv_inertia[a]
        imb = inv_mass[b]
        iib = inv_inertia[b]
        wtt = ima + imb + iia * ta * ta + iib * tb * tb
        wtn = iia * ta * na + iib * tb * nb
        wnn = ima + imb + iia * na * na + iib * nb * nb
        det = wtt * wnn - wtn * wtn
        out_pack[c, P_NX] = nx
        out_pack[c, P_NY] = ny
        out_pack[c, P_TA] = ta
        out_pack[c, P_NA] = na
        out_pack[c, P_TB] = tb
        out_pack[c, P_NB] = nb
        out_pack[c, P_WTT] = wtt
        out_pack[c, P_WTN] = wtn
        out_pack[c, P_WNN] = wnn
        g = contact_gap[c]
        out_pack[c, P_BIAS] = g / dt if g > 0.0 else 0.0
        if det > 0.0:
            out_pack[c, P_ITT] = wnn / det
            out_pack[c, P_ITN] = -wtn / det
            out_pack[c, P_INN] = wtt / det
        else:  # degenerate (never for finite masses): the stick branch is skipped
            out_pack[c, P_ITT] = 0.0
            out_pack[c, P_ITN] = 0.0
            out_pack[c, P_INN] = 0.0
        dp = wnn - mu * wtn
        dm = wnn + mu * wtn
        out_pack[c, P_ISP] = 1.0 / dp if dp > 0.0 else 0.0
        out_pack[c, P_ISM] = 1.0 / dm if dm > 0.0 else 0.0
        out_pack[c, P_IMA] = ima
        out_pack[c, P_IIA] = iia
        out_pack[c, P_IMB] = imb
        out_pack[c, P_IIB] = iib


@njit(inline="always")
def _local_solve(ut, un, pack, c, mu):
    # Inlined by numba into each sweep (inline="always"): left to LLVM it stayed a call, with the row
    # passed on the stack and the result through memory, and the sweep's registers spilled around it
    # (1.25× the time per contact·sweep of the inlined sweep on captured steps of the 248-block wall).
    # Exact solution of the 2×2 Signorini–Coulomb problem u = u_free + W r,
    # enumerating the cases (pack[c]: the contact's packed row):
    #   open:   r = 0 if u_free_n + bias ≥ 0
    #   stick:  u = (0, −bias) → r = W⁻¹(−u_t, −bias − u_n), valid if r_n ≥ 0 and |r_t| ≤ μ r_n
    #   slide:  r_t = −s μ r_n (s = ±1, the sliding direction), u_n = −bias fixes r_n,
    #           valid if s·u_t ≥ 0 afterwards
    # Returns (r_t, r_n, status).
    bias = pack[c, P_BIAS]
    if un + bias >= 0.0:
        return 0.0, 0.0, STATUS_OPEN
    target = -bias - un  # > 0: the normal velocity change needed
    if pack[c, P_INN] > 0.0:
        rt = -pack[c, P_ITT] * ut + pack[c, P_ITN] * target
        rn = -pack[c, P_ITN] * ut + pack[c, P_INN] * target
        if rn >= 0.0 and abs(rt) <= mu * rn:
            return rt, rn, STATUS_STICK
    # Try the free sliding direction first; the t–n coupling W_tn can reverse it, so then the other.
    s0 = 1.0 if ut >= 0.0 else -1.0
    for k in range(2):
        s = s0 if k == 0 else -s0
        inv = pack[c, P_ISP] if s > 0.0 else pack[c, P_ISM]
        if inv <= 0.0:
            continue
        rn = target * inv
        rt = -s * mu * rn
        slip = ut + pack[c, P_WTT] * rt + pack[c, P_WTN] * rn
        if s * slip >= 0.0:
            return rt, rn, STATUS_SLIP
    # Unreachable for μ ≥ 0 and a positive definite W; keep the normal solve and project friction.
    rn = target / pack[c, P_WNN]
    rt = -ut / pack[c, P_WTT]
    lim = mu * rn
    if rt > lim:
        rt = lim
    elif rt < -lim:
        rt = -lim
    return rt, rn, STATUS_SLIP


@kernel_only
def _relative_velocity(v, a, b, pack, c):
    # u = H_αᵀ v: b's contact point velocity minus a's, on (t, n); with t = (n_y, −n_x),
    #   u_t = (v_b − v_a)·t + ω_b (r_b×t) − ω_a (r_a×t),   u_n likewise with n.
    nx = pack[c, P_NX]
    ny = pack[c, P_NY]
    dvx = v[b, 0] - v[a, 0]
    dvy = v[b, 1] - v[a, 1]
    ut = dvx * ny - dvy * nx + v[b, 2] * pack[c, P_TB] - v[a, 2] * pack[c, P_TA]
    un = dvx * nx + dvy * ny + v[b, 2] * pack[c, P_NB] - v[a, 2] * pack[c, P_NA]
    return ut, un


@kernel_only
def _push(v, a, b, pack, c, drt, drn):
    # v_b += M_b⁻¹ H_b Δr, v_a −= M_a⁻¹ H_a Δr  (impulse Δr_t t + Δr_n n at the contact point).
    # Branch-free: a support's inverse mass and inertia are 0, so it gets +0 (its imposed velocity
    # stays bit-identical) and the sweep has no unpredictable branch.
    nx = pack[c, P_NX]
    ny = pack[c, P_NY]
    px = drt * ny + drn * nx
    py = -drt * nx + drn * ny
    ima = pack[c, P_IMA]
    v[a, 0] -= ima * px
    v[a, 1] -= ima * py
    v[a, 2] -= pack[c, P_IIA] * (pack[c, P_TA] * drt + pack[c, P_NA] * drn)
    imb = pack[c, P_IMB]
    v[b, 0] += imb * px
    v[b, 1] += imb * py
    v[b, 2] += pack[c, P_IIB] * (pack[c, P_TB] * drt + pack[c, P_NB] * drn)


@njit
def _nlgs(contact_body, pack, count, mu, tolerance, max_iterations, v, r, status, alternate=False):
    # v enters as v_free and leaves as v_n+1; r enters as the warm start and leaves as the solution.
    #   v ← v_free + M⁻¹ H r_warm
    #   repeat (one sweep):
    #       for α in order (alternate: every second sweep in reverse order — what a stalled accelerated
    #       solve uses, since it breaks the stick/slip cycles of the one-way sweep; stalled.py):
    #                       u_free = H_αᵀ v − W_αα r_α ; r_α' = local_solve(u_free)
    #                       e_α = W_αα (r_α' − r_α)      (m/s: α's violation of its law at the visit)
    #                       v += M⁻¹ H_α (r_α' − r_α)
    #       residual = sqrt(Σ_α |e_α|² / C)
    #   until residual ≤ tolerance, or the cap, or (tolerance > 0) PLAIN_STALL sweeps in a row without
    #   a new lowest residual: sweeping on would only cycle (module doc), dispatch.solve goes on by faces.
    for c in range(count):
        # c unsigned as in the sweep below: one compiled _push serves both
        _push(v, contact_body[c, 0], contact_body[c, 1], pack, np.uint64(c), r[c, 0], r[c, 1])
    iterations = 0
    residual = 0.0
    if count == 0:
        return iterations, residual
    best = np.inf
    best_at = 0
    for it in range(max_iterations):
        iterations = it + 1
        sum_e2 = 0.0
        first, step = 0, 1
        if alternate and it % 2 == 1:
            first, step = count - 1, -1
        for k in range(count):
            c = np.uint64(first + step * k)  # unsigned: no wrap-around test per row access (momentum.py)
            a = contact_body[c, 0]
            b = contact_body[c, 1]
            ut, un = _relative_velocity(v, a, b, pack, c)
            rt0 = r[c, 0]
            rn0 = r[c, 1]
            wtt = pack[c, P_WTT]
            wtn = pack[c, P_WTN]
            wnn = pack[c, P_WNN]
            ut -= wtt * rt0 + wtn * rn0
            un -= wtn * rt0 + wnn * rn0
            rt, rn, st = _local_solve(ut, un, pack, c, mu)
            status[c] = st
            drt = rt - rt0
            drn = rn - rn0
            if drt != 0.0 or drn != 0.0:
                _push(v, a, b, pack, c, drt, drn)
                r[c, 0] = rt
                r[c, 1] = rn
                et = wtt * drt + wtn * drn
                en = wtn * drt + wnn * drn
                sum_e2 += et * et + en * en
        residual = np.sqrt(sum_e2 / count)
        if residual <= tolerance:
            break
        if residual < best:
            best = residual
            best_at = it
        elif tolerance > 0.0 and it - best_at >= PLAIN_STALL:
            break
    return iterations, residual


INTERLEAVE = 4
"""The scalar sweeps visit the contacts in this many interleaved runs of detection order (:mod:`.interleaved`)."""


def prepare_contacts(contact_body, contact_point, contact_normal, contact_gap, count, body_q, model, out_pack) -> None:
    """The packed per-contact constants ``out_pack`` (C, PACK_WIDTH) at configuration ``body_q``:
    frame, moment arms (m), W_αα (1/kg) and its inverse, sliding denominators, Signorini bias (m/s)."""
    _prepare(
        contact_body,
        contact_point,
        contact_normal,
        contact_gap,
        count,
        body_q,
        model.body_inv_mass,
        model.body_inv_inertia,
        model.friction,
        model.dt,
        out_pack,
    )
