"""Alart–Curnier semismooth Newton on one step's contact problem: the first of the round-robin's methods
in a stalled solve (Tuning.methods, stalled.py).

Unknowns: the impulses r (C, 2); v(r) = v_free + M⁻¹ H r, u = Hᵀ v(r) (nlgs's notation). Per contact, with
W = W_αα's diagonal entries (W_tt, W_nn; 1/W is Alart–Curnier's step ρ) and the Signorini bias b,

    x   = r_n − (u_n + b) / W_nn
    F_n = W_nn (r_n − max(x, 0))                         (Signorini: r_n ≥ 0 ⊥ u_n + b ≥ 0)
    F_t = W_tt (r_t − clip(y, −s, s)),  y = r_t − u_t / W_tt,  s = μ max(x, 0)   (Coulomb; AC's original
                                                         augmented threshold: the limit opens with x)

F = 0 exactly on nlgs's contact law, in velocity units (m/s per component). Its generalised Jacobian is
F' = A Hᵀ M⁻¹ H + B with A = ∂F/∂u and B = ∂F/∂r upper triangular 2×2 per contact:

    closed (x > 0):               ∂F_n/∂u_n = 1                  else ∂F_n/∂r_n = W_nn
    stick (|y| < s):              ∂F_t/∂u_t = 1                  else ∂F_t/∂r_t = W_tt, and sliding with
                                  x > 0, σ = sign(y):  ∂F_t/∂r_n = −W_tt μ σ,  ∂F_t/∂u_n = W_tt μ σ / W_nn

Hᵀ M⁻¹ H is singular on a hyperstatic wall, so the step is Levenberg–Marquardt shifted, B → B + λ D,
D = diag(W), λ held at LAMBDA. B + λD is invertible per contact, so dr is eliminated and the Newton system is
the 3B velocity system, banded when bodies are numbered by position (one banded LU per Newton step,
:mod:`masonrycli.engine.banded`; the bodies in the order banded.body_order gives, once per resume):

    (M + H (B + λD)⁻¹ A Hᵀ) dv = −H (B + λD)⁻¹ F,    dr = (B + λD)⁻¹ (−F − A Hᵀ dv)

One resume for a budget of U sweep units (stalled.py; the iterate r and λ carry over between resumes):

    while units < newton_shares[k] · U:               (k: this resume's number, the last share after;
                                                       Tuning.newton_shares)
        F = F(r);  K, rhs = the system above, into the band;  dr from its LU   (NEWTON_UNITS)
        α = 1, ½, ¼ … ≥ ALPHA_MIN: accept the first with ½|F(r + α dr)|² ≤ (1 − 2σα) ½|F(r)|²  (Armijo)
        accepted: r += α dr;  λ = max(λ / 4, LAMBDA) if α = 1
        rejected: λ = min(10 λ, LAMBDA_MAX);  WATCHDOG plain engine sweeps from r   (WATCHDOG units)
    the rest of U: momentum sweeps turning at restarts (stalled.py's "turning") from a COPY of r, to the
    tolerance or POLISH_STALL sweeps without a new low: their residual is the engine's measure (nlgs
    module doc), their (v, r, status) the state the method reports (consistent), while the next resume
    goes on from the Newton iterate r

Why: Newton alone converges only linearly near the solution (λ held, short steps), but it gets a stalled
step out of its stick/slip cycle: on the 32-course wall's step that turning sweeps need 21 377 units for,
turning sweeps from the iterate of 10 Newton steps finish in ~1000. Hence 10 Newton steps in a first resume
(newton_shares[0] of stalled.py's 2 × 2000 units) and sweeps from there, 40 in the next (newton_shares[1]),
the iterate going on. First in stalled.py's order, it takes the 98 stalled steps of the 32- and 64-course
walls' first 0.2 s from 408 422 sweep units to 212 312 (0.52×; benchmarks/JOURNAL.md, "Alart–Curnier in the
engine, as a fifth stalled-step method"). It starts from the warm start: from momentum's stalled iterate it
does worse ("Alart–Curnier: globalised semismooth Newton on the full law").

Not on ordinary steps (those momentum converges without stalling): 1.06–4.4× momentum's units on the
248-block wall's, at best 0.985× (noise) on the tall walls' ("Newton-type steps on ordinary steps"): a wall's
solution set is a continuum of self-stresses, and the sweeps' work there is choosing one inside the cone,
which F's Newton step does not do.

Units. A Newton step costs 46–60 turning sweeps of the same step in CPU (the banded assembly, LU and solve),
plus ~4 evaluations of F in its line search at ~1 sweep each: NEWTON_UNITS = 60, a constant so that sweep
counts stay deterministic.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine import banded, interleaved, nlgs
from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import P_BIAS, P_IIA, P_IIB, P_IMA, P_IMB, P_NA, P_NB, P_NX, P_NY, P_TA, P_TB, P_WNN, P_WTT
from masonrycli.engine.tuning import TUNING

LAMBDA = 1e-3
"""Levenberg–Marquardt shift λ (× diag W): the lowest; × 10 after a rejected step, ÷ 4 after a full one."""
LAMBDA_MAX = 1.0
"""The largest shift λ: rejected steps raise it no further."""
SIGMA = 1e-4
"""Armijo's sufficient-decrease constant."""
ALPHA_MIN = 2.0**-10
"""Shortest step the line search tries before the Newton step is rejected."""
WATCHDOG = 20
"""Plain engine sweeps after a rejected Newton step."""
NEWTON_UNITS = 60
"""Sweep units one Newton step counts (module doc, "Units")."""
POLISH_STALL = 1000
"""Sweeps from the Newton iterate without a new lowest residual after which the resume ends (the method is
then dropped by stalled.py's rule, the budget left to the others)."""
# Columns of the per-contact Jacobian pieces (module doc): A = [[a_t, a_tn], [0, a_n]], B = [[b_t, b_tn], [0, b_n]].
J_AT, J_AN, J_ATN, J_BT, J_BN, J_BTN = 0, 1, 2, 3, 4, 5


