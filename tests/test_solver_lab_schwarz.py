"""The lab's overlapping Schwarz on vertical strips (benchmarks/solver_lab/methods/schwarz.py): each cutting
splits the contacts into strips that hold both bodies (or a body and a support); with strips two or three
block lengths wide and two or three shifted cuttings no contact is cut in all of them; and the method's
answer is the tight reference's."""

import numpy as np
import pytest

from benchmarks.solver_lab import law
from benchmarks.solver_lab.capture import SINE, capture_run
from benchmarks.solver_lab.methods import schwarz
from benchmarks.solver_lab.outcome import Context
from masonrycli.run import Simulation
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder
from tests.solver_lab_helpers import tiny_cold_problem

SHIFTED = [(2, 2), (3, 2), (2, 3), (3, 3), (4, 2)]
"""(width in block lengths, cuttings): the variants the lab runs."""


@pytest.fixture(scope="module")
def ctx():
    return Context(tiny_cold_problem())


@pytest.fixture(scope="module")
def wide():
    """The cold step of the lab's walls' running bond, two courses: 15 blocks, then 14 and two halves."""
    sc = scenario_from_builder(
        "wall", {"blocks": 31, "courses": 2}, RunConfig(duration=0.002), Material(), {"ground": SINE}
    )
    return Context(capture_run(Simulation(sc), typical_step=1)[0]["cold"])


def _check_cuttings(c, width, count):
    p = c.p
    cut = schwarz.cuttings(p, c.pack, width, count)
    groups, uncovered, b = cut.groups, cut.uncovered, cut.b
    assert b == pytest.approx(0.3, rel=0.02)  # the builder's block length
    assert len(groups) == count
    support = p.inv_mass == 0
    for cutting in groups:
        every = np.concatenate(cutting)
        assert np.unique(every).size == every.size  # a contact is in one strip of a cutting at most
        xs = []
        for g in cutting:
            bodies = np.unique(p.body[g])
            free = bodies[~support[bodies]]
            xs.append(p.q_m[free, 0])
            # a strip's contacts join its own blocks or one of them to a support: nothing outside it
            for a, bb in p.body[g]:
                assert support[a] or support[bb] or abs(p.q_m[a, 0] - p.q_m[bb, 0]) < width * b
        for left, right in zip(xs, xs[1:], strict=False):
            assert left.max() < right.min()  # strips left to right, disjoint in x
    covered = np.unique(np.concatenate([g for cutting in groups for g in cutting]))
    return covered, uncovered


@pytest.mark.parametrize("width,count", SHIFTED)
def test_shifted_cuttings_leave_no_contact_uncovered(ctx, wide, width, count):
    for c in (ctx, wide):
        covered, uncovered = _check_cuttings(c, width, count)
        assert uncovered.size == 0
        assert np.array_equal(covered, np.arange(c.p.count))  # every contact inside a strip somewhere


def test_one_block_strips_cut_every_head_joint_twice(wide):
    # The control: strips one block long, shifted by half a block, cut each head joint in both cuttings,
    # so the coverage check above is able to fail.
    p = wide.p
    covered, uncovered = _check_cuttings(wide, 1, 2)
    head = np.abs(wide.pack[uncovered, schwarz.nlgs.P_NY]) < schwarz.HEAD
    assert uncovered.size > 20 and head.all()
    assert np.array_equal(np.sort(np.concatenate([covered, uncovered])), np.arange(p.count))


@pytest.mark.parametrize("method", ["schwarz-2b", "schwarz-3b-3"])
def test_schwarz_converges_to_the_reference(ctx, method):
    out = schwarz.METHODS[method](ctx, 1e-6)
    assert out.converged
    assert ctx.residual(out.v, out.r) <= 1e-6
    np.testing.assert_allclose(out.v, law.velocity_from_impulse(ctx.p, ctx.H, out.r), rtol=0, atol=1e-9)
    assert law.velocity_error(ctx.p, out.v) < 1e-4  # the reference is unique in velocities
    assert out.iterations >= 2  # the tiny wall spans two strips: one cutting alone does not solve it


def test_a_strip_with_velocities_held_moves_only_its_blocks_and_balances_them(ctx):
    # The primal variant's strip solve: every other body a moving support. Held at the reference's
    # velocities, the neighbours leave the strip's blocks the reference's (velocities are unique); the blocks
    # end with v = v_free + M⁻¹Hᵀr over all their contacts and the law holds there; no other body moves.
    p = ctx.p
    cut = schwarz.cuttings(p, ctx.pack, 2, 2)
    strip = max(schwarz._dirichlet_strips(ctx, cut.bodies[0]), key=lambda s: s[0].size)
    blocks, idx = strip[0], strip[1]
    r = p.r_warm.copy()
    v = p.v_ref.copy()
    schwarz._solve_dirichlet(p, v, r, np.zeros(p.count, np.int8), strip)
    others = np.setdiff1d(np.arange(v.shape[0]), blocks)
    assert np.array_equal(v[others], p.v_ref[others])
    np.testing.assert_allclose(v[blocks], p.v_ref[blocks], rtol=0, atol=1e-6)
    assert np.abs(v[blocks] - p.v_free[blocks]).max() > 1e-3  # the strip was solved, not left at v_free
    np.testing.assert_allclose(v[blocks], law.velocity_from_impulse(p, ctx.H, r)[blocks], rtol=0, atol=1e-10)
    assert law.law_residual(p, ctx.pack, ctx.H, v, r)[idx].max() < 1e-7
