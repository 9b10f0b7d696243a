"""Two-level NLGS with a Galerkin coarse correction in impulse space, on interface resultants.

Gauss–Seidel moves load (self-stress) down a hyperstatic stack about one course per sweep. Here the
stack is cut into layers and the correction acts on whole interfaces at once: for each interface it
finds the normal force, shear and moment that minimise the contact energy

    E(r) = ½ rᵀ W r + qᵀ r,   W = H M⁻¹ Hᵀ (never formed),   q = H v_free + (0, bias),   ∇E = H v(r) + (0, bias)

on the subspace the interface's interior contacts span (Kornhuber's monotone multigrid idea, truncated:
contacts on the cone's boundary or open are left out of the coarse space, so for the contacts it moves the
law is ∇E = 0, i.e. u_t = 0 and u_n + bias = 0).

    layers  (once a solve) graph distance of each block from the supports through the contacts (supports =
            layer 0; blocks with no path to a support: none). grouping "interface": contact α between
            layers k and k+1 belongs to interface k; contacts within a layer (head joints) or across
            more than one layer belong to none. grouping "joint": one group per block pair.
            o_α = +1 if body b is the upper one (b's layer is the larger), −1 else ("joint": +1).
    interior  α in a group with r_n > 0 and |r_t| < (1 − MARGIN) μ r_n (strictly inside the cone)
    prolong P (2C × 3K): for group k with interior contacts I_k (centroid x̄_k of their points, mean
            tangent t̄_k = normalise(Σ o_α t_α), ξ_α = (x_α − x̄_k)·t̄_k / rms ξ):
                column N_k:  Δr_n,α = 1              (uniform compression)
                column T_k:  Δr_t,α = o_α (t_α·t̄_k)  (uniform shear along t̄_k, as seen by the upper layer)
                column M_k:  Δr_n,α = ξ_α            (Navier-like linear distribution: the moment)
            columns with no interior contact (or, for M, fewer than two points) are dropped.
            follow (variant): closed contacts on the cone's edge join N and M with Δr_t = σ μ Δr_n
            (σ = sign r_t), tested on their normal row only (Petrov–Galerkin, Q ≠ P).
    coarse  G = Hᵀ P (3B × 3K'), W_c = Gᵀ M⁻¹ G (block-tridiagonal over interfaces), g = ∇E(r) = H v + bias,
            W_c c = −Pᵀ g  (dense Cholesky with a relative pivot floor PIVOT; "joint": sparse LU of
            W_c + JOINT_REG·diag, the joint space is rank deficient on a hyperstatic wall)
    step    Δr = P c, Δv = M⁻¹ G c; α = min(1, largest α keeping every touched contact in its cone
            (r_n + αΔr_n ≥ 0, |r_t + αΔr_t| ≤ μ (r_n + αΔr_n))); r' = r + αΔr, v' = v + αΔv.
            E is convex along Δr with its minimum at α = 1, so E(r') ≤ E(r) (without follow).
    guard   keep (r', v') only if the lab's RMS contact-law residual does not rise (open and sliding
            contacts are not governed by ∇E = 0, so a lower E is not a lower residual). guard=False
            ("-e" variants): every step is kept, monotone in E only, as in Kornhuber's method.

    solve:  r = r_warm
            repeat: SWEEPS engine sweeps (plain, or the default's momentum sweeps: smoother="nlgs-accel",
                    the momentum restarting at each call);
                    stop if RMS law residual ≤ target or CAP fine sweeps;
                    one coarse correction (kept if the guard allows)

A diagnostic (``python -m benchmarks.solver_lab.methods.galerkin PROBLEM …``, :func:`projection`) says what the
coarse space could do at all: the M-orthogonal projection of the true velocity error onto M⁻¹ Hᵀ P.

``iterations`` counts fine sweeps; ``sweeps`` (units) = plain sweeps (momentum sweeps × ctx.accel_cost) + the
CPU of the coarse work (layers, prolongation, coarse assembly and solve, step) over one engine sweep's. The
numpy residual checks after the sweeps are not counted (the engine checks during the sweep), as in cluster.py;
each guard's residual counts as one sweep.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import dijkstra

from benchmarks.solver_lab.outcome import Clock, Outcome
from masonrycli.engine import nlgs as N

SWEEPS = 20
"""Fine sweeps between coarse corrections."""
MARGIN = 0.05
"""A contact is coarse-aggregated only if |r_t| < (1 − MARGIN) μ r_n (strictly inside the cone)."""
PIVOT = 1e-10
"""Relative floor on the coarse matrix's diagonal (tiny pivots: an interface with nearly collinear points)."""
JOINT_REG = 1e-2
"""Tikhonov weight (relative to each diagonal) of the joint space's coarse matrix (1e-8 … 1e-2 tried on
wall-8-cold and wall-16-cold/typical, `python -m benchmarks.solver_lab.methods.galerkin`: 1e-2 gave the Galerkin
step closest to the reference, none a cone-limited α above 0.02 on the cold steps)."""
CAP = 50_000
"""Fine sweeps."""


