"""Recompute the figures quoted in docs/scenarios.md from the runs' history files.

Run the five scenarios of docs/scenarios.md with ``--history X.npz``, then, from the repository root::

    python docs/scenario_figures.py --wall wall51.npz --wall wall248.npz --arch arch.npz \\
        --aqueduct aqueduct.npz --aqueduct aqueduct-shaken.npz \\
        [--static wall51-static.npz --static wall248-static.npz]

Any subset of the options works; each prints its tables (plain text, numbers as quoted in the doc).
``--static`` takes the history of the same wall with the ground at rest (``masonry simulate wall
--amp 0 --duration 0.01 --record-every 1 --history ...``) for the exact check of σ_yy per course.

Joint states are read from the history: ``block_max_opening`` (the widest opening of the block's initial
face joints — body pairs with two initial contact points — followed kinematically by
``masonrycli.mechanism``; single corner contacts are left out), ``block_sliding_ratio`` (share of the block's
normal contact load carried by sliding contacts: at the friction limit *and* sliding faster than
``masonrycli.mechanism.SLIP_SPEED``, 1 mm/s) and ``joint_hinged``. Two things the history does not hold
per joint — which end of a joint is open (intrados / extrados) and how far its faces have slid — are
measured geometrically, which also gives an independent cross-check of the openings and hinges: the
structure is rebuilt with the project's builder (defaults, ``blocks`` = N for a wall; checked against the
recorded initial centroids), the two end points of every joint face of ``joint_body`` are attached to both
bodies, and each end's opening is the normal separation of the two copies, (p_b − p_a)·n_a, with the rigid
motions of ``block_q`` / ``support_q``. Positive = open, negative = interpenetration. The script prints how
far the widest geometric opening of each block is from ``block_max_opening``.

The colour ranges of the recording are replayed from the history the way the recorder follows the data
(``masonrycli.colour_range.RangeTracker`` over every frame after the initial one).
"""

from __future__ import annotations

import argparse
import re
from dataclasses import dataclass

import numpy as np
from shapely.geometry import LineString, MultiLineString

RHO, G = 2500.0, 9.81  # the CLI defaults (density kg/m³, gravity m/s²)


# ----------------------------------------------------------------------------------------------------
# loading and geometry
# ----------------------------------------------------------------------------------------------------


@dataclass
class Run:
    path: str
    h: dict
    names: np.ndarray  # blocks then supports
    n: int
    polys: list  # shapely polygons, blocks then supports (initial configuration)

    def at(self, t: float) -> int:
        return int(np.argmin(np.abs(self.h["time"] - t)))


def load(path: str, kind: str) -> Run:
    with np.load(path) as f:
        h = {k: f[k] for k in f.files}
    n = h["block_name"].size
    if kind == "wall":
        from geometry_library.builders import build_wall

        asm = build_wall(blocks=n)
    elif kind == "arch":
        from geometry_library.builders import build_arch

        asm = build_arch()
    else:
        from geometry_library.builders import build_aqueduct

        asm = build_aqueduct()
    polys = [b.polygon for b in asm.blocks] + [s.polygon for s in asm.supports]
    names = np.concatenate([h["block_name"], h["support_name"]])
    built = [b.name for b in asm.blocks] + [s.name for s in asm.supports]
    if list(names) != built:
        raise SystemExit(f"{path}: block names differ from the default {kind} builder's")
    c0 = np.array([[p.centroid.x, p.centroid.y] for p in polys[:n]])
    err = np.abs(c0 - h["block_q"][0, :, :2]).max()
    if err > 1e-9:
        raise SystemExit(f"{path}: initial centroids differ from the default {kind} builder's by {err:g} m")
    return Run(path, h, names, n, polys)


def body_q(run: Run) -> np.ndarray:
    """(T, B, 3) x, y, rotation of blocks then supports."""
    return np.concatenate([run.h["block_q"], run.h["support_q"]], axis=1)


def joint_faces(run: Run):
    """Per joint: end points (J, 2, 2) and unit normal from body a to body b (J, 2), initial configuration."""
    jb = run.h["joint_body"]
    ends = np.full((len(jb), 2, 2), np.nan)
    normal = np.full((len(jb), 2), np.nan)
    for j, (a, b) in enumerate(jb):
        # the part of a's boundary within 1e-7 m of b (coordinates are not exactly shared: 1.2 vs 1.2000000000000002)
        g = run.polys[a].exterior.intersection(run.polys[b].buffer(1e-7))
        lines = [g] if isinstance(g, LineString) else list(getattr(g, "geoms", []))
        pts = np.array([c for line in lines if isinstance(line, (LineString, MultiLineString)) for c in line.coords])
        if len(pts) < 2 or np.ptp(pts, axis=0).max() < 1e-6:
            continue
        axis = np.linalg.svd(pts - pts.mean(0))[2][0]  # principal direction of the face
        s = (pts - pts[0]) @ axis
        e1, e2 = pts[np.argmin(s)], pts[np.argmax(s)]
        t = (e2 - e1) / np.hypot(*(e2 - e1))
        nrm = np.array([t[1], -t[0]])
        ca = np.array(run.polys[a].centroid.coords[0])
        if nrm @ (0.5 * (e1 + e2) - ca) < 0:
            nrm = -nrm
        ends[j] = (e1, e2)
        normal[j] = nrm
    return ends, normal


def _rot(theta):
    c, s = np.cos(theta), np.sin(theta)
    return c, s


def joint_openings(run: Run, ends, normal):
    """(T, J, 2) normal opening of each joint end (m, + open) and (T, J) tangential slip (m)."""
    q = body_q(run)
    q0 = q[0]
    jb = run.h["joint_body"]
    out = np.empty((q.shape[0], len(jb), 2))
    slip = np.zeros((q.shape[0], len(jb)))
    ca, cb = q0[jb[:, 0], :2], q0[jb[:, 1], :2]
    for k in range(2):
        e = ends[:, k]
        pos = []
        for body, c0 in ((jb[:, 0], ca), (jb[:, 1], cb)):
            x = q[:, body, :2]
            c, s = _rot(q[:, body, 2])
            r = e - c0
            pos.append(np.stack([x[..., 0] + c * r[:, 0] - s * r[:, 1], x[..., 1] + s * r[:, 0] + c * r[:, 1]], -1))
        c, s = _rot(q[:, jb[:, 0], 2])
        n = np.stack([c * normal[:, 0] - s * normal[:, 1], s * normal[:, 0] + c * normal[:, 1]], -1)
        d = pos[1] - pos[0]
        out[:, :, k] = np.einsum("tjk,tjk->tj", d, n)
        tang = np.stack([-n[..., 1], n[..., 0]], -1)
        slip += 0.5 * np.einsum("tjk,tjk->tj", d, tang)
    return out, slip


