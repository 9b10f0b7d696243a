"""Overlapping Schwarz on vertical strips: strips of blocks solved exactly, two or three cuttings in turn.

Why try it. Line Gauss–Seidel (``lines.py``) solved vertical chains exactly and failed because 61–66 % of the
contacts lie *between* lines, where load still moves one course per point sweep. Any single cutting into
strips leaves its cuts' joints along the whole height; but two (or three) cuttings shifted against each other
leave no joint cut in all of them. On a Laplacian, multiplicative overlapping Schwarz without a coarse space
converges at a rate set by the number of strips across (~7 on a 15-block wall), whatever the height.

Cuttings (``cuttings``): b = the typical block length (median centre distance across head joints); strips of
width w = WIDTH·b by body centre x; cutting j of n is shifted by j·w/n. A contact belongs to a strip when both
its bodies' centres lie in it, or one body is a support (supports belong to every strip). In running bond a
bed-joint pair's centres are b/2 apart and a head-joint pair's b: with w = 2b and n = 2 every cut of the union
is b from the next, so each pair is cut in at most one cutting. The cuts' common phase is chosen (among 32)
to leave the fewest contacts cut in every cutting; those left (``uncovered``, none on the lab's walls) are
solved as one more subset at the end of each round, so the method stays a solver whatever the geometry.

    for each cutting A, B (, C):
        for each strip S of the cutting, left to right:
            v_free_S = v − M⁻¹ H_Sᵀ r_S                 (the strip's own impulses taken out)
            (v, r_S) = the engine's accelerated NLGS on S's contacts alone to INNER_TOL (≈ exact)
        residual = RMS contact-law residual (law.py) over all contacts; stop if ≤ target
    (then the uncovered contacts the same way, if any); at most ROUNDS rounds

That is block Gauss–Seidel on the impulses: a strip sees its neighbours as *forces* held. The classical
(primal) overlapping Schwarz holds the neighbours' *velocities* instead — ``-v-`` (``held="v"``): a strip's
blocks with every contact touching them, every other body a support moving at its current velocity in v,
solved from the blocks' own v_free; v is the iterate (each block's from the last strip holding it), r the
contacts' last answers, and the test and the answer are on v(r) = v_free + M⁻¹Hᵀr, which agrees with v only
at the solution. With rigid contacts that variant has nothing to damp the error across the overlap (a block
stuck to a held neighbour takes its velocity, error and all) and a cut contact's impulse treats the far
body as immovable: JOURNAL.md, "Overlapping Schwarz on vertical strips", says what it gives.

An oracle experiment, like ``lines.py``: each strip's solve is the engine's kernel (``lines.solve_subset``),
whose cost is not the question. The question is whether the rounds (a round = one pass of every cutting)
stay flat with height. ``detail`` gives the rounds (in passes: 2.5 rounds = A, B, A), the strips, the
contact visits in sweep equivalents (visits / C), how many strip solves stopped short of INNER_TOL, and the
residual after each of the first passes. ``python -m benchmarks.solver_lab.methods.schwarz PROBLEM…`` prints
the residual and velocity error per pass, where the residual sits (bed or head joints, on a cut or inside
every strip, quarters of height) and what the velocity error is made of (``error_shape``), for the journal.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods.lines import solve_subset
from benchmarks.solver_lab.outcome import Outcome
from benchmarks.solver_lab.problems import pack_contacts
from masonrycli.engine import dispatch, nlgs

INNER_TOL = 1e-8
"""m/s: a strip's solve stops here (1000× below the lab's target: near exact)."""
INNER_CAP = 100_000
"""Sweeps a strip solve may take (hard steps' strips can stall above INNER_TOL; counted in ``detail``)."""
ROUNDS = 200
HEAD = 0.3
"""|mean n_y| below which a joint is a head joint (its centres one block length apart)."""
PHASES = 32


def block_length(p, pack) -> float:
    """m: the median distance between the centres of two blocks across a head joint (2 × the median radius
    when there is none)."""
    free = p.inv_mass > 0
    a, b = p.body[:, 0], p.body[:, 1]
    head = free[a] & free[b] & (np.abs(pack[:, nlgs.P_NY]) < HEAD)
    if not head.any():
        return float(2 * np.median(p.radius[free]))
    return float(np.median(np.abs(p.q_m[a[head], 0] - p.q_m[b[head], 0])))


def _strip_owner(p, strip: np.ndarray) -> np.ndarray:
    """Per contact: the strip holding both bodies (a support is in every strip), else −1 (cut)."""
    support = p.inv_mass == 0
    a, b = p.body[:, 0], p.body[:, 1]
    sa, sb = strip[a], strip[b]
    return np.where(support[a], sb, np.where(support[b], sa, np.where(sa == sb, sa, -1)))


@dataclass(frozen=True)
class Cuttings:
    groups: list
    """Per cutting, its strips' contacts (both bodies in the strip, or one a support), left to right."""
    bodies: list
    """Per cutting, its strips' blocks, left to right."""
    uncovered: np.ndarray
    """The contacts cut in every cutting."""
    b: float
    """m: the block length the widths are counted in."""


def cuttings(p, pack, width: float, count: int) -> Cuttings:
    """``count`` cuttings into strips ``width`` block lengths wide, shifted by width/count from each other."""
    b = block_length(p, pack)
    w = width * b
    x = p.q_m[:, 0]
    free = p.inv_mass > 0
    left = x[free].min() - w  # every strip index ≥ 0
    best = None
    for phase in np.arange(PHASES) * (w / count / PHASES):
        strips, owners = [], []
        for j in range(count):
            strip = np.floor((x - left - phase - j * w / count) / w).astype(np.int64)
            strip[~free] = -1
            strips.append(strip)
            owners.append(_strip_owner(p, strip))
        cut_everywhere = int(np.all(np.array(owners) < 0, axis=0).sum())
        if best is None or cut_everywhere < best[0]:
            best = (cut_everywhere, strips, owners)
    _, strips, owners = best
    groups = [[np.flatnonzero(o == k) for k in np.unique(o[o >= 0])] for o in owners]
    bodies = [[np.flatnonzero(s == k) for k in np.unique(s[s >= 0])] for s in strips]
    return Cuttings(groups, bodies, np.flatnonzero(np.all(np.array(owners) < 0, axis=0)), b)


@dataclass(frozen=True)
class Run:
    v: np.ndarray
    r: np.ndarray
    passes: int
    """Strip passes of one cutting each (a round is ``count`` passes)."""
    visits: int
    """Contact visits of the strip solves."""
    history: list
    """RMS law residual (m/s) after each pass."""
    errors: list
    """Largest velocity error against the reference (m/s) after each pass (if asked for)."""
    short: int
    """Strip solves that stopped above INNER_TOL (their cap or the engine's stall)."""
    cut: Cuttings
    residual: float


def _dirichlet_strips(ctx, bodies: list[np.ndarray]) -> list[tuple]:
    """Per strip of blocks: (its blocks, every contact touching them, their pack and shim with every body
    outside the strip made a support)."""
    p = ctx.p
    out = []
    for s in bodies:
        inside = np.zeros(p.inv_mass.size, bool)
        inside[s] = True
        idx = np.flatnonzero(inside[p.body[:, 0]] | inside[p.body[:, 1]])
        shim = p.shim(INNER_TOL, INNER_CAP, solver="nlgs-accel")
        shim.body_inv_mass = np.where(inside, p.inv_mass, 0.0)
        shim.body_inv_inertia = np.where(inside, p.inv_inertia, 0.0)
        body = np.ascontiguousarray(p.body[idx])
        pack = pack_contacts(body, p.point[idx], p.normal[idx], p.gap[idx], p.q_m, shim)
        out.append((s, idx, body, pack, shim))
    return out


def _solve_dirichlet(p, v, r, status, strip) -> tuple[int, float]:
    """The strip's blocks with all their contacts, every other body held at its velocity in ``v`` (a moving
    support): the engine's accelerated NLGS from the blocks' own v_free and the contacts' impulses in ``r``.
    Updates v on the strip's blocks and r, status on its contacts; returns (sweeps, residual)."""
    s, idx, body, pack, shim = strip
    work = v.copy()
    work[s] = p.v_free[s]
    r_sub, s_sub = r[idx].copy(), status[idx].copy()
    sweeps, residual = dispatch.solve(body, pack, idx.size, shim, work, r_sub, s_sub)
    v[s], r[idx], status[idx] = work[s], r_sub, s_sub
    return int(sweeps), float(residual)


def run(
    ctx, target: float, width: float, count: int, rounds_cap: int = ROUNDS, errors: bool = False, held: str = "r"
) -> Run:
    """The method's loop (module doc); ``held``: "r", the other contacts' impulses held (the strip's own
    contacts solved); "v", the other bodies' velocities held (the strip's blocks with all their contacts)."""
    p = ctx.p
    cut = cuttings(p, ctx.pack, width, count)
    dirichlet = [_dirichlet_strips(ctx, bodies) for bodies in cut.bodies] if held == "v" else None
    r = p.r_warm.copy()
    v = law.velocity_from_impulse(p, ctx.H, r)
    status = np.zeros(p.count, np.int8)
    visits, passes, short, history, errs = 0, 0, 0, [], []
    residual = ctx.residual(v, r)
    while passes < rounds_cap * count and residual > target:
        j = passes % count
        if dirichlet is None:
            for g in cut.groups[j] + ([cut.uncovered] if j == count - 1 else []):
                sweeps, inner = solve_subset(ctx, v, r, status, g, INNER_TOL, INNER_CAP, "nlgs-accel")
                visits += g.size * sweeps
                short += inner > INNER_TOL
        else:
            for strip in dirichlet[j]:
                sweeps, inner = _solve_dirichlet(p, v, r, status, strip)
                visits += strip[1].size * sweeps
                short += inner > INNER_TOL
        passes += 1
        # With velocities held, v is the iterate (each block's from the last strip that held it) and r follows;
        # v(r) differs from it until they agree at the solution, and the test and the answer are on v(r).
        v_r = v if dirichlet is None else law.velocity_from_impulse(p, ctx.H, r)
        residual = ctx.residual(v_r, r)
        history.append(residual)
        if errors:
            errs.append(law.velocity_error(p, v_r))
    v_r = v if dirichlet is None else law.velocity_from_impulse(p, ctx.H, r)
    return Run(v_r, r, passes, visits, history, errs, short, cut, residual)


def _method(width: float, count: int, held: str = "r"):
    def solve(ctx, target) -> Outcome:
        p = ctx.p
        t = time.process_time()
        o = run(ctx, target, width, count, held=held)
        cpu = time.process_time() - t
        sizes = [g.size for cutting in o.cut.groups for g in cutting]
        first = ", ".join(f"{e:.1e}" for e in o.history[: 2 * count])
        detail = (
            f"{o.passes / count:.1f} rounds; {count}×{len(o.cut.groups[0])}–{len(o.cut.groups[-1])} strips of"
            f" {min(sizes)}–{max(sizes)} contacts, b {o.cut.b:.3f} m, {o.cut.uncovered.size} uncovered;"
            f" visits {o.visits / p.count:.0f} sweeps; {o.short} strip solves short of {INNER_TOL:g};"
            f" first passes {first}"
        )
        rounds = math.ceil(o.passes / count)
        out = Outcome(o.v, o.r, rounds, o.visits / p.count, {"strips": cpu}, converged=o.residual <= target)
        out.detail = detail
        return out

    return solve


METHODS = {
    "schwarz-2b": _method(2, 2),
    "schwarz-2b-3": _method(2, 3),
    "schwarz-3b": _method(3, 2),
    "schwarz-3b-3": _method(3, 3),
    "schwarz-4b": _method(4, 2),
    "schwarz-v-2b": _method(2, 2, "v"),
    "schwarz-v-3b": _method(3, 2, "v"),
    "schwarz-v-4b": _method(4, 2, "v"),
}
"""The lab's methods (``schwarz-[v-]WIDTHb[-CUTTINGS]``: strips WIDTH block lengths wide, 2 (or 3) cuttings;
``-v-``: the other bodies' velocities held instead of the other contacts' impulses)."""


def where(ctx, v, r, groups) -> dict[str, float]:
    """RMS law residual (m/s) over classes of contacts: bed / head joints, contacts on a cut of some cutting
    (its strips' edges) or inside every cutting's strips, and the wall's four quarters of height."""
    p = ctx.p
    e = law.law_residual(p, ctx.pack, ctx.H, v, r)
    head = np.abs(ctx.pack[:, nlgs.P_NY]) < HEAD
    inside = np.ones(p.count, bool)
    for cutting in groups:
        inner = np.zeros(p.count, bool)
        for g in cutting:
            inner[g] = True
        inside &= inner
    y = p.point[:, 1]
    quarter = np.minimum((4 * (y - y.min()) / max(np.ptp(y), 1e-12)).astype(int), 3)
    classes = {"bed": ~head, "head": head, "on a cut": ~inside, "inside all": inside}
    classes.update({f"height q{k + 1}": quarter == k for k in range(4)})
    return {k: float(np.sqrt((e[m] ** 2).mean())) if m.any() else 0.0 for k, m in classes.items()}


def error_shape(p, pack, v) -> dict[str, float]:
    """How the velocity error v − v_ref is made, as shares of its kinetic energy (mass- and inertia-weighted):
    horizontal, vertical, spin; and per course (blocks binned by centre height, one bin a course), the share
    of the horizontal energy in each course's uniform horizontal velocity (shear of the courses), of the
    vertical energy in each course's uniform vertical velocity and in its part linear in x (the course's
    section turning: bending or rocking of the wall as a whole)."""
    free = p.inv_mass > 0
    d = (v - p.v_ref)[free]
    m, inertia = 1 / p.inv_mass[free], 1 / p.inv_inertia[free]
    x, y = p.q_m[free, 0], p.q_m[free, 1]
    a, b = p.body[:, 0], p.body[:, 1]
    bed = free[a] & free[b] & (np.abs(pack[:, nlgs.P_NY]) >= HEAD)
    course_h = float(np.median(np.abs(p.q_m[a[bed], 1] - p.q_m[b[bed], 1]))) if bed.any() else 1.0
    course = np.round((y - y.min()) / course_h).astype(int)
    ex, ey, ew = (m * d[:, 0] ** 2).sum(), (m * d[:, 1] ** 2).sum(), (inertia * d[:, 2] ** 2).sum()
    shear = uniform_y = linear_y = 0.0
    for k in np.unique(course):
        s = course == k
        w, xs = m[s], x[s] - np.average(x[s], weights=m[s])
        shear += np.average(d[s, 0], weights=w) ** 2 * w.sum()
        uniform_y += np.average(d[s, 1], weights=w) ** 2 * w.sum()
        if (w * xs * xs).sum() > 0:
            linear_y += (w * xs * d[s, 1]).sum() ** 2 / (w * xs * xs).sum()
    total = max(ex + ey + ew, 1e-300)
    return {
        "horizontal": ex / total,
        "vertical": ey / total,
        "spin": ew / total,
        "courses' shear (of horizontal)": shear / max(ex, 1e-300),
        "courses' lift (of vertical)": uniform_y / max(ey, 1e-300),
        "sections turning (of vertical)": linear_y / max(ey, 1e-300),
    }


if __name__ == "__main__":
    import argparse

    from benchmarks.solver_lab.outcome import Context
    from benchmarks.solver_lab.problems import load_all

    ap = argparse.ArgumentParser(description="rounds, residual history and where the residual sits, per problem")
    ap.add_argument("problems", nargs="+")
    ap.add_argument("--widths", nargs="+", type=float, default=[2, 3])
    ap.add_argument("--cuttings", nargs="+", type=int, default=[2])
    ap.add_argument("--rounds", type=int, default=ROUNDS)
    ap.add_argument("--target", type=float, default=1e-5)
    ap.add_argument("--held", choices=("r", "v"), default="r")
    args = ap.parse_args()
    for prob in load_all(args.problems):
        ctx = Context(prob)
        for width in args.widths:
            for count in args.cuttings:
                t = time.process_time()
                o = run(ctx, args.target, width, count, args.rounds, errors=True, held=args.held)
                print(
                    f"{prob.name} width {width:g}b × {count}, {args.held} held: {o.passes / count:.1f} rounds, residual"
                    f" {o.residual:.2e}, velocity error {o.errors[-1] if o.errors else 0:.2e} m/s, visits"
                    f" {o.visits / prob.count:.0f} sweeps, {o.short} short, {time.process_time() - t:.1f} CPU s",
                    flush=True,
                )
                print("  residual by pass: " + " ".join(f"{e:.1e}" for e in o.history), flush=True)
                print("  velocity error by pass: " + " ".join(f"{e:.1e}" for e in o.errors), flush=True)
                at = where(ctx, o.v, o.r, o.cut.groups)
                print("  where (RMS m/s): " + ", ".join(f"{k} {e:.1e}" for k, e in at.items()), flush=True)
                shares = error_shape(prob, ctx.pack, o.v)
                print("  error's energy: " + ", ".join(f"{k} {e:.2f}" for k, e in shares.items()), flush=True)