@dataclass(frozen=True)
class Groups:
    """Which coarse group each contact belongs to (−1: none), and its orientation."""

    layer: np.ndarray
    """(B,) graph distance from the supports (−1: no path)."""
    group: np.ndarray
    """(C,) group index (interface k: contacts between layers k and k+1), −1 if not aggregated."""
    orient: np.ndarray
    """(C,) +1 if body b is on the upper side of the group, −1 if body a is."""
    count: int
    kind: str
    """"interface" or "joint"."""


def layers(p) -> np.ndarray:
    """(B,) graph distance of each body from the nearest support through the contacts (−1: unreachable)."""
    nb = p.inv_mass.size
    a, b = p.body[:, 0].astype(np.int64), p.body[:, 1].astype(np.int64)
    graph = sp.coo_matrix((np.ones(a.size), (a, b)), shape=(nb, nb)).tocsr()
    sup = np.flatnonzero(p.inv_mass == 0)
    if sup.size == 0:
        return np.full(nb, -1)
    d = dijkstra(graph, directed=False, indices=sup, unweighted=True, min_only=True)
    return np.where(np.isfinite(d), d, -1).astype(np.int64)


def interface_groups(p) -> Groups:
    """Contacts between consecutive layers, grouped by interface (module doc, "layers")."""
    lay = layers(p)
    la, lb = lay[p.body[:, 0]], lay[p.body[:, 1]]
    ok = (la >= 0) & (lb >= 0) & (np.abs(la - lb) == 1)
    group = np.where(ok, np.minimum(la, lb), -1)
    orient = np.where(lb > la, 1.0, -1.0)
    return Groups(lay, group, orient, int(group.max(initial=-1)) + 1, "interface")


def joint_groups(p) -> Groups:
    """One group per block pair (supports included), oriented a → b."""
    a, b = p.body[:, 0].astype(np.int64), p.body[:, 1].astype(np.int64)
    _, group = np.unique(a * p.inv_mass.size + b, return_inverse=True)
    return Groups(layers(p), group.astype(np.int64), np.ones(p.count), int(group.max(initial=-1)) + 1, "joint")


def interior(p, r, g: Groups) -> np.ndarray:
    """(C,) bool: aggregated contacts strictly inside their cone."""
    return (g.group >= 0) & (r[:, 1] > 0.0) & (np.abs(r[:, 0]) < (1.0 - MARGIN) * p.mu * r[:, 1])