@njit(inline="always")
def _rows(pack, c):
    # Hᵀ's two rows for contact c on (a's dofs, b's dofs), as nlgs._relative_velocity reads them:
    #   u_t = (v_b − v_a)·t + ω_b (r_b×t) − ω_a (r_a×t),  t = (n_y, −n_x);  u_n likewise with n.
    nx = pack[c, P_NX]
    ny = pack[c, P_NY]
    return (-ny, nx, -pack[c, P_TA], ny, -nx, pack[c, P_TB]), (-nx, -ny, -pack[c, P_NA], nx, ny, pack[c, P_NB])


@njit
def _velocity(contact_body, pack, count, v_free, r, out_v):
    # v = v_free + M⁻¹ H r (nlgs._push of every impulse).
    out_v[:] = v_free
    for c in range(count):
        nlgs._push(out_v, contact_body[c, 0], contact_body[c, 1], pack, c, r[c, 0], r[c, 1])


@njit
def _phi(contact_body, pack, count, mu, v, r, out_f, out_jac):
    # F(r) per contact (module doc) at velocities v = v(r), its Jacobian pieces in out_jac (C, 6);
    # returns the merit ½|F|².
    merit = 0.0
    for c in range(count):
        ut, un = nlgs._relative_velocity(v, contact_body[c, 0], contact_body[c, 1], pack, c)
        wt = pack[c, P_WTT]
        wn = pack[c, P_WNN]
        rt = r[c, 0]
        rn = r[c, 1]
        x = rn - (un + pack[c, P_BIAS]) / wn
        closed = x > 0.0
        s = mu * x if closed else 0.0
        y = rt - ut / wt
        stick = abs(y) < s
        ft = wt * (rt - min(max(y, -s), s))
        fn = wn * (rn - (x if closed else 0.0))
        out_f[c, 0] = ft
        out_f[c, 1] = fn
        merit += 0.5 * (ft * ft + fn * fn)
        sy = 1.0 if y > 0.0 else (-1.0 if y < 0.0 else 0.0)
        slide = closed and not stick
        out_jac[c, J_AT] = 1.0 if stick else 0.0
        out_jac[c, J_AN] = 1.0 if closed else 0.0
        out_jac[c, J_ATN] = wt / wn * mu * sy if slide else 0.0
        out_jac[c, J_BT] = 0.0 if stick else wt
        out_jac[c, J_BN] = 0.0 if closed else wn
        out_jac[c, J_BTN] = -wt * mu * sy if slide else 0.0
    return merit


@njit
def _merit(contact_body, pack, count, mu, v_free, r, v_work, f_work, jac_work):
    # ½|F(r)|² (the line search's test): v(r), then F.
    _velocity(contact_body, pack, count, v_free, r, v_work)
    return _phi(contact_body, pack, count, mu, v_work, r, f_work, jac_work)


