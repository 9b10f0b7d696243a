"""The lab's line Gauss–Seidel (benchmarks/solver_lab/methods/lines.py): lines are chains of blocks through
bed joints covering every block once, the subset solve is the engine's sweep when the subset is everything,
a line's solve meets the contact law on its contacts, and the method's answer is the tight reference's."""

import numpy as np
import pytest

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import lines
from benchmarks.solver_lab.outcome import Context
from tests.solver_lab_helpers import tiny_cold_problem


@pytest.fixture(scope="module")
def ctx():
    return Context(tiny_cold_problem())


def test_lines_cover_every_block_once_through_bed_joints(ctx):
    p = ctx.p
    chains, groups, between = lines.build_lines(p, ctx.pack)
    blocks = sorted(b for chain in chains for b in chain)
    assert blocks == list(np.flatnonzero(p.inv_mass > 0))
    pairs = {tuple(sorted(map(int, pair))) for pair in p.body}
    for chain in chains:
        for lo, hi in zip(chain, chain[1:], strict=False):
            assert tuple(sorted((lo, hi))) in pairs  # consecutive blocks touch
            assert p.q_m[hi, 1] > p.q_m[lo, 1]  # bottom up
    assert any(len(chain) == 2 for chain in chains)  # two courses: some line climbs a bed joint
    every = np.sort(np.concatenate([*groups, between]))
    assert np.array_equal(every, np.arange(p.count))  # each contact in one line or between lines


def test_the_subset_solve_of_every_contact_is_the_engine_sweep(ctx):
    p = ctx.p
    r = p.r_warm.copy()
    v = law.velocity_from_impulse(p, ctx.H, r)
    status = np.zeros(p.count, np.int8)
    lines.solve_subset(ctx, v, r, status, np.arange(p.count), 0.0, 7, "nlgs")
    r_engine = p.r_warm.copy()
    v_engine, _ = ctx.sweep(r_engine, 7)
    np.testing.assert_allclose(r, r_engine, rtol=0, atol=1e-12)
    np.testing.assert_allclose(v, v_engine, rtol=0, atol=1e-12)


def test_a_line_solve_meets_the_law_on_its_contacts_and_keeps_v_of_r(ctx):
    p = ctx.p
    _, groups, _ = lines.build_lines(p, ctx.pack)
    g = max(groups, key=len)
    r = p.r_warm.copy()
    v = law.velocity_from_impulse(p, ctx.H, r)
    lines.solve_subset(ctx, v, r, np.zeros(p.count, np.int8), g, 1e-10, 100_000, "nlgs-accel")
    np.testing.assert_allclose(v, law.velocity_from_impulse(p, ctx.H, r), rtol=0, atol=1e-10)
    e = law.law_residual(p, ctx.pack, ctx.H, v, r)
    assert e[g].max() < 1e-8  # the line's own contacts hold the law (numpy's independent local solve)
    assert e.max() > 1e-6  # the others, not yet visited, do not: the solve touched only the line


def test_line_gs_converges_to_the_reference(ctx):
    out = lines.METHODS["line-gs"](ctx, 1e-6)
    assert out.converged
    assert ctx.residual(out.v, out.r) <= 1e-6
    assert law.velocity_error(ctx.p, out.v) < 1e-4  # the reference is unique in velocities
