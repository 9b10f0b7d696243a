"""Truncated nonsmooth Newton with a projected line search (TNNMG-like, after Gräser & Kornhuber): ``tnnmg``.

With the friction thresholds frozen (Tresca, s_α = μ r̂_n,α) the impulse problem is a convex QP on a box,

    E(r) = ½ rᵀ W r + rᵀ q,   W = H M⁻¹ Hᵀ,  q = H v_free + (0, bias_α)_α,   r_n ≥ 0,  |r_t| ≤ s,

whose gradient is ∇E = u + (0, bias) (u = H v(r), v(r) = v_free + M⁻¹ Hᵀ r): its KKT conditions are
Signorini and Tresca friction, and at s = μ r_n they are Signorini–Coulomb. W is never formed:
E(r) = ½ wᵀ M⁻¹ w + rᵀ q with w = Hᵀ r. One iteration (one "Newton step"):

    smooth    SMOOTH engine NLGS sweeps (exact Coulomb local solves) from r;  stop if law residual ≤ target
    freeze    s = μ r_n;  F = normals with r_n > 0, tangentials with r_n > 0 and |r_t| < (1 − MARGIN) s
              (components at a bound are truncated: held fixed in the Newton step)
    Newton    minimise E over r_F, the rest fixed — in velocity space, where it is well posed (W_FF is
              singular on a hyperstatic wall): M dv = H_Fᵀ dr_F, H_F dv = −∇E_F. Augmented Lagrangian
              with ONE factor of K = M + H_Fᵀ D⁻¹ H_F (D = EPS_REL · W_αα per row; scipy's splu here):
                λ = 0;  repeat ≤ AL_CAP:  K dv = H_Fᵀ (λ − D⁻¹ ∇E_F);  c = H_F dv + ∇E_F;  λ −= D⁻¹ c
              (= proximal point on E_F from dr = 0: a near-minimum-norm dr_F, the self-equilibrated part
              of r kept);  dr_F = λ
    search    r(α) = P_box(r + α dr), α = 1, ½, ¼ … (≥ ALPHA_MIN): accept the first with
              E(r(α)) ≤ E(r) + σ ∇Eᵀ(r(α) − r)  (Armijo: monotone in E for the frozen s), else keep r

EPS_REL: on the walls the equalities H_F dv = −∇E_F at an iterate's free set are inconsistent (Signorini
biases of redundant contacts; wall-8-hard after 5 sweeps: least-squares residual up to 6e-5 m/s), so E_F
is unbounded below and λ runs away as 1/ε: at 1e-6 every Newton step of wall-8-hard was rejected by the
line search; 1e-2 keeps the step a regularised (proximal) Newton step.

Options (each measured, see benchmarks/JOURNAL.md "tnnmg"): ``inner`` Newton steps at the same s before the
next smoothing (nested Tresca); ``inward`` also frees components at a bound whose descent direction points
into the box (projected-Newton rule); ``rounds`` active-set passes: components the step pushes out of the
box are put on their bound (or, ``hold``, held where they are), dropped from F, and the rest re-solved
(one factor each); ``normals_only`` Newton on the normal components only; ``search=False`` the full
projected step, no line search (diverges: what ``ssn-v`` did). Measured outcome: no gain over the engine's
sweeps at any height — the step helps only at the solution's statuses and thresholds (benchmarks/JOURNAL.md, "tnnmg").

Iterations: Newton steps (threshold updates with ``inner`` > 1). Sweep units: the harness's (all CPU time
over one engine sweep's), numpy/scipy included; the phases split smoothing, checks, assembly, factor, AL
solves and line search.
``oracle_step`` (CLI: ``python -m benchmarks.solver_lab.methods.tnnmg [--sweeps K] [--all] PROBLEM …``)
takes one Newton step from the iterate after K sweeps with the statuses and the thresholds of the reference
or of the iterate — what the step is worth once the active set and the thresholds are right.
"""

from __future__ import annotations

import sys

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from benchmarks.solver_lab import law
from benchmarks.solver_lab.outcome import Clock, Outcome
from masonrycli.engine import nlgs as N

SMOOTH = 5
"""Engine NLGS sweeps before each Newton step."""
EPS_REL = 1e-2
"""Penalty of a constraint row relative to its contact's W_tt / W_nn (module doc)."""
AL_CAP = 5
AL_TOL = 1e-3
"""AL iterations stop when the constraint violation is below this fraction of |∇E_F| (max norms)."""
MARGIN = 0.0
SIGMA = 1e-4
ALPHA_MIN = 2.0**-12
NEWTON_CAP = 200


class Operators:
    """What one problem needs, built once (phase "setup")."""

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

    def velocity(self, r: np.ndarray) -> np.ndarray:
        """v(r) (B, 3) for flat impulses r."""
        return (self.ctx.p.v_free.ravel() + self.minv * (self.HT @ r)).reshape(-1, 3)

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