def joint_label(run: Run, j: int) -> str:
    a, b = run.h["joint_body"][j]
    return f"{run.names[a]}|{run.names[b]}"


def table(header, rows, fmt=None):
    cols = [header] + [
        [(f.format(v) if isinstance(f, str) else f(v)) if f else str(v) for f, v in zip(fmt or [None] * len(r), r)]
        for r in rows
    ]
    width = [max(len(str(c[i])) for c in cols) for i in range(len(header))]
    line = "| " + " | ".join(str(h).ljust(w) for h, w in zip(header, width)) + " |"
    print(line)
    print("|" + "|".join("-" * (w + 2) for w in width) + "|")
    for c in cols[1:]:
        print("| " + " | ".join(str(v).rjust(w) for v, w in zip(c, width)) + " |")
    print()


def per_block_max(run: Run, values: np.ndarray) -> np.ndarray:
    """(..., J) values per joint -> (..., N) the largest over each block's joints (0 with none)."""
    jb, n = run.h["joint_body"], run.n
    out = np.zeros(values.shape[:-1] + (n,))
    for k in range(2):
        m = jb[:, k] < n
        for j in np.where(m)[0]:
            b = jb[j, k]
            out[..., b] = np.maximum(out[..., b], values[..., j])
    return out


def opening_crosscheck(run: Run, op, slip) -> str:
    """Widest geometric opening per block vs the recorded ``block_max_opening``, over every frame; at the last
    frame, the blocks where they differ by more than 0.1 mm, with the largest slip of their joints."""
    geo = per_block_max(run, np.maximum(op.max(axis=2), 0.0))
    bmo = run.h["block_max_opening"]
    d = np.abs(geo - bmo)
    t, b = np.unravel_index(np.argmax(d), d.shape)
    flips = [int(((geo > thr) != (bmo > thr)).sum()) for thr in (1e-4, 1e-3)]
    out = (
        f"widest geometric opening per block vs block_max_opening, all {d.shape[0]} frames × {d.shape[1]} "
        f"blocks: max |difference| {1e3 * d.max():.4f} mm ({run.names[b]}, t = {run.h['time'][t]:.2f} s: "
        f"geometric {1e3 * geo[t, b]:.3f} mm, recorded {1e3 * bmo[t, b]:.3f} mm); (block, frame) pairs on "
        f"different sides of 0.1 mm / 1 mm: {flips[0]} / {flips[1]}; largest block_max_opening over the run "
        f"{1e3 * bmo.max():.1f} mm"
    )
    off = np.where(d[-1] > 1e-4)[0]
    if off.size:
        gslip = per_block_max(run, np.abs(slip[-1]))
        off = off[np.argsort(-d[-1, off])]
        out += (
            f". At the end {off.size} blocks differ by more than 0.1 mm (recorded / geometric opening / largest "
            "|slip| of the block's joints, mm): "
            + ", ".join(
                f"{run.names[i]} {1e3 * bmo[-1, i]:.1f} / {1e3 * geo[-1, i]:.1f} / {1e3 * gslip[i]:.1f}"
                for i in off[:16]
            )
            + (" …" if off.size > 16 else "")
        )
    return out


def single_point_contacts(run: Run, kind: str) -> str:
    """The initial contacts that are not one of two ends of a joint, as the run's JointTracker sees them
    (``masonrycli.run.Simulation`` set-up, no time step), classified by where the contact point lies on
    each body (a corner or inside a face); ``block_max_opening`` leaves them out (joints only)."""
    from masonrycli.run import Simulation
    from masonrycli.scenario import Material, RunConfig, scenario_from_builder

    options = {"blocks": run.n} if kind == "wall" else {}
    tracker = Simulation(scenario_from_builder(kind, options, RunConfig(duration=0.001), Material(), {})).joints
    single = np.where(tracker._end_joint < 0)[0]
    counts: dict[str, int] = {}
    for e in single:
        a, b = tracker.end_body[e]
        pt = tracker._local_a[e] + run.h["block_q"][0, a, :2] if a < run.n else None
        if pt is None:
            continue
        where = []
        for body in (a, b):
            d = np.hypot(*(np.array(run.polys[body].exterior.coords) - pt).T).min()
            where.append("corner" if d < 1e-6 else "face")
        key = "–".join(where)
        counts[key] = counts.get(key, 0) + 1
    return (
        f"initial contact points: {tracker.end_body.shape[0]}, of which {single.size} are not one of two ends "
        "of a joint (" + ", ".join(f"{v} {k}" for k, v in sorted(counts.items())) + ")"
    )


RECORDED_FIELDS = (
    ("cell_volumetric_strain_rate", True),
    ("cell_deviatoric_strain", False),
    ("cell_spherical_stress", True),
    ("cell_deviatoric_stress", False),
)


def recorded_ranges(h: dict, key: str) -> list:
    """The colour range of ``key`` at every frame, as ``masonrycli.recording`` logs it: a
    ``masonrycli.colour_range.RangeTracker`` fed the frames from the first computed one on (the initial
    state is not shown); the volumetric strain rate falls back on the chain strain rate. Entry 0: None."""
    from masonrycli.colour_range import RangeTracker
    from masonrycli.recording.layout import CHAIN_KEY, FIELD_BY_KEY

    spec = FIELD_BY_KEY[key]
    v = h[key]
    if key == "cell_volumetric_strain_rate" and CHAIN_KEY in h:
        v = np.where(np.isnan(v), h[CHAIN_KEY], v)
    tracker = RangeTracker(spec.kind, spec.floor)
    return [None] + [tracker.update(v[i]) for i in range(1, v.shape[0])]


def colour_ranges(run: Run, i: int) -> str:
    h = run.h
    parts = []
    for key, _ in RECORDED_FIELDS:
        r = recorded_ranges(h, key)[i]
        v = h[key][i]
        d = v[np.isfinite(v)]
        over = int(((d < r.lo) | (d > r.hi)).sum())
        span = (min(d.max(), r.hi) - max(d.min(), r.lo)) / (r.hi - r.lo)
        parts.append(
            f"{key.removeprefix('cell_')} {r.lo:.3g} … {r.hi:.3g} ({over} of {d.size} defined cells beyond, "
            f"cells span {100 * span:.0f} % of it at t = {h['time'][i]:.2f} s)"
        )
    return "Recording colour ranges at that frame (replayed from the history): " + "; ".join(parts)


def detector_vs_geometry(run: Run, op, i: int) -> str:
    """Compare the hinge detector (joint_hinged) with the geometric openings at frame i."""
    o = op[i]
    hinged = run.h["joint_hinged"][i]
    geo = (o.max(1) > 1e-4) & (o.min(1) < 1e-5)
    both = o.min(1) > 1e-4
    return (
        f"{geo.sum()} joints have one end open > 0.1 mm and the other closed (< 0.01 mm); {both.sum()} are "
        f"open at both ends (> 0.1 mm); the detector reports {hinged.sum()} hinged; "
        f"{(geo & hinged).sum()} in both, {(geo & ~hinged).sum()} geometric-only, "
        f"{(~geo & hinged).sum()} detector-only."
    )


