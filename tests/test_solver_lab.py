"""The solver lab's capture and measures (benchmarks/solver_lab), on a tiny wall.

The lab's numpy H and local solve are written independently of the engine's kernels: a reference solved
by the engine's NLGS must satisfy the lab's contact law and reproduce v = v_free + M⁻¹ H r.
"""

import numpy as np

from benchmarks.solver_lab import law
from benchmarks.solver_lab.capture import SINE, capture_run, reference
from benchmarks.solver_lab.methods import gauss_seidel
from benchmarks.solver_lab.outcome import Context
from benchmarks.solver_lab.problems import REF_RESIDUAL, Problem
from masonrycli.engine import dispatch
from masonrycli.engine import nlgs as N
from masonrycli.run import Simulation
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder


def _tiny_wall():
    return scenario_from_builder(
        "wall", {"blocks": 7, "courses": 2}, RunConfig(duration=0.03, solver="nlgs-accel"), Material(), {"ground": SINE}
    )


def _captured(tmp_path):
    sc = _tiny_wall()
    # Step 15: on this run (default solver nlgs-accel) steps 18-28 each have a contact sitting exactly on
    # its friction limit, where the reference's Gauss–Seidel settles into a stick/slip cycle at 2-3e-9 m/s,
    # above REF_RESIDUAL; step 15 has none (its reference converges in 500 sweeps).
    kept, _ = capture_run(Simulation(sc), typical_step=15)
    assert sorted(kept) == ["cold", "hard", "typical"]
    p = kept["typical"]
    p.name = "tiny"
    reference(p)
    p.save(tmp_path / "tiny.npz")
    return Problem.load(tmp_path / "tiny.npz")


def test_reference_satisfies_the_lab_law_and_momentum(tmp_path):
    p = _captured(tmp_path)
    assert p.step == 15 and p.count > 0 and (p.r_warm[:, 1] > 0).any()
    ctx = Context(p)
    assert p.ref_residual <= REF_RESIDUAL
    assert ctx.residual(p.v_ref, p.r_ref) <= REF_RESIDUAL
    np.testing.assert_allclose(law.velocity_from_impulse(p, ctx.H, p.r_ref), p.v_ref, atol=1e-12)
    # the warm start alone is not a solution: the residual measures something
    v_warm = law.velocity_from_impulse(p, ctx.H, p.r_warm)
    assert ctx.residual(v_warm, p.r_warm) > 1e3 * REF_RESIDUAL


def test_a_captured_v_n_is_the_velocity_its_step_began_with_as_the_solver_s_public_array(tmp_path):
    # capture reads Solver.body_v_n (public) in the hooked solve; the reference: the state's velocities
    # before that step, from a second run of the same scenario stepped to it
    p = _captured(tmp_path)
    sim = Simulation(_tiny_wall())
    for _ in range(p.step - 1):
        sim.step()
    before = sim.state.body_v.copy()
    np.testing.assert_array_equal(p.v_n, before)
    sim.step()
    np.testing.assert_array_equal(sim.solver.body_v_n, before)
    assert not np.array_equal(sim.state.body_v, before)  # the step moved the blocks: the array is v_n, not v


def test_local_solve_open_stick_slide():
    # one contact with W = I (unit mass, no lever arm), μ = 0.5, no gap
    pack = np.zeros((1, N.PACK_WIDTH))
    pack[0, [N.P_NX, N.P_NY]] = 0.0, 1.0
    pack[0, [N.P_WTT, N.P_WTN, N.P_WNN]] = 1.0, 0.0, 1.0
    pack[0, [N.P_ITT, N.P_ITN, N.P_INN]] = 1.0, 0.0, 1.0
    mu = 0.5
    pack[0, [N.P_ISP, N.P_ISM]] = 1.0, 1.0
    # approaching at 2 m/s with 0.5 m/s tangential: stick, r = (−0.5, 2) (|r_t| ≤ μ r_n = 1)
    rt, rn = law.local_solve(np.array([0.5]), np.array([-2.0]), pack, mu)
    assert np.allclose([rt[0], rn[0]], [-0.5, 2.0])
    # with 3 m/s tangential it slides: r_n = 2, r_t = −μ r_n = −1
    rt, rn = law.local_solve(np.array([3.0]), np.array([-2.0]), pack, mu)
    assert np.allclose([rt[0], rn[0]], [-1.0, 2.0])
    # separating: open
    rt, rn = law.local_solve(np.array([3.0]), np.array([0.5]), pack, mu)
    assert (rt[0], rn[0]) == (0.0, 0.0)


def test_gauss_seidel_methods_reach_the_target(tmp_path):
    p = _captured(tmp_path)
    ctx = Context(p)
    for name in ("nlgs-law", "nlgs-predict", "nlgs-cold"):
        out = gauss_seidel.METHODS[name](ctx, 1e-6)
        assert out.converged
        v = law.velocity_from_impulse(p, ctx.H, out.r)
        assert ctx.residual(v, out.r) <= 1e-6
        assert law.velocity_error(p, v) < 1e-3


def test_every_lab_method_solves_a_tiny_wall_step(tmp_path):
    # what the table reports for each method, on a problem every one of them can solve
    from benchmarks.solver_lab import harness

    p = _captured(tmp_path)
    ctx = Context(p)
    harness._register_optional()
    for name in harness.DEFAULT_METHODS:
        row = harness.measure(ctx, name, 1e-6)
        assert row["converged"], name
        assert row["v_mismatch"] < 1e-9, name
        assert row["v_error"] < 1e-4, name
        if name not in ("nlgs", "nlgs-oracle"):  # stopped by the engine's own test / the oracle
            assert row["law_residual"] <= 1e-6, name


