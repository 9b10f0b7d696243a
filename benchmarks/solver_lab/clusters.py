"""How much of a Gauss–Seidel iterate's velocity error is rigid motion of clusters of sticking blocks.

Clusters: connected components of the blocks joined by contacts whose exact local solve is a stick
(statuses as in ``methods/newton.statuses``). A cluster holding a stick contact with a support is left
out (its rigid motion is the support's). For every other cluster the error e = v − v_ref of its blocks
is projected, mass-weighted, on rigid motions (V, ω): e_i ≈ (V + ω ẑ × (x_i − X), ω). The share is
Σ |projection|²_M / Σ |e|²_M over all blocks. A share near 1 says a coarse correction that moves whole
clusters would remove the error Gauss–Seidel is slow to remove.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import newton
from benchmarks.solver_lab.outcome import Context
from benchmarks.solver_lab.problems import load_all


def rigid_share(p, st: np.ndarray, v: np.ndarray) -> tuple[float, int]:
    """(share of the mass-weighted error energy in cluster-rigid motion, number of free clusters)."""
    dyn = p.inv_mass > 0
    m = np.where(dyn, 1.0 / np.where(dyn, p.inv_mass, 1.0), 0.0)
    inertia = np.where(dyn, 1.0 / np.where(dyn, p.inv_inertia, 1.0), 0.0)
    a, b = p.body[:, 0], p.body[:, 1]
    inner = (st == 1) & dyn[a] & dyn[b]
    nb = dyn.size
    _, label = connected_components(sp.coo_matrix((np.ones(inner.sum()), (a[inner], b[inner])), shape=(nb, nb)))
    grounded = set(label[np.where(dyn[b], b, a)[(st == 1) & ~(dyn[a] & dyn[b])]].tolist())
    e = v - p.v_ref
    proj = np.zeros_like(e)
    free = 0
    for c in np.unique(label[dyn]):
        idx = np.flatnonzero((label == c) & dyn)
        if c in grounded:
            continue
        free += 1
        d = p.q_m[idx, :2] - (m[idx, None] * p.q_m[idx, :2]).sum(0) / m[idx].sum()
        A = np.zeros((3 * idx.size, 3))
        A[0::3, 0] = A[1::3, 1] = A[2::3, 2] = 1.0
        A[0::3, 2], A[1::3, 2] = -d[:, 1], d[:, 0]
        w = np.sqrt(np.stack([m[idx], m[idx], inertia[idx]], axis=1).ravel())
        sol = np.linalg.lstsq(A * w[:, None], e[idx].ravel() * w, rcond=None)[0]
        proj[idx] = (A @ sol).reshape(-1, 3)

    def energy(z):
        return float((m * (z[:, 0] ** 2 + z[:, 1] ** 2) + inertia * z[:, 2] ** 2).sum())

    return energy(proj) / max(energy(e), 1e-300), free


def report(specs: list[str]) -> None:
    """``specs``: PROBLEM:SWEEPS — run that many engine sweeps from the warm start, then measure."""
    print(
        "| problem | sweeps | velocity error m/s | free clusters | rigid share (iterate's statuses) | (reference's) |"
    )
    print("|---|---|---|---|---|---|")
    for spec in specs:
        name, sweeps = spec.rsplit(":", 1)
        (p,) = load_all([name])
        ctx = Context(p)
        r = p.r_warm.copy()
        v, _ = ctx.sweep(r, int(sweeps))
        share, free = rigid_share(p, newton.statuses(ctx, v, r)[0], v)
        share_ref, _ = rigid_share(p, newton.statuses(ctx, p.v_ref, p.r_ref)[0], v)
        err = law.velocity_error(p, v)
        print(f"| {name} | {sweeps} | {err:.1e} | {free} | {share:.3f} | {share_ref:.3f} |", flush=True)
