"""Oracles that bound coarse corrections: each is handed part of the tight reference and the engine's sweeps
do the rest (the lab's solver_lab JOURNAL, "nlgs-slip", table 4 and after).

    velocity space  "full": the true error v_ref − v, "rigid": its per-course rigid fit (modes u, v, ω of every
                    course, course_rigid_fit), realised as impulses by slip_realise.min_norm (least norm, with an
                    active set for tension and the cones).
    impulse space   "joint-N", "joint-NM", "joint-NMT": every bed joint's resultants set to the reference's: the
                    normal resultant N_k = Σ r_n (a uniform change over the joint's touching contacts), with
                    "M" its moment about the contacts' mean x (a linear change, Navier's distribution), with "T"
                    its x-friction total (spread by room, slip_realise.spread); r_n clipped at 0 and r_t into the
                    new cones (with_resultants). "pair-N", "pair-NM", "pair-NMT": the same for every body pair
                    (all its contacts, head joints too: the Galerkin "joint" space's resultants). "pair-NM+joint-T": the
                    pairs' N and M, then the bed joints' friction totals; "pair-NM+slip-R": the pairs' N and M,
                    then one slip coarse step (realisation R: tangential, balance, min-norm) from there.

    oracle: sweeps to the target from the warm start alone; with one oracle step after SWEEPS sweeps; with one
            every SWEEPS sweeps (at most ``steps``).
"""

from __future__ import annotations

import numpy as np

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import slip as S
from benchmarks.solver_lab.methods import slip_realise as R
from masonrycli.engine import nlgs as N


def with_resultants(ctx, chain: S.Chain, r, what: str, pairs: bool = False) -> np.ndarray:
    """r with every bed joint's N, M, T (those whose letter is in ``what``) set to the reference's (module doc);
    ``pairs``: every body pair's instead (all contacts, head joints too; M about the pair's mean point along its
    contacts' tangent, T the sum of r_t)."""
    p = ctx.p
    if pairs:
        a_, b_ = p.body[:, 0].astype(np.int64), p.body[:, 1].astype(np.int64)
        inj = np.ones(p.count, bool)
        k = np.unique(a_ * p.inv_mass.size + b_, return_inverse=True)[1].ravel()
        tau = np.ones(p.count)
        t = np.stack([ctx.pack[:, N.P_NY], -ctx.pack[:, N.P_NX]], axis=1)
    else:
        inj = chain.joint >= 0
        k = chain.joint[inj]
        tau = chain.tau[inj]
        t = np.tile([1.0, 0.0], (k.size, 1))
    rows = np.flatnonzero(inj)
    n = int(k.max(initial=-1)) + 1
    x = p.point[inj]
    cnt = np.maximum(np.bincount(k, minlength=n), 1)
    mean = np.stack([np.bincount(k, x[:, j], n) for j in (0, 1)], axis=1) / cnt[:, None]
    xi = ((x - mean[k]) * t).sum(1)
    w = ((r[inj, 1] > 0) | (ctx.pack[inj, N.P_BIAS] <= 0)).astype(float)
    s0, s1, s2 = (np.bincount(k, w * xi**j, n) for j in range(3))
    dN = np.bincount(k, p.r_ref[inj, 1] - r[inj, 1], n) if "N" in what else np.zeros(n)
    dM = np.bincount(k, (p.r_ref[inj, 1] - r[inj, 1]) * xi, n) if "M" in what else np.zeros(n)
    det = s0 * s2 - s1 * s1
    det = np.where(np.abs(det) > 1e-12 * np.maximum(s0 * s2, 1e-300), det, np.inf)  # one point: N only
    a = np.where(np.isfinite(det), (dN * s2 - dM * s1) / det, dN / np.maximum(s0, 1e-300))
    b = np.where(np.isfinite(det), (s0 * dM - s1 * dN) / det, 0.0)
    out = r.copy()
    out[rows, 1] = np.maximum(r[inj, 1] + w * (a[k] + b[k] * xi), 0.0)
    lam = p.mu * out[rows, 1] * np.abs(tau)
    xt = np.clip(tau * r[inj, 0], -lam, lam)
    if "T" in what:
        total = np.bincount(k, lam, n)
        xt = R.spread(lam, xt, k, np.clip(np.bincount(k, tau * p.r_ref[inj, 0], n), -total, total))
    out[rows, 0] = xt / tau
    return out


