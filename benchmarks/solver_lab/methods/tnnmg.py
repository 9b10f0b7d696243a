"""Truncated nonsmooth Newton with a projected line search (TNNMG-like, after Gräser & Kornhuber): ``tnnmg``.

With the friction thresholds frozen (Tresca, s_α = μ r̂_n,α) the impulse problem is a convex QP on a box,

    E(r) = ½ rᵀ W r + rᵀ q,   W = H M⁻¹ Hᵀ,  q = H v_free + (0, bias_α)_α,   r_n ≥ 0,  |r_t| ≤ s,

whose gradient is ∇E = u + (0, bias) (u = H v(r), v(r) = v_free + M⁻¹ Hᵀ r): its KKT conditions are
Signorini and Tresca friction, and at s = μ r_n they are Signorini–Coulomb. W is never formed:
E(r) = ½ wᵀ M⁻¹ w + rᵀ q with w = Hᵀ r. One iteration:

    smooth    SMOOTH engine NLGS sweeps (exact Coulomb local solves) from r;  stop if law residual ≤ target
    freeze    s = μ r_n;  F = normals with r_n > 0, tangentials with r_n > 0 and |r_t| < (1 − MARGIN) s
              (components at a bound are truncated: held fixed in the Newton step)
    Newton    minimise E over r_F, the rest fixed — in velocity space, where it is well posed (W_FF is
              singular on a hyperstatic wall): M dv = H_Fᵀ dr_F, H_F dv = −∇E_F. Augmented Lagrangian
              with ONE Cholesky-type factor of K = M + H_Fᵀ D⁻¹ H_F (D = EPS_REL · W_αα per row):
                  λ = 0;  repeat AL_CAP:  K dv = H_Fᵀ (λ − D⁻¹ ∇E_F);  c = H_F dv + ∇E_F;  λ −= D⁻¹ c
              (= proximal point on E_F from dr = 0: the near-minimum-norm dr_F, self-equilibrated part
              of r kept);  dr_F = λ
    search    r(α) = P_box(r + α dr), α = 1, ½, ¼ … (≥ ALPHA_MIN): accept the first with
              E(r(α)) ≤ E(r) + σ ∇Eᵀ(r(α) − r)  (Armijo; monotone in E for the frozen s), else keep r

Iterations: Newton steps. Sweep units: the harness's (all CPU time / one engine sweep's), numpy/scipy
included; the phases split smoothing, checks, assembly, factor, AL solves and line search.
Variants (``METHODS``): ``tnnmg-n`` (Newton on the normal components only), ``tnnmg-s20`` (20 smoothing
sweeps), ``tnnmg-m`` (truncation margin 0.05).
"""

from __future__ import annotations

import os

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from benchmarks.solver_lab import law
from benchmarks.solver_lab.outcome import Clock, Outcome
from masonrycli.engine import nlgs as N

os.environ.setdefault("OMP_NUM_THREADS", "1")

SMOOTH = 5
"""Engine NLGS sweeps before each Newton step."""
EPS_REL = 1e-2
"""Penalty of a constraint row relative to its contact's W_tt / W_nn (conditions K; λ removes it)."""
AL_CAP = 5
AL_TOL = 1e-3
"""AL iterations stop when the constraint violation is below this fraction of |∇E_F| (max norms)."""
MARGIN = 0.0
SCALING_POWER = 2.0
HOLD = False
SIGMA = 1e-4
ALPHA_MIN = 2.0**-12
NEWTON_CAP = 200


class Operators:
    """What one problem needs, built once (counted in the phase "setup": the engine would need it too)."""

    def __init__(self, ctx):
        p, H, pack = ctx.p, ctx.H, ctx.pack
        self.ctx = ctx
        self.dyn = np.flatnonzero(ctx.minv > 0)
        self.Hd = H[:, self.dyn].tocsr()
        self.HT = H.T.tocsr()
        self.minv = ctx.minv
        self.m = 1.0 / ctx.minv[self.dyn]
        bias = np.zeros((p.count, 2))
        bias[:, 1] = pack[:, N.P_BIAS]
        self.bias = bias.ravel()
        self.q = H @ p.v_free.ravel() + self.bias
        self.wdiag = np.stack([pack[:, N.P_WTT], pack[:, N.P_WNN]], axis=1).ravel()
        self.mu = p.mu

    def energy(self, r: np.ndarray) -> float:
        w = self.HT @ r
        return 0.5 * float(w @ (self.minv * w)) + float(r @ self.q)

    def gradient(self, v: np.ndarray) -> np.ndarray:
        """∇E = H v + (0, bias) for the velocities v (B, 3) of the current r."""
        return self.ctx.H @ v.ravel() + self.bias


