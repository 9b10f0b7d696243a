"""benchmarks/joints_compare.py, the joint-for-joint comparison of two runs (no LMGC90 needed): joint
groups and end names on the built arch and aqueduct, and compare() on hand-made runs with exact motions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from benchmarks.arch_joints import face_joints
from benchmarks.joints_compare import compare, end_names, joint_groups, report
from geometry_library.builders import build_aqueduct, build_arch

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def _bodies(assembly):
    bodies = [*assembly.blocks, *assembly.supports]
    return [b.name for b in bodies], [np.asarray(b.vertices) for b in bodies]


@pytest.fixture(scope="module")
def aqueduct():
    names, polys = _bodies(build_aqueduct())
    return names, polys, face_joints(polys)


def test_aqueduct_joint_groups_partition_its_joints_and_keep_the_arch_ring(aqueduct):
    names, polys, joints = aqueduct
    groups = joint_groups(names, joints)
    assert sum(m.astype(int) for m in groups.values()).tolist() == [1] * len(joints.body)
    ring = [tuple(sorted((names[a], names[b]))) for a, b in joints.body[groups["ring"]]]
    # the 29 voussoir-voussoir joints and the two springings, as in the arch alone
    assert len(ring) == 31 and ("left-pier-c17-b2", "v01") in ring and ("right-pier-c17-b1", "v30") in ring
    # every voussoir carries spandrel blocks on its extrados chord; a wall block touches no intrados
    extrados = joints.body[groups["extrados"]]
    voussoirs = {names[i] for pair in extrados for i in pair if names[i].startswith("v")}
    assert voussoirs == {f"v{k:02d}" for k in range(1, 31)}
    a_names, a_polys = _bodies(build_arch())
    a_joints = face_joints(a_polys)
    a_groups = joint_groups(a_names, a_joints)
    assert int(a_groups["ring"].sum()) == 31 and int(a_groups["piers"].sum()) == len(a_joints.body) - 31
    assert int(groups["piers"].sum()) == len(a_joints.body) - 31  # the same piers, untouched by the wall


def test_end_names_of_the_aqueduct_follow_each_joints_geometry(aqueduct):
    names, polys, joints = aqueduct
    ends = end_names(names, polys, joints)
    springing = 3.4
    for (a, b), pair, e, n in zip(joints.body, ends, joints.end, joints.normal):
        kinds = {names[a][0], names[b][0]}
        if kinds <= {"v", "l", "r"} and "v" in kinds:  # radial joint of the ring
            r = np.hypot(e[:, 0], e[:, 1] - springing)
            assert pair == (("intrados", "extrados") if r[0] < r[1] else ("extrados", "intrados"))
        elif "w" in kinds and abs(n[1]) > abs(n[0]):
            assert pair == (("left", "right") if e[0, 0] < e[1, 0] else ("right", "left"))
        elif "w" in kinds:
            assert pair == (("lower", "upper") if e[0, 1] < e[1, 1] else ("upper", "lower"))
    # the crown's spandrel joint is a nearly horizontal chord: left / right
    crown = [k for k, (a, b) in enumerate(joints.body) if {names[a], names[b]} & {"v15", "v16"}]
    assert any(set(ends[k]) == {"left", "right"} for k in crown)


def _run(q0, q, contacts):
    body, point, fn = zip(*contacts) if contacts else ((), (), ())
    snap = {"step": 1, "t": 0.001, "q": q.tolist(), "contact_body": list(body), "contact_point": list(point)}
    return {"q0": q0.tolist(), "snapshots": [{**snap, "contact_fn": list(fn)}]}


def test_compare_tells_a_hinge_from_a_slide_with_the_exact_amounts():
    # a pier block on a foundation, a wall block on it, a second wall block beside that one (not on the pier)
    names = ["left-pier-c01-b1", "wall-c01-b01", "wall-c01-b02", "left-foundation"]
    polys = [SQUARE + (0.0, 1.0), SQUARE + (0.0, 2.0), SQUARE + (1.0, 2.0), SQUARE]
    q0 = np.array([[0.5, 1.5, 0.0], [0.5, 2.5, 0.0], [1.5, 2.5, 0.0], [0.5, 0.5, 0.0]])
    phi, slide = 0.002, 3e-4
    # run a: wall-c01-b01 rocks counter-clockwise about its bottom left corner (0, 2): its bed joint hinges
    # about its left end, its head joint opens at the top by cos φ + sin φ − 1 and its closed bottom end is
    # dragged up the neighbour's face by sin φ (a slide)
    hinged = q0.copy()
    c, s = math.cos(phi), math.sin(phi)
    hinged[1] = [c * 0.5 - s * 0.5, 2.0 + s * 0.5 + c * 0.5, phi]
    # run b: it slides 0.3 mm to the left along its bed joint, away from its neighbour
    slid = q0.copy()
    slid[1, 0] -= slide
    a = _run(q0, hinged, [[[0, 1], [1.0, 2.0], 1000.0], [[0, 3], [0.5, 1.0], 500.0]])
    b = _run(q0, slid, [[[1, 0], [0.0, 2.0], 600.0], [[0, 1], [1.0, 2.0], 1000.0], [[3, 0], [0.5, 1.0], 500.0]])
    cmp = compare(a, b, names, polys, 3)
    assert cmp["joints"] == 3 and cmp["groups"] == {"ring": 0, "extrados": 0, "spandrel": 2, "piers": 1}
    (r,) = cmp["times"]
    bed, head = "left-pier-c01-b1|wall-c01-b01", "wall-c01-b01|wall-c01-b02"
    assert r["hinges"] == [[f"{bed} hinge@left", f"{head} hinge@lower"], [f"{head} open"]]
    assert r["states_agree"] == 1 and r["group_states_agree"] == {"ring": 0, "extrados": 0, "spandrel": 0, "piers": 1}
    assert r["group_hinged"]["spandrel"] == [2, 1]
    assert r["sliding"] == [[f"{head} 2.000 mm (hinge@lower)"], [f"{bed} 0.300 mm (closed)"]]
    assert r["max_slip_m"] == pytest.approx([s, slide], rel=1e-9) and r["max_slip_joint"] == [head, bed]
    assert r["sliding_agree"] == 1
    assert r["group_sliding"] == {"ring": [0, 0, 0], "extrados": [0, 0, 0], "spandrel": [1, 1, 0], "piers": [0, 0, 0]}
    assert r["slip_ratio_minus_1_both"] == {}
    # forces: the pier's bed joint 500 N in both; the wall's bed joint 1000 N at its right end against
    # 1600 N (600 at the left end): centres of pressure 0.5 m and 0.125 m from the middle
    assert r["fn_diff_N"]["median"] == pytest.approx(300.0) and r["fn_diff_N"]["max"] == pytest.approx(600.0)
    assert r["fn_ratio_minus_1"]["max"] == pytest.approx(0.375)
    assert r["ecc_diff_m"]["max"] == pytest.approx(0.375) and r["ecc_diff_m"]["median"] == pytest.approx(0.1875)
    text = report(cmp)
    assert "spandrel: same state (of 2); hinged/open LMGC90 / ours" in text
    assert f"ours sliding: {bed} 0.300 mm (closed)" in text
