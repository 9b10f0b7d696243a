"""Two-level NLGS with a coarse correction in velocity space: each course's uniform horizontal slip.

On cold steps of the shaken walls most of the slow error is whole courses sliding at the wrong horizontal
speed on bed joints whose contacts slide or sit at the friction limit ("nlgs-galerkin", "Overlapping Schwarz"
in the JOURNAL). An impulse-space interface shear cannot make that motion (it spins the blocks) and a truncated
space is empty there; here the coarse unknowns are the courses' horizontal velocity corrections δu_c, and the
bed joints' friction enters through its exact support function, so sliding joints are in the space.

With the normal impulses (and every impulse but the bed joints' tangential ones) held, the tangential problem
is, in velocity space,  min_v ½ ‖v − v*‖²_M + Σ_{α bed} μ r_n,α |u_t,α(v)|,  v* = v with the bed tangential
impulses removed. Restricted to v = v_cur + P δu (P: course c translated along x; courses = layers by graph
distance from the supports, galerkin.layers):

    chain   course c = layer c+1 (c = 0 … n−1), mass m_c; joint k = contacts between layers k and k+1 whose
            tangent is near horizontal (|τ_α| ≥ TAU_MIN, τ_α = o_α t_α·e_x, o_α = +1 if body b is the upper);
            joint k lies under course k (joint 0: on the supports). Other contacts are held.
    state   λ_α = μ r_n,α |τ_α|, x_α = τ_α r_t,α (x-impulse on the upper body), s_α = τ_α u_t,α (slip, upper −
            lower); classes: 0 = at the limit with x = +λ and s < 0 (sliding −x), 2 = at the limit with x = −λ
            and s > 0, 1 = the rest. Per joint and class: λ_kj = Σ λ_α, S_kj = Σ λ_α s_α / λ_kj; F_k = Σ x_α.
    coarse  min_δu Σ_c ½ m_c (δu_c − a_c)² + Σ_k Σ_j λ_kj |δu_k − δu_{k−1} + S_kj|,  δu_{−1} = 0 (supports),
            a_c = −(F_c − F_{c+1}) / m_c (course c's share of the current bed friction, F_n = 0): each class of a
            joint slips uniformly. Exactly through its dual (chain_dual): min_F ½ Σ_c (F_c − F_{c+1} + m_c a_c)²
            / m_c + Σ_k ψ_k(F_k), ψ_k convex piecewise linear on [−λ_k, λ_k] with slopes S_kj (classes sorted by
            slip, each over a length 2 λ_kj: the cheapest friction first), a tridiagonal M-matrix QP with kinks
            (primal–dual active set on the pieces); δu_c = a_c + (F_c − F_{c+1}) / m_c.
            At the fine solution the step is a no-op: every class-1 contact sticks (S_k1 = 0), every class-0/2
            contact is at the limit against its slip, and a_c makes F the stationary point of the quadratic.
    realise δu as impulses Δr with (v, r) consistent (slip_realise: "tangential", "balance", "min-norm"; the
            default min-norm: the least-norm Δr whose velocity change is P δu, with an active set for the cones).

    solve:  r = r_warm
            repeat: SWEEPS engine sweeps (plain, or the default's momentum sweeps, restarted at each call);
                    stop if RMS law residual ≤ target or CAP fine sweeps;
                    if a coarse step came before these sweeps and the residual is now above the one before it:
                        undo it (back to the pre-step r) and run SWEEPS sweeps from there (counted);
                        ("-once" variants: no coarse step any more)
                    one coarse step

``iterations`` counts fine sweeps (the undone ones included); ``sweeps`` (units) = fine sweeps (momentum sweeps
× ctx.accel_cost) + the CPU of the coarse work (chain, state, dual solve, realisation, v update; numpy and
scipy) over one engine sweep's. The residual checks after the sweeps are not counted (the engine checks during
the sweep), as in galerkin.py. Diagnostics (``python -m benchmarks.solver_lab.methods.slip PROBLEM …``):
:func:`projection` gives the best correction the space allows (the M-orthogonal projection of the true error
onto course x-translations) against what one step does; :func:`rounds` (``--rounds K``) follows K rounds;
:mod:`slip_oracle` (``--oracle rigid full joint-NM …``) bounds coarse steps by handing them the true answer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from benchmarks.solver_lab.methods import slip_realise as R
from benchmarks.solver_lab.methods.galerkin import layers
from benchmarks.solver_lab.outcome import Clock, Outcome
from masonrycli.engine import nlgs as N

SWEEPS = 20
"""Fine sweeps between coarse steps."""
TAU_MIN = 0.5
"""A contact between consecutive layers is in a joint only if its tangent's x-part is at least this."""
CAP = 50_000
"""Fine sweeps."""
LIMIT = 1e-6
"""A joint contact is at the friction limit (sliding class) if |x_α| ≥ (1 − LIMIT) λ_α."""


