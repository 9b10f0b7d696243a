"""Two-level NLGS: the engine's sweeps plus a coarse correction that moves clusters of stuck blocks rigidly.

On the walls most of the velocity error Gauss–Seidel leaves is rigid motion of clusters of blocks held
together by sticking joints (``clusters.py``), which a sweep corrects about one contact layer at a time.
Every ``SWEEPS`` fine sweeps:

    join    contacts between two blocks with r_n > 0 and |r_t| < (1 − MARGIN) μ r_n, where the pair has
            at least two such points (one point is a hinge, not a rigid joint); supports never join
    label   connected components of the joined blocks = clusters (singletons included)
    coarse  one rigid body per cluster: mass Σm, centroid X, inertia Σ(I + m|x − X|²); supports stay
            themselves (infinite mass). V̄ = mass-weighted rigid projection of the current v per cluster.
            Contacts between clusters keep their points, normals and gaps; the engine's own
            ``prepare_contacts`` gives their coarse W_αα, and the normal velocity the rigid projection
            misses (u_n(v) − u_n(P V̄)) is added to the Signorini bias so that the coarse problem starts
            from the fine one's normal velocities. Coarse v_free = V̄ − Mc⁻¹ Hcᵀ r_inter, warm start
            r_inter: ``COARSE_SWEEPS`` sweeps of the engine's NLGS kernel on this small problem, with the
            exact 2×2 local Signorini–Coulomb solve, give Δr_inter and the cluster correction δV.
    prolong δv = P δV (rigid per cluster). Momentum then needs M P δV = Hᵀ Δr: the inter-cluster part is
            Δr_inter, the rest must come from the joining (stick) contacts: Hjᵀ Δr_j = M P δV − H_interᵀ
            Δr_inter, solvable because the coarse solve balances each cluster's momentum (Pᵀ of the right
            side is 0) and joined pairs admit only rigid relative motion. Minimum-norm Δr_j = Hj y with
            (HjᵀHj + τ I) y = rhs (τ only touches the rigid null space, which Hj removes).
    accept  r' = r + Δr, v' = v_free + M⁻¹ H r' (re-derived: v and r stay exactly consistent); kept only
            if the contact-law RMS residual does not increase (monotonicity guard), else dropped.

Stopped on the contact-law residual (checked every ``SWEEPS`` sweeps, in numpy: counts up to SWEEPS − 1
high). ``iterations`` counts fine sweeps; ``sweeps`` adds the coarse work (build, coarse solve, intra
solve) converted at the problem's measured time per engine sweep.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import connected_components

from benchmarks.solver_lab import law
from benchmarks.solver_lab.outcome import Clock, Outcome, sweeps_with_corrections
from benchmarks.solver_lab.problems import pack_contacts
from masonrycli.engine import dispatch, nlgs

SWEEPS = 20
"""Fine sweeps between coarse corrections."""
COARSE_SWEEPS = 30
"""Engine NLGS sweeps on the coarse (cluster) problem per correction."""
MARGIN = 0.05
PAIR_POINTS = 2
"""Sticking points a block pair needs to be joined (one point alone is a hinge, not a rigid joint)."""
"""A contact joins two blocks only if |r_t| < (1 − MARGIN) μ r_n (clearly inside the cone)."""
CAP = 50_000


def _clusters(p, r):
    """(label (B,), joined (C,) bool): clusters of blocks joined by ≥ 2 clearly sticking points."""
    dyn = p.inv_mass > 0
    a, b = p.body[:, 0].astype(np.int64), p.body[:, 1].astype(np.int64)
    nb = dyn.size
    stick = dyn[a] & dyn[b] & (r[:, 1] > 0.0) & (np.abs(r[:, 0]) < (1.0 - MARGIN) * p.mu * r[:, 1])
    pair = np.minimum(a, b) * nb + np.maximum(a, b)
    keys, counts = np.unique(pair[stick], return_counts=True)
    joined = stick & np.isin(pair, keys[counts >= PAIR_POINTS])
    graph = sp.coo_matrix((np.ones(joined.sum()), (a[joined], b[joined])), shape=(nb, nb))
    _, label = connected_components(graph, directed=False)
    return label, joined


def _prolongation(p, label):
    """(P (3B × 3K) rigid prolongation, Mc (3K,) coarse mass diagonal, X (K, 2) coarse centroids)."""
    dyn = p.inv_mass > 0
    nb, k = dyn.size, int(label.max()) + 1
    m = np.where(dyn, 1.0 / np.where(dyn, p.inv_mass, 1.0), 0.0)
    inertia = np.where(dyn, 1.0 / np.where(dyn, p.inv_inertia, 1.0), 0.0)
    x = p.q_m[:, :2]
    mass = np.bincount(label, m, k)
    free = mass > 0  # a support is a cluster of its own, massless here: infinite mass below
    X = np.stack([np.bincount(label, m * x[:, j], k) for j in (0, 1)], axis=1) / np.where(free, mass, 1.0)[:, None]
    sup = np.flatnonzero(~dyn)
    X[label[sup]] = x[sup]
    d = x - X[label]
    inert = np.bincount(label, inertia + m * (d * d).sum(1), k)
    i3 = 3 * np.arange(nb)
    rows = np.concatenate([i3, i3, i3 + 1, i3 + 1, i3 + 2])
    cols = np.concatenate([3 * label, 3 * label + 2, 3 * label + 1, 3 * label + 2, 3 * label + 2])
    vals = np.concatenate([np.ones(nb), -d[:, 1], np.ones(nb), d[:, 0], np.ones(nb)])
    P = sp.csr_matrix((vals, (rows, cols)), shape=(3 * nb, 3 * k))
    mc = np.stack([mass, mass, inert], axis=1).ravel()
    return P, mc, X, free


def coarse_step(ctx, v, r, clock):
    """(r', v', clusters): one coarse correction from the consistent pair (v, r); see the module docstring."""
    p, H = ctx.p, ctx.H
    with clock("build"):
        label, joined = _clusters(p, r)
        a, b = p.body[:, 0], p.body[:, 1]
        inter = label[a] != label[b]
        P, mc, X, free = _prolongation(p, label)
        mfine = np.where(ctx.minv > 0, 1.0 / np.where(ctx.minv > 0, ctx.minv, 1.0), 0.0)
        mc_inv = np.where(np.repeat(free, 3), 1.0 / np.where(mc > 0, mc, 1.0), 0.0)
        vbar = mc_inv * (P.T @ (mfine * v.ravel()))  # rigid projection (mass-weighted) per cluster
        sup = np.repeat(~free, 3)
        vbar[sup] = (P.T @ v.ravel())[sup]  # a support's own velocity (P is the identity there)
        n_in = int(inter.sum())
        cbody = np.stack([label[a][inter], label[b][inter]], axis=1).astype(p.body.dtype)
        cq = np.zeros((X.shape[0], 3))
        cq[:, :2] = X
        shim = p.shim(0.0, COARSE_SWEEPS)
        shim.body_inv_mass, shim.body_inv_inertia = mc_inv[0::3], mc_inv[2::3]
        cpack = pack_contacts(cbody, p.point[inter], p.normal[inter], p.gap[inter], cq, shim)
        Hi = H[np.flatnonzero(np.repeat(inter, 2))]
        Hc = Hi @ P
        cpack[:, nlgs.P_BIAS] += (Hi @ v.ravel() - Hc @ vbar)[1::2]  # normal velocity the rigid V̄ misses
        r_in = r[inter]
        vc = (vbar - mc_inv * (Hc.T @ r_in.ravel())).reshape(-1, 3)
    with clock("coarse"):
        rc = r_in.copy()
        dispatch.solve(cbody, cpack, n_in, shim, vc, rc, np.zeros(n_in, dtype=np.int8))
    with clock("intra"):
        dV = vc.ravel() - vbar
        dr_in = rc - r_in
        rhs = mfine * (P @ dV) - Hi.T @ dr_in.ravel()
        Hj = H[np.flatnonzero(np.repeat(joined, 2))]
        A = (Hj.T @ Hj).tocsc()
        tau = 1e-12 * max(float(A.diagonal().max(initial=0.0)), 1e-300)
        y = spla.spsolve(A + tau * sp.identity(A.shape[0], format="csc"), rhs)
        r2 = r.copy()
        r2[inter] = rc
        r2[joined] += (Hj @ y).reshape(-1, 2)
        v2 = law.velocity_from_impulse(p, H, r2)
    return r2, v2, int(free.sum())


def cluster_nlgs(ctx, target) -> Outcome:
    clock = Clock()

    def correct(v, r, res):
        r2, v2, _ = coarse_step(ctx, v, r, clock)
        with clock("check"):
            return (r2, v2) if ctx.residual(v2, r2) <= res else None

    v, r, fine, corrections, accepted, ok = sweeps_with_corrections(ctx, target, SWEEPS, CAP, clock, correct)
    coarse_s = sum(s for k, s in clock.phases.items() if k in ("build", "coarse", "intra"))
    out = Outcome(v, r, fine, fine + coarse_s / ctx.sweep_s, clock.phases, converged=ok)
    out.corrections, out.accepted = corrections, accepted  # read by the lab's diagnostics, not the table
    return out


METHODS = {"nlgs-cluster": cluster_nlgs}
