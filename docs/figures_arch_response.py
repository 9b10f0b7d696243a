"""docs/scenario_figures.py --arch / --aqueduct, continued: sliding by joint kind, displacements and
rotations, stress and sliding by group, the piers' volumetric strain and the energy balance."""

from __future__ import annotations

import numpy as np

# sibling modules of docs/scenario_figures.py: its folder is first on sys.path when it runs as a script
from figures_history import (
    colour_ranges,
    table,
)


def arch_response(run, T, grp, h, ie, jb, marks, n, names, op, pier_top, slip) -> None:
    """The second half of figures_arch.arch: the state of run at the end (frame ie) and over time."""
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
