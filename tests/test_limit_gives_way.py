"""What gives way when a structure cannot carry its own weight: the "no equilibrium" line names one mechanism
(its hinges, sliding and opening joints) and its blocks as the few rigid parts that move, against the
four-hinge enumeration (tests/four_hinge_reference.py ``least_opening_mechanism``: no LP).

The Farkas mechanism is chosen as the one that opens its joints least for the work the dead load does (the
LP's Σ of cone-edge powers is twice the joints' opening); the reference enumerates every admissible four-hinge
mechanism of the ring with the same criterion, so both name the same four hinges. The old line maximised the
dead load's work over a box of velocities: every block at a corner of the box, a sum of mechanisms (the
bridge on slender piers: 100 of 100 blocks, 15 hinges and 10 sliding joints)."""

from __future__ import annotations

import re

import numpy as np
import pytest
from four_hinge_reference import least_opening_mechanism
from shapely.geometry import Polygon, box
from test_limit_ring_mechanisms import voussoir_loads

from masonrycli.limit import LiveLoad, analyse
from masonrycli.limit.problem import NoEquilibrium

from cli_helpers import invoke, words
from limit_helpers import scenario

VOUSSOIRS = 24


def uneven_semicircle(thickness: float):
    """A semicircle (intrados radius 1) of voussoirs of growing angle, left to right (no mirror twin to tie
    with), on two springers at y = 0; its joint points, left to right."""
    phi = np.pi * (1 - (np.arange(VOUSSOIRS + 1) / VOUSSOIRS) ** 1.2)
    unit = np.stack([np.cos(phi), np.sin(phi)], axis=1)
    return unit, unit * (1 + thickness)


def uneven_scenario(thickness: float):
    i, e = uneven_semicircle(thickness)
    blocks = [(f"v{k:02d}", Polygon([i[k], i[k + 1], e[k + 1], e[k]])) for k in range(VOUSSOIRS)]
    springers = [("left", box(-1.3 - thickness, -0.5, -0.7, 0.0)), ("right", box(0.7, -0.5, 1.3 + thickness, 0.0))]
    return scenario(blocks, springers, friction=10.0, name="uneven")


def joint_name(k: int) -> str:
    pair = (
        ("left", "v00")
        if k == 0
        else ("right", f"v{VOUSSOIRS - 1:02d}")
        if k == VOUSSOIRS
        else (f"v{k - 1:02d}", f"v{k:02d}")
    )
    return "|".join(sorted(pair))


@pytest.mark.parametrize("thickness", [0.06, 0.09])
def test_a_ring_too_thin_to_stand_gives_way_on_the_references_four_hinges_as_three_parts(thickness):
    i, e = uneven_semicircle(thickness)
    centroid, area = voussoir_loads(i, e)
    _, (hinged, _) = least_opening_mechanism(i, e, centroid, np.stack([0 * area, -area], axis=1))
    with pytest.raises(NoEquilibrium) as caught:
        analyse(uneven_scenario(thickness), LiveLoad())
    said = str(caught.value)
    found = re.search(r"— hinges ([^;]*)$", said)
    assert found and "sliding" not in said and "opening" not in said, said
    names = {"|".join(sorted(n.split("|"))) for n in found.group(1).split(", ")}
    assert names == {joint_name(k) for k in hinged}, said
    a, b, c, d = hinged
    moving = d - a  # the voussoirs between the outer hinges
    assert f"under its own weight {moving} of {VOUSSOIRS} blocks give way, as 3 rigid parts (" in said, said
    sizes = sorted(int(n) for n in re.findall(r"(\d+) blocks[;)]", said))
    assert sizes == sorted([b - a, c - b, d - c]), said


def test_the_bridge_on_slender_piers_gives_way_as_its_pier_and_two_halves_of_its_ring():
    """`masonry limit arch --span 8 --rise 2 --ring-thickness 0.5` (the builder's piers, 0.90 m wide): the left
    pier tips about its outer toe with its skewback (its inner column's bed opening), the ring hinges at its
    springings and the crown. It said 100 of 100 blocks, 15 hinges and 10 sliding joints."""
    result = invoke("limit", "arch", "--span", "8", "--rise", "2", "--ring-thickness", "0.5")
    said = words(result.output)
    assert result.exit_code == 2 and "Traceback" not in said
    assert (
        "65 of 100 blocks give way, as 3 rigid parts (left-pier-c01-b1 … left-skewback, 35 blocks; v01 … v15, 15 blocks; v16 … v30, 15 blocks)"
        in said
    ), said
    hinges = said.split("— hinges ")[1].split(";")[0].split(", ")
    assert sorted(hinges) == ["left-pier-c01-b1|left-foundation", "left-skewback|v01", "v15|v16", "v30|right-skewback"]
    assert said.endswith("opening left-pier-c01-b2|left-foundation"), said


