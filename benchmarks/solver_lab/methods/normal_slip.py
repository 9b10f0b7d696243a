"""Normal impulses solved exactly, alternated with the course-slip step: does the outer count stay flat with height?

"nlgs-slip" (JOURNAL) found the sweeps spent on the contacts' normal impulses (the load path of weight and
overturning): handed the reference's normals, its course-slip step converges the cold steps in 11–15× fewer fine
sweeps. Here the normals come from no oracle: with the tangential impulses held, the normal (Signorini) sub-problem
is the strictly convex QP in the dynamic blocks' velocities x

    min ½ (x − x*)ᵀ M (x − x*)   subject to   z = H_n x + c ≥ 0,     x* = x_free + M⁻¹ H_tᵀ r_t,
    c = bias + the supports' part of u_n,  multipliers r_n ≥ 0:  M (x − x*) = H_nᵀ r_n,  z ∘ r_n = 0,

solved to NORMAL_TOL by a primal–dual interior point (Mehrotra predictor–corrector, as methods/ipm.py with the
normal rows only: K = M + H_nᵀ diag(r_n / z) H_n, one banded Cholesky an iteration, ipm.Operators' band map with
G = (0, 0, 0, d)). x is unique; r_n is not on a hyperstatic wall, and the interior point ends near the analytic
centre of the solution set (every closed contact of a pair shares the load).

    cones:  with the bound r_n ≥ l = |r_t| / μ in place of r_n ≥ 0 (r_n = l + λ, λ ≥ 0, x* shifted by M⁻¹ H_nᵀ l),
            the held r_t stays in its cone and the full solution is a fixed point of (a); with r_n ≥ 0 and r_t
            clipped afterwards it is not (the interior point moves load between a pair's contacts, the clip then
            moves v: wall-8-cold stalled at 4.9e-5 m/s with k = 20, an early version)

    round:  (a) r_n ← normal_solve(r_t held, cones) (warm: the current r_n − l lifted by START, then Mehrotra's
                shift); v = v(r)
            (b) one course-slip step of slip.py from (v, r), realised by the tangential spread (the realisation
                JOURNAL "nlgs-slip" measured from the reference's normals: 133 / 372 / 1400 / 3296 fine sweeps to
                1e-5 m/s on the cold steps of 8 / 16 / 32 / 64 courses); "guard" (the METHODS): undone when it
                raises the residual above (a)'s; "always": kept (k = 0 then diverges on wall-8-cold, residual 1e12
                after 40 rounds); "none": skipped; "tresca": replaced by the exact tangential sub-problem with the
                normals held (tangential_solve: the two-block exact alternation)
            (c) k engine sweeps (plain Gauss–Seidel), k = 0, 5 or 20
    solve:  r = r_warm; repeat rounds until the RMS law residual of (v(r), r) ≤ target, ROUND_CAP rounds or CAP fine
            sweeps.
    once:   SWEEPS engine sweeps, one round (a, b), then engine sweeps to the target (counted in chunks ≥ 10 %
            apart, as slip_oracle): the oracle-free counterpart of "pair-NM+slip-tangential".

``iterations``: outer rounds; ``detail``: fine sweeps and the interior point's factorisations (an engine version
would spend ~39 sweep units on each on 64 courses: JOURNAL, "Issue 10's second point as a budget"). Sweep units:
fine sweeps + the numpy / scipy CPU of (a) and (b) over one engine sweep's (not a cost estimate, the lab's rule).
"""

from __future__ import annotations

import sys

import numpy as np

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import ipm as I
from benchmarks.solver_lab.methods import slip as S
from benchmarks.solver_lab.outcome import Clock, Outcome

