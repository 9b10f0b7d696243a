"""The limit-analysis LP against closed forms: a block on a tilting table, a column of blocks, point loads.

References (rigid blocks, no-tension joints, Coulomb friction μ):
* a block B wide and H high on a table tilted by ψ overturns about its downhill corner when
  tan ψ = B/H < μ, and slides when tan ψ = μ < B/H (statics of one block);
* a column of n such blocks under a horizontal body force λ·weight overturns as a whole about its toe at
  λ = B/(nH) (the n-block column is the most slender of its sub-columns) unless it slides first at λ = μ;
* a horizontal point force P at the centroid of the top block of that column: the top j blocks tip
  about their base joint when P (j − ½) H = j w B/2, i.e. P/w = jB/((2j − 1)H), least for j = n; the top
  block slides when P/w = μ.
Each within 0.5 % (the LP should in fact be exact to its tolerance).
"""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import Polygon, box

from masonrycli.errors import InputError
from masonrycli.limit import LimitError, LiveLoad, analyse
from masonrycli.limit.joints import find_joints
from masonrycli.limit.problem import equilibrium_matrix, load_vectors
from masonrycli.model import build_model

from limit_helpers import column, scenario

REL = 5e-3


@pytest.mark.parametrize(
    ("width", "height", "mu", "expected", "mode"),
    [(0.4, 0.8, 0.7, 0.5, "overturns"), (0.4, 0.8, 0.3, 0.3, "slides"), (0.6, 0.3, 1.5, 1.5, "slides")],
)
@pytest.mark.parametrize("direction", ["+x", "-x"])
def test_block_on_a_tilting_table(width, height, mu, expected, mode, direction):
    sc = column(1, width, height, mu)
    r = analyse(sc, LiveLoad("tilt", direction))
    assert r.load_factor == pytest.approx(expected, rel=REL)
    assert r.tilt_angle() == pytest.approx(np.degrees(np.arctan(expected)), rel=REL)
    if mode == "overturns":
        assert r.hinges == ["b0|ground"] and r.sliding_joints == []
        toe = width if direction == "+x" else 0.0
        np.testing.assert_allclose(r.motion.hinge_point, [[toe, 0.0]], atol=1e-9)
        # At collapse the whole weight and push pass through the toe: eccentricity ±1 on the joint.
        assert abs(r.thrust.joint_eccentricity[0]) == pytest.approx(1.0, abs=1e-6)
    else:
        assert r.sliding_joints == ["b0|ground"] and r.hinges == []
        vx = r.solution.block_velocity[0, 0]
        assert np.sign(vx) == (1 if direction == "+x" else -1)


@pytest.mark.parametrize(("mu", "expected"), [(0.6, 0.4 / (5 * 0.2)), (0.3, 0.3)])
def test_column_of_blocks_under_a_horizontal_body_force(mu, expected):
    r = analyse(column(5, 0.4, 0.2, mu), LiveLoad("horizontal"))
    assert r.load_factor == pytest.approx(expected, rel=REL)
    if mu > expected:
        assert "b0|ground" in r.hinges  # the whole column tips about its toe
        assert set(r.moving_blocks) == {f"b{k}" for k in range(5)}
    else:
        assert r.sliding_joints and not r.hinges


@pytest.mark.parametrize(("mu", "expected"), [(2.0, 5 * 0.4 / (9 * 0.2)), (0.5, 0.5)])
def test_column_under_a_point_load_on_its_top_block(mu, expected):
    sc = column(5, 0.4, 0.2, mu)
    r = analyse(sc, LiveLoad("point", "+x", block="b4"))
    assert r.load_factor == pytest.approx(expected, rel=REL)
    weight = 0.4 * 0.2 * 2000.0 * 9.81
    assert r.reference_force == pytest.approx(weight, rel=1e-12)
    assert r.summary()["collapse_load_N"] == pytest.approx(expected * weight, rel=REL)
    if mu < expected:
        assert r.sliding_joints == ["b3|b4"] and r.moving_blocks == ["b4"]


def test_mechanism_is_kinematically_admissible_and_does_the_work_of_lambda():
    """Upper-bound theorem, checked on the dual itself: every cone edge does non-negative power (joints
    open or slide with dilation, never interpenetrate) and λ = dead-load power / live-load power."""
    sc = column(4, 0.3, 0.25, 0.45)
    model = build_model(sc)
    joints = find_joints(model)
    r = analyse(sc, LiveLoad("horizontal", "-x"))
    u = r.solution.block_velocity.ravel()
    a = equilibrium_matrix(model, joints)
    assert (a.T @ u).min() >= -1e-7
    dead, live, _ = load_vectors(model, LiveLoad("horizontal", "-x"))
    assert -(dead @ u) / (live @ u) == pytest.approx(r.load_factor, rel=1e-6)