def newton_direction(ops, rows, g, clock, eps=None, al_cap=None, al_tol=None) -> tuple[np.ndarray, int]:
    """dr (flat, zero off ``rows``) minimising E over the rows with the rest fixed (module doc); AL
    iterations done."""
    eps = EPS_REL if eps is None else eps
    al_cap = AL_CAP if al_cap is None else al_cap
    al_tol = AL_TOL if al_tol is None else al_tol
    with clock("assemble"):
        HF = ops.Hd[rows]
        d_inv = 1.0 / (eps * ops.wdiag[rows])
        K = (sp.diags(ops.m) + HF.T @ sp.diags(d_inv) @ HF).tocsc()
        gF = g[rows]
        HFt = HF.T.tocsr()
    with clock("factor"):  # K is symmetric positive definite: symmetric ordering, no pivoting
        lu = spla.splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    lam = np.zeros(rows.size)
    scale = float(np.abs(gF).max(initial=0.0))
    its = 0
    with clock("AL solves"):
        while its < al_cap:
            its += 1
            dv = lu.solve(HFt @ (lam - d_inv * gF))
            c = HF @ dv + gF
            lam -= d_inv * c
            if np.abs(c).max(initial=0.0) <= al_tol * scale:
                break
    dr = np.zeros_like(g)
    dr[rows] = lam
    return dr, its


