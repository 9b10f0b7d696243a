"""A primal–dual interior-point method (Mehrotra predictor–corrector) for the per-step contact problem.

In 2-D the Coulomb cone is polyhedral: K = {r : |r_t| ≤ μ r_n} is spanned by the two rays e± = (±μ, 1)
(in (t, n)), so r = λ₊ e₊ + λ₋ e₋ with λ ≥ 0, and its dual cone is K* = {w : w_n ± μ w_t ≥ 0}. With the
De Saxcé shift s_α ≥ 0 frozen (added to the normal velocity bias), the step is the convex QP in the
blocks' velocities x (the dynamic dofs; supports keep their imposed v_free)

    min ½ (x − x_free)ᵀ M (x − x_free)   subject to   z = A x + c ≥ 0,
    A = E H (rows w_n + μ w_t and w_n − μ w_t of each contact),  c_α = bias_α + s_α (+ the supports' part),

whose multipliers are λ: M (x − x_free) = Aᵀ λ, i.e. v = v_free + M⁻¹ Hᵀ r(λ), r_t = μ (λ₊ − λ₋),
r_n = λ₊ + λ₋. Complementarity z ∘ λ = 0 with s_α = μ |u_t,α| is exactly the contact law of DESIGN.md §2:
a sliding contact has u_n + bias + μ|u_t| = μ|u_t| (no dilatancy), a sticking one u = (0, −bias).
W = H M⁻¹ Hᵀ is never formed (it is singular on hyperstatic walls: the impulses are not unique).

One Mehrotra iteration (x is always recomputed from λ, so the dual residual is 0 and v = v(r) exactly):

    rp = A x + c − z ;  D = λ / z
    K = M + Aᵀ D A = M + Σ_α J_αᵀ G_α J_α,  G_α = Eᵀ diag(d₊, d₋) E   (banded: bodies in body order)
    predictor:  K dx = −Aᵀ (λ + D rp) ;  dz = A dx + rp ;  dλ = −λ − D dz
    σ = (μ_aff / μ_c)³,  μ_c = zᵀλ / m
    corrector:  g = λ + (dz_a ∘ dλ_a − σ μ_c) / z ;  K dx = −Aᵀ (g + D rp) ;  dz = A dx + rp ; dλ = −g − D dz
    step α = min(1, 0.995 · largest step keeping z, λ > 0) on (λ, z); x ← x(λ)

The factorisation is LAPACK's banded Cholesky (scipy ``cholesky_banded``) of K in the engine's body order
(``banded.body_order``), assembled by one fixed sparse map from the G_α entries to the band.

The shift s = μ|u_t| (Coulomb, not Tresca) makes the problem nonconvex. Three ways to handle it:

    rounds      s frozen for a whole IPM; then s ← s + θ (μ|u_t| − s) and the IPM restarted (Mehrotra's
                starting point heuristic from the current impulses) — the De Saxcé fixed point
    each        s ← μ|u_t| of the current iterate at every iteration (K as above, s not differentiated)
    newton      the same, and s linearised in the Newton matrix where a contact slides (2μ|u_t| >
                SLIP_RATIO × its smaller slack): ∂s = μ sg ∂u_t, so dz = Ã dx + rp with Ã = A + μ sg e H_t
                on both rows; K = M + Aᵀ D Ã is then non-symmetric (banded LU, LAPACK gbtrf); a step shorter
                than FALLBACK_STEP is replaced by the frozen-s step of the same iterate

Methods (every one stopped on the lab's law residual of (v(r), r) ≤ target, checked every iteration, like
the rest of the lab; cap ITER_CAP iterations):

    ipm            rounds, θ = 1; a round ends when its frozen-s problem is solved (RMS primal residual
                   and RMS min(z, W_nn λ) ≤ INNER_FRACTION · target); s from the warm start's velocities first
    ipm-damped     rounds, θ = ½ (undamped, s oscillates)
    ipm-each       each
    ipm-newton     newton
    ipm-oracle-s   one IPM with s frozen at the reference's μ|u_t| (reads the answer: the cost of the convex
                   part alone, the self-stress under the inequalities)
    ipm-close      ipm-newton stopped at the law residual LOOSE (1e-3 m/s), then the engine's accelerated
                   sweeps ("nlgs-accel" kernel, tolerance 0) from its impulses to the target
    ipm-close4, ipm-close-3e-5   the same from 1e-4 and 3e-5 m/s

Start: impulses from the warm start (λ± = (r_n ± r_t/μ)/2, clipped at 0), then Mehrotra's shift into the
interior. ``iterations``: IPM iterations; ``Outcome.detail`` the rounds and closing sweeps. Sweep units: the
harness's rule (CPU time over one engine sweep), closing sweeps included at their CPU time; the untimed
search for the closing sweep count and the one-off "setup" (band order and assembly map, numpy) are not
counted (``cpu_s``): a compiled version would assemble the band directly each step.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.linalg as sla
import scipy.linalg.lapack as lapack
import scipy.sparse as sp

from benchmarks.solver_lab.methods.gauss_seidel import CAP
from benchmarks.solver_lab.outcome import Clock, Outcome
from masonrycli.engine import banded
from masonrycli.engine import nlgs as N

INNER_FRACTION = 0.1
"""A round's IPM stops when its RMS primal residual and complementarity measure are ≤ this × target."""
ITER_CAP = 200
"""IPM iterations a solve (over all rounds)."""
ROUND_CAP = 30
D_CAP = 1e12
"""The barrier weights λ/z are capped at this × the largest block mass (uncapped, the banded Cholesky broke
down on wall-64's hard step; 1e10 doubled ipm-oracle-s's iterations on wall-64's typical step, 40 → 21)."""
STEP_FRACTION = 0.995
FALLBACK_STEP = 0.1
"""ipm-newton: a linearised-shift step shorter than this is replaced by the frozen-shift step."""
SLIP_RATIO = 2.0
"""A contact slides (the shift is linearised there) when 2μ|u_t| > this × its smaller slack."""
LOOSE = 1e-3
"""m/s: ipm-close hands over to the sweeps at this RMS law residual."""