def project(r: np.ndarray, s: np.ndarray) -> np.ndarray:
    """P_box: r_n ≥ 0, |r_t| ≤ s (flat (2C,) r, s per contact)."""
    out = r.copy()
    out[1::2] = np.maximum(out[1::2], 0.0)
    out[0::2] = np.clip(out[0::2], -s, s)
    return out


def free_components(r, s, margin: float, normals_only: bool, g=None) -> np.ndarray:
    """Indices (into flat r) of the untruncated components. With the gradient ``g`` (projected-Newton
    rule) a component at its bound whose descent direction points into the box is free too."""
    rn, rt = r[1::2], r[0::2]
    closed = rn > 0.0
    inside_t = np.abs(rt) < (1.0 - margin) * s
    if g is not None:
        closed = closed | (g[1::2] < 0.0)
        inside_t = inside_t | ((rt >= s) & (g[0::2] > 0.0)) | ((rt <= -s) & (g[0::2] < 0.0))
        inside_t &= s > 0.0
    fn = np.flatnonzero(closed)
    if normals_only:
        return 2 * fn + 1
    ft = np.flatnonzero(closed & inside_t)
    return np.sort(np.concatenate([2 * ft, 2 * fn + 1]))


def newton_direction(ops: Operators, rows: np.ndarray, g: np.ndarray, clock: Clock, weight=None) -> tuple[np.ndarray, int]:
    """dr (flat, zero off ``rows``) minimising E over the rows with the rest fixed; AL iterations done.
    ``weight`` (per row, ≥ 1): the metric of the proximal term is multiplied by it (affine scaling)."""
    with clock("assemble"):
        HF = ops.Hd[rows]
        d_inv = 1.0 / (EPS_REL * ops.wdiag[rows] * (1.0 if weight is None else weight))
        K = (sp.diags(ops.m) + HF.T @ sp.diags(d_inv) @ HF).tocsc()
        gF = g[rows]
        HFt = HF.T.tocsr()
    with clock("factor"):
        lu = spla.splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    lam = np.zeros(rows.size)
    scale = float(np.abs(gF).max(initial=0.0))
    its = 0
    with clock("AL solves"):
        while its < AL_CAP:
            its += 1
            dv = lu.solve(HFt @ (lam - d_inv * gF))
            c = HF @ dv + gF
            lam -= d_inv * c
            if np.abs(c).max(initial=0.0) <= AL_TOL * scale:
                break
    dr = np.zeros_like(g)
    dr[rows] = lam
    return dr, its


def active_set_direction(ops, r, s, rows, g, rounds, clock) -> tuple[np.ndarray, int]:
    """``rounds`` primal-dual active-set passes on the frozen-s box QP: solve on ``rows``; components the
    solution pushes out of the box are put on their bound (a normal at 0 takes its tangential to 0 too)
    and removed from the free set; the gradient is updated (∇E += W Δr) and the rest re-solved.
    Returns (dr to the last pass's point, AL iterations)."""
    fixed = np.zeros_like(r)
    total = 0
    dr = np.zeros_like(r)
    for k in range(rounds):
        with clock("assemble"):
            ge = g + ops.ctx.H @ (ops.minv * (ops.HT @ fixed)) if k else g
        dr, its = newton_direction(ops, rows, ge, clock)
        total += its
        with clock("active set"):
            trial = r + fixed + dr
            out_n = trial[1::2] < 0.0
            out_t = np.abs(trial[0::2]) > s
            bad = np.zeros(r.size, dtype=bool)
            bad[1::2] = out_n
            bad[0::2] = out_t | out_n
            bad_rows = bad[rows]
            if not bad_rows.any() or k == rounds - 1:
                break
            idx = rows[bad_rows]
            if HOLD:  # truncate where the step leaves the box: hold those components where they are
                fixed[idx] = 0.0
            else:
                target = project(trial, s)
                target[0::2][out_n] = 0.0
                fixed[idx] = target[idx] - r[idx]
            rows = rows[~bad_rows]
    dr = dr + fixed
    return dr, total