@dataclass(frozen=True)
class Chain:
    course: np.ndarray
    """(B,) course of each dynamic block (layer − 1), −1 for supports and unreachable blocks."""
    mass: np.ndarray
    """(n,) kg per course."""
    joint: np.ndarray
    """(C,) joint index k (under course k), −1 if the contact is held."""
    tau: np.ndarray
    """(C,) o_α t_α·e_x (0 for held contacts)."""
    n: int


def sweeps_to(ctx, r, target: float, cap: int = CAP, done: int = 0, v=None):
    """Engine sweeps on ``r`` (in place) in chunks of max(10, a tenth of those done), so that the count is
    within 10 % of the fewest that reach ``target`` (RMS law residual), until then or ``cap``:
    (sweeps done in all, the last v; ``v`` if none was run)."""
    while done < cap:
        k = max(10, done // 10)
        v, _ = ctx.sweep(r, k)
        done += k
        if ctx.residual(v, r) <= target:
            break
    return done, v


def build_chain(p, pack) -> Chain:
    """Courses from the layers, joints from the contacts between consecutive layers (module doc, "chain")."""
    lay = layers(p)
    dyn = p.inv_mass > 0
    course = np.where(dyn & (lay >= 1), lay - 1, -1)
    n = int(course.max(initial=-1)) + 1
    m = np.where(dyn, 1.0 / np.where(dyn, p.inv_mass, 1.0), 0.0)
    mass = np.bincount(course[course >= 0], m[course >= 0], minlength=n)
    la, lb = lay[p.body[:, 0]], lay[p.body[:, 1]]
    orient = np.where(lb > la, 1.0, -1.0)
    tau = orient * pack[:, N.P_NY]  # t = (n_y, −n_x): t·e_x = n_y
    ok = (la >= 0) & (lb >= 0) & (np.abs(la - lb) == 1) & (np.abs(tau) >= TAU_MIN) & (np.minimum(la, lb) < n)
    joint = np.where(ok, np.minimum(la, lb), -1)
    return Chain(course, mass, joint, np.where(ok, tau, 0.0), n)


def chain_dual(m, a, B, S, max_iter: int | None = None) -> tuple[np.ndarray, int]:
    """(F (n,), active-set iterations): F minimising ½ Σ_c (F_c − F_{c+1} + m_c a_c)² / m_c + Σ_k ψ_k(F_k),
    F_n = 0, where ψ_k is convex piecewise linear on [B_k0, B_k3] with slopes S_k0 ≤ S_k1 ≤ S_k2 on
    [B_k0, B_k1], [B_k1, B_k2], [B_k2, B_k3] (+∞ outside): the dual of the coarse problem (module doc).

    The quadratic is ½ Fᵀ Q F + gᵀ F, Q = Dᵀ diag(1/m) D (d_c = F_c − F_{c+1}) tridiagonal, Q_kk = 1/m_k +
    1/m_{k−1} (Q_00 = 1/m_0), Q_k,k−1 = −1/m_{k−1}: an M-matrix; g_k = a_k − a_{k−1} (g_0 = a_0). Active set
    on the pieces (primal–dual active set, Hintermüller–Ito–Kunisch, with ψ's kinks as further bounds):
        each k is free on a piece p (row: (QF)_k + g_k + S_kp = 0) or fixed at a kink j (row: F_k = B_kj)
        start: every k free on piece 1
        repeat: banded solve; y = −(QF + g);
                free on p and F_k < B_kp → fixed at p; F_k > B_k,p+1 → fixed at p+1;
                fixed at j and y_k < S_k,j−1 → free on j−1; y_k > S_kj → free on j   (S_k,−1 = −∞, S_k3 = +∞)
        until nothing changes.
    """
    n = m.size
    if n == 0:
        return np.zeros(0), 0
    inv = 1.0 / m
    diag = inv.copy()
    diag[1:] += inv[:-1]
    off = -inv[:-1]  # Q_k,k−1 = Q_k−1,k
    g = a.copy()
    g[1:] -= a[:-1]
    eps = 1e-12 * max(float(np.abs(B).max()), 1e-300)
    lo = np.concatenate([np.full((n, 1), -np.inf), S], axis=1)  # slope left of kink j
    hi = np.concatenate([S, np.full((n, 1), np.inf)], axis=1)  # slope right of kink j
    rows = np.arange(n)
    free = np.ones(n, bool)
    piece = np.ones(n, np.int64)  # free: the piece; fixed: the kink
    F = np.zeros(n)
    its, cap = 0, max_iter or 4 * n + 20
    while its < cap:
        its += 1
        ab = np.zeros((3, n))
        ab[1] = np.where(free, diag, 1.0)
        ab[0, 1:] = np.where(free[:-1], off, 0.0)  # row i's upper entry sits at ab[0, i+1]
        ab[2, :-1] = np.where(free[1:], off, 0.0)  # row i's lower entry sits at ab[2, i−1]
        rhs = np.where(free, -g - S[rows, np.minimum(piece, 2)], B[rows, piece])
        F = sla.solve_banded((1, 1), ab, rhs, check_finite=False)
        QF = diag * F
        QF[1:] += off * F[:-1]
        QF[:-1] += off * F[1:]
        y = -(QF + g)
        new_free, new_piece = free.copy(), piece.copy()
        p = np.minimum(piece, 2)
        below = free & (F < B[rows, p] - eps)
        above = free & ~below & (F > B[rows, p + 1] + eps)
        new_free[below | above] = False
        new_piece[above] = p[above] + 1
        left = ~free & (y < lo[rows, piece])
        right = ~free & ~left & (y > hi[rows, piece])
        new_free[left | right] = True
        new_piece[left] = piece[left] - 1
        if not (below.any() or above.any() or left.any() or right.any()):
            break
        free, piece = new_free, new_piece
    return np.clip(F, B[:, 0], B[:, 3]), its


@dataclass
class State:
    """The bed joints' friction at (v, r) (module doc, "state")."""

    lam_c: np.ndarray  # (C,) λ_α (0 for held contacts)
    x: np.ndarray  # (C,) x_α
    cls: np.ndarray  # (C,) 0: sliding with the upper body going −x (x = +λ), 1: the rest, 2: sliding +x
    lam: np.ndarray  # (n, 3) Σ λ_α per joint and class
    F: np.ndarray  # (n,) F_k
    S: np.ndarray  # (n, 3) λ-weighted mean slip per class


def joint_state(ctx, chain: Chain, v, r) -> State:
    p = ctx.p
    j = chain.joint
    inj = j >= 0
    k = j[inj]
    lam_c = np.zeros(p.count)
    lam_c[inj] = p.mu * np.maximum(r[inj, 1], 0.0) * np.abs(chain.tau[inj])
    x = chain.tau * r[:, 0]
    s = chain.tau * (ctx.H @ v.ravel())[0::2]  # upper − lower x-slip at the contact
    at = np.abs(x) >= (1.0 - LIMIT) * lam_c
    cls = np.ones(p.count, np.int64)
    cls[inj & at & (x > 0) & (s < 0)] = 0
    cls[inj & at & (x < 0) & (s > 0)] = 2
    idx = k * 3 + cls[inj]
    lam = np.bincount(idx, lam_c[inj], 3 * chain.n).reshape(-1, 3)
    slip = np.bincount(idx, lam_c[inj] * s[inj], 3 * chain.n).reshape(-1, 3)
    S = np.where(lam > 0, slip / np.where(lam > 0, lam, 1.0), 0.0)
    F = np.bincount(k, x[inj], chain.n)
    return State(lam_c, x, cls, lam, F, S)


def coarse_step(ctx, chain: Chain, v, r, realise: str = "min-norm", theta: float = 1.0):
    """One coarse step from the consistent pair (v, r): (r', v', δu (n,) the courses' x-velocity changes);
    ``realise``: "tangential", "balance" or "min-norm" (slip_realise); ``theta``: the step's fraction."""
    st = joint_state(ctx, chain, v, r)
    m = chain.mass
    # ψ_k: the classes in increasing slip (the cheapest friction first), kinks at their cumulative bounds
    order = np.argsort(st.S, axis=1, kind="stable")
    lam_s = np.take_along_axis(st.lam, order, 1)
    lam = lam_s.sum(1)
    B = np.concatenate([-lam[:, None], -lam[:, None] + 2 * np.cumsum(lam_s, axis=1)], axis=1)
    a = -(st.F - np.append(st.F[1:], 0.0)) / m
    F_new, _ = chain_dual(m, a, B, np.take_along_axis(st.S, order, 1))
    # the greedy allocation of F' over the classes (ψ's minimiser), each class's new total
    X_sorted = np.clip(F_new[:, None] - B[:, :3], 0.0, 2 * lam_s) - lam_s
    X_new = np.empty_like(X_sorted)
    np.put_along_axis(X_new, order, X_sorted, 1)
    du = (F_new - np.append(F_new[1:], 0.0)) / m + a
    if realise == "min-norm":
        dr = R.min_norm(ctx, chain.course, chain.joint, r, st.cls != 1, theta * du)
    else:
        inj = chain.joint >= 0
        idx = chain.joint[inj] * 3 + st.cls[inj]
        X_cur = np.bincount(idx, st.x[inj], 3 * chain.n)
        target = X_cur + theta * (X_new.ravel() - X_cur)
        dr = R.spread_joints(ctx, chain.joint, chain.tau, r, st.lam_c, st.x, idx, target, realise == "balance")
    return r + dr, v + (ctx.minv * (ctx.H.T @ dr.ravel())).reshape(-1, 3), du


def slip_solve(
    ctx, target, sweeps=SWEEPS, smoother="nlgs", cap=CAP, realise="min-norm", once=False, theta=1.0, trace=None
) -> Outcome:
    """The two-level solve of the module doc. ``once``: no coarse step after the first one undone. ``trace`` (a
    list): appends (fine sweeps, residual before the coarse step, residual after) per coarse step."""
    p = ctx.p
    clock = Clock()
    with clock("coarse"):
        chain = build_chain(p, ctx.pack)
    r = p.r_warm.copy()
    done = steps = kept = 0
    ok = False
    v = p.v_free.copy()
    saved = None  # (r before the last coarse step, the residual then): the delayed guard's fallback
    coarse = True
    while done < cap:
        with clock("sweeps"):
            v, _ = ctx.sweep(r, sweeps, smoother)
        done += sweeps
        with clock("check"):
            res = ctx.residual(v, r)
        if res <= target:
            ok = True
            break
        if saved is not None:
            if res > saved[1]:  # the step and its sweeps did worse than the pre-step iterate: undo
                r, coarse = saved[0], not once
                with clock("sweeps"):
                    v, _ = ctx.sweep(r, sweeps, smoother)
                done += sweeps
                with clock("check"):
                    res = ctx.residual(v, r)
                if res <= target:
                    ok = True
                    break
            else:
                kept += 1
            saved = None
        if not coarse:
            continue
        saved = (r.copy(), res)
        with clock("coarse"):
            r, v, _ = coarse_step(ctx, chain, v, r, realise, theta)
        steps += 1
        if trace is not None:
            trace.append((done, res, ctx.residual(v, r)))
    fine = done * (ctx.accel_cost if smoother == "nlgs-accel" else 1.0)
    units = fine + clock.phases.get("coarse", 0.0) / ctx.sweep_s
    return Outcome(v, r, done, units, clock.phases, converged=ok, detail=f"{kept}/{steps} coarse kept")


def _variant(**kw):
    return lambda ctx, target: slip_solve(ctx, target, **kw)


METHODS = {  # "nlgs-…": the harness takes the method's own units (not its numpy checks), as for nlgs-galerkin
    "nlgs-slip": _variant(),
    "nlgs-slip-once": _variant(once=True),
    "nlgs-slip-s50": _variant(sweeps=50),
    "nlgs-slip-balance": _variant(realise="balance"),
    "nlgs-slip-tangential": _variant(realise="tangential"),
    "nlgs-slip-accel": _variant(smoother="nlgs-accel"),
    "nlgs-slip-accel-once": _variant(smoother="nlgs-accel", once=True),
}


def course_means(p, chain: Chain, e: np.ndarray) -> np.ndarray:
    """(n,) mass-weighted mean x of ``e`` (B, 3) over each course."""
    s = chain.course >= 0
    m = np.where(p.inv_mass > 0, 1.0 / np.where(p.inv_mass > 0, p.inv_mass, 1.0), 0.0)
    return np.bincount(chain.course[s], m[s] * e[s, 0], chain.n) / chain.mass


def projection(ctx, sweeps: int, smoother: str = "nlgs", realise: str = "min-norm") -> dict:
    """After ``sweeps`` engine sweeps from the warm start: the mass-weighted RMS velocity error against the
    reference (m/s) before, after the best correction the space allows (each course's mean x-error removed:
    the M-orthogonal projection onto course x-translations), after one coarse step, and after the step plus
    the same number of sweeps again against those sweeps alone; the law residual before / after the step."""
    p = ctx.p
    chain = build_chain(p, ctx.pack)
    r = p.r_warm.copy()
    v, _ = ctx.sweep(r, sweeps, smoother)
    m = np.where(ctx.minv > 0, 1.0 / np.where(ctx.minv > 0, ctx.minv, 1.0), 0.0).reshape(-1, 3)

    def err(vv):
        e = p.v_ref - vv
        return float(np.sqrt((m * e * e).sum() / m.sum()))

    e = p.v_ref - v
    best = v.copy()
    s = chain.course >= 0
    best[s, 0] += course_means(p, chain, e)[chain.course[s]]
    r2, v2, du = coarse_step(ctx, chain, v, r, realise)
    shift = v.copy()  # the step's course translations alone, as the coarse problem meant them
    shift[s, 0] += du[chain.course[s]]
    r_more, r_step = r.copy(), r2.copy()
    v_more, _ = ctx.sweep(r_more, sweeps, smoother)
    v_step, _ = ctx.sweep(r_step, sweeps, smoother)
    return {
        "courses": chain.n,
        "joint_contacts": int((chain.joint >= 0).sum()),
        "error": err(v),
        "best": err(best),
        "translation": err(shift),
        "step": err(v2),
        "more": err(v_more),
        "step_more": err(v_step),
        "residual": ctx.residual(v, r),
        "residual_step": ctx.residual(v2, r2),
    }


def rounds(ctx, sweeps: int, count: int, realise: str = "min-norm") -> list[tuple]:
    """``count`` rounds of (``sweeps`` engine sweeps, one coarse step, always kept) against the same sweeps
    alone: per round (sweeps, M-RMS velocity error and its course-translation part, residual) for the sweeps
    alone, for the two-level iterate before its step, and after the step."""
    p = ctx.p
    chain = build_chain(p, ctx.pack)
    m = np.where(ctx.minv > 0, 1.0 / np.where(ctx.minv > 0, ctx.minv, 1.0), 0.0).reshape(-1, 3)
    s = chain.course >= 0

    def measure(v, r):
        e = p.v_ref - v
        t = np.zeros_like(e)
        t[s, 0] = course_means(p, chain, e)[chain.course[s]]
        return (
            float(np.sqrt((m * e * e).sum() / m.sum())),
            float(np.sqrt((m * t * t).sum() / m.sum())),
            ctx.residual(v, r),
        )

    r, r0 = p.r_warm.copy(), p.r_warm.copy()
    out = []
    for i in range(count):
        v, _ = ctx.sweep(r, sweeps)
        v0, _ = ctx.sweep(r0, sweeps)
        before = measure(v, r)
        r, v, _ = coarse_step(ctx, chain, v, r, realise)
        out.append(((i + 1) * sweeps, measure(v0, r0), before, measure(v, r)))
    return out


def _projection_table(names, sweeps, smoother: str, realise: str, count: int, oracle_kinds=()) -> None:
    from benchmarks.solver_lab.outcome import Context
    from benchmarks.solver_lab.problems import load_all

    probs = load_all(names)
    if oracle_kinds:
        from benchmarks.solver_lab.methods.slip_oracle import oracle

        print("| problem | oracle | fine sweeps to 1e-5 m/s: alone / one step / a step every SWEEPS (steps) |")
        print("|---|---|---|")
        for prob in probs:
            for kind in oracle_kinds:
                o = oracle(Context(prob), kind, sweeps[0])
                print(
                    f"| {prob.name} | {kind} | {o['alone']} / {o['once']} / {o['repeated']} ({o['steps']}) |",
                    flush=True,
                )
        return
    if count:
        print("| problem | sweeps | alone: error / translation part / residual | two-level before its step | after |")
        print("|---|---|---|---|---|")
        for prob in probs:
            for n, *cols in rounds(Context(prob), sweeps[0], count, realise):
                text = " | ".join(f"{e:.2e} / {t:.2e} / {r:.1e}" for e, t, r in cols)
                print(f"| {prob.name} | {n} | {text} |", flush=True)
        return
    print(
        "| problem | sweeps | M-RMS velocity error m/s: iterate / best in space / step's translation / after the"
        " step | then as many sweeps again: without / with the step | law residual RMS m/s: iterate / after the"
        " step |"
    )
    print("|---|---|---|---|---|")
    for prob in probs:
        ctx = Context(prob)
        for n in sweeps:
            o = projection(ctx, n, smoother, realise)
            print(
                f"| {prob.name} | {n} | {o['error']:.2e} / {o['best']:.2e} / {o['translation']:.2e} / {o['step']:.2e}"
                f" | {o['more']:.2e} / {o['step_more']:.2e} | {o['residual']:.1e} / {o['residual_step']:.1e} |",
                flush=True,
            )


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description="the course-slip space's reach against its coarse step (projection())")
    ap.add_argument("problems", nargs="+")
    ap.add_argument("--sweeps", nargs="+", type=int, default=[20, 200])
    ap.add_argument("--smoother", default="nlgs", choices=["nlgs", "nlgs-accel"])
    ap.add_argument("--realise", default="min-norm", choices=["tangential", "balance", "min-norm"])
    ap.add_argument("--rounds", type=int, default=0, help="instead: this many rounds of sweeps + step (rounds())")
    kinds = ["rigid", "full", "pair-NM+joint-T", "pair-NM+slip-tangential", "pair-NM+slip-min-norm"] + [
        f"{g}-{w}" for g in ("joint", "pair") for w in ("N", "NM", "NMT")
    ]
    ap.add_argument("--oracle", nargs="*", default=[], choices=kinds, help="instead: slip_oracle.oracle()")
    a = ap.parse_args()
    _projection_table(a.problems, a.sweeps, a.smoother, a.realise, a.rounds, a.oracle)