def test_contact_forces_are_admissible_and_in_equilibrium():
    sc = column(3, 0.4, 0.3, 0.5)
    model = build_model(sc)
    joints = find_joints(model)
    r = analyse(sc, LiveLoad("horizontal"))
    n, t = r.solution.contact_force.T
    assert n.min() >= -1e-6 and (np.abs(t) - 0.5 * n).max() <= 1e-6
    # Rebuild the generalised forces from (N, T) directly, independent of the cone-edge columns.
    dead, live, _ = load_vectors(model, LiveLoad("horizontal"))
    total = dead + r.load_factor * live
    f = n[:, None] * joints.contact_normal + t[:, None] * joints.contact_tangent
    for side, sign in ((0, -1.0), (1, 1.0)):
        for k, body in enumerate(joints.contact_body[:, side]):
            if body < model.block_count:
                lever = joints.contact_point[k] - model.body_q0[body, :2]
                force = sign * f[k]
                total[3 * body : 3 * body + 3] += [*force, lever[0] * force[1] - lever[1] * force[0]]
    assert np.abs(total).max() <= 1e-6 * model.body_mass[:3].sum() * 9.81


def test_a_block_with_nothing_under_it_is_one_clear_error():
    sc = scenario([("floater", box(0, 1, 1, 2)), ("sitter", box(2, 0, 3, 1))], [("ground", box(1.5, -1, 4, 0))], 0.6)
    # "block floater touches nothing" named it unlike every other message (block 1 ("floater"), as the
    # structure's own warning just above it says)
    with pytest.raises(LimitError, match=r'^block 1 \("floater"\) touches nothing'):
        analyse(sc, LiveLoad())


def test_a_block_that_cannot_stand_is_infeasible():
    # A block resting on a ground that ends under its left third: it tips under its own weight.
    sc = scenario([("overhang", box(0, 0, 1, 1))], [("ground", box(-1, -1, 0.3, 0))], 0.6)
    with pytest.raises(LimitError, match="no equilibrium"):
        analyse(sc, LiveLoad())


def test_no_equilibrium_names_what_gives_way_under_the_dead_load():
    """The Farkas mechanism of an infeasible structure, against statics: a block whose centroid (x = 0.5) lies
    beyond the ground's edge (x = 0.3) tips about that edge; one on a 30° slope with μ = 0.3 < tan 30° and a
    base wider than tall slides down it (it said only "no equilibrium", whatever failed)."""
    tipping = scenario([("overhang", box(0, 0, 1, 1))], [("ground", box(-1, -1, 0.3, 0))], 0.6)
    with pytest.raises(LimitError, match=r"under its own weight 1 of 1 blocks give way — hinges overhang\|ground$"):
        analyse(tipping, LiveLoad())
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    slope = Polygon([(0, 0), (4 * c, -4 * s), (4 * c, -3), (0, -3)])
    block = Polygon([(x * c + y * s, -x * s + y * c) for x, y in [(1, 0), (2, 0), (2, 0.4), (1, 0.4)]])
    with pytest.raises(LimitError, match=r"1 of 1 blocks give way — sliding (block\|slope|slope\|block)$"):
        analyse(scenario([("block", block)], [("slope", slope)], 0.3), LiveLoad())


def test_a_load_no_mechanism_can_follow_is_unbounded():
    # A block boxed between two walls: pushing it sideways is resisted at any factor.
    walls = [("ground", box(-1, -1, 2, 0)), ("left", box(-1, 0, 0, 2)), ("right", box(1, 0, 2, 2))]
    with pytest.raises(LimitError, match="unbounded"):
        analyse(scenario([("boxed", box(0, 0, 1, 1))], walls, 0.6), LiveLoad())


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"kind": "wind"}, "--load wind"),
        ({"kind": "point"}, "--block NAME"),
        ({"kind": "horizontal", "block": "b0"}, "only a point load"),
        ({"kind": "horizontal", "direction": "-y"}, "--direction -y"),
    ],
)
def test_bad_loads_are_refused(kwargs, match):
    with pytest.raises(InputError, match=match):
        LiveLoad(**kwargs)