class Operators:
    """The problem's fixed pieces in the band order of the dynamic dofs (built once per problem)."""

    def __init__(self, ctx):
        p, pack = ctx.p, ctx.pack
        self.mu = p.mu
        c = p.count
        nb = p.q_m.shape[0]
        dyn_body = p.inv_mass > 0
        a_, b_ = p.body[:, 0].astype(np.int64), p.body[:, 1].astype(np.int64)
        coupled = dyn_body[a_] & dyn_body[b_]
        position, _ = banded.body_order(p.body, coupled, nb)
        bodies = np.flatnonzero(dyn_body)
        bodies = bodies[np.argsort(position[bodies], kind="stable")]
        rank = np.full(nb, -1)
        rank[bodies] = np.arange(bodies.size)
        self.bodies = bodies
        n = 3 * bodies.size
        self.n = n
        # dof → band index (−1: a support's dof, held at v_free)
        dof_index = np.full(3 * nb, -1)
        for k in range(3):
            dof_index[3 * bodies + k] = 3 * np.arange(bodies.size) + k
        minv = ctx.minv
        self.minv = minv[self._dofs(bodies)]
        self.m = 1.0 / self.minv
        self.x_free = p.v_free.ravel()[self._dofs(bodies)]
        # local Jacobians J (C, 2, 6): rows (t, n), columns (dofs of a, dofs of b)
        nx, ny = pack[:, N.P_NX], pack[:, N.P_NY]
        J = np.zeros((c, 2, 6))
        J[:, 0, 0:3] = -np.stack([ny, -nx, pack[:, N.P_TA]], 1)
        J[:, 0, 3:6] = np.stack([ny, -nx, pack[:, N.P_TB]], 1)
        J[:, 1, 0:3] = -np.stack([nx, ny, pack[:, N.P_NA]], 1)
        J[:, 1, 3:6] = np.stack([nx, ny, pack[:, N.P_NB]], 1)
        dofs = np.concatenate([3 * a_[:, None] + np.arange(3), 3 * b_[:, None] + np.arange(3)], axis=1)
        idx = dof_index[dofs]  # (C, 6)
        live = idx >= 0
        # H restricted to the dynamic dofs (2C × n) and the supports' constant part of u
        rows = np.repeat(np.arange(2 * c).reshape(c, 2, 1), 6, axis=2)
        cols = np.broadcast_to(idx[:, None, :], (c, 2, 6))
        keep = np.broadcast_to(live[:, None, :], (c, 2, 6))
        self.Hd = sp.csr_matrix((J[keep], (rows[keep], cols[keep])), shape=(2 * c, n))
        self.HdT = self.Hd.T.tocsr()
        vf = p.v_free.ravel()
        u_sup = np.where(live, 0.0, 1.0)[:, None, :] * J * vf[dofs][:, None, :]
        self.u_const = u_sup.sum(axis=2)  # (C, 2)
        self.bias = pack[:, N.P_BIAS].copy()
        self.wnn = pack[:, N.P_WNN].copy()
        # K's band from G's entries per contact: K_ij += Σ_kl J_ki G_kl J_lj, one fixed sparse map per
        # problem from the G entries (kl = tt, tn, nt, nn: 4C numbers) to the band. Symmetric G (s frozen):
        # lower storage ab[i − j, j] = K[i, j], i ≥ j (LAPACK pbtrf); general G (s linearised): LAPACK
        # gbtrf's storage ab[2w + i − j, j], |i − j| ≤ w (w rows above left for the pivoting's fill).
        ii = np.broadcast_to(idx[:, :, None], (c, 6, 6))
        jj = np.broadcast_to(idx[:, None, :], (c, 6, 6))
        both = (ii >= 0) & (jj >= 0)
        w = int(np.abs(ii - jj)[both].max(initial=0))
        self.w = w
        outer = [np.einsum("ci,cj->cij", J[:, k], J[:, j]) for k, j in ((0, 0), (0, 1), (1, 0), (1, 1))]
        cid = np.broadcast_to(np.arange(c)[:, None, None], (c, 6, 6))
        lower = both & (ii >= jj)
        flat = ((ii - jj) * n + jj)[lower]
        self.S = sp.csr_matrix(
            (
                np.concatenate([outer[k][lower] for k in range(4)]),
                (np.tile(flat, 4), np.concatenate([cid[lower] + k * c for k in range(4)])),
            ),
            shape=((w + 1) * n, 4 * c),
        )
        self.S.sum_duplicates()
        flat = ((2 * w + ii - jj) * n + jj)[both]
        self.S_general = sp.csr_matrix(
            (
                np.concatenate([outer[k][both] for k in range(4)]),
                (np.tile(flat, 4), np.concatenate([cid[both] + k * c for k in range(4)])),
            ),
            shape=((3 * w + 1) * n, 4 * c),
        )
        self.S_general.sum_duplicates()

    @staticmethod
    def _dofs(bodies):
        return (3 * bodies[:, None] + np.arange(3)).ravel()

    # u = H v per contact (C, 2); A x = E u; Aᵀ y = Hᵀ Eᵀ y
    def contact_velocity(self, x):
        return (self.Hd @ x).reshape(-1, 2) + self.u_const

    def impulse(self, lam):
        """r (C, 2) = Eᵀ λ."""
        return np.stack([self.mu * (lam[:, 0] - lam[:, 1]), lam[:, 0] + lam[:, 1]], axis=1)

    def rows(self, u, c):
        """A x + c (C, 2): u_n + c ± μ u_t."""
        return np.stack([u[:, 1] + c + self.mu * u[:, 0], u[:, 1] + c - self.mu * u[:, 0]], axis=1)

    def velocity(self, lam):
        """x(λ) = x_free + M⁻¹ Aᵀ λ."""
        return self.x_free + self.minv * (self.HdT @ self.impulse(lam).ravel())

    def at_rows(self, y):
        return self.HdT @ self.impulse(y).ravel()

    def factor(self, d, sg=None):
        """Factor of K = M + Aᵀ diag(d) Ã, d (C, 2). ``sg`` None: Ã = A (s frozen), banded Cholesky. ``sg``
        (C,) in {−1, 0, 1}: Ã = A + ∂s/∂x with s = μ |u_t| linearised (∂s = μ sg ∂u_t), banded LU."""
        mu = self.mu
        dp, dm = d[:, 0], d[:, 1]
        if sg is None:
            g = np.concatenate([mu * mu * (dp + dm), mu * (dp - dm), mu * (dp - dm), dp + dm])
            ab = (self.S @ g).reshape(self.w + 1, self.n)
            ab[0] += self.m
            return "chol", sla.cholesky_banded(ab, lower=True, check_finite=False)
        # G = Eᵀ D Ẽ, Ẽ = E + (1, 1)ᵀ (μ sg, 0): rows (μ(1 + sg), 1) and (μ(sg − 1), 1)
        g = np.concatenate(
            [
                mu * mu * (dp * (1 + sg) + dm * (1 - sg)),
                mu * (dp - dm),
                mu * (dp * (1 + sg) - dm * (1 - sg)),
                dp + dm,
            ]
        )
        return self.factor_blocks(g)

    def factor_blocks(self, g):
        """Banded LU of K = M + Σ_α J_αᵀ G_α J_α for any 2×2 G_α, ``g`` = (G_tt, G_tn, G_nt, G_nn) concatenated."""
        ab = (self.S_general @ g).reshape(3 * self.w + 1, self.n)
        ab[2 * self.w] += self.m
        lu, piv, info = lapack.dgbtrf(ab, self.w, self.w, overwrite_ab=True)
        if info != 0:
            raise np.linalg.LinAlgError(f"banded LU: zero pivot {info}")
        return "lu", (lu, piv)

    def solve(self, fac, rhs):
        kind, f = fac
        if kind == "chol":
            return sla.cho_solve_banded((f, True), rhs, check_finite=False)
        x, info = lapack.dgbtrs(f[0], self.w, self.w, rhs, f[1])
        return x

    def rows_linear(self, du, sg=None):
        """Ã dx (C, 2) from du = H dx: A's rows, plus μ sg du_t on both when s is linearised."""
        out = self.rows(du, 0.0)
        if sg is not None:
            out += (self.mu * sg * du[:, 0])[:, None]
        return out

    def full_velocity(self, p, x):
        v = p.v_free.copy()
        v[self.bodies] = x.reshape(-1, 3)
        return v