def _stack():
    """Two blocks 1 m × 1 m stacked on a ground (base: block 0, y 0 … 1; top: block 1, y 1 … 2), μ = 0.6."""
    from masonrycli.limit.joints import find_joints
    from masonrycli.model import build_model

    sc = scenario([("base", box(0, 0, 1, 1)), ("top", box(0, 1, 1, 2))], [("ground", box(-1, -1, 2, 0))], 0.6)
    model = build_model(sc)
    return model, find_joints(model)


def _about(model, point, omega, blocks):
    """Block velocities (vx, vy, ω) of ``blocks`` turning ω about ``point`` (the others still)."""
    u = np.zeros((model.block_count, 3))
    for k in blocks:
        r = model.body_q0[k, :2] - np.asarray(point)
        u[k] = (-omega * r[1], omega * r[0], omega)
    return u


def test_a_joint_turning_about_an_end_in_contact_is_a_hinge_one_parting_all_along_is_opening():
    """Kinematics by hand. The whole stack tipping about the base's right toe (1, 0): the base's bed is a hinge
    (that end stays shut), the bed between the blocks does not move, one rigid part. The top block alone
    turning about (1.5, 1), off its bed: both ends of the bed part (at 0.75 and 0.25 for ω = −0.5), so it is no
    hinge but opening (it was listed as a hinge, as a wall's wedge turning on one pivot listed 10)."""
    from masonrycli.limit.kinematics import joint_motion, rigid_parts

    model, joints = _stack()
    by_pair = {tuple(sorted(p)): k for k, p in enumerate(joints.joint_body.tolist())}
    bed, between = by_pair[(0, 2)], by_pair[(0, 1)]
    tipping = joint_motion(model, joints, _about(model, (1.0, 0.0), -0.5, (0, 1)))
    assert tipping.joint_hinged.tolist() == [k == bed for k in range(joints.joint_count)]
    assert not tipping.joint_opening.any() and not tipping.joint_sliding.any()
    np.testing.assert_allclose(tipping.hinge_point, [[1.0, 0.0]], atol=1e-12)
    assert [p.tolist() for p in rigid_parts(model, joints, tipping)] == [[0, 1]]
    parting = joint_motion(model, joints, _about(model, (1.5, 1.0), -0.5, (1,)))
    assert not parting.joint_hinged.any() and parting.joint_opening.tolist() == [k == between for k in range(2)]
    np.testing.assert_allclose(sorted(parting.contact_opening[joints.contact_joint == between]), [0.25, 0.75])


def test_an_end_sliding_with_the_flow_rules_dilation_stays_in_contact():
    """The top block turning about its bed's right end while that end slides at s and opens at μ s (the
    associative flow rule's dilation, the LP's sliding): a hinge that slides, not an opening joint."""
    from masonrycli.limit.kinematics import joint_motion

    model, joints = _stack()
    u = _about(model, (1.0, 1.0), 0.2, (1,))
    u[1, :2] += (0.1, 0.6 * 0.1)  # slide +x at 0.1 and lift μ · 0.1
    motion = joint_motion(model, joints, u)
    between = [sorted(p) for p in joints.joint_body.tolist()].index([0, 1])
    assert motion.joint_hinged[between] and motion.joint_sliding[between] and not motion.joint_opening[between]


def test_the_recordings_panel_names_the_opening_joints_and_rigid_parts_as_the_table():
    """The aqueduct's mechanism has 3 joints opening (no end in contact, 234b679): the table and --json listed
    them, the recording's side panel did not (they were among its hinges before), nor the rigid parts."""
    from masonrycli.limit.command import resolve_structure
    from masonrycli.limit.drawing import mechanism_document

    result = analyse(resolve_structure("aqueduct", None, {}), LiveLoad("horizontal"))
    opening = result.opening_largest_first()
    assert opening, "the aqueduct's mechanism has joints opening"
    said = mechanism_document(result)
    assert f"joints opening ({len(opening)}, the fastest first): {', '.join(opening)}" in said, said
    table = words(invoke("limit", "aqueduct").output.replace("│", " "))
    moving = re.search(r"blocks in the mechanism (\d+ of \d+, as \d+ rigid parts \([^)]*\))", table).group(1)
    assert f"blocks in the mechanism: {moving}" in said, said