NORMAL_TOL = 1e-8
"""m/s: the normal solve stops when the RMS primal residual and RMS min(z, W_nn r_n) are both below this (1e-3 ×
the lab's target; the factor's rounding stalls it near 1e-9 on wall-8-cold), or when its step falls below STALL."""
STALL = 1e-6
PROGRESS = 0
"""CLI --progress: a line on stderr every this many rounds (0: none)."""
SIGMA = 0.1
"""The tangential solve's centring parameter."""
NORMAL_CAP = 100
"""Interior-point iterations a normal solve."""
ROUND_CAP = 400
CAP = 50_000
"""Fine sweeps."""
SWEEPS = 20
"""``once``: engine sweeps before its one round."""
START = 0.1
"""The normal solve's start: slacks and multipliers lifted by this fraction of their largest value."""
OPEN = 1e-9
"""A contact counts as carrying load (for the status flips) when r_n > OPEN × the largest r_n."""


def normal_solve(
    ops: I.Operators, r: np.ndarray, tol: float = NORMAL_TOL, cones: bool = True
) -> tuple[np.ndarray, int]:
    """(r_n (C,), factorisations): the normal sub-problem of the module doc with r's tangential impulses held,
    warm-started from r's normal impulses. ``cones``: r_n ≥ l = |r_t| / μ instead of r_n ≥ 0 (solved as
    r_n = l + λ, λ ≥ 0): the held r_t stays in its cone, and the full problem's solution stays a fixed point."""
    c = r.shape[0]
    low = np.abs(r[:, 0]) / ops.mu if cones else np.zeros(c)
    rt = np.stack([r[:, 0], low], 1).ravel()
    x_star = ops.x_free + ops.minv * (ops.HdT @ rt)
    cst = ops.bias + ops.u_const[:, 1]
    hn = ops.Hd[1::2]
    hnT = hn.T.tocsr()

    def velocity(lam):
        return x_star + ops.minv * (hnT @ lam)

    def rows(x):
        return hn @ x + cst

    lam = np.maximum(r[:, 1] - low, 0.0)
    z = rows(velocity(lam))
    # off the boundary first: a consistent warm start has z ∘ r_n ≈ 0, where Mehrotra's shift alone left the
    # iterate stuck (wall-8-cold: complementarity 3e-14 at the first iteration, steps 1e-5 … 0 after)
    z = np.maximum(z, 0.0) + START * max(float(np.abs(z).max(initial=0.0)), 1e-3)
    lam = lam + START * max(float(lam.max(initial=0.0)), 1e-3)
    z, lam = I.interior(z, lam)
    x = velocity(lam)
    cap_d = I.D_CAP * ops.m.max(initial=1.0)
    its = 0
    while its < NORMAL_CAP:
        rp = rows(x) - z
        comp = np.minimum(z, ops.wnn * lam)
        if np.sqrt((rp * rp).mean()) <= tol and np.sqrt((comp * comp).mean()) <= tol:
            break
        its += 1
        mu_c = float(z @ lam) / c
        d = np.minimum(lam / z, cap_d)
        zero = np.zeros(c)
        fac = ops.factor_blocks(np.concatenate([zero, zero, zero, d]))
        dx = ops.solve(fac, -(hnT @ (lam + d * rp)))
        dz_a = hn @ dx + rp
        dl_a = -lam - d * dz_a
        a_aff = min(1.0, I._max_step(z, dz_a), I._max_step(lam, dl_a))
        mu_aff = float((z + a_aff * dz_a) @ (lam + a_aff * dl_a)) / c
        sigma = min((mu_aff / mu_c) ** 3, 1.0) if mu_c > 0 else 0.0
        g = lam + (dz_a * dl_a - sigma * mu_c) / z
        dx = ops.solve(fac, -(hnT @ (g + d * rp)))
        dz = hn @ dx + rp
        dl = -g - d * dz
        alpha = min(1.0, I.STEP_FRACTION * min(I._max_step(z, dz), I._max_step(lam, dl)))
        lam = lam + alpha * dl
        z = z + alpha * dz
        x = velocity(lam)
        if alpha < STALL:
            break
    return low + lam, its