def course_rigid_fit(p, chain: S.Chain, e: np.ndarray) -> np.ndarray:
    """(B, 3): each course's mass-weighted rigid-body fit (translation and rotation about its centroid) of ``e``."""
    out = np.zeros_like(e)
    m = np.where(p.inv_mass > 0, 1.0 / np.where(p.inv_mass > 0, p.inv_mass, 1.0), 0.0)
    inertia = np.where(p.inv_inertia > 0, 1.0 / np.where(p.inv_inertia > 0, p.inv_inertia, 1.0), 0.0)
    for c in range(chain.n):
        s = chain.course == c
        d = p.q_m[s, :2] - (m[s, None] * p.q_m[s, :2]).sum(0) / m[s].sum()
        V = (m[s, None] * e[s, :2]).sum(0) / m[s].sum()
        L = (inertia[s] * e[s, 2] + m[s] * (d[:, 0] * e[s, 1] - d[:, 1] * e[s, 0])).sum()
        w = L / (inertia[s] + m[s] * (d * d).sum(1)).sum()
        out[s] = np.stack([V[0] - w * d[:, 1], V[1] + w * d[:, 0], np.full(d.shape[0], w)], axis=1)
    return out


def oracle(ctx, kind: str, sweeps: int = S.SWEEPS, target: float = 1e-5, steps: int = 200, cap: int = S.CAP) -> dict:
    """What a coarse step could do at best (module doc): ``kind`` "full", "rigid", "joint-…" or "pair-…" (N, NM,
    NMT). Fine sweeps to the RMS law residual ``target``: from the warm start alone, after one
    oracle step at ``sweeps`` sweeps, and with an oracle step every ``sweeps`` sweeps (at most ``steps``). Counts
    alone and after one step in chunks ≥ 10 % apart (as nlgs-law), the repeated one exactly."""
    p = ctx.p
    chain = S.build_chain(p, ctx.pack)

    def step(v, r):
        if kind.startswith(("joint-", "pair-")):
            for part in kind.split("+"):  # "pair-NM+joint-T": the pairs' normals, then the joints' friction
                if part.startswith("slip-"):  # the slip step itself, from the iterate with the normals given
                    v = law.velocity_from_impulse(p, ctx.H, r)
                    r = S.coarse_step(ctx, chain, v, r, part[len("slip-") :])[0]
                    continue
                group, what = part.split("-")
                r = with_resultants(ctx, chain, r, what, group == "pair")
            return r
        e = p.v_ref - v
        dv = e if kind == "full" else course_rigid_fit(p, chain, e)
        sliding = S.joint_state(ctx, chain, v, r).cls != 1
        return r + R.min_norm(ctx, chain.course, chain.joint, r, sliding, None, dv=dv)

    def count(r, done=0):
        return S.sweeps_to(ctx, r, target, cap, done)[0]

    alone = count(p.r_warm.copy())
    r = p.r_warm.copy()
    v, _ = ctx.sweep(r, sweeps)
    once = count(step(v, r), sweeps)
    r, done, taken = p.r_warm.copy(), 0, 0
    while done < cap:
        v, _ = ctx.sweep(r, sweeps)
        done += sweeps
        if ctx.residual(v, r) <= target:
            break
        if taken < steps:
            r, taken = step(v, r), taken + 1
    return {"alone": alone, "once": once, "repeated": done, "steps": taken}