def prolongation(p, pack, r, g: Groups, follow: bool = False):
    """(P trial (2C × K'), Q test (2C × K'), touched (C,) bool): the coarse basis of the module doc, zero
    columns dropped. ``follow``: closed contacts on the cone's edge join the N and M columns with their
    friction tied to the edge (Δr_t = σ μ Δr_n, σ = sign r_t), tested on their normal row only
    (Petrov–Galerkin: a sliding contact's law in the coarse space is u_n + bias = 0). Without it Q = P."""
    inside = interior(p, r, g)
    edge = (g.group >= 0) & (r[:, 1] > 0.0) & ~inside if follow else np.zeros_like(inside)
    touched = inside | edge
    idx = np.flatnonzero(touched)
    k = g.group[idx]
    o = g.orient[idx]
    ins = inside[idx]
    t = np.stack([pack[idx, N.P_NY], -pack[idx, N.P_NX]], axis=1)  # contact tangent, as law.h_matrix
    x = p.point[idx]
    cnt = np.bincount(k, minlength=g.count).astype(float)
    n_in = np.bincount(k[ins], minlength=g.count)
    safe = np.maximum(cnt, 1.0)
    xbar = np.stack([np.bincount(k, x[:, j], g.count) for j in (0, 1)], axis=1) / safe[:, None]
    tsum = np.stack([np.bincount(k, o * t[:, j], g.count) for j in (0, 1)], axis=1)
    tbar = tsum / np.maximum(np.hypot(tsum[:, 0], tsum[:, 1]), 1e-300)[:, None]
    xi = ((x - xbar[k]) * tbar[k]).sum(1)
    spread = np.sqrt(np.bincount(k, xi * xi, g.count) / safe)
    has_m = (cnt >= 2) & (spread > 1e-9 * max(float(p.radius.max(initial=1.0)), 1e-300))
    xi = xi / np.where(has_m, spread, 1.0)[k]
    shear = np.where(ins, o * (t * tbar[k]).sum(1), 0.0)
    tie = np.where(ins, 0.0, np.sign(r[idx, 0]) * p.mu)  # edge contacts: Δr_t = σ μ Δr_n
    # columns: 3k (N), 3k+1 (T), 3k+2 (M); rows 2α (t), 2α+1 (n)
    m_val = np.where(has_m[k], xi, 0.0)
    cols = np.concatenate([3 * k, 3 * k + 1, 3 * k + 2, 3 * k, 3 * k + 2])
    rows = np.concatenate([2 * idx + 1, 2 * idx, 2 * idx + 1, 2 * idx, 2 * idx])
    trial = np.concatenate([np.ones(idx.size), shear, m_val, tie, tie * m_val])
    test = np.concatenate([np.ones(idx.size), shear, m_val, 0.0 * tie, 0.0 * tie])
    dropped = np.concatenate([3 * np.flatnonzero(cnt == 0) + j for j in range(3)] + [3 * np.flatnonzero(~has_m) + 2])
    dropped = np.concatenate([dropped, 3 * np.flatnonzero(n_in == 0) + 1])  # no interior contact: no shear
    keep = np.setdiff1d(np.arange(3 * g.count), dropped)
    shape = (2 * p.count, 3 * g.count)
    P = sp.csr_matrix((trial, (rows, cols)), shape=shape)[:, keep].tocsr()
    Q = sp.csr_matrix((test, (rows, cols)), shape=shape)[:, keep].tocsr() if follow else P
    return P, Q, touched


def gradient(ctx, v) -> np.ndarray:
    """(2C,) ∇E = H v + (0, bias): the contacts' relative velocities with the Signorini bias on the normals."""
    u = ctx.H @ v.ravel()
    u[1::2] += ctx.pack[:, N.P_BIAS]
    return u