def test_unknown_block_is_named_with_suggestions():
    with pytest.raises(InputError, match=r"--block b01: no such block \(did you mean b1, b0\?\)"):
        analyse(column(2, 0.4, 0.2, 0.6), LiveLoad("point", block="b01"))


@pytest.mark.parametrize("alert", [0.6, 1.0])
def test_a_raised_alert_distance_adds_no_joint_across_a_gap(alert):
    # A column of 4 blocks 0.3 × 0.25 overturns at λ = B/(nH) = 0.3 whatever contacts the run watches.
    # With alert_distance 0.6 the LP also had "joints" between blocks 0.25 and 0.5 m apart, carrying
    # force across the gaps (the 51-block wall: λ 0.544 at 0.5 m, 0.569 at 1e9, against 0.464). 1.0 m is
    # the column's height, the largest alert distance a scenario accepts (1e9 is refused since).
    sc = column(4, 0.3, 0.25, 0.45, alert_distance=alert)
    joints = find_joints(build_model(sc))
    assert [tuple(b) for b in joints.joint_body] == [(0, 1), (0, 4), (1, 2), (2, 3)]
    assert analyse(sc, LiveLoad("horizontal")).load_factor == pytest.approx(0.3, rel=REL)


def test_thrust_without_bound_is_said_and_lambda_still_found():
    """`--thrust` on a panel jammed between two supports: they can squeeze it with any force (a self-stress
    of the two blocks against each other), so its greatest thrust has no bound, while the free columns on
    either side still collapse at λ = B/H = 0.25. The unbounded LP made the whole analysis fail with "no collapse:
    the joints resist the live load at any factor". A lone column pushes nothing sideways on its ground:
    0 … 0 exactly (it printed -4e-10 … -7e-12 N, the LP's rounding)."""
    jammed = scenario(
        [
            ("a", box(-0.2, 0.0, 0.0, 0.4)),
            ("b", box(0.0, 0.0, 0.2, 0.4)),
            ("c", box(2.0, 0.0, 2.2, 0.8)),
            ("d", box(-2.2, 0.0, -2.0, 0.8)),
        ],
        [("left", box(-0.5, 0.0, -0.2, 1.0)), ("right", box(0.2, 0.0, 0.5, 1.0)), ("ground", box(-4, -0.5, 4, 0))],
        friction=0.6,
    )
    result = analyse(jammed, LiveLoad(), thrust=True)
    assert result.load_factor == pytest.approx(0.25, rel=REL)
    thrusts = {name: (way, least, greatest) for name, way, least, greatest in result.support_thrust}
    assert thrusts["left"] == ("-x", 0.0, np.inf) and thrusts["right"] == ("+x", 0.0, np.inf)
    data = result.summary()["support_thrust"]
    assert [t["greatest_N"] for t in data if t["support"] != "ground"] == [None, None]  # JSON has no infinity
    lone = analyse(column(1, 0.4, 0.8, friction=0.6), LiveLoad(), thrust=True)
    assert lone.support_thrust[0][2:] == (0.0, 0.0)


def test_a_point_load_given_by_its_place_acts_there_not_at_the_blocks_centroid():
    """`--at X` is a load on the deck at x = X: its line of action passes there, on the block's top. Statics
    of one block: a beam 2 m × 0.2 m on a support under x ∈ [0, 1.2] (centroid x = 1 over it) tips about the
    support's edge x = 1.2 under a load P down at x = X > 1.2 when P (X − 1.2) = W (1.2 − 1): λ = 0.2 / (X − 1.2);
    at the centroid (--block) it never tips. A push +x at the top of a B × H block on the ground tips it at
    λ = B / (2H), at the centroid at B / H. Before, --at loaded the centroid: 'no collapse' (unbounded) for
    the beam, whatever X."""
    beam = scenario([("beam", box(0.0, 0.0, 2.0, 0.2))], [("ground", box(-1.0, -0.5, 1.2, 0.0))], friction=2.0)
    for x in (1.5, 1.9):
        result = analyse(beam, LiveLoad("point", at=x))
        assert result.load.block == "beam"
        assert result.load_factor == pytest.approx(0.2 / (x - 1.2), rel=REL)
    with pytest.raises(LimitError, match="no collapse"):
        analyse(beam, LiveLoad("point", block="beam"))
    block = column(1, 0.4, 0.8, 2.0)
    assert analyse(block, LiveLoad("point", "+x", at=0.2)).load_factor == pytest.approx(0.25, rel=REL)
    assert analyse(block, LiveLoad("point", "+x", block="b0")).load_factor == pytest.approx(0.5, rel=REL)
