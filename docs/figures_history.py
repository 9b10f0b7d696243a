"""Shared by docs/scenario_figures.py: a run's history file, its joint faces and their geometric openings,
plain-text tables, and the cross-checks against the recorded joint states and colour ranges."""

from __future__ import annotations

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
    from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

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
    ``masonrycli.recording.colour_range.RangeTracker`` fed the frames from the first computed one on; the initial
    state (entry 0, t = 0) takes the range of the frame after it. The volumetric strain rate falls back
    on the chain strain rate."""
    from masonrycli.recording.colour_range import RangeTracker
    from masonrycli.recording.layout import CHAIN_KEY, FIELD_BY_KEY

    spec = FIELD_BY_KEY[key]
    v = h[key]
    if key == "cell_volumetric_strain_rate" and CHAIN_KEY in h:
        v = np.where(np.isnan(v), h[CHAIN_KEY], v)
    tracker = RangeTracker(spec.kind, spec.floor)
    ranges = [tracker.update(v[i]) for i in range(1, v.shape[0])]
    return ranges[:1] + ranges


def colour_ranges(run: Run, i: int) -> str:
    h = run.h
    parts = []
    for key, _ in RECORDED_FIELDS:
        r = recorded_ranges(h, key)[i]
        v = h[key][i]
        d = v[np.isfinite(v)]
        over = int(((d < r.lo) | (d > r.hi)).sum())
        span = r.span(d)  # the use rule's: the 1 % most extreme cells at each end left out
        parts.append(
            f"{key.removeprefix('cell_')} {r.lo:.3g} … {r.hi:.3g} ({over} of {d.size} defined cells beyond, "
            f"their bulk spans {100 * span:.0f} % of it at t = {h['time'][i]:.2f} s)"
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
