"""docs/scenario_figures.py --arch / --aqueduct: hinges, supports and solver figures; the displacements,
stresses, strains and energy at the end follow in figures_arch_response.py."""

from __future__ import annotations

import numpy as np
from figures_arch_response import arch_response

# sibling modules of docs/scenario_figures.py: its folder is first on sys.path when it runs as a script
from figures_history import (
    detector_vs_geometry,
    joint_faces,
    joint_label,
    joint_openings,
    load,
    opening_crosscheck,
    single_point_contacts,
    table,
)


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
        f"NLGS: mean {it.mean():.0f} sweeps per recorded step (max {it.max()}), "
        f"{int(h['nlgs_unconverged'][-1])} unconverged steps in the run, "
        f"residual max {h['nlgs_residual'][1:].max():.2e} m/s\n"
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

    arch_response(run, T, grp, h, ie, jb, marks, n, names, op, pier_top, slip)