def tangential_solve(ops: I.Operators, r: np.ndarray, tol: float = NORMAL_TOL) -> tuple[np.ndarray, int]:
    """(r_t (C,), factorisations): the Tresca sub-problem with r's normal impulses held, g = μ r_n,

        min ½ (x − x°)ᵀ M (x − x°) + Σ_α g_α |u_t,α(x)|,   x° = x_free + M⁻¹ H_nᵀ r_n,

    as min ½ |x − x°|²_M + gᵀw s.t. s1 = w − u_t ≥ 0, s2 = w + u_t ≥ 0 with multipliers a, b ≥ 0 (a ⟂ s1, b ⟂ s2,
    a + b = g, r_t = b − a, x = x° + M⁻¹ H_tᵀ r_t), by a primal–dual interior point (σ = SIGMA); w eliminated,
    each iteration factors K = M + H_tᵀ diag(4 d1 d2 / (d1 + d2)) H_t (d1 = a / s1, d2 = b / s2). Contacts with
    g ≤ OPEN × the largest g keep r_t = 0. Cold: r_t = 0 (module code says why)."""
    c = r.shape[0]
    g = ops.mu * np.maximum(r[:, 1], 0.0)
    on = g > OPEN * max(float(g.max(initial=0.0)), 1e-300)  # a bound ~1e-16 of the largest stalls the steps at 1e-14
    ht = ops.Hd[0::2][on]
    htT = ht.T.tocsr()
    ct = ops.u_const[on, 0]
    x0 = ops.x_free + ops.minv * (ops.HdT @ np.stack([np.zeros(c), r[:, 1]], 1).ravel())
    gg = g[on]
    # start at the box's centre (r_t = 0) with every product a s1 = b s2 equal: the warm r_t's near-bound a or b
    # stalled the steps at 1e-14 (wall-64-cold after 20 sweeps)
    a = 0.5 * gg.copy()
    b = 0.5 * gg.copy()

    def velocity(a, b):
        return x0 + ops.minv * (htT @ (b - a))

    x = velocity(a, b)
    u = ht @ x + ct
    scale = max(float(np.abs(u).max(initial=0.0)), 1e-3)
    s1 = scale * gg.mean() / gg
    s2 = s1.copy()
    w = np.abs(u) + scale
    zero = np.zeros(c)
    its = 0
    while its < NORMAL_CAP and gg.size:
        p1, p2 = w - u - s1, w + u - s2
        rw = a + b - gg
        mu_c = float(a @ s1 + b @ s2) / (2 * gg.size)
        worst = max(np.abs(p1).max(), np.abs(p2).max())
        comp = np.maximum(np.minimum(s1, a * ops.wnn[on]), np.minimum(s2, b * ops.wnn[on]))  # both pairs
        if worst <= tol and np.sqrt((comp * comp).mean()) <= tol and np.abs(rw).max() <= 1e-9 * gg.max():
            break
        its += 1
        d1, d2 = a / s1, b / s2
        D = d1 + d2
        e1, e2 = SIGMA * mu_c / s1 - a, SIGMA * mu_c / s2 - b
        f = rw + e1 + e2 - d1 * p1 - d2 * p2
        h = e1 - e2 - d1 * p1 + d2 * p2
        gt = zero.copy()
        gt[on] = 4 * d1 * d2 / D
        fac = ops.factor_blocks(np.concatenate([gt, zero, zero, zero]))
        dx = ops.solve(fac, -(htT @ (h + (d2 - d1) * f / D)))
        du = ht @ dx
        dw = (f + (d1 - d2) * du) / D
        ds1, ds2 = dw - du + p1, dw + du + p2
        da, db = e1 - d1 * ds1, e2 - d2 * ds2
        alpha = min(
            1.0,
            I.STEP_FRACTION * min(I._max_step(a, da), I._max_step(b, db), I._max_step(s1, ds1), I._max_step(s2, ds2)),
        )
        a, b, s1, s2, w = a + alpha * da, b + alpha * db, s1 + alpha * ds1, s2 + alpha * ds2, w + alpha * dw
        x = velocity(a, b)
        u = ht @ x + ct
        if alpha < STALL:
            break
    out = np.zeros(c)
    out[on] = np.clip(b - a, -gg, gg)
    return out, its