@njit
def _system(contact_body, pack, count, lam, f, jac, body_count, position, w, band, rhs):
    # K = M + H G Hᵀ into the band (banded.py's storage, half-bandwidth w dofs), rhs = −H (B + λD)⁻¹ F, over
    # the 3B velocity dofs with body x's at 3 position[x] + (0, 1, 2); per contact
    #   B' = B + λ diag(W_tt, W_nn),  G = B'⁻¹ A = [[a_t/b_t, a_tn/b_t − b_tn a_n/(b_t b_n)], [0, a_n/b_n]]
    #   K += h_iᵀ G_ij h_j over the 6 dofs of (a, b) that move (a support's inverse mass is 0: its rows stay
    #   the identity, its rhs 0, so dv = 0 there), K_dd = m (1/inverse mass) or 1 for a body that cannot move.
    band[:, :] = 0.0
    for d in range(3 * body_count):
        band[d, w] = 1.0
        rhs[d] = 0.0
    for c in range(count):
        for side in range(2):
            x = contact_body[c, side]
            im = pack[c, P_IMA] if side == 0 else pack[c, P_IMB]
            ii = pack[c, P_IIA] if side == 0 else pack[c, P_IIB]
            if im > 0.0:
                d = 3 * position[x]
                band[d, w] = 1.0 / im
                band[d + 1, w] = 1.0 / im
                band[d + 2, w] = 1.0 / ii
    ht = np.empty(6, np.float64)
    hn = np.empty(6, np.float64)
    dof = np.empty(6, np.int64)
    moves = np.empty(6, np.bool_)
    for c in range(count):
        a = contact_body[c, 0]
        b = contact_body[c, 1]
        rt_, rn_ = _rows(pack, c)
        for k in range(6):
            ht[k] = rt_[k]
            hn[k] = rn_[k]
            dof[k] = 3 * position[a] + k if k < 3 else 3 * position[b] + k - 3
            moves[k] = pack[c, P_IMA] > 0.0 if k < 3 else pack[c, P_IMB] > 0.0
        bt = jac[c, J_BT] + lam * pack[c, P_WTT]
        bn = jac[c, J_BN] + lam * pack[c, P_WNN]
        gt = jac[c, J_AT] / bt
        gn = jac[c, J_AN] / bn
        gtn = jac[c, J_ATN] / bt - jac[c, J_BTN] * jac[c, J_AN] / (bt * bn)
        zn = f[c, 1] / bn  # z = B'⁻¹ F (upper triangular)
        zt = (f[c, 0] - jac[c, J_BTN] * zn) / bt
        for i in range(6):
            if not moves[i]:
                continue
            rhs[dof[i]] -= ht[i] * zt + hn[i] * zn
            # row i of Hᵀ… : (h_t,i, h_n,i) G (h_t,j, h_n,j)ᵀ
            left_t = ht[i] * gt
            left_n = ht[i] * gtn + hn[i] * gn
            for j in range(6):
                if not moves[j]:
                    continue
                band[dof[i], dof[j] - dof[i] + w] += left_t * ht[j] + left_n * hn[j]


@njit
def _direction(contact_body, pack, count, lam, f, jac, body_count, position, w, band, rhs, dv, out_dr):
    # dv from the banded system (position order), back to body order, then dr. False on a zero pivot (banded.py).
    _system(contact_body, pack, count, lam, f, jac, body_count, position, w, band, rhs)
    n = 3 * body_count
    if banded.band_lu(band, n, w) >= 0:
        return False
    banded.band_solve(band, n, w, rhs)
    for x in range(body_count):
        for k in range(3):
            dv[x, k] = rhs[3 * position[x] + k]
    _step_back(contact_body, pack, count, lam, f, jac, dv, out_dr)
    return True


@njit
def _step_back(contact_body, pack, count, lam, f, jac, dv, out_dr):
    # dr = B'⁻¹ (−F − A Hᵀ dv) per contact.
    for c in range(count):
        ut, un = nlgs._relative_velocity(dv, contact_body[c, 0], contact_body[c, 1], pack, c)
        bt = jac[c, J_BT] + lam * pack[c, P_WTT]
        bn = jac[c, J_BN] + lam * pack[c, P_WNN]
        xt = -f[c, 0] - jac[c, J_AT] * ut - jac[c, J_ATN] * un
        xn = -f[c, 1] - jac[c, J_AN] * un
        drn = xn / bn
        out_dr[c, 0] = (xt - jac[c, J_BTN] * drn) / bt
        out_dr[c, 1] = drn


class Band:
    """The work arrays of banded Newton steps on one step's problem: the body order and half-bandwidth
    (banded.body_order), the band (3B, 2w + 1), the right-hand side and dv."""

    def __init__(self, contact_body, pack, count, bodies):
        coupled = (pack[:count, P_IMA] > 0.0) & (pack[:count, P_IMB] > 0.0)
        self.position, width = banded.body_order(contact_body[:count], coupled, bodies)
        self.w = 3 * width + 2  # a body's 3 dofs and its neighbour's at most width bodies away
        self.band = np.empty((3 * bodies, 2 * self.w + 1))
        self.rhs = np.empty(3 * bodies)
        self.dv = np.empty((bodies, 3))


