"""docs/scenario_figures.py --wall: the figures quoted in docs/scenarios.md for the shaken walls."""

from __future__ import annotations

import re

import numpy as np

# sibling modules of docs/scenario_figures.py: its folder is first on sys.path when it runs as a script
from figures_history import (
    RHO,
    G,
    colour_ranges,
    detector_vs_geometry,
    joint_faces,
    joint_openings,
    load,
    opening_crosscheck,
    single_point_contacts,
    table,
)


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
            f"Ground at rest ({static}), t = {hs['time'][last]:.3f} s (NLGS residual "
            f"{hs['nlgs_residual'][last]:.2g} m/s):\n"
        )
        table(hdr, syy_rows(hs, last), fmt)