_operators: dict = {}


def operators(ctx, clock) -> Operators:
    """Built once per problem (timed as "setup" the first time only: the engine's band order and map would
    be rebuilt when the contact set changes, which the per-step time below leaves out; reported apart)."""
    if ctx.p.name not in _operators:
        with clock("setup"):
            _operators[ctx.p.name] = Operators(ctx)
    return _operators[ctx.p.name]


def _start(ops, lam0, c):
    """Mehrotra's starting point from the impulses λ̂ (a warm start): x̂ = x(λ̂), ẑ = A x̂ + c, then both shifted
    to be positive and balanced."""
    lam = lam0.copy()
    x = ops.velocity(lam)
    z = ops.rows(ops.contact_velocity(x), c)
    z, lam = interior(z, lam)
    return lam, ops.velocity(lam), z


def interior(z: np.ndarray, lam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mehrotra's starting point: slacks ``z`` and multipliers ``lam`` shifted strictly positive, then
    balanced so that neither complementarity product is far below the other."""
    z = z + max(-1.5 * z.min(), 0.0)
    lam = lam + max(-1.5 * lam.min(), 0.0)
    zl = float((z * lam).sum())
    if zl <= 0.0:
        z, lam = z + 1e-3, lam + 1e-3
        zl = float((z * lam).sum())
    z = z + 0.5 * zl / lam.sum()
    lam = lam + 0.5 * zl / z.sum()
    return z, lam


def _max_step(v, dv):
    neg = dv < 0
    return float((-v[neg] / dv[neg]).min(initial=np.inf))


def _complementarity(ops, z, lam):
    """m/s: RMS over rows of min(z, W_nn λ), the frozen-s problem's complementarity in velocity units."""
    e = np.minimum(z, ops.wnn[:, None] * lam)
    return float(np.sqrt((e * e).mean())) if e.size else 0.0


def iterate(ops, x, lam, z, s, sg=None):
    """One Mehrotra predictor–corrector iteration at the shift s (``sg``: s linearised, see ``factor``).
    Returns (x, λ, z, step)."""
    m = z.size
    u = ops.contact_velocity(x)
    rp = ops.rows(u, ops.bias + s) - z
    mu_c = float((z * lam).sum()) / m
    d = np.minimum(lam / z, D_CAP * ops.m.max(initial=1.0))  # past it K's factor loses every digit
    fac = ops.factor(d, sg)
    # predictor
    dx = ops.solve(fac, -ops.at_rows(lam + d * rp))
    dz_a = ops.rows_linear(ops.contact_velocity(dx) - ops.u_const, sg) + rp
    dl_a = -lam - d * dz_a
    a_aff = min(1.0, _max_step(z, dz_a), _max_step(lam, dl_a))
    mu_aff = float(((z + a_aff * dz_a) * (lam + a_aff * dl_a)).sum()) / m
    sigma = (mu_aff / mu_c) ** 3 if mu_c > 0 else 0.0
    # corrector
    g = lam + (dz_a * dl_a - sigma * mu_c) / z
    dx = ops.solve(fac, -ops.at_rows(g + d * rp))
    dz = ops.rows_linear(ops.contact_velocity(dx) - ops.u_const, sg) + rp
    dl = -g - d * dz
    alpha = min(1.0, STEP_FRACTION * min(_max_step(z, dz), _max_step(lam, dl)))
    lam = lam + alpha * dl
    z = z + alpha * dz
    return ops.velocity(lam), lam, z, alpha


def guarded_iterate(ops, x, lam, z, s, sg=None):
    """``iterate``; a linearised-shift step shorter than FALLBACK_STEP (a poor linearisation) is replaced by
    the frozen-shift step of the same iterate. Returns (x, λ, z); LinAlgError if the factor breaks down."""
    x1, lam1, z1, alpha = iterate(ops, x, lam, z, s, sg)
    if sg is not None and alpha < FALLBACK_STEP:
        x1, lam1, z1, alpha = iterate(ops, x, lam, z, s, None)
    return x1, lam1, z1


def slip_sign(ops, u, z):
    """sg (C,): sign of u_t at the contacts that slide, 0 elsewhere (s = μ|u_t| has a kink at u_t = 0, where
    the interior point's sticking contacts sit: there u_t ~ z is small, of either sign). Sliding: one row
    clearly inactive, 2μ|u_t| > SLIP_RATIO × the smaller slack."""
    sliding = 2 * ops.mu * np.abs(u[:, 0]) > SLIP_RATIO * z.min(axis=1)
    return np.where(sliding, np.sign(u[:, 0]), 0.0)


def run_ipm(ctx, target, stop_at, clock, mode="rounds", theta=1.0, lam_start=None):
    """Mehrotra IPMs on the step (module doc). ``mode``: "rounds" (s frozen per round, s ← s + θ (μ|u_t| − s)
    between rounds), "each" (s ← μ|u_t| every iteration), "newton" (the same, s linearised in the Newton
    matrix) or "frozen" (one IPM at the shift of ``lam_start``'s velocities, like "oracle"). Stops when the
    lab's RMS law residual ≤ ``stop_at`` (checked after each round, or each iteration). Returns (v, r, iterations, rounds, residual)."""
    p = ctx.p
    ops = operators(ctx, clock)
    mu = p.mu
    with clock("ipm"):
        if lam_start is None:
            r0 = p.r_warm
            lam_start = np.stack([(r0[:, 1] + r0[:, 0] / mu) / 2, (r0[:, 1] - r0[:, 0] / mu) / 2], axis=1)
        lam_start = np.maximum(lam_start, 0.0)
        if mode == "oracle":  # the reference's own shift (not usable: it reads the answer)
            s = mu * np.abs(ops.contact_velocity(p.v_ref.ravel()[Operators._dofs(ops.bodies)])[:, 0])
        else:
            s = mu * np.abs(ops.contact_velocity(ops.velocity(lam_start))[:, 0])
        lam, x, z = _start(ops, lam_start, ops.bias + s)
    its = rounds = 0
    residual = np.inf
    while its < ITER_CAP and rounds < ROUND_CAP:
        rounds += 1
        inner_done = False
        while its < ITER_CAP:
            with clock("ipm"):
                sg = None
                if mode in ("each", "newton"):
                    u = ops.contact_velocity(x)
                    s = mu * np.abs(u[:, 0])
                    if mode == "newton":
                        sg = slip_sign(ops, u, z)
                try:
                    x, lam, z = guarded_iterate(ops, x, lam, z, s, sg)
                except np.linalg.LinAlgError:  # the factor broke down: stop with the last iterate
                    break
            its += 1
            with clock("check"):
                v = ops.full_velocity(p, x)
                residual = ctx.residual(v, ops.impulse(lam))
                if residual <= stop_at:
                    return v, ops.impulse(lam), its, rounds, residual
                if mode in ("rounds", "oracle", "frozen"):
                    u = ops.contact_velocity(x)
                    rp_rms = float(np.sqrt(((ops.rows(u, ops.bias + s) - z) ** 2).mean()))
                    if max(rp_rms, _complementarity(ops, z, lam)) <= INNER_FRACTION * target:
                        inner_done = True
                        break
        if not inner_done or mode in ("oracle", "frozen"):
            break
        with clock("ipm"):  # next round: s towards this iterate's, restarted from its impulses
            s = s + theta * (mu * np.abs(ops.contact_velocity(x)[:, 0]) - s)
            lam, x, z = _start(ops, lam, ops.bias + s)
    v = ops.full_velocity(p, x)
    return v, ops.impulse(lam), its, rounds, residual


def _outcome(clock, v, r, its, rounds, residual, target, cpu_s, closing=0) -> Outcome:
    """The harness's Outcome; CPU time without the one-off "setup" (module doc of ``operators``)."""
    detail = f"{rounds} rounds" + (f", {closing} closing sweeps" if closing else "")
    cpu_s -= clock.phases.get("setup", 0.0)
    return Outcome(v, r, its, 0.0, clock.phases, converged=residual <= target, cpu_s=cpu_s, detail=detail)


def _plain(mode: str, theta: float = 1.0):
    def solve(ctx, target) -> Outcome:
        clock = Clock()
        t0 = time.process_time()
        v, r, its, rounds, res = run_ipm(ctx, target, target, clock, mode, theta)
        return _outcome(clock, v, r, its, rounds, res, target, time.process_time() - t0)

    return solve


_closing: dict = {}  # (method, problem, target) → (sweeps, converged): the search is not timed, do it once


def close(ctx, v, r, res, target, method: tuple, clock):
    """The engine's accelerated sweeps from an IPM's impulses ``r`` (updated in place) to ``target``:
    ``(sweeps, converged, v, CPU s of the sweeps)``. The fewest sweeps that reach it are searched once per
    ``method`` and problem, in steps of ~10 %, untimed; only the final run of that many is timed."""
    if res <= target:
        return 0, True, v, 0.0
    key = (*method, ctx.p.name, target)
    if key not in _closing:
        n, ok = 0, False
        while n < CAP and not ok:
            n += max(1, n // 10)
            rr = r.copy()
            vv, _ = ctx.sweep(rr, n, "nlgs-accel")
            ok = ctx.residual(vv, rr) <= target
        _closing[key] = n, ok
    n, ok = _closing[key]
    t1 = time.process_time()
    with clock("sweeps"):
        v, _ = ctx.sweep(r, n, "nlgs-accel")
    return n, ok, v, time.process_time() - t1


def closing(loose: float, mode: str, start=None):
    """``start(ctx, clock)``: the IPM's starting λ (C, 2) instead of the warm start's (a predictor, timed)."""

    def solve(ctx, target) -> Outcome:
        clock = Clock()
        t0 = time.process_time()
        lam_start = None if start is None else start(ctx, clock)
        v, r, its, rounds, res = run_ipm(ctx, target, loose, clock, mode, lam_start=lam_start)
        ipm_s = time.process_time() - t0
        n, ok, v, sweeps_s = close(ctx, v, r, res, target, ("ipm", loose, mode, start), clock)
        return _outcome(clock, v, r, its, rounds, 0.0 if ok else np.inf, target, ipm_s + sweeps_s, closing=n)

    return solve


METHODS = {
    "ipm": _plain("rounds"),
    "ipm-damped": _plain("rounds", 0.5),
    "ipm-each": _plain("each"),
    "ipm-oracle-s": _plain("oracle"),
    "ipm-newton": _plain("newton"),
    "ipm-close": closing(LOOSE, "newton"),
    "ipm-close4": closing(1e-4, "newton"),
    "ipm-close-3e-5": closing(3e-5, "newton"),
}
