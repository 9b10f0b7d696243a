"""Joint-for-joint comparison of two runs of one block structure (pure numpy; used by lmgc90_arch.py).

A run is a JSON document (``lmgc90_arch.py run``): the bodies' initial poses ``q0`` and, per snapshot, the
poses ``q`` and every contact's bodies, in-plane point and normal force. :func:`compare` reduces both runs
to the measures of ``arch_joints`` over the joints of the initial polygons (``face_joints``), at each
snapshot, and :func:`report` prints them as Markdown.

Joint groups (:func:`joint_groups`, by the bodies' names as the builders give them):

* ``ring``: a voussoir (``v01``…) against a voussoir or a pier (the arch's 31 radial joints);
* ``extrados``: a voussoir against a spandrel wall block (``wall-…``), along the extrados chords;
* ``spandrel``: a wall block against a wall block or a pier;
* ``piers``: pier against pier or foundation.

The ends of a joint are named (:func:`end_names`) "intrados" / "extrados" on a radial joint of the ring,
"inner" / "outer" on a bed joint of the piers (nearer x = 0 or not), "left" / "right" on any other joint
whose normal is nearer vertical, "lower" / "upper" on the rest (head joints).

A joint **slides** when, at one of its *closed* ends (opening ≤ ``OPENING``), the end's two material
points have moved along the face by more than ``OPENING`` relative to each other (``end_openings``'
slip). An open end's tangential offset is not a slide: a block rocking on one corner lifts the other
ends of its joints along their faces.
"""

from __future__ import annotations

import math

import numpy as np

from benchmarks.arch_joints import OPENING, diff_stats, end_openings, face_joints, joint_resultants, joint_states

GROUPS = ("ring", "extrados", "spandrel", "piers")
LOADED = 1000.0
"""N: the force ratios over all joints take the joints carrying at least this in both runs (a full
spandrel block weighs 1472 N); lighter ones are near opening and their ratios mean little."""
NEAR = 5e-4
"""m: a joint in different states whose ends' openings differ by less than this in the two runs is a
disagreement at the threshold (both near 0.1 mm), counted apart."""


def _kind(name: str) -> str:
    if name.startswith("wall"):
        return "wall"
    return "voussoir" if name.startswith("v") else "pier"  # piers and foundations


def joint_groups(names, joints) -> dict[str, np.ndarray]:
    """{group: (J,) bool} over ``joints`` (see the module doc); every joint is in exactly one group."""
    kinds = [tuple(sorted((_kind(names[a]), _kind(names[b])))) for a, b in joints.body]
    ring = np.array([k in (("pier", "voussoir"), ("voussoir", "voussoir")) for k in kinds], dtype=bool)
    extrados = np.array([k == ("voussoir", "wall") for k in kinds], dtype=bool)
    spandrel = np.array([k in (("wall", "wall"), ("pier", "wall")) for k in kinds], dtype=bool)
    piers = np.array([k == ("pier", "pier") for k in kinds], dtype=bool)
    return {"ring": ring, "extrados": extrados, "spandrel": spandrel, "piers": piers}


def end_names(names, polys, joints) -> list[tuple[str, str]]:
    """What each joint end is (see the module doc)."""
    kind = [_kind(nm) for nm in names]
    springing = max(p[:, 1].max() for p, nm in zip(polys, names) if "pier" in nm)
    radii = [np.hypot(p[:, 0], p[:, 1] - springing) for p, k in zip(polys, kind) if k == "voussoir"]
    r_mid = 0.5 * (min(r.min() for r in radii) + max(r.max() for r in radii)) if radii else 0.0
    out = []
    for (a, b), ends, n in zip(joints.body, joints.end, joints.normal):
        pair = {kind[a], kind[b]}
        if "voussoir" in pair and "wall" not in pair:  # radial: one end at the intrados, one at the extrados
            key, words = np.hypot(ends[:, 0], ends[:, 1] - springing) > r_mid, ("intrados", "extrados")
        elif abs(n[1]) > abs(n[0]) and "wall" not in pair and "voussoir" not in pair:
            key, words = np.abs(ends[:, 0]) > np.abs(ends[:, 0]).min(), ("inner", "outer")
        elif abs(n[1]) > abs(n[0]):
            key, words = ends[:, 0] > ends[:, 0].min(), ("left", "right")
        else:
            key, words = ends[:, 1] > ends[:, 1].min(), ("lower", "upper")
        out.append(tuple(words[int(k)] for k in key))
    return out