def coarse_solve(ctx, P, v, Q=None, reg: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(Δr (2C,), Δv (3B,)): the Galerkin step W_c c = −Pᵀ ∇E, Δr = P c, Δv = M⁻¹ Hᵀ Δr (``Q``: the
    Petrov–Galerkin test space, W_c = Qᵀ W P, right side −Qᵀ ∇E). ``reg`` None: dense, tiny pivots
    floored at PIVOT · max diag (the interface space); else sparse LU of W_c + reg · diag(W_c) (the joint
    space, rank deficient on a hyperstatic wall: Tikhonov keeps the self-stress part of c small)."""
    G = (ctx.H.T @ P).tocsc()
    GQ = G if Q is None or Q is P else (ctx.H.T @ Q).tocsc()
    Wc = GQ.T @ sp.diags(ctx.minv) @ G
    rhs = -((P if Q is None else Q).T @ gradient(ctx, v))
    d = np.abs(Wc.diagonal())
    floor = PIVOT * max(float(d.max(initial=0.0)), 1e-300)
    if reg is None:
        dense = Wc.toarray() + np.diag(np.full(d.size, floor))
        if Q is None or Q is P:
            c = sla.cho_solve(sla.cho_factor(dense, check_finite=False), rhs, check_finite=False)
        else:
            c = sla.lu_solve(sla.lu_factor(dense, check_finite=False), rhs, check_finite=False)
    else:
        K = (Wc + sp.diags(np.maximum(reg * d, floor))).tocsc()
        c = spla.splu(K, permc_spec="MMD_AT_PLUS_A").solve(rhs)
    return P @ c, ctx.minv * (G @ c)


def cone_step(p, r, dr, touched, tied=None) -> float:
    """The largest α ∈ [0, 1] with every touched contact still in its cone (closed). ``tied`` contacts (the
    edge contacts of ``follow``) keep μ r_n − |r_t| unchanged by construction: only r_n ≥ 0 binds them."""
    tied = np.zeros_like(touched) if tied is None else tied
    free = touched & ~tied
    d, rr = dr.reshape(-1, 2)[free], r[free]
    dt_, rt_ = dr.reshape(-1, 2)[tied], r[tied]
    a = np.concatenate([rr[:, 1], p.mu * rr[:, 1] - rr[:, 0], p.mu * rr[:, 1] + rr[:, 0], rt_[:, 1]])
    b = np.concatenate([d[:, 1], p.mu * d[:, 1] - d[:, 0], p.mu * d[:, 1] + d[:, 0], dt_[:, 1]])
    down = b < 0
    return float(min(1.0, (a[down] / -b[down]).min(initial=np.inf)))


def correction(
    ctx, v, r, g: Groups, clock: Clock, residual: float | None = None, follow: bool = False, guard: bool = True
):
    """One coarse correction from the consistent pair (v, r). Returns (r', v', α, residual after) if the
    guard keeps it, else None (``residual``: the pair's RMS law residual, measured here if not given)."""
    p = ctx.p
    with clock("coarse"):
        P, Q, touched = prolongation(p, ctx.pack, r, g, follow)
        if P.shape[1] == 0:
            return None
        dr, dv = coarse_solve(ctx, P, v, Q, None if g.kind == "interface" else JOINT_REG)
        alpha = cone_step(p, r, dr, touched, touched & ~interior(p, r, g))
        if alpha <= 0.0:
            return None
        r2 = r + alpha * dr.reshape(-1, 2)
        v2 = v + alpha * dv.reshape(-1, 3)
    if not guard:  # E(r') ≤ E(r) by construction: Kornhuber's monotonicity, in the energy
        return r2, v2, alpha, np.nan
    with clock("check"):
        before = ctx.residual(v, r) if residual is None else residual
        after = ctx.residual(v2, r2)
    return (r2, v2, alpha, after) if after <= before else None


def galerkin(
    ctx, target, sweeps=SWEEPS, smoother="nlgs", grouping="interface", follow=False, guard=True, cap=CAP, trace=None
) -> Outcome:
    """The two-level solve of the module doc. ``trace`` (a list): appends (fine sweeps, residual, α, residual
    after) per correction tried (α, residual after: None where the guard refused it), for diagnostics."""
    p = ctx.p
    clock = Clock()
    with clock("coarse"):
        g = interface_groups(p) if grouping == "interface" else joint_groups(p)
    r = p.r_warm.copy()
    done = tried = kept = 0
    ok = False
    v = p.v_free.copy()
    while done < cap:
        with clock("sweeps"):
            v, _ = ctx.sweep(r, sweeps, smoother)
        done += sweeps
        with clock("check"):
            res = ctx.residual(v, r)
        if res <= target:
            ok = True
            break
        tried += 1
        new = correction(ctx, v, r, g, clock, res, follow, guard)
        if trace is not None:
            trace.append((done, res) + ((None, None) if new is None else (new[2], new[3])))
        if new is not None:
            r, v = new[0], new[1]
            kept += 1
    fine = done * (ctx.accel_cost if smoother == "nlgs-accel" else 1.0)
    # each guard's residual counted as one sweep (an engine pass over the contacts like the sweep's)
    units = fine + (tried if guard else 0) + clock.phases.get("coarse", 0.0) / ctx.sweep_s
    out = Outcome(v, r, done, units, clock.phases, converged=ok, detail=f"{kept}/{tried} kept")
    out.corrections, out.accepted = tried, kept
    return out


def _variant(**kw):
    return lambda ctx, target: galerkin(ctx, target, **kw)


METHODS = {  # "nlgs-…": the harness takes the method's own units (not its numpy checks), as for nlgs-cluster
    "nlgs-galerkin": _variant(),
    "nlgs-galerkin-s5": _variant(sweeps=5),
    "nlgs-galerkin-s2": _variant(sweeps=2),
    "nlgs-galerkin-s1": _variant(sweeps=1),
    "nlgs-galerkin-e": _variant(guard=False),
    "nlgs-galerkin-e-s5": _variant(sweeps=5, guard=False),
    "nlgs-galerkin-e-s1": _variant(sweeps=1, guard=False),
    "nlgs-galerkin-follow": _variant(follow=True),
    "nlgs-galerkin-accel": _variant(smoother="nlgs-accel", guard=False),
    "nlgs-galerkin-joint": _variant(sweeps=5, grouping="joint"),
    "nlgs-galerkin-joint-e": _variant(sweeps=5, grouping="joint", guard=False),
}


def layer_rigid_share(p, e: np.ndarray, layer: np.ndarray) -> float:
    """Share of the kinetic energy of the velocity error ``e`` (B, 3) that is rigid motion of whole layers
    (each layer's mass-weighted rigid-body fit: translation and rotation about its centroid)."""
    dyn = p.inv_mass > 0
    m = np.where(dyn, 1.0 / np.where(dyn, p.inv_mass, 1.0), 0.0)
    inertia = np.where(dyn, 1.0 / np.where(dyn, p.inv_inertia, 1.0), 0.0)
    total = float((m * (e[:, 0] ** 2 + e[:, 1] ** 2) + inertia * e[:, 2] ** 2).sum())
    rigid = 0.0
    for k in range(1, int(layer.max(initial=0)) + 1):
        s = (layer == k) & dyn
        if not s.any():
            continue
        mass = m[s].sum()
        d = p.q_m[s, :2] - (m[s, None] * p.q_m[s, :2]).sum(0) / mass
        inert = (inertia[s] + m[s] * (d * d).sum(1)).sum()
        V = (m[s, None] * e[s, :2]).sum(0) / mass
        L = (inertia[s] * e[s, 2] + m[s] * (d[:, 0] * e[s, 1] - d[:, 1] * e[s, 0])).sum()
        rigid += mass * float(V @ V) + L * L / inert
    return rigid / total if total > 0 else 0.0


SPACES = {"interface": ("interface", False), "interface-follow": ("interface", True), "joint": ("joint", False)}


def projection(ctx, sweeps: int, space: str = "interface") -> dict:
    """What the coarse space could do and what the Galerkin step does, after ``sweeps`` engine sweeps from
    the warm start: the mass-weighted RMS velocity error against the reference (m/s) before, after the best
    correction the space allows (the M-orthogonal projection of the error onto M⁻¹ Hᵀ P: W_c c = Gᵀ(v_ref − v)),
    after the Galerkin step at α = 1 and at the cone-limited α, and the law residual before / after."""
    p = ctx.p
    grouping, follow = SPACES[space]
    g = interface_groups(p) if grouping == "interface" else joint_groups(p)
    r = p.r_warm.copy()
    v, _ = ctx.sweep(r, sweeps)
    P, Q, touched = prolongation(p, ctx.pack, r, g, follow)
    m = np.where(ctx.minv > 0, 1.0 / np.where(ctx.minv > 0, ctx.minv, 1.0), 0.0)

    def err(dv):
        e = (p.v_ref - v).ravel() - dv
        return float(np.sqrt((m * e * e).sum() / m.sum()))

    Gm = (ctx.H.T @ P).tocsc()
    Wc = (Gm.T @ sp.diags(ctx.minv) @ Gm).toarray()
    c_best = np.linalg.lstsq(Wc, Gm.T @ (p.v_ref - v).ravel(), rcond=1e-12)[0]
    dr, dv = coarse_solve(ctx, P, v, Q, None if g.kind == "interface" else JOINT_REG)
    alpha = cone_step(p, r, dr, touched, touched & ~interior(p, r, g))
    return {
        "rigid_share": layer_rigid_share(p, p.v_ref - v, g.layer),
        "columns": P.shape[1],
        "touched": int(touched.sum()),
        "error": err(0.0),
        "best": err(ctx.minv * (Gm @ c_best)),
        "galerkin": err(dv),
        "alpha": alpha,
        "galerkin_alpha": err(alpha * dv),
        "residual": ctx.residual(v, r),
        "residual_alpha": ctx.residual(v + alpha * dv.reshape(-1, 3), r + alpha * dr.reshape(-1, 2)),
    }


def _projection_table(names: list[str], sweeps: list[int], spaces: list[str]) -> None:
    from benchmarks.solver_lab.outcome import Context
    from benchmarks.solver_lab.problems import load_all

    print(
        "| problem | sweeps | coarse space | columns | touched contacts | M-RMS velocity error m/s: iterate / best in"
        " space / Galerkin α=1 / Galerkin α (α) | law residual RMS m/s: iterate / after the step | layers' rigid"
        " share of the error |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for prob in load_all(names):
        ctx = Context(prob)
        for n in sweeps:
            for space in spaces:
                o = projection(ctx, n, space)
                print(
                    f"| {prob.name} | {n} | {space} | {o['columns']} | {o['touched']} | {o['error']:.2e} / {o['best']:.2e}"
                    f" / {o['galerkin']:.2e} / {o['galerkin_alpha']:.2e} ({o['alpha']:.2f}) |"
                    f" {o['residual']:.1e} / {o['residual_alpha']:.1e} | {o['rigid_share']:.2f} |",
                    flush=True,
                )


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description="the coarse space's reach against the Galerkin step (projection())")
    ap.add_argument("problems", nargs="+")
    ap.add_argument("--sweeps", nargs="+", type=int, default=[20, 200])
    ap.add_argument("--spaces", nargs="+", default=list(SPACES), choices=list(SPACES))
    a = ap.parse_args()
    _projection_table(a.problems, a.sweeps, a.spaces)