def test_rigid_share_of_a_free_cluster(tmp_path):
    from benchmarks.solver_lab.clusters import rigid_share

    p = _captured(tmp_path)
    dyn = p.inv_mass > 0
    a, b = p.body[:, 0], p.body[:, 1]
    st = np.where(dyn[a] & dyn[b], 1, 0).astype(np.int8)  # blocks stuck together, free of the ground
    x = p.q_m[:, :2]
    rigid = np.zeros_like(p.v_ref)
    rigid[:, 0], rigid[:, 1], rigid[:, 2] = 0.1 - 0.05 * x[:, 1], 0.05 * x[:, 0], 0.05  # V + ω ẑ × x
    share, free = rigid_share(p, st, p.v_ref + np.where(dyn[:, None], rigid, 0.0))
    assert free == 1 and abs(share - 1.0) < 1e-12
    wobble = np.zeros_like(p.v_ref)
    wobble[np.flatnonzero(dyn)[0], 0] = 1e-3  # one block alone: mostly not a motion of the whole cluster
    share, _ = rigid_share(p, st, p.v_ref + wobble)
    assert share < 0.5
    # stuck to the ground: nothing is free to move rigidly
    assert rigid_share(p, np.ones_like(st), p.v_ref + wobble) == (0.0, 0)


def test_cluster_correction_moves_joined_blocks_rigidly(tmp_path):
    # the coarse step of nlgs-cluster: velocities follow the impulses, joined pairs keep their relative velocity
    from benchmarks.solver_lab.methods import cluster
    from benchmarks.solver_lab.outcome import Clock

    p = _captured(tmp_path)
    ctx = Context(p)
    r = p.r_warm.copy()
    dyn = p.inv_mass > 0
    inner = dyn[p.body[:, 0]] & dyn[p.body[:, 1]]
    r[inner] = (0.0, 1e-3)  # every block–block contact clearly sticking: the blocks form clusters
    v = law.velocity_from_impulse(p, ctx.H, r)
    label, joined = cluster._clusters(p, r)
    assert joined.any() and label.max() + 1 < p.q_m.shape[0]  # some blocks are joined into clusters
    r2, v2, _ = cluster.coarse_step(ctx, v, r, Clock())
    np.testing.assert_allclose(v2, law.velocity_from_impulse(p, ctx.H, r2), atol=1e-12)
    assert np.abs(v2 - v).max() > 1e-9  # the correction does something
    du = (ctx.H @ (v2 - v).ravel()).reshape(-1, 2)[joined]
    assert np.abs(du).max() < 1e-8 * max(np.abs(v2 - v).max(), 1.0)
    # only the joining contacts and the contacts between clusters change
    a, b = p.body[:, 0], p.body[:, 1]
    same = (label[a] == label[b]) & ~joined
    np.testing.assert_array_equal(r2[same], r[same])


def test_linear_correction_keeps_a_solution(tmp_path):
    # At the reference the linearised problem already holds (every constraint row's violation is 0):
    # the correction must leave the velocities where they are. (Off the solution the statuses change
    # under it and the step can be worse, which is what the table measures and the guard rejects.)
    from benchmarks.solver_lab.methods import linear

    p = _captured(tmp_path)
    ctx = Context(p)
    r = linear.correction(ctx, p.v_ref, p.r_ref)
    v = law.velocity_from_impulse(p, ctx.H, r)
    assert law.velocity_error(p, v) < 1e-7
    assert ctx.residual(v, r) < 1e-6


def test_accelerated_method_takes_the_engine_default_and_stops_on_the_law(tmp_path):
    # nlgs-accel is the engine's default solve: at the count it found, the lab's law residual is at the
    # target and the impulses are those of dispatch.solve with the engine's default solver from r_warm
    from benchmarks.solver_lab.methods import accelerated
    from masonrycli.scenario.scenario import RunConfig

    p = _captured(tmp_path)
    ctx = Context(p)
    ctx.accel_cost = 1.2
    out = accelerated.accelerated(ctx, 1e-6)
    assert out.converged and out.sweeps == 1.2 * out.iterations
    v = law.velocity_from_impulse(p, ctx.H, out.r)
    assert ctx.residual(v, out.r) <= 1e-6 and law.velocity_error(p, v) < 1e-4
    r = p.r_warm.copy()
    dispatch.solve(
        p.body,
        ctx.pack,
        p.count,
        p.shim(0.0, out.iterations, RunConfig().solver),
        p.v_free.copy(),
        r,
        np.zeros(p.count, np.int8),
    )
    np.testing.assert_array_equal(r, out.r)


def test_accelerated_variants_differ_only_by_restart_growth():
    # A variant hands dispatch.solve a Tuning with another lane_growth (a kernel argument, in this process):
    # at the engine's own growth it reproduces the shipped solve bit for bit; at a growth that restarts
    # less often it does not (the value really reached the compiled kernel).
    from benchmarks.solver_lab.methods import accelerated
    from masonrycli.engine import momentum
    from masonrycli.engine.tuning import TUNING
    from tests.solver_lab_helpers import tiny_cold_problem

    ctx = Context(tiny_cold_problem())
    ctx.accel_cost = 1.0
    assert TUNING.lane_growth == momentum.RESTART_GROWTH == 1.1
    base = accelerated.accelerated(ctx, 1e-7)
    same = accelerated.variant(TUNING.lane_growth)(ctx, 1e-7)
    assert same.iterations == base.iterations
    np.testing.assert_array_equal(same.r, base.r)
    other = accelerated.variant(2.0)(ctx, 1e-7)
    assert other.iterations != base.iterations or not np.array_equal(other.r, base.r)
