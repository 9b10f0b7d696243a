"""Anderson (Krylov-type) acceleration of NLGS, with the mixing chosen in velocity space.

Impulses are not unique on hyperstatic walls, velocities are: so the least-squares mixing minimises the
mass-weighted velocity change of a sweep, f = M^½ (v(G(r)) − v(r)), not an impulse residual. With G one
engine NLGS sweep and the last ``DEPTH`` iterates,

    r'_k = G(r_k),  f_k = M^½ (v(r'_k) − v(r_k))
    γ = argmin |f_k − ΔF γ|           (ΔF: differences of consecutive f)
    r_k+1 = Π_cone(r'_k − ΔR' γ)       (ΔR': differences of consecutive r'; v follows r affinely)

and the history is dropped when |f| grows (safeguard). Stopped on the contact-law residual of (v(r'), r').
"""

from __future__ import annotations

import numpy as np

from benchmarks.solver_lab import law
from benchmarks.solver_lab.outcome import Clock, Outcome, project_cone

DEPTH = 5
CAP = 5_000
CHECK_EVERY = 10
"""The lab checks the (numpy) residual every this many iterations; counts are ≤ 9 high."""


def anderson(ctx, target, depth: int = DEPTH) -> Outcome:
    p = ctx.p
    clock = Clock()
    w = np.sqrt(np.where(ctx.minv > 0, 1.0 / np.where(ctx.minv > 0, ctx.minv, 1.0), 0.0))
    r = p.r_warm.copy()
    with clock("mix"):
        v = law.velocity_from_impulse(p, ctx.H, r)
    hist_r, hist_v, hist_f = [], [], []
    last = np.inf
    ok = False
    iterations = 0
    while iterations < CAP:
        iterations += 1
        rp = r.copy()
        with clock("sweeps"):
            vp, _ = ctx.sweep(rp, 1)
        with clock("check"):
            if iterations % CHECK_EVERY == 0 and ctx.residual(vp, rp) <= target:
                r, v, ok = rp, vp, True
                break
        with clock("mix"):
            f = w * (vp - v).ravel()
            norm = float(np.linalg.norm(f))
            if norm > last:
                hist_r, hist_v, hist_f = [], [], []
            last = norm
            hist_r.append(rp.ravel())
            hist_v.append(vp.ravel())
            hist_f.append(f)
            if len(hist_f) > depth + 1:
                hist_r.pop(0), hist_v.pop(0), hist_f.pop(0)
            if len(hist_f) >= 2:
                dF = np.diff(np.array(hist_f), axis=0).T
                gamma = np.linalg.lstsq(dF, f, rcond=None)[0]
                rn = rp.ravel() - np.diff(np.array(hist_r), axis=0).T @ gamma
                r = project_cone(rn.reshape(-1, 2), p.mu)
                v = law.velocity_from_impulse(p, ctx.H, r)
            else:
                r, v = rp, vp
    return Outcome(v, r, iterations, float(iterations), clock.phases, converged=ok)


METHODS = {"anderson-v": anderson}