def active_set_direction(ops, r, s, rows, g, rounds, hold, clock) -> tuple[np.ndarray, int]:
    """Up to ``rounds`` active-set passes on the frozen-s box QP: solve on ``rows``; components the
    solution pushes out of the box are put on their bound (a normal at 0 takes its tangential to 0 too;
    ``hold``: left where they are), dropped from the rows, ∇E updated by W Δr, the rest re-solved.
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
            bad = np.zeros(r.size, dtype=bool)
            bad[1::2] = out_n
            bad[0::2] = (np.abs(trial[0::2]) > s) | out_n
            bad_rows = bad[rows]
            if not bad_rows.any() or k == rounds - 1:
                break
            idx = rows[bad_rows]
            if not hold:
                target = project(trial, s)
                target[0::2][out_n] = 0.0
                fixed[idx] = target[idx] - r[idx]
            rows = rows[~bad_rows]
    return dr + fixed, total


def line_search(ops, r, dr, s, g, clock):
    """Projected Armijo backtracking on E; returns (new r, α) or (r, 0.0) when no step lowers E."""
    with clock("line search"):
        e0 = ops.energy(r)
        alpha = 1.0
        while alpha >= ALPHA_MIN:
            trial = project(r + alpha * dr, s)
            if ops.energy(trial) <= e0 + SIGMA * float(g @ (trial - r)):
                return trial, alpha
            alpha *= 0.5
    return r, 0.0


def tnnmg(
    ctx,
    target,
    smooth=SMOOTH,
    margin=MARGIN,
    normals_only=False,
    inner=1,
    inward=False,
    rounds=1,
    hold=False,
    search=True,
    cap=NEWTON_CAP,
    trace=False,
) -> Outcome:
    """The method of the module doc from r_warm; ``trace``: also the law residual after each Newton step
    (extra checks, timed as "trace")."""
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
                dr, its = active_set_direction(ops, flat, s, rows, g, rounds, hold, clock)
            else:
                dr, its = newton_direction(ops, rows, g, clock)
            if search:
                flat, alpha = line_search(ops, flat, dr, s, g, clock)
            else:  # the full step, projected (no globalisation)
                flat, alpha = project(flat + dr, s), 1.0
            stats["alpha"].append(alpha)
            stats["al"].append(its)
            stats["free"].append(rows.size)
            if k + 1 < inner:
                with clock("assemble"):
                    v = ops.velocity(flat)
        r = flat.reshape(-1, 2)
        newton += 1
        if trace:
            with clock("trace"):
                stats["newton"].append(ctx.residual(ops.velocity(flat), r))
    out = Outcome(v, r, newton, float(sweeps), clock.phases, converged=ok)
    out.smooth_sweeps, out.stats = sweeps, stats  # read by the lab's diagnostics and tests, not the table
    return out


def oracle_start(p, r: np.ndarray, statuses: str = "reference", thresholds: str = "reference"):
    """(r0, s, rows) for a Newton step from the impulses ``r`` (flat) with the statuses (closed / sticking)
    and thresholds (s = μ r_n) of the reference's impulses or of ``r`` itself ("reference" / "iterate"):
    r0 = r with open contacts set to 0 and sliding tangentials on their bound (sign of the statuses' owner),
    rows = the closed normals and sticking tangentials."""
    rr = p.r_ref.ravel()
    own = rr if statuses == "reference" else r
    s = p.mu * (rr if thresholds == "reference" else r)[1::2]
    s_own = p.mu * own[1::2]
    closed = own[1::2] > 0.0
    stick = closed & (np.abs(own[0::2]) < s_own * (1.0 - 1e-9))
    rows = np.sort(np.concatenate([2 * np.flatnonzero(stick), 2 * np.flatnonzero(closed) + 1]))
    r0 = r.copy()
    r0[1::2][~closed] = 0.0
    r0[0::2][~closed] = 0.0
    slide = closed & ~stick
    r0[0::2][slide] = np.sign(own[0::2][slide]) * s[slide]
    return project(r0, s), s, rows


def oracle_step(ctx, sweeps=0, statuses="reference", thresholds="reference", eps=1e-4, al_cap=10) -> dict:
    """One Newton step from the iterate after ``sweeps`` engine sweeps (0: the warm start) with the statuses
    and thresholds of ``oracle_start``, near exact (AL to 1e-9 relative). Returns the velocity error and law
    residual of the iterate, of the step unprojected and projected, and how many components the step
    pushes out of the box."""
    p = ctx.p
    ops = Operators(ctx)
    r = p.r_warm.copy()
    if sweeps:
        ctx.sweep(r, sweeps)
    r = r.ravel()
    r0, s, rows = oracle_start(p, r, statuses, thresholds)
    dr, its = newton_direction(ops, rows, ops.gradient(ops.velocity(r0)), Clock(), eps, al_cap, 1e-9)
    r1 = r0 + dr
    r1p = project(r1, s)
    out = {"free": int(rows.size), "al": its, "r_iterate": r.reshape(-1, 2), "r_projected": r1p.reshape(-1, 2)}
    for key, rv in (("iterate", r), ("step", r1), ("projected", r1p)):
        v = ops.velocity(rv)
        out[key] = (law.velocity_error(p, v), ctx.residual(v, rv.reshape(-1, 2)))
    out["rn<0"] = int((r1[1::2] < 0.0).sum())
    out["|rt|>s"] = int((np.abs(r1[0::2]) > s * (1.0 + 1e-9)).sum())
    # how far the iterate's statuses are from the reference's: contacts closed in one and open in the
    # other, and closed in both but sticking in one and sliding in the other
    closed = [x[1::2] > 0.0 for x in (r, p.r_ref.ravel())]
    stick = [c & (np.abs(x[0::2]) < p.mu * x[1::2] * (1.0 - 1e-9)) for c, x in zip(closed, (r, p.r_ref.ravel()))]
    out["closed≠"] = int((closed[0] != closed[1]).sum())
    out["stick≠"] = int((closed[0] & closed[1] & (stick[0] != stick[1])).sum())
    return out


METHODS = {
    "tnnmg": tnnmg,
    "tnnmg-s20": lambda ctx, target: tnnmg(ctx, target, smooth=20),
    "tnnmg-n": lambda ctx, target: tnnmg(ctx, target, normals_only=True),
    "tnnmg-m": lambda ctx, target: tnnmg(ctx, target, margin=0.05),
    "tnnmg-i3": lambda ctx, target: tnnmg(ctx, target, inner=3),
    "tnnmg-a3": lambda ctx, target: tnnmg(ctx, target, rounds=3),
    "tnnmg-t10": lambda ctx, target: tnnmg(ctx, target, smooth=20, inner=10, inward=True),
}


def _oracle_table(names: list[str], sweeps: int, combos: list[tuple[str, str]]) -> None:
    from benchmarks.solver_lab.methods.gauss_seidel import _law_sweeps
    from benchmarks.solver_lab.outcome import Context
    from benchmarks.solver_lab.problems import load_all

    print(
        "| problem | statuses, thresholds | free rows | velocity error m/s: iterate / step / projected | r_n < 0 |"
        " \\|r_t\\| > s | NLGS sweeps to 1e-5 m/s: from the iterate / after the projected step |"
        " iterate vs reference: open/closed, stick/slide differ |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for p in load_all(names):
        ctx = Context(p)
        base = None
        for statuses, thresholds in combos:
            o = oracle_step(ctx, sweeps, statuses, thresholds)
            if base is None:
                base = _law_sweeps(ctx, o["r_iterate"], 1e-5)
            after, ok_a = _law_sweeps(ctx, o["r_projected"], 1e-5)
            e = [f"{o[k][0]:.1e}" for k in ("iterate", "step", "projected")]
            print(
                f"| {p.name} | {statuses}, {thresholds} | {o['free']} | {' / '.join(e)} | {o['rn<0']} |"
                f" {o['|rt|>s']} | {base[0]}{'' if base[1] else '*'} / {after}{'' if ok_a else '*'} |"
                f" {o['closed≠']}, {o['stick≠']} |",
                flush=True,
            )


if __name__ == "__main__":
    # python -m benchmarks.solver_lab.methods.tnnmg [--sweeps K] [--all] PROBLEM …
    args = sys.argv[1:]
    k = 0
    if "--sweeps" in args:
        i = args.index("--sweeps")
        k = int(args[i + 1])
        del args[i : i + 2]
    combos = [("reference", "reference")]
    if "--all" in args:
        args.remove("--all")
        combos = [(a, b) for a in ("iterate", "reference") for b in ("iterate", "reference")]
    _oracle_table(args, k, combos)