def state_label(state: int, ends) -> str:
    """A joint's state (arch_joints.joint_states) in words: a hinge is named by the end it turns about."""
    return ("closed", f"hinge@{ends[0]}", f"hinge@{ends[1]}", "open")[state]


def _stats(x, y) -> dict:
    """diff_stats, or {} over no element (a structure without a ring, no joint loaded in both runs)."""
    return diff_stats(x, y) if len(x) else {}


def _ratio_stats(fa, fb, mask) -> dict:
    return _stats(fa[mask] / fb[mask], np.ones(int(mask.sum())))


def compare(a: dict, b: dict, names, polys, n: int) -> dict:
    """Joint-for-joint comparison of two ``run`` documents (``a`` the reference) over every joint of the
    initial ``polys`` (bodies ``names``, the first ``n`` of them blocks). Returns a JSON-able dict;
    :func:`report` formats it. The keys before ``groups`` are those of the arch's first comparison."""
    joints = face_joints(polys)
    ends = end_names(names, polys, joints)
    groups = joint_groups(names, joints)
    ring = groups["ring"]
    label = [f"{names[i]}|{names[j]}" for i, j in joints.body]
    q0a, q0b = np.array(a["q0"]), np.array(b["q0"])  # each code's own initial poses
    out = {
        "joints": len(label),
        "ring_joints": int(ring.sum()),
        "n_blocks": n,
        "times": [],
        "q0_diff_m": diff_stats(q0a[:, :2], q0b[:, :2]),
        "opening_threshold_m": OPENING,
        "groups": {g: int(m.sum()) for g, m in groups.items()},
    }
    for sa, sb in zip(a["snapshots"], b["snapshots"]):
        assert sa["step"] == sb["step"], "the two runs' snapshots are not at the same steps"
        rows = {}
        for key, s, q0 in (("a", sa, q0a), ("b", sb, q0b)):
            q = np.array(s["q"])
            opening, slip, rel = end_openings(joints, q0, q)
            total, ecc = joint_resultants(joints, s["contact_body"], s["contact_point"], s["contact_fn"], q0, q)
            slip = np.where(opening <= OPENING, np.abs(slip), 0.0).max(axis=1)  # at closed ends only
            rows[key] = dict(q=q, opening=opening, rel=rel, state=joint_states(opening), fn=total, ecc=ecc, slip=slip)
        ra, rb = rows["a"], rows["b"]
        da, db = ra["q"][:n, :2] - q0a[:n, :2], rb["q"][:n, :2] - q0b[:n, :2]
        same = ra["state"] == rb["state"]
        word = lambda r, j: state_label(int(r["state"][j]), ends[j])  # noqa: E731
        loaded = ring & (ra["fn"] > 0) & (rb["fn"] > 0)
        both = (ra["fn"] > 0) & (rb["fn"] > 0)
        heavy = (ra["fn"] >= LOADED) & (rb["fn"] >= LOADED)
        gap = np.abs(ra["opening"] - rb["opening"]).max(axis=1)  # largest end-opening difference
        sliding = [ra["slip"] > OPENING, rb["slip"] > OPENING]
        out["times"].append(
            {
                "t": sa["t"],
                "displacement_diff_m": diff_stats(da, db),
                "displacement_max_m": [float(np.hypot(*da.T).max()), float(np.hypot(*db.T).max())],
                "rotation_diff_rad": diff_stats(ra["q"][:n, 2] - q0a[:n, 2], rb["q"][:n, 2] - q0b[:n, 2]),
                "ring_max_opening_diff_m": _stats(ra["opening"][ring].max(axis=1), rb["opening"][ring].max(axis=1)),
                "ring_rel_rotation_diff_rad": _stats(ra["rel"][ring], rb["rel"][ring]),
                "states_agree": int(same.sum()),
                "ring_states_agree": int(same[ring].sum()),
                "hinges": [[f"{label[j]} {word(r, j)}" for j in np.flatnonzero(r["state"])] for r in (ra, rb)],
                "disagree": [
                    f"{label[j]}: {word(ra, j)} (openings {1e3 * ra['opening'][j, 0]:.3f}, "
                    f"{1e3 * ra['opening'][j, 1]:.3f} mm) vs {word(rb, j)} ({1e3 * rb['opening'][j, 0]:.3f}, "
                    f"{1e3 * rb['opening'][j, 1]:.3f} mm)"
                    for j in np.flatnonzero(~same)
                ],
                "ring_fn_total_N": [float(ra["fn"][ring].sum()), float(rb["fn"][ring].sum())],
                "ring_fn_ratio_minus_1": _ratio_stats(ra["fn"], rb["fn"], loaded),
                "ring_ecc_diff_m": _stats(ra["ecc"][loaded], rb["ecc"][loaded]),
                "per_ring_joint": [
                    {
                        "joint": label[j],
                        "ends": ends[j],
                        "state": [word(r, j) for r in (ra, rb)],
                        "opening_mm": [[round(1e3 * x, 4) for x in r["opening"][j]] for r in (ra, rb)],
                        "rel_rotation_mrad": [round(1e3 * float(r["rel"][j]), 4) for r in (ra, rb)],
                        "fn_N": [round(float(r["fn"][j]), 1) for r in (ra, rb)],
                        "ecc_mm": [
                            None if math.isnan(r["ecc"][j]) else round(1e3 * float(r["ecc"][j]), 2) for r in (ra, rb)
                        ],
                    }
                    for j in np.flatnonzero(ring)
                ],
                # beyond the arch's first comparison: per group, all joints' forces, sliding
                "group_states_agree": {g: int(same[m].sum()) for g, m in groups.items()},
                "group_hinged": {g: [int((r["state"][m] > 0).sum()) for r in (ra, rb)] for g, m in groups.items()},
                "disagree_near": int(np.sum(~same & (gap < NEAR))),
                "disagree_opening_diff_m": _stats(gap[~same], np.zeros(int((~same).sum()))),
                "fn_ratio_minus_1": _ratio_stats(ra["fn"], rb["fn"], heavy),
                "fn_heavy_joints": int(heavy.sum()),
                "fn_diff_N": _stats(ra["fn"][both], rb["fn"][both]),
                "fn_median_N": [float(np.median(r["fn"][both])) if both.any() else 0.0 for r in (ra, rb)],
                "ecc_diff_m": _stats(ra["ecc"][both], rb["ecc"][both]),
                "max_slip_m": [float(r["slip"].max()) for r in (ra, rb)],
                "max_slip_joint": [label[int(r["slip"].argmax())] for r in (ra, rb)],
                "slip_diff_m": diff_stats(ra["slip"], rb["slip"]),
                "sliding": [
                    [f"{label[j]} {1e3 * r['slip'][j]:.3f} mm ({word(r, j)})" for j in np.flatnonzero(s)]
                    for r, s in zip((ra, rb), sliding)
                ],
                "sliding_agree": int((sliding[0] == sliding[1]).sum()),
                "group_sliding": {  # LMGC90 / ours / both
                    g: [
                        int((sliding[0] & m).sum()),
                        int((sliding[1] & m).sum()),
                        int((sliding[0] & sliding[1] & m).sum()),
                    ]
                    for g, m in groups.items()
                },
                "slip_ratio_minus_1_both": _stats(
                    ra["slip"][sliding[0] & sliding[1]] / rb["slip"][sliding[0] & sliding[1]],
                    np.ones(int((sliding[0] & sliding[1]).sum())),
                ),
            }
        )
    return out