def with_normals(ctx, r: np.ndarray, rn: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(r', v'): r's normals replaced by ``rn``, its tangentials clipped into the new cones; v' = v(r')."""
    out = r.copy()
    out[:, 1] = rn
    lim = ctx.p.mu * rn
    out[:, 0] = np.clip(out[:, 0], -lim, lim)
    return out, law.velocity_from_impulse(ctx.p, ctx.H, out)


def outer_round(ctx, ops, chain, r, clock, slip="always") -> tuple[np.ndarray, np.ndarray, int, float]:
    """(a) and (b) of the module doc from r: (r', v', factorisations, residual after (a)). ``slip``: "always",
    "guard" ((b) undone when it raises the residual above (a)'s) or "none" ((a) alone)."""
    with clock("normal"):
        rn, its = normal_solve(ops, r)
        r, v = with_normals(ctx, r, rn)
    with clock("check"):
        res_a = ctx.residual(v, r)
    if slip == "none":
        return r, v, its, res_a
    if slip == "tresca":  # (b) replaced by the exact tangential sub-solve: a two-block exact alternation
        with clock("slip"):
            rt, its_t = tangential_solve(ops, r)
            r = np.stack([rt, r[:, 1]], 1)
            v = law.velocity_from_impulse(ctx.p, ctx.H, r)
        ctx.slip_kept = getattr(ctx, "slip_kept", 0) + 1
        return r, v, its + its_t, res_a
    with clock("slip"):
        r2, v2, _ = S.coarse_step(ctx, chain, v, r, "tangential")
    if slip == "guard":
        with clock("check"):
            if ctx.residual(v2, r2) > res_a:
                return r, v, its, res_a
    ctx.slip_kept = getattr(ctx, "slip_kept", 0) + 1
    return r2, v2, its, res_a


def alternate(
    ctx, target: float, k: int, trace: list | None = None, rounds_cap: int = ROUND_CAP, slip: str = "always"
) -> Outcome:
    """The solve of the module doc with k engine sweeps a round. ``trace`` (a list): per round (fine sweeps,
    residual after (a), after (b), after (c), velocity error, contacts whose load status flipped in (a), the
    share of the residual² on head joints)."""
    p = ctx.p
    clock = Clock()
    with clock("setup"):
        ops = I.Operators(ctx)
        chain = S.build_chain(p, ctx.pack)
    r = p.r_warm.copy()
    done = rounds = factors = 0
    ctx.slip_kept = 0
    ok = False
    v = law.velocity_from_impulse(p, ctx.H, r)
    head = np.abs(p.normal[:, 1]) < 0.5
    while rounds < rounds_cap and done < CAP:
        loaded = r[:, 1] > OPEN * max(float(r[:, 1].max(initial=0.0)), 1e-300)
        r, v, its, res_a = outer_round(ctx, ops, chain, r, clock, slip)
        factors += its
        rounds += 1
        flips = int((loaded != (r[:, 1] > OPEN * max(float(r[:, 1].max(initial=0.0)), 1e-300))).sum())
        with clock("check"):
            res_b = ctx.residual(v, r)
        if k:
            with clock("sweeps"):
                v, _ = ctx.sweep(r, k)
            done += k
        with clock("check"):
            e = law.law_residual(p, ctx.pack, ctx.H, v, r)
            res = float(np.sqrt((e * e).mean()))
        if trace is not None:
            share = float((e[head] ** 2).sum() / max((e * e).sum(), 1e-300))
            trace.append((done, res_a, res_b, res, law.velocity_error(p, v), flips, share))
            if PROGRESS and rounds % PROGRESS == 0:
                print(f"  {p.name} round {rounds}: residual {res:.2e} m/s, flips {flips}", file=sys.stderr, flush=True)
        if res <= target:
            ok = True
            break
    units = done + sum(clock.phases.get(n, 0.0) for n in ("normal", "slip")) / ctx.sweep_s
    detail = f"{done} fine, {factors} factorisations, slip kept {ctx.slip_kept}"
    return Outcome(v, r, rounds, units, clock.phases, converged=ok, detail=detail)


def once(ctx, target: float, sweeps: int = SWEEPS) -> dict:
    """``sweeps`` engine sweeps, one round (a, b), then engine sweeps to ``target`` (chunks ≥ 10 % apart):
    {"fine": sweeps in all, "factorisations", "residual_a", "residual_b", "v_error"}."""
    p = ctx.p
    ops = I.Operators(ctx)
    chain = S.build_chain(p, ctx.pack)
    r = p.r_warm.copy()
    ctx.sweep(r, sweeps)
    r, v, its, res_a = outer_round(ctx, ops, chain, r, Clock())
    res_b = ctx.residual(v, r)
    done, v = S.sweeps_to(ctx, r, target, CAP, sweeps, v)
    return {
        "fine": done,
        "factorisations": its,
        "residual_a": res_a,
        "residual_b": res_b,
        "v_error": law.velocity_error(p, v),
    }


def _variant(k):
    return lambda ctx, target: alternate(ctx, target, k, slip="guard")


METHODS = {f"nlgs-normal-slip-k{k}": _variant(k) for k in (0, 5, 20)}  # slip "guard"


def quartiles(ctx, v, r) -> list[float]:
    """Shares of the residual² on the contacts of each quarter of the courses, bottom first (a contact's course:
    its upper body's; the ground's contacts in the first)."""
    p = ctx.p
    e = law.law_residual(p, ctx.pack, ctx.H, v, r) ** 2
    course = S.build_chain(p, ctx.pack).course
    c = np.maximum(course[p.body[:, 0]], course[p.body[:, 1]])
    q = np.minimum(4 * np.maximum(c, 0) // max(int(course.max()) + 1, 1), 3)
    return list(np.bincount(q, e, 4) / max(e.sum(), 1e-300))


def _table(names, ks, target, slip, rounds_cap=ROUND_CAP) -> None:
    from benchmarks.solver_lab.outcome import Context
    from benchmarks.solver_lab.problems import load_all

    print(
        "| problem | k | rounds | fine sweeps | factorisations (slip steps kept) | residual m/s | velocity error m/s | last round:"
        " residual after (a) / (b) / (c), status flips in (a), head-joint share of residual² |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for prob in load_all(names):
        ctx = Context(prob)
        ctx.sweep_s = 1.0  # units unused here
        for k in ks:
            if k < 0:
                o = once(ctx, target)
                print(
                    f"| {prob.name} | once | 1 | {o['fine']} | {o['factorisations']} | ≤ {target:g} |"
                    f" {o['v_error']:.1e} | {o['residual_a']:.1e} / {o['residual_b']:.1e} / – |",
                    flush=True,
                )
                continue
            trace: list = []
            out = alternate(ctx, target, k, trace, rounds_cap, slip)
            last = trace[-1]
            quart = quartiles(ctx, out.v, out.r)
            hist = ", ".join(f"{i}: {trace[i - 1][3]:.1e}" for i in (10, 30, 100, 300) if i <= len(trace))
            flips = [t[5] for t in trace]
            print(
                f"| {prob.name} | {k} | {out.iterations}{'' if out.converged else '*'} | {trace[-1][0]} |"
                f" {out.detail.split(', ')[1].split()[0]} ({ctx.slip_kept}) | {last[3]:.1e} | {last[4]:.1e} |"
                f" {last[1]:.1e} / {last[2]:.1e} / {last[3]:.1e}, flips {flips[-1]} (max {max(flips)}),"
                f" head {last[6]:.2f}, by height quarter {' / '.join(f'{q:.2f}' for q in quart)};"
                f" residual at rounds {hist} |",
                flush=True,
            )


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description="normal impulses solved exactly, alternated with the slip step")
    ap.add_argument("problems", nargs="+")
    ap.add_argument("--k", nargs="+", type=int, default=[0, 5, 20], help="engine sweeps a round; -1: 'once'")
    ap.add_argument("--target", type=float, default=1e-5)
    ap.add_argument("--slip", default="guard", choices=["always", "guard", "none", "tresca"])
    ap.add_argument("--rounds", type=int, default=ROUND_CAP, help="outer rounds at most")
    ap.add_argument("--progress", type=int, default=0, help="a line on stderr every this many rounds")
    a = ap.parse_args()
    PROGRESS = a.progress
    _table(a.problems, a.k, a.target, a.slip, a.rounds)
