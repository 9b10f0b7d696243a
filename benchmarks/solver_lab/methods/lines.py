"""Line Gauss–Seidel: each vertical chain of blocks solved exactly, the joints between chains by point sweeps.

Why try it. Point Gauss–Seidel moves load about one course per sweep, so its sweeps grow with height; a
relaxation that solves whole lines exactly along the long direction converges, on a Laplacian, at a rate set
by the short direction alone (here the wall's ~15 blocks across), whatever the height. A masonry wall's
long direction is vertical, so the lines are vertical chains of blocks linked through bed joints.

Lines (``build_lines``): bodies taken bottom up; each takes as the block below it in its line the bed-joint
neighbour below (mean contact normal within ~45° of vertical) whose line started nearest its own x and is
not yet continued — zigzag columns in running bond, one block of each course.

    line contacts of L = contacts between two bodies of L, or between a body of L and a support
    joints between lines = every other contact (head joints, the other half of each bed joint)
    repeat (one outer round):
        for each line L, left to right:
            v_free_L = v − M⁻¹ H_Lᵀ r_L                        (the line's own impulses taken out)
            (v, r_L) = the engine's accelerated NLGS on L's contacts alone to INNER_TOL (≈ exact)
        SWEEPS_BETWEEN plain engine sweeps on the joints between lines
    until the contact-law residual (law.py, RMS over all contacts) ≤ target, or ROUNDS rounds

Each line is solved by the engine's kernel (``dispatch.solve`` on the line's contacts): an oracle of an exact
line solve, whose own cost is not the question. The question is whether the outer rounds stay flat with
height; ``detail`` gives the rounds and the contact visits in sweep equivalents (visits / C) so the inner
work can be read too. The harness's sweep units are CPU-based and include Python's per-line overhead.
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.solver_lab import law
from benchmarks.solver_lab.outcome import Outcome
from masonrycli.engine import dispatch, nlgs

INNER_TOL = 1e-8
"""m/s: a line's solve stops here (1000× below the lab's target: near exact)."""
INNER_CAP = 2_000_000
ROUNDS = 400
VERTICAL = 0.7
"""|mean n_y| above which a joint is a bed joint (a line may pass through it)."""


def build_lines(p, pack) -> tuple[list[list[int]], list[np.ndarray], np.ndarray]:
    """(lines as lists of bodies bottom up, each line's contacts, the contacts between lines)."""
    support = p.inv_mass == 0
    a, b = p.body[:, 0], p.body[:, 1]
    joints: dict[tuple[int, int], list[int]] = {}
    for c in range(p.count):
        joints.setdefault((int(a[c]), int(b[c])), []).append(c)
    below: dict[int, list[int]] = {}
    for (i, j), cs in joints.items():
        if support[i] or support[j] or abs(pack[cs, nlgs.P_NY].mean()) < VERTICAL:
            continue
        lo, hi = (i, j) if p.q_m[i, 1] < p.q_m[j, 1] else (j, i)
        below.setdefault(hi, []).append(lo)
    n = p.q_m.shape[0]
    up, down, anchor = -np.ones(n, int), -np.ones(n, int), p.q_m[:, 0].copy()
    for hi in np.argsort(p.q_m[:, 1], kind="stable"):
        free = [lo for lo in below.get(int(hi), []) if up[lo] < 0]
        if support[hi] or not free:
            continue
        lo = min(free, key=lambda k: abs(anchor[k] - p.q_m[hi, 0]))
        up[lo], down[hi], anchor[hi] = hi, lo, anchor[lo]
    lines = []
    for start in range(n):
        if support[start] or down[start] >= 0:
            continue
        line = [start]
        while up[line[-1]] >= 0:
            line.append(int(up[line[-1]]))
        lines.append(line)
    lines.sort(key=lambda line: p.q_m[line[0], 0])
    line_of = -np.ones(n, int)
    for k, line in enumerate(lines):
        line_of[line] = k
    la, lb = line_of[a], line_of[b]
    owner = np.where(support[a], lb, np.where(support[b], la, np.where(la == lb, la, -1)))
    return lines, [np.flatnonzero(owner == k) for k in range(len(lines))], np.flatnonzero(owner < 0)


def solve_subset(ctx, v, r, status, idx, tolerance, cap, solver) -> tuple[int, float]:
    """The engine's NLGS on contacts ``idx`` alone, all other impulses held: updates v, r, status; returns
    (sweeps, the engine's last RMS law residual over ``idx``, m/s)."""
    if idx.size == 0:
        return 0, 0.0
    p = ctx.p
    rows = np.empty(2 * idx.size, np.int64)
    rows[0::2], rows[1::2] = 2 * idx, 2 * idx + 1
    r_sub = r[idx].copy()
    v_free = v - (ctx.minv * (ctx.H[rows].T @ r_sub.ravel())).reshape(-1, 3)
    s_sub = status[idx].copy()
    shim = p.shim(tolerance, cap, solver=solver)
    body, pack = np.ascontiguousarray(p.body[idx]), np.ascontiguousarray(ctx.pack[idx])
    sweeps, residual = dispatch.solve(body, pack, idx.size, shim, v_free, r_sub, s_sub)
    v[:], r[idx], status[idx] = v_free, r_sub, s_sub
    return int(sweeps), float(residual)


def _method(sweeps_between: int):
    def solve(ctx, target) -> Outcome:
        p = ctx.p
        t = time.process_time()
        lines, groups, between = build_lines(p, ctx.pack)
        built = time.process_time() - t
        r = p.r_warm.copy()
        v = law.velocity_from_impulse(p, ctx.H, r)
        status = np.zeros(p.count, np.int8)
        visits, rounds, residual = 0, 0, np.inf
        while rounds < ROUNDS and residual > target:
            rounds += 1
            for g in groups:
                visits += g.size * solve_subset(ctx, v, r, status, g, INNER_TOL, INNER_CAP, "nlgs-accel")[0]
            visits += between.size * solve_subset(ctx, v, r, status, between, 0.0, sweeps_between, "nlgs")[0]
            residual = ctx.residual(v, r)
        sizes = [len(line) for line in lines]
        detail = (
            f"{len(lines)} lines of {min(sizes)}–{max(sizes)} blocks, {between.size} contacts between;"
            f" visits {visits / p.count:.0f} sweeps"
        )
        out = Outcome(v, r, rounds, float(visits) / p.count, {"lines": built}, converged=residual <= target)
        out.detail = detail
        return out

    return solve


METHODS = {"line-gs": _method(1), "line-gs-b4": _method(4)}