def scaling(r: np.ndarray, s: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Affine-scaling weight per free row: (typical impulse / distance to the row's bound)², ≥ 1, so the
    proximal AL picks, among the impulse changes that give the same velocities, one that moves the
    components near a bound least."""
    dist = np.empty_like(r)
    dist[1::2] = r[1::2]
    dist[0::2] = s - np.abs(r[0::2])
    d = dist[rows]
    scale = float(np.median(r[1::2][r[1::2] > 0])) if (r[1::2] > 0).any() else 1.0
    return np.maximum((scale / np.maximum(d, 1e-12 * scale)) ** SCALING_POWER, 1.0)


def line_search(ops: Operators, r: np.ndarray, dr: np.ndarray, s: np.ndarray, g: np.ndarray, clock: Clock):
    """Projected Armijo backtracking on E; returns (new r, α) or (r, 0.0) when no step lowers E."""
    with clock("line search"):
        e0 = ops.energy(r)
        alpha = 1.0
        while alpha >= ALPHA_MIN:
            trial = project(r + alpha * dr, s)
            step = trial - r
            if ops.energy(trial) <= e0 + SIGMA * float(g @ step):
                return trial, alpha
            alpha *= 0.5
    return r, 0.0


def tnnmg(
    ctx,
    target,
    smooth=SMOOTH,
    margin=MARGIN,
    normals_only=False,
    cap=NEWTON_CAP,
    rounds=1,
    inner=1,
    inward=False,
    trace=False,
) -> Outcome:
    p = ctx.p
    clock = Clock()
    with clock("setup"):
        ops = Operators(ctx)
    r = p.r_warm.copy()
    newton = sweeps = 0
    ok = False
    stats = {"alpha": [], "al": [], "free": [], "smoothed": [], "newton": []}
    while True:
        with clock("sweeps"):
            v, _ = ctx.sweep(r, smooth)
        sweeps += smooth
        with clock("check"):
            res = ctx.residual(v, r)
            if trace:
                stats["smoothed"].append(res)
            if res <= target:
                ok = True
                break
        if newton >= cap:
            break
        flat = r.ravel().copy()
        s = ops.mu * flat[1::2]
        for k in range(inner):  # nested Tresca: ``inner`` Newton steps at the same thresholds s
            with clock("assemble"):
                g = ops.gradient(v)
                rows = free_components(flat, s, margin, normals_only, g if (inward or k) else None)
            if rows.size == 0:
                break
            if rounds > 1:
                dr, its = active_set_direction(ops, flat, s, rows, g, rounds, clock)
            else:
                dr, its = newton_direction(ops, rows, g, clock)
            flat, alpha = line_search(ops, flat, dr, s, g, clock)
            stats["alpha"].append(alpha)
            stats["al"].append(its)
            stats["free"].append(rows.size)
            if k + 1 < inner:
                with clock("assemble"):
                    v = (ops.ctx.p.v_free.ravel() + ops.minv * (ops.HT @ flat)).reshape(-1, 3)
        r = flat.reshape(-1, 2)
        newton += 1
        if trace:
            stats["newton"].append(ctx.residual(law.velocity_from_impulse(p, ctx.H, r), r))
    out = Outcome(v, r, newton, float(sweeps), clock.phases, converged=ok)
    out.smooth_sweeps, out.stats = sweeps, stats  # read by the lab's diagnostics, not the table
    return out


METHODS = {
    "tnnmg": tnnmg,
    "tnnmg-s20": lambda ctx, target: tnnmg(ctx, target, smooth=20),
    "tnnmg-n": lambda ctx, target: tnnmg(ctx, target, normals_only=True),
    "tnnmg-m": lambda ctx, target: tnnmg(ctx, target, margin=0.05),
    "tnnmg-i3": lambda ctx, target: tnnmg(ctx, target, inner=3),
}