def newton_direction(contact_body, pack, count, v_free, f, jac, lam=LAMBDA, band=None):
    """dr (C, 2) of the shifted Newton system (module doc) at F = ``f`` (C, 2) with Jacobian pieces ``jac``,
    or None if the banded elimination meets a zero pivot. ``band``: a :class:`Band` of this problem to reuse."""
    bodies = v_free.shape[0]
    band = band or Band(contact_body, pack, count, bodies)
    dr = np.empty((count, 2))
    ok = _direction(
        contact_body, pack, count, lam, f, jac, bodies, band.position, band.w, band.band, band.rhs, band.dv, dr
    )
    return dr if ok else None


def newton_matrix(contact_body, pack, count, bodies, f, jac, lam=LAMBDA):
    """(K (3B × 3B dense, body order), rhs (3B,)) of the velocity system, for tests."""
    band = Band(contact_body, pack, count, bodies)
    _system(contact_body, pack, count, lam, f, jac, bodies, band.position, band.w, band.band, band.rhs)
    n, w = 3 * bodies, band.w
    dofs = (3 * band.position[:, None] + np.arange(3)).ravel()  # body order → band order
    dense = np.zeros((n, n))
    for i in range(n):
        lo, hi = max(0, i - w), min(n - 1, i + w)
        dense[i, lo : hi + 1] = band.band[i, lo - i + w : hi - i + w + 1]
    return dense[np.ix_(dofs, dofs)], band.rhs[dofs]


def phi(contact_body, pack, count, mu, v_free, r):
    """(F (C, 2) m/s, Jacobian pieces (C, 6), merit ½|F|²) at impulses ``r``."""
    v = np.empty_like(v_free)
    f, jac = np.empty((count, 2)), np.empty((count, 6))
    _velocity(contact_body, pack, count, v_free, r, v)
    merit = _phi(contact_body, pack, count, mu, v, r, f, jac)
    return f, jac, merit


def _newton_step(contact_body, pack, count, mu, v_free, r, status, shift, band, work, f, jac, ft, jt) -> int:
    # One globalised Newton step from r (in place; module doc); returns the units it counts.
    merit = _merit(contact_body, pack, count, mu, v_free, r, work, f, jac)
    dr = newton_direction(contact_body, pack, count, v_free, f, jac, shift[0], band)  # None: rejected
    alpha = 1.0
    while dr is not None and alpha >= ALPHA_MIN:
        trial = r + alpha * dr
        if _merit(contact_body, pack, count, mu, v_free, trial, work, ft, jt) <= (1.0 - 2.0 * SIGMA * alpha) * merit:
            r[:] = trial
            if alpha == 1.0:
                shift[0] = max(shift[0] / 4.0, LAMBDA)
            return NEWTON_UNITS
        alpha *= 0.5
    # a poor model: shift more, and let plain sweeps move r where the line search could not
    shift[0] = min(10.0 * shift[0], LAMBDA_MAX)
    work[:] = v_free
    interleaved.sweeps(contact_body, pack, count, mu, 0.0, WATCHDOG, work, r, status, interleaved.PLAIN)
    return NEWTON_UNITS + WATCHDOG


def newton_steps(
    contact_body,
    pack,
    count,
    mu,
    tolerance,
    units,
    limit,
    v_free,
    r,
    r_out,
    v,
    status,
    shift,
    share=TUNING.newton_shares[0],
) -> tuple[int, float]:
    """One resume of the method (module doc) for a budget of ``units`` sweep units, never beyond ``limit``
    (the step's cap): Newton steps from the iterate ``r`` (C, 2, updated in place) for ``share`` of the
    budget, then turning momentum sweeps from a copy of it for the rest, until ``tolerance`` or a stall of
    POLISH_STALL sweeps. ``r_out``,
    ``v``, ``status`` get the sweeps' state (consistent: v = v_free + M⁻¹ H r_out). ``shift``: [λ], carried
    from resume to resume. Returns (units done, the sweeps' residual m/s)."""
    done = 0
    residual = np.inf
    f, jac = np.empty((count, 2)), np.empty((count, 6))
    ft, jt = np.empty((count, 2)), np.empty((count, 6))
    work = np.empty_like(v_free)
    band = Band(contact_body, pack, count, v_free.shape[0])
    args = (contact_body, pack, count, mu, v_free, r, status, shift, band, work, f, jac, ft, jt)
    while done < units * share and done + NEWTON_UNITS + WATCHDOG + 1 <= limit:
        done += _newton_step(*args)
    sweeps = min(max(units - done, 1), limit - done)
    if sweeps > 0:
        r_out[:] = r
        v[:] = v_free
        d, residual = interleaved.sweeps(
            contact_body, pack, count, mu, tolerance, sweeps, v, r_out, status, interleaved.TURNING, POLISH_STALL
        )
        done += d
    return done, residual