def report(cmp: dict, names=("LMGC90", "ours")) -> str:
    """Markdown summary of :func:`compare`: one row per time, per group and sliding table when the
    comparison has them, then the hinges and the disagreements."""
    a, b = names
    lines = [
        f"| t (s) | joints in the same state, ring (of {cmp['ring_joints']}) / all (of {cmp['joints']}) | "
        f"hinges {a} / {b} | block displacement \\|diff\\| median / RMS / max (mm) | largest block displacement "
        f"{a} / {b} (mm) | ring joints' max opening \\|diff\\| median / max (mm) | ring joints' Fn / "
        f"{b}'s − 1, median / max \\|·\\| | eccentricity \\|diff\\| median / max (mm) |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    nan = {"median": math.nan, "rms": math.nan, "max": math.nan}
    for r in cmp["times"]:
        d, o, f, e = (
            r["displacement_diff_m"],
            r["ring_max_opening_diff_m"] or nan,
            r["ring_fn_ratio_minus_1"] or nan,
            r["ring_ecc_diff_m"] or nan,
        )
        lines.append(
            f"| {r['t']:g} | {r['ring_states_agree']} / {r['states_agree']} | "
            f"{len(r['hinges'][0])} / {len(r['hinges'][1])} | "
            f"{1e3 * d['median']:.3f} / {1e3 * d['rms']:.3f} / {1e3 * d['max']:.3f} | "
            f"{1e3 * r['displacement_max_m'][0]:.2f} / {1e3 * r['displacement_max_m'][1]:.2f} | "
            f"{1e3 * o['median']:.4f} / {1e3 * o['max']:.4f} | {f['median']:.4f} / {f['max']:.4f} | "
            f"{1e3 * e['median']:.1f} / {1e3 * e['max']:.1f} |"
        )
    if "groups" in cmp:
        groups = [g for g in GROUPS if cmp["groups"][g]]
        lines += [
            "",
            "| t (s) | "
            + " | ".join(f"{g}: same state (of {cmp['groups'][g]}); hinged/open {a} / {b}" for g in groups)
            + " | in another state: of them within 0.5 mm in opening"
            + f" | all loaded joints: Fn \\|diff\\| median / max (N; median Fn {a})"
            + f" | Fn / {b}'s − 1 (≥ 1 kN), median / max"
            f" | eccentricity \\|diff\\| median / max (mm) | largest slip {a} / {b} (mm) | sliding joints {a} / {b}"
            " (> 0.1 mm) |",
            "| --- | " + " | ".join("---" for _ in groups) + " | --- | --- | --- | --- | --- | --- |",
        ]
        for r in cmp["times"]:
            fd, fr, ed = r["fn_diff_N"] or nan, r["fn_ratio_minus_1"] or nan, r["ecc_diff_m"] or nan
            cells = [
                f"{r['group_states_agree'][g]}; {r['group_hinged'][g][0]} / {r['group_hinged'][g][1]}" for g in groups
            ]
            lines.append(
                f"| {r['t']:g} | "
                + " | ".join(cells)
                + f" | {len(r['disagree'])}: {r['disagree_near']}"
                + f" | {fd['median']:.0f} / {fd['max']:.0f} ({r['fn_median_N'][0]:.0f}) | "
                f"{fr['median']:.4f} / {fr['max']:.3f} | {1e3 * ed['median']:.1f} / {1e3 * ed['max']:.1f} | "
                f"{1e3 * r['max_slip_m'][0]:.3f} / {1e3 * r['max_slip_m'][1]:.3f} | "
                f"{len(r['sliding'][0])} / {len(r['sliding'][1])} |"
            )
    for r in cmp["times"]:
        lines.append(f"\nt = {r['t']:g} s: {a} hinges: {', '.join(r['hinges'][0]) or '-'}")
        lines.append(f"t = {r['t']:g} s: {b} hinges: {', '.join(r['hinges'][1]) or '-'}")
        lines += [f"  differs: {line}" for line in r["disagree"]]
        for who, slid in zip((a, b), r.get("sliding", ())):
            if slid:
                lines.append(f"t = {r['t']:g} s: {who} sliding: {', '.join(slid)}")
    return "\n".join(lines)