# ----------------------------------------------------------------------------------------------------
# walls
# ----------------------------------------------------------------------------------------------------


def course_of(names) -> np.ndarray:
    return np.array([int(re.match(r"c(\d+)-", s).group(1)) for s in names])


def wall(path: str, static: str | None) -> None:
    run = load(path, "wall")
    h, n = run.h, run.n
    course = course_of(h["block_name"])
    C = course.max()
    height = np.ptp(h["block_q"][0, :, 1]) / (C - 1)  # course height
    i1 = run.at(0.1)
    t1 = h["time"][i1]
    print(f"## {path}: wall, {n} blocks, {C} courses, t = {t1:.3f} s (step {h['step'][i1]}) for the snapshot\n")

    ends, normal = joint_faces(run)
    op, slip = joint_openings(run, ends, normal)
    jb = h["joint_body"]
    ground = n  # the single support
    opmax = op.max(axis=2)  # (T, J) widest end of each joint

    evr = h["cell_volumetric_strain_rate"][i1]
    bmo_all = h["block_max_opening"]  # (T, N) recorded, followed kinematically
    bmo = bmo_all[i1]
    sr = h["block_sliding_ratio"]
    dx = h["block_q"][:, :, 0] - h["block_q"][0, :, 0]
    ug = h["support_q"][:, 0, 0] - h["support_q"][0, 0, 0]
    rot = np.degrees(h["block_q"][:, :, 2])
    # bed joints under each course (course 1: the ground joints), for the slip by course
    a_c = np.where(jb[:, 0] < n, course[np.minimum(jb[:, 0], n - 1)], 0)
    b_c = np.where(jb[:, 1] < n, course[np.minimum(jb[:, 1], n - 1)], 0)
    under = np.where(a_c != b_c, np.maximum(a_c, b_c), -1)  # course above the bed joint, -1 for head joints
    aslip = np.abs(slip)
    T = h["time"]
    rate = np.abs(slip[i1 + 1] - slip[i1 - 1]) / (T[i1 + 1] - T[i1 - 1])  # (J,) m/s, central difference at t

    rows = []
    for c in range(C, 0, -1):
        m = course == c
        bj = under == c
        rows.append(
            [
                c,
                m.sum(),
                (bmo[m] > 1e-4).sum(),
                (bmo[m] > 1e-3).sum(),
                1e3 * bmo[m].max(),
                (evr[m] > 0).sum(),
                evr[m].mean(),
                sr[i1, m].mean(),
                sr[1:, m].mean(),
                1e3 * rate[bj].mean(),
                1e3 * aslip[i1, bj].mean(),
                1e3 * aslip[i1, bj].max(),
                1e3 * aslip[-1, bj].max(),
                1e3 * dx[i1, m].mean(),
                rot[i1, m].mean(),
            ]
        )
    print(
        f"Per course at t = {t1:.2f} s (course 1 = bottom). open>0.1/open>1/max open: from block_max_opening; "
        "ev>0: cells with volumetric strain rate > 0; slide: mean block_sliding_ratio (share of the normal "
        "load on sliding contacts) at t and over the whole run; bed slip: relative tangential displacement "
        "of the faces of the bed joints under the course (geometric; course 1: the ground joints): mean rate "
        "at t (central difference over ±1 frame), mean and max at t, max at the end; dx: mean horizontal displacement; rot: mean rotation.\n"
    )
    table(
        [
            "course",
            "blocks",
            "open>0.1",
            "open>1",
            "max open mm",
            "ev>0",
            "mean ev 1/s",
            "slide(t)",
            "slide(run)",
            "bed slip rate mm/s",
            "bed slip mean mm",
            "bed slip max mm",
            "bed slip max end",
            "dx mm",
            "rot deg",
        ],
        rows,
        [
            None,
            None,
            None,
            None,
            "{:.1f}",
            None,
            "{:+.3f}",
            "{:.2f}",
            "{:.2f}",
            "{:.0f}",
            "{:.1f}",
            "{:.1f}",
            "{:.1f}",
            "{:.1f}",
            "{:+.2f}",
        ],
    )
    print("Cross-check: " + opening_crosscheck(run, op, slip))
    print("Set-up: " + single_point_contacts(run, "wall") + "\n")

    # maps: one character per block, left to right
    x0 = h["block_q"][0, :, 0]
    widest = max((course == k).sum() for k in range(1, C + 1))

    def show_map(i):
        g = bmo_all[i]
        e = h["cell_volumetric_strain_rate"][i]
        print(f"Map at t = {h['time'][i]:.2f} s, top course first, one character per block (left → right).")
        print(
            "Joint opening (block_max_opening): '#' > 5 mm, 'o' 1–5 mm, '+' 0.1–1 mm, "
            "'.' closed. Volumetric strain rate ε̇v: 'O' > 0.3 1/s, '+' 0.05–0.3, '.' |ε̇v| ≤ 0.05, '-' < −0.05.\n"
        )
        print("```")
        for c in range(C, 0, -1):
            idx = np.where(course == c)[0]
            idx = idx[np.argsort(x0[idx])]
            a = "".join("#" if v > 5e-3 else "o" if v > 1e-3 else "+" if v > 1e-4 else "." for v in g[idx])
            b = "".join("O" if v > 0.3 else "+" if v > 0.05 else "-" if v < -0.05 else "." for v in e[idx])
            pad = " " if len(idx) < widest else ""
            print(f"c{c:02d}  {pad}{a:<{widest + 2}s}  {pad}{b}")
        print("```\n")

    show_map(i1)
    # where the dilatant band sits: x of the cells with ε̇v > 0.05 per course
    band_x = [(c, x0[(course == c) & (evr > 0.05)]) for c in range(1, C + 1)]
    print(
        f"Cells with ε̇v > 0.05 1/s at t = {t1:.2f} s, x range of their initial centroids per course (m): "
        + ", ".join(f"c{c:02d} [{b.min():+.2f}, {b.max():+.2f}]" for c, b in band_x if b.size)
        + "\n"
    )
    vy = h["block_v"][i1, :, 1]
    for c in (C, (C + 1) // 2):
        idx = np.where(course == c)[0]
        idx = idx[np.argsort(x0[idx])]
        print(
            f"Vertical velocity at t = {t1:.2f} s, course {c}, left → right (mm/s): "
            + " ".join(f"{1e3 * v:.0f}" for v in vy[idx])
        )
    print()
    show_map(len(h["time"]) - 1)

    # bed joints vs head joints, ground joint (geometric openings per joint)
    is_ground = jb[:, 1] == ground
    is_bed = (a_c != b_c) & ~is_ground
    is_head = (a_c == b_c) & ~is_ground
    hinged = h["joint_hinged"]
    rows = []
    for label, m in (("ground", is_ground), ("bed", is_bed), ("head", is_head)):
        rows.append(
            [
                label,
                m.sum(),
                (opmax[i1, m] > 1e-4).sum(),
                (opmax[i1, m] > 1e-3).sum(),
                1e3 * opmax[i1, m].max(),
                hinged[i1, m].sum(),
                1e3 * np.abs(slip[i1, m]).max(),
                (opmax[-1, m] > 1e-3).sum(),
                hinged[-1, m].sum(),
            ]
        )
    print(
        f"Joints by type (geometric openings of the joint ends): open / hinged at t = {t1:.2f} s and at the "
        f"end (t = {h['time'][-1]:.2f} s); slip = largest relative tangential displacement of the two faces.\n"
    )
    table(
        [
            "joints",
            "count",
            "open>0.1mm",
            "open>1mm",
            "max open mm",
            "hinged",
            "max slip mm",
            "open>1mm end",
            "hinged end",
        ],
        rows,
        [None, None, None, None, "{:.1f}", None, "{:.1f}", None, None],
    )

    print(f"Hinge detector vs geometry at t = {t1:.2f} s: " + detector_vs_geometry(run, op, i1))
    print("… and at the end: " + detector_vs_geometry(run, op, len(h["time"]) - 1) + "\n")
    # opening and closing: the volumetric strain rate of the whole wall changes sign
    ev_mean = np.nanmean(h["cell_volumetric_strain_rate"][1:], axis=1)
    evc = np.nanmean(h["cell_volumetric_strain"], axis=1)
    ed = h["cell_deviatoric_strain"][i1]
    band = evr > 0.05
    print(
        f"Mean volumetric strain rate over the cells: > 0 in {(ev_mean > 0).mean() * 100:.0f} % of the frames, "
        f"< 0 in {(ev_mean < 0).mean() * 100:.0f} %; range {ev_mean.min():+.3f} … {ev_mean.max():+.3f} 1/s. "
        "Mean cumulated volumetric strain at t = 0.1/0.25/0.5/0.75/1 s: "
        + ", ".join(f"{evc[run.at(t)]:+.4f}" for t in (0.1, 0.25, 0.5, 0.75, 1.0))
    )
    print(
        f"Dilatant cells vs open joints at t = {t1:.2f} s: of the {band.sum()} cells with ε̇v > 0.05 1/s, "
        f"{(band & (bmo > 1e-4)).sum()} have a joint open > 0.1 mm; of the {(bmo > 1e-3).sum()} blocks with a "
        f"joint open > 1 mm, {((bmo > 1e-3) & band).sum()} have ε̇v > 0.05 1/s (block_max_opening)."
    )
    print(
        f"Deviatoric cumulated strain at t = {t1:.2f} s: mean {ed[band].mean():.4f} in the {band.sum()} cells of the "
        f"dilatant band (ε̇v > 0.05 1/s), {ed[~band].mean():.4f} elsewhere; max {ed.max():.4f} "
        f"({h['block_name'][np.argmax(ed)]})\n"
    )

    # base slip, drift, over time
    bottom, top = course == 1, course == C
    rows = []
    for t in (0.01, 0.05, 0.1, 0.25, 0.5, 0.75, 1.0):
        i = run.at(t)
        ub, ut = dx[i, bottom].mean(), dx[i, top].mean()
        rows.append(
            [
                h["time"][i],
                1e3 * ug[i],
                1e3 * ub,
                1e3 * (ug[i] - ub),
                1e3 * ut,
                1e3 * (ut - ub),
                np.abs(rot[i]).max(),
                h["hinge_count"][i],
                h["contact_count"][i],
            ]
        )
    print(
        "Ground vs wall over time: ground displacement, mean displacement of the bottom course, base slip "
        "(ground − bottom course), top course, drift (top − bottom), largest |rotation| of a block, hinged "
        "joints, contacts.\n"
    )
    table(
        ["t s", "ground mm", "bottom mm", "base slip mm", "top mm", "drift mm", "max |rot| deg", "hinges", "contacts"],
        rows,
        ["{:.2f}", "{:+.1f}", "{:+.1f}", "{:+.1f}", "{:+.1f}", "{:+.1f}", "{:.2f}", None, None],
    )
    weight = RHO * G * sum(p.area for p in run.polys[:n])
    f1 = h["support_force"][1, 0]
    print(
        f"Ground reaction at t = {h['time'][1]:.2f} s: horizontal {-f1[0] / weight:+.3f} × weight, vertical "
        f"{-f1[1] / weight:.4f} × weight (μ × vertical = {0.6 * -f1[1] / weight:.3f}); mean block vy "
        f"{1e3 * h['block_v'][1, :, 1].mean():+.1f} mm/s at t = {h['time'][1]:.2f} s, "
        f"{1e3 * h['block_v'][run.at(0.05), :, 1].mean():+.1f} mm/s at t = 0.05 s"
    )
    ar = np.abs(rot)
    print(
        f"Largest block rotation over the run: {ar.max():.2f}° ({h['block_name'][ar.max(0).argmax()]}, "
        f"t = {h['time'][ar.max(1).argmax()]:.2f} s)"
    )
    vb = h["block_v"][:, bottom, 0].mean(axis=1)
    vg = h["support_v"][:, 0, 0]
    print(
        f"Bottom course velocity vs ground: max |v_ground − v_bottom| = {np.abs(vg - vb).max():.3f} m/s; "
        f"max |v_bottom| = {np.abs(vb).max():.3f} m/s (ground amplitude {np.abs(vg).max():.3f} m/s); the "
        f"bottom course moves with the ground (|Δv| < 0.01 m/s) in {(np.abs(vg - vb) < 0.01).mean() * 100:.0f} % "
        "of the frames."
    )
    e = h["energy_dissipated"][-1], h["support_work"][-1]
    dE = (h["energy_kinetic"][-1] + h["energy_potential"][-1]) - (h["energy_kinetic"][0] + h["energy_potential"][0])
    print(
        f"Energy over the run: support work {e[1]:.0f} J, dissipated {e[0]:.0f} J, Δ(kinetic+potential) "
        f"{dE:.0f} J (balance error {dE - (e[1] - e[0]):.1f} J).\n"
    )

    # stresses at t: where compression concentrates
    p = h["cell_spherical_stress"][i1]
    qd = h["cell_deviatoric_stress"][i1]
    k = np.argsort(p)[:3]
    print(
        f"Most compressed cells at t = {t1:.2f} s (spherical p): "
        + ", ".join(f"{h['block_name'][i]} p = {p[i] / 1e3:.0f} kPa, q = {qd[i] / 1e3:.0f} kPa" for i in k)
    )
    thirds = np.digitize(x0, [x0.min() + np.ptp(x0) / 3, x0.min() + 2 * np.ptp(x0) / 3])
    print(
        "Bottom course mean p by third of the length (left, middle, right): "
        + ", ".join(f"{p[bottom & (thirds == k)].mean() / 1e3:.0f} kPa" for k in range(3))
    )
    print(
        f"Tension (p > 0) cells: {(p > 0).sum()}; largest p = {p.max() / 1e3:.1f} kPa; "
        f"max skew |σxy−σyx|/2 = {np.nanmax(h['cell_stress_skew'][i1]):.0f} Pa (over the run {np.nanmax(h['cell_stress_skew']):.0f} Pa)"
    )
    print(colour_ranges(run, i1) + "\n")

    # σ_yy per course vs statics
    def syy_rows(hh, i):
        bs = hh["block_stress"][i, :, 1, 1]
        cs = hh["cell_stress"][i, :, 1, 1]
        out = []
        for c in range(C, 0, -1):
            kk = C - c + 1
            exact = -RHO * G * height * (kk - 0.5)
            m = course == c
            out.append(
                [
                    c,
                    exact / 1e3,
                    bs[m].mean() / 1e3,
                    100 * (bs[m].mean() / exact - 1),
                    cs[m].mean() / 1e3,
                    100 * (cs[m].mean() / exact - 1),
                ]
            )
        return out

    fmt = [None, "{:.2f}", "{:.2f}", "{:+.2f}", "{:.2f}", "{:+.2f}"]
    hdr = ["course", "−ρgH(k−½) kPa", "block σyy kPa", "err %", "cell σyy kPa", "err %"]
    print(
        f"σ_yy per course (k = course counted from the top, H = {height:.2f} m, ρ = {RHO:g}, g = {G}); "
        f"frame 0 holds no stress (NaN: no contacts before the first step), so the first computed frame, "
        f"t = {h['time'][1]:.3f} s (ground already moving):\n"
    )
    table(hdr, syy_rows(h, 1), fmt)
    if static:
        with np.load(static) as f:
            hs = {k: f[k] for k in f.files}
        if hs["block_name"].size != n:
            raise SystemExit(f"{static}: not the same wall as {path}")
        last = len(hs["time"]) - 1
        print(
            f"Ground at rest ({static}), t = {hs['time'][last]:.3f} s (NLGS tolerance "
            f"{hs['nlgs_residual'][last]:.2g} reached):\n"
        )
        table(hdr, syy_rows(hs, last), fmt)


# ----------------------------------------------------------------------------------------------------
# arch and aqueduct
# ----------------------------------------------------------------------------------------------------


def group_of(name: str) -> str:
    if name.startswith("v"):
        return "ring"
    if name.startswith("left-pier"):
        return "left pier"
    if name.startswith("right-pier"):
        return "right pier"
    if name.startswith("wall"):
        return "spandrel"
    return "support"


def arch(path: str, kind: str) -> None:
    run = load(path, kind)
    h, n = run.h, run.n
    names = run.names
    grp = np.array([group_of(s) for s in names])
    T = h["time"]
    ie = len(T) - 1
    print(f"## {path}: {kind}, {n} blocks, t = 0 … {T[-1]:.2f} s\n")
    su = h["support_q"][-1] - h["support_q"][0]
    print(
        "Support displacement at the end: "
        + ", ".join(f"{s} ({1e3 * d[0]:+.1f}, {1e3 * d[1]:+.1f}) mm" for s, d in zip(h["support_name"], su))
        + "\n"
    )

    f1, fe = h["support_force"][1], h["support_force"][-1]
    print(
        "Force of the blocks on each support (kN per m of thickness), first computed frame → end: "
        + "; ".join(
            f"{s} Fx {a[0] / 1e3:+.1f} → {b[0] / 1e3:+.1f}, Fy {a[1] / 1e3:+.1f} → {b[1] / 1e3:+.1f}"
            for s, a, b in zip(h["support_name"], f1, fe)
        )
        + "\n"
    )
    it = h["nlgs_iterations"][1:]
    print(
        f"NLGS: mean {it.mean():.0f} sweeps per recorded step, {(it >= 1000).mean() * 100:.1f} % of the recorded "
        f"steps at the 1000-sweep cap, residual max {h['nlgs_residual'][1:].max():.2e}\n"
    )

    ends, normal = joint_faces(run)
    op, slip = joint_openings(run, ends, normal)
    jb = h["joint_body"]
    hinged = h["joint_hinged"]

    # arch centre: midway between the foundations, at the springing (top of the piers)
    pier_top = max(run.polys[i].bounds[3] for i in range(n) if grp[i].endswith("pier"))
    xc = 0.5 * (h["support_q"][0, 0, 0] + h["support_q"][0, -1, 0])
    rad = np.hypot(ends[..., 0] - xc, ends[..., 1] - pier_top)  # (J, 2)

    def side(j, k):
        """'intrados'/'extrados' for a ring joint end (nearer / farther from the arch centre)."""
        return "intrados" if rad[j, k] < rad[j, 1 - k] else "extrados"

    # hinges over time
    hc = h["hinge_count"]
    ever = np.where(hinged.any(0))[0]
    marks = [t for t in (0.1, 0.25, 0.5, 1, 2, 3, 4, 5) if t <= T[-1] + 1e-9]
    print(
        f"Hinged joints: {len(ever)} joints hinged at some frame; count at t = "
        + "/".join(f"{t:g}" for t in marks)
        + " s: "
        + ", ".join(str(hc[run.at(t)]) for t in marks)
        + f"; max {hc.max()} at t = {T[hc.argmax()]:.2f} s\n"
    )
    many = np.where(hc > 3)[0]
    if many.size and len(ever) <= 30:
        from collections import Counter

        sets = Counter(" + ".join(joint_label(run, j) for j in np.where(hinged[i])[0]) for i in many)
        print(
            f"Frames with more than 3 hinged joints: {many.size} ({100 * many.size / len(T):.0f} %), "
            f"t = {T[many[0]]:.2f} … {T[many[-1]]:.2f} s; sets: "
            + "; ".join(f"{k} ({v})" for k, v in sets.most_common())
            + "\n"
        )
    rows = []
    ring_like = [j for j in ever if "ring" in (grp[jb[j, 0]], grp[jb[j, 1]])]
    show = ever if len(ever) <= 30 else np.array(ring_like + [j for j in ever if j not in ring_like])[:30]
    for j in show:
        idx = np.where(hinged[:, j])[0]
        o = op[ie, j]
        k_open = int(np.argmax(o))
        where = side(j, 1 - k_open) if {grp[jb[j, 0]], grp[jb[j, 1]]} & {"ring"} else "-"
        rows.append(
            [
                joint_label(run, j),
                T[idx[0]],
                T[idx[-1]],
                100 * hinged[:, j].mean(),
                "yes" if hinged[ie, j] else "no",
                1e3 * o.min(),
                1e3 * o.max(),
                where,
            ]
        )
    print(
        "Per hinged joint: first/last frame hinged, % of frames, hinged at the end, geometric opening of its "
        "two ends at the end (mm), and the side of the pivot (the closed end) for joints of the ring.\n"
    )
    table(
        ["joint", "first s", "last s", "% frames", "end", "closed end mm", "open end mm", "pivot"],
        rows,
        [None, "{:.2f}", "{:.2f}", "{:.0f}", None, "{:+.2f}", "{:.2f}", None],
    )
    if len(ever) > len(show):
        print(f"({len(ever) - len(show)} more hinged joints not listed)\n")

    ring_end = [j for j in np.where(hinged[ie])[0] if "ring" in (grp[jb[j, 0]], grp[jb[j, 1]])]
    if 0 < len(ring_end) <= 6:
        together = hinged[:, ring_end].all(1)
        if together.any():
            i0 = int(np.argmax(together))
            print(
                f"The {len(ring_end)} ring joints hinged at the end ({', '.join(joint_label(run, j) for j in ring_end)}) "
                f"are first all flagged together at t = {T[i0]:.2f} s, then in {100 * together[i0:].mean():.0f} % of "
                "the frames. Geometric opening of their open end (mm) at t = "
                + "/".join(f"{t:g}" for t in marks)
                + " s: "
                + "; ".join(
                    joint_label(run, j) + " " + ", ".join(f"{1e3 * op[run.at(t), j].max():.2f}" for t in marks)
                    for j in ring_end
                )
                + "\n"
            )
    o = op[ie]
    print("Hinge detector vs geometry at the end: " + detector_vs_geometry(run, op, ie))
    print("Cross-check: " + opening_crosscheck(run, op, slip))
    print("Set-up: " + single_point_contacts(run, kind) + "\n")
    if kind == "aqueduct":
        rows = []
        pairs = {}
        for j in np.where(o.max(1) > 1e-3)[0]:
            key = " / ".join(sorted({grp[jb[j, 0]], grp[jb[j, 1]]}))
            pairs.setdefault(key, []).append(j)
        for key, js in sorted(pairs.items()):
            js = np.array(js)
            rows.append(
                [
                    key,
                    len(js),
                    (hinged[ie, js]).sum(),
                    1e3 * o[js].max(),
                    ", ".join(joint_label(run, j) for j in js[np.argsort(-o[js].max(1))][:3]),
                ]
            )
        print("Joints open more than 1 mm at the end (geometric, widest end), by the bodies they join:\n")
        table(["bodies", "open>1mm", "hinged", "max mm", "widest three"], rows, [None, None, None, "{:.1f}", None])
        # spandrel cracks by region
        xs = run.h["block_q"][0, :, 0]
        rows = []
        wj = [j for j in range(len(jb)) if grp[jb[j, 0]] == "spandrel" or grp[jb[j, 1]] == "spandrel"]
        wj = np.array(wj)
        mid = 0.5 * (ends[wj, 0] + ends[wj, 1])
        for label, m in (
            ("left of the crown (x < −0.5 m)", mid[:, 0] < -0.5),
            ("over the crown (|x| ≤ 0.5 m)", np.abs(mid[:, 0]) <= 0.5),
            ("right of the crown (x > 0.5 m)", mid[:, 0] > 0.5),
        ):
            js = wj[m]
            for lo, hi in ((0, 4.4), (4.4, 5.3), (5.3, 99)):
                mm = (mid[m, 1] >= lo) & (mid[m, 1] < hi)
                jj = js[mm]
                if not jj.size:
                    continue
                rows.append(
                    [
                        label,
                        f"{lo:g}–{hi:g}" if hi < 99 else f"> {lo:g}",
                        len(jj),
                        (o[jj].max(1) > 1e-3).sum(),
                        hinged[ie, jj].sum(),
                        1e3 * o[jj].max(),
                    ]
                )
        print(
            "Spandrel-wall joints by region (midpoint of the joint face, initial position): open > 1 mm and "
            "hinged at the end.\n"
        )
        table(
            ["region", "y m", "joints", "open>1mm", "hinged", "max open mm"],
            rows,
            [None, None, None, None, None, "{:.1f}"],
        )
        dd = h["block_q"][ie] - h["block_q"][0]
        sp = grp[:n] == "spandrel"
        rows = []
        for label, m in (("x < −0.5 m", xs < -0.5), ("|x| ≤ 0.5 m", np.abs(xs) <= 0.5), ("x > 0.5 m", xs > 0.5)):
            m = m & sp
            rows.append(
                [
                    label,
                    m.sum(),
                    1e3 * dd[m, 0].mean(),
                    1e3 * dd[m, 1].mean(),
                    np.degrees(dd[m, 2]).mean(),
                    np.degrees(dd[m, 2]).min(),
                ]
            )
        print("Spandrel blocks by initial x: mean displacement (mm) and rotation (deg) at the end.\n")
        table(
            ["spandrel blocks", "count", "mean dx", "mean dy", "mean rot", "min rot"],
            rows,
            [None, None, "{:+.1f}", "{:+.1f}", "{:+.2f}", "{:+.2f}"],
        )
        # voids: holes of the union of the moved blocks (each grown by 0.1 mm to close the contact gaps)
        from shapely import affinity
        from shapely.geometry import Polygon
        from shapely.ops import unary_union

        moved = []
        for b in range(n):
            c0 = h["block_q"][0, b, :2]
            pb = affinity.rotate(run.polys[b], h["block_q"][ie, b, 2], origin=tuple(c0), use_radians=True)
            moved.append(affinity.translate(pb, *(h["block_q"][ie, b, :2] - c0)).buffer(1e-4))
        u = unary_union(moved)
        holes = [Polygon(ring) for g in getattr(u, "geoms", [u]) for ring in g.interiors]
        rows = []
        for label, test in (
            ("x < −0.5 m", lambda x: x < -0.5),
            ("|x| ≤ 0.5 m", lambda x: abs(x) <= 0.5),
            ("x > 0.5 m", lambda x: x > 0.5),
        ):
            sel = [hh for hh in holes if test(hh.centroid.x)]
            big = max(sel, key=lambda hh: hh.area) if sel else None
            rows.append(
                [
                    label,
                    len(sel),
                    1e4 * sum(hh.area for hh in sel),
                    1e4 * big.area if big else 0.0,
                    f"({big.centroid.x:+.2f}, {big.centroid.y:.2f})" if big else "-",
                ]
            )
        print("Voids at the end (holes in the union of the moved blocks), by x of their centroid:\n")
        table(
            ["region", "voids", "total cm²", "largest cm²", "largest at (x, y) m"],
            rows,
            [None, None, "{:.1f}", "{:.1f}", None],
        )
        rs = np.array([j for j in range(len(jb)) if {grp[jb[j, 0]], grp[jb[j, 1]]} == {"ring", "spandrel"}])
        top = rs[np.argsort(-np.abs(slip[ie, rs]))][:6]
        print(
            "Largest slips along the extrados (ring / spandrel joints) at the end: "
            + ", ".join(f"{joint_label(run, j)} {1e3 * slip[ie, j]:+.1f} mm" for j in top)
            + "\n"
        )

    # real sliding: relative tangential displacement of the joint faces, by the bodies they join
    key = np.array([" / ".join(sorted({grp[a], grp[b]})) for a, b in jb])
    rows = []
    for k in np.unique(key):
        m = key == k
        rows.append(
            [
                k,
                m.sum(),
                1e3 * np.abs(slip[ie, m]).max(),
                1e3 * np.abs(slip[:, m]).max(),
                (np.abs(slip[ie, m]) > 1e-3).sum(),
                1e3 * op[ie, m].max(),
            ]
        )
    print(
        "Joints by the bodies they join: largest |slip| (relative tangential displacement of the faces) at the "
        "end and over the run, joints slipped > 1 mm at the end, widest opening at the end.\n"
    )
    table(
        ["bodies", "joints", "max |slip| end mm", "max |slip| run mm", "slip>1mm", "max open mm"],
        rows,
        [None, None, "{:.3f}", "{:.3f}", None, "{:.2f}"],
    )

    # displacements and rotations
    d = h["block_q"][ie] - h["block_q"][0]
    rot = np.degrees(h["block_q"][ie, :, 2])
    ring = np.where(grp[:n] == "ring")[0]
    ring = ring[np.argsort(names[ring])]
    crown = ring[len(ring) // 2 - 1 : len(ring) // 2 + 1]
    print("Displacement at the end (mm) and rotation (deg, + counter-clockwise):\n")
    rows = []
    for g in ("left pier", "right pier", "spandrel"):
        m = grp[:n] == g
        if m.any():
            rows.append(
                [
                    g,
                    m.sum(),
                    1e3 * d[m, 0].mean(),
                    1e3 * d[m, 1].mean(),
                    1e3 * np.abs(d[m, :2]).max(),
                    rot[m].min(),
                    rot[m].max(),
                ]
            )
    table(
        ["group", "blocks", "mean dx mm", "mean dy mm", "max |d| mm", "min rot", "max rot"],
        rows,
        [None, None, "{:+.2f}", "{:+.2f}", "{:.2f}", "{:+.3f}", "{:+.3f}"],
    )
    pier = [i for i in range(n) if grp[i].endswith("pier")]
    pier_course = {i: int(names[i].split("-c")[1][:2]) for i in pier}
    top_course = max(pier_course.values())
    rows = [
        [names[i], h["block_q"][0, i, 0], 1e3 * d[i, 0], 1e3 * d[i, 1], rot[i], h["cell_spherical_stress"][ie, i] / 1e3]
        for i in pier
        if pier_course[i] <= 3 or pier_course[i] == top_course
    ]
    print("Pier blocks, bottom three courses and top course, at the end:\n")
    table(
        ["block", "x0 m", "dx mm", "dy mm", "rot deg", "p kPa"],
        rows,
        [None, "{:+.2f}", "{:+.2f}", "{:+.2f}", "{:+.3f}", "{:.0f}"],
    )
    rows = []
    for i in ring:
        rows.append(
            [
                names[i],
                1e3 * d[i, 0],
                1e3 * d[i, 1],
                rot[i],
                h["cell_spherical_stress"][ie, i] / 1e3,
                h["cell_deviatoric_stress"][ie, i] / 1e3,
                h["block_sliding_ratio"][1:, i].mean(),
            ]
        )
    print(
        "Voussoirs (v01 = left springing), end of the run: displacement, rotation, p and q (kPa), mean sliding "
        "ratio over the run.\n"
    )
    table(
        ["voussoir", "dx mm", "dy mm", "rot deg", "p kPa", "q kPa", "slide(run)"],
        rows,
        [None, "{:+.2f}", "{:+.2f}", "{:+.3f}", "{:.1f}", "{:.1f}", "{:.3f}"],
    )
    print(
        "Crown (" + " & ".join(names[crown]) + f") mean displacement: dx = {1e3 * d[crown, 0].mean():+.1f} mm, "
        f"dy = {1e3 * d[crown, 1].mean():+.1f} mm"
    )
    dq = h["block_q"][:, crown, :2].mean(1) - h["block_q"][0, crown, :2].mean(0)
    ds = h["support_q"][:, -1, 1] - h["support_q"][0, -1, 1]
    print(
        "Crown displacement (dx, dy mm) over time, with the right support's vertical displacement: "
        + "; ".join(
            f"t = {T[run.at(t)]:g} s: ({1e3 * dq[run.at(t), 0]:+.1f}, {1e3 * dq[run.at(t), 1]:+.1f}) / {1e3 * ds[run.at(t)]:+.1f}"
            for t in marks
        )
        + "\n"
    )

    # stress and sliding by group
    p, q = h["cell_spherical_stress"], h["cell_deviatoric_stress"]
    sr = h["block_sliding_ratio"]
    evol = h["cell_volumetric_strain"][ie]
    evr = h["cell_volumetric_strain_rate"]
    defined = ~np.isnan(evol)
    rows = []
    for g in ("ring", "left pier", "right pier", "spandrel"):
        m = grp[:n] == g
        if not m.any():
            continue
        late = T > 0.5
        rows.append(
            [
                g,
                m.sum(),
                p[ie, m].mean() / 1e3,
                p[ie, m].min() / 1e3,
                q[ie, m].mean() / 1e3,
                np.nanmean(q[ie, m] / np.abs(p[ie, m])),
                sr[ie, m].mean(),
                sr[1:, m].mean(),
                (sr[1:, m] > 0).mean() * 100,
                (sr[late][:, m] > 0).mean() * 100,
                defined[m].sum(),
                np.nanmean(evol[m]) if defined[m].any() else np.nan,
                np.nanmax(np.abs(evol[m])) if defined[m].any() else np.nan,
            ]
        )
    print(
        "By group at the end: mean / most negative spherical stress p, mean deviatoric q (kPa), mean q/|p|, "
        "sliding ratio at the end and averaged over the run, % of (block, frame) with any slipping contact over "
        "the run and after t = 0.5 s, blocks with a defined strain (in a centroid triangle), mean and largest "
        "|volumetric cumulated strain|.\n"
    )
    table(
        [
            "group",
            "blocks",
            "mean p",
            "min p",
            "mean q",
            "q/|p|",
            "slide end",
            "slide run",
            "% slipping",
            "% slip t>0.5",
            "strain def.",
            "mean εv",
            "max |εv|",
        ],
        rows,
        [
            None,
            None,
            "{:.1f}",
            "{:.1f}",
            "{:.1f}",
            "{:.2f}",
            "{:.3f}",
            "{:.4f}",
            "{:.1f}",
            "{:.1f}",
            None,
            "{:+.2e}",
            "{:.2e}",
        ],
    )
    # compare the ring with pier blocks at the same height band
    ymid = h["block_q"][0, :, 1]
    hi = ymid > pier_top - 1.0
    for g in ("left pier", "right pier"):
        m = (grp[:n] == g) & hi
        if m.any():
            print(
                f"{g} blocks in the top metre (y > {pier_top - 1:.1f} m): mean p = {p[ie, m].mean() / 1e3:.1f} kPa, "
                f"mean q = {q[ie, m].mean() / 1e3:.1f} kPa"
            )
    k = np.argsort(p[ie])[:5]
    print("Five most compressed cells: " + ", ".join(f"{names[i]} ({p[ie, i] / 1e3:.0f} kPa)" for i in k))
    k = np.argsort(-np.nan_to_num(np.abs(evol), nan=-1))[:5]
    print(
        "Five largest |volumetric cumulated strain|: "
        + ", ".join(f"{names[i]} ({evol[i]:+.1e})" for i in k if defined[i])
    )
    print(
        f"Cells with a defined strain (in a centroid triangle): {defined.sum()} of {n}; without: "
        + (", ".join(names[:n][~defined]) if (~defined).sum() <= 40 else f"{(~defined).sum()} blocks")
    )
    print(colour_ranges(run, ie))
    k = np.argsort(-np.nan_to_num(np.abs(evr[ie]), nan=-1))[:5]
    print(
        "Five largest |volumetric strain rate| at the end: "
        + ", ".join(f"{names[i]} ({evr[ie, i]:+.1e} 1/s)" for i in k if defined[i])
        + "\n"
    )
    # the piers' volumetric strain, course by course (the paper: "a great part of the left pile is under the
    # highest level of a volume strain")
    pc = np.array([pier_course.get(i, 0) for i in range(n)])
    ev_all = h["cell_volumetric_strain"]
    rows = []
    for c in range(top_course, 0, -1):
        row = [c]
        for g in ("left pier", "right pier"):
            for b in ("b1", "b2"):
                i = next(i for i in pier if grp[i] == g and pc[i] == c and names[i].endswith(b))
                row += [1e5 * evol[i]]
        for g in ("left pier", "right pier"):
            m = (grp[:n] == g) & (pc == c)
            row += [1e5 * evr[ie, m].mean()]
        rows.append(row)
    print(
        "Pier cells at the end, course by course (c01 = bottom; b1 = the block at the pier's left): cumulated "
        "volumetric strain εv (×1e-5) and the course's mean volumetric strain rate (×1e-5 1/s).\n"
    )
    table(
        ["course", "left b1 εv", "left b2 εv", "right b1 εv", "right b2 εv", "left ε̇v", "right ε̇v"],
        rows,
        [None] + ["{:+.1f}"] * 6,
    )
    rows = []
    for g in ("left pier", "right pier"):
        m = grp[:n] == g
        js = np.array([j for j in range(len(jb)) if grp[jb[j, 0]] == g and grp[jb[j, 1]] == g])
        pos = evr[1:, m] > 0
        mean_ev = np.nanmean(ev_all[:, m], axis=1)
        rows.append(
            [
                g,
                *(1e5 * mean_ev[run.at(t)] for t in marks),
                1e5 * mean_ev.min(),
                1e5 * mean_ev.max(),
                1e5 * np.nanmax(np.abs(evol[m])),
                100 * pos.mean(),
                1e3 * op[ie, js].max(),
                1e3 * op[ie, js].min(),
            ]
        )
    print(
        "Piers: mean εv (×1e-5) over time and its range over every frame, largest |εv| at the end (×1e-5), "
        "share of (block, frame) with ε̇v > 0, and the widest opening / deepest interpenetration of the joints "
        "inside the pier at the end (geometric, mm) — the scale of the relative motions behind these strains.\n"
    )
    table(
        ["pier", *(f"εv {t:g} s" for t in marks), "min", "max", "max |εv|", "% ε̇v>0", "open mm", "penetr. mm"],
        rows,
        [None] + ["{:+.1f}"] * (len(marks) + 2) + ["{:.1f}", "{:.0f}", "{:.3f}", "{:+.3f}"],
    )
    ranks = np.argsort(-np.nan_to_num(np.abs(evol), nan=-1))
    for k in (10, 20):
        top = ranks[:k]
        print(
            f"Of the {k} largest |εv| at the end: "
            + ", ".join(
                f"{(grp[top] == g).sum()} {g}"
                for g in ("ring", "left pier", "right pier", "spandrel")
                if (grp[top] == g).any()
            )
        )
    print()
    s = h["energy_dissipated"][-1], h["support_work"][-1]
    dE = (h["energy_kinetic"][-1] + h["energy_potential"][-1]) - (h["energy_kinetic"][0] + h["energy_potential"][0])
    print(
        f"Energy: support work {s[1]:.0f} J, dissipated {s[0]:.1f} J, Δ(kinetic+potential) {dE:.0f} J "
        f"(balance error {dE - (s[1] - s[0]):.1f} J); kinetic energy max {h['energy_kinetic'].max():.2f} J "
        f"(t = {T[h['energy_kinetic'].argmax()]:.2f} s), at the end {h['energy_kinetic'][-1]:.2f} J\n"
    )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--wall", action="append", default=[], help="history of a wall run (repeatable)")
    ap.add_argument(
        "--static",
        action="append",
        default=[],
        help="history of the same wall at rest, in the order of --wall (optional)",
    )
    ap.add_argument("--arch", action="append", default=[], help="history of an arch run")
    ap.add_argument("--aqueduct", action="append", default=[], help="history of an aqueduct run")
    args = ap.parse_args(argv)
    np.seterr(invalid="ignore", divide="ignore")  # NaN strains (blocks in no triangle) are expected
    np.set_printoptions(linewidth=160)
    for i, w in enumerate(args.wall):
        wall(w, args.static[i] if i < len(args.static) else None)
    for a in args.arch:
        arch(a, "arch")
    for a in args.aqueduct:
        arch(a, "aqueduct")


if __name__ == "__main__":
    main()
