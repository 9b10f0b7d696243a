"""masonrycli.analysis.joint_forces against hand-computed resultants and an independent moment balance."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.analysis.joint_forces import JOINT_OPEN, JOINT_SLIP, JOINT_STICK, joint_resultants, magnification
from masonrycli.outputs.frame import CONTACT_OPEN, CONTACT_SLIP, CONTACT_STICK


def test_a_bed_joint_under_an_eccentric_load():
    """Two contact points 0.3 m apart carrying 3 kN and 1 kN: R = 4 kN at 0.075 m from the middle, and
    the moment of R about any point equals that of the two forces (no friction here)."""
    body = [[0, 1], [0, 1]]
    point = [[-0.15, 0.0], [0.15, 0.0]]
    normal = [[0.0, 1.0], [0.0, 1.0]]
    force = [[0.0, 3000.0], [0.0, 1000.0]]
    j = joint_resultants(body, point, normal, force, [CONTACT_STICK, CONTACT_STICK])
    assert j.body.tolist() == [[0, 1]] and j.state.tolist() == [JOINT_STICK]
    np.testing.assert_allclose(j.force, [[0.0, 4000.0]])
    np.testing.assert_allclose(j.point, [[-0.075, 0.0]])
    o = np.array([0.4, -0.2])

    def cross(r, f):
        return r[0] * f[1] - r[1] * f[0]

    moment = sum(cross(np.array(p) - o, f) for p, f in zip(point, force))
    assert cross(j.point[0] - o, j.force[0]) == pytest.approx(moment)


def test_order_of_bodies_states_and_unloaded_joints():
    # pair (2, 0) written the other way round: its force is turned to be the force on body 2
    body = [[2, 0], [0, 2], [1, 3], [1, 3], [4, 5]]
    point = [[0.0, 1.0], [1.0, 1.0], [5.0, 0.0], [6.0, 0.0], [9.0, 9.0]]
    normal = [[0.0, -1.0], [0.0, 1.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    force = [[0.0, -500.0], [0.0, 1500.0], [300.0, 50.0], [0.0, 0.0], [0.0, 0.0]]
    status = [CONTACT_STICK, CONTACT_SLIP, CONTACT_STICK, CONTACT_OPEN, CONTACT_OPEN]
    j = joint_resultants(body, point, normal, force, status)
    assert j.body.tolist() == [[0, 2], [1, 3]]  # (4, 5) carries no compression: no resultant
    np.testing.assert_allclose(j.force, [[0.0, 2000.0], [300.0, 50.0]])
    np.testing.assert_allclose(j.point, [[0.75, 1.0], [5.0, 0.0]])
    assert j.state.tolist() == [JOINT_SLIP, JOINT_OPEN]


def test_magnification_draws_the_largest_displacement_at_five_percent():
    d = np.zeros((3, 10, 2))
    d[2, 4] = [0.03, -0.04]  # 5 cm
    assert magnification(d, 7.0) == 6.0  # 0.05 · 7 / 0.05 = 7 → 6 (nice, rounded down)
    assert magnification(d, 0.5) == 1.0  # already more than 5 %
    assert magnification(np.zeros((2, 3, 2)), 7.0) == 1.0


@pytest.mark.parametrize("in_order", [False, True])
def test_the_kernels_sums_are_bincounts_bit_for_bit(in_order):
    """The per-joint sums (engine.joints.resultants) against numpy's bincount formulation they replaced:
    the same bits, with flipped pairs, self-pairs, several frames, open and sliding contacts, a NaN force;
    contacts in any order (put in order first) and in key order (as the engine gives them: one pass)."""
    rng = np.random.default_rng(11)
    c = 3000
    body = rng.integers(0, 12, (c, 2))
    point, normal = rng.normal(size=(c, 2)), rng.normal(size=(c, 2))
    force = rng.normal(scale=1e3, size=(c, 2))
    force[17] = np.nan
    status = rng.choice([CONTACT_OPEN, CONTACT_STICK, CONTACT_SLIP], c).astype(np.int8)
    frame = np.sort(rng.integers(0, 4, c))
    if in_order:
        order = np.lexsort((body.max(axis=1), body.min(axis=1), frame))
        body, point, normal, force, status, frame = (x[order] for x in (body, point, normal, force, status, frame))
    got = joint_resultants(body, point, normal, force, status, frame)

    keep = body[:, 0] != body[:, 1]
    b, p, n, f, s, fr = body[keep], point[keep], normal[keep], force[keep], status[keep], frame[keep]
    sign = np.where(b[:, 0] > b[:, 1], -1.0, 1.0)[:, None]
    f, n = f * sign, n * sign
    lo, hi = b.min(axis=1), b.max(axis=1)
    base = int(hi.max()) + 1
    keys, joint = np.unique((fr * base + lo) * base + hi, return_inverse=True)
    m = len(keys)
    fn = np.maximum(np.einsum("ij,ij->i", f, n), 0.0)
    weight = np.bincount(joint, weights=fn, minlength=m)
    resultant = np.stack([np.bincount(joint, weights=f[:, k], minlength=m) for k in range(2)], axis=1)
    centre = np.stack([np.bincount(joint, weights=fn * p[:, k], minlength=m) for k in range(2)], axis=1)
    slipping = np.bincount(joint, weights=s == CONTACT_SLIP, minlength=m) > 0
    opened = np.bincount(joint, weights=s == CONTACT_OPEN, minlength=m) > 0
    state = np.where(slipping, JOINT_SLIP, np.where(opened, JOINT_OPEN, JOINT_STICK)).astype(np.int8)
    loaded = weight > 0.0
    assert loaded.sum() > 100 and not loaded.all()
    expected = (
        np.stack([keys // base % base, keys % base], axis=1)[loaded],
        centre[loaded] / weight[loaded, None],
        resultant[loaded],
        state[loaded],
        keys[loaded] // (base * base),
    )
    for name, mine, theirs in zip(got._fields, got, expected):
        assert mine.dtype == theirs.dtype and mine.tobytes() == theirs.tobytes(), name
