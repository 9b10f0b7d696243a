"""The per-step watch kernel against numpy on the state of a shaken wall (contacts sliding and open)."""

from __future__ import annotations

import numpy as np

from masonrycli.engine.watch import watch_step
from masonrycli.run import Simulation
from masonrycli.scenario.motion import Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder


def test_watch_matches_numpy():
    scenario = scenario_from_builder(
        "wall",
        {"blocks": 12},
        RunConfig(duration=0.3),
        Material(friction=0.3),
        {"ground": Sine(amplitude=1.0, frequency=2.0)},
    )
    sim = Simulation(scenario)
    for _ in range(150):
        sim.step()
    s, st, m = sim.solver, sim.state, sim.model
    n = m.block_count
    height = np.array([np.ptp(b.vertices[:, 1]) for b in scenario.assembly.blocks])
    top = np.array([0, 5, 7], dtype=np.int64)
    q0 = m.body_q0
    rock, slide, fall, turn, top_dx = watch_step(s, st.body_q, st.body_v, q0, height, top)
    closed = s.contact_status != 0
    assert closed.sum() > 0 and (~closed).sum() > 0
    u_t = s.contact_tangential_velocity(st.body_v)
    assert slide == np.abs(u_t[closed]).max() > 0
    assert rock == np.abs(st.body_v[:n, 2]).max()
    assert fall == np.max((q0[:n, 1] - st.body_q[:n, 1]) / height)
    assert turn == np.abs(st.body_q[:n, 2]).max()
    assert top_dx == np.mean(st.body_q[top, 0] - q0[top, 0])


def test_watch_measures_the_fall_below_the_supports_settlement():
    # The settlement (max over the supports of y0 - y, at least 0) lowers the blocks' reference: numpy's
    # formula of CollapseMonitor.update before the kernel took it over; a NaN support's counts as none.
    scenario = scenario_from_builder("wall", {"blocks": 12}, RunConfig(duration=0.05), Material(friction=0.6), {})
    sim = Simulation(scenario)
    for _ in range(20):
        sim.step()
    s, m = sim.solver, sim.model
    n = m.block_count
    assert m.body_q0.shape[0] > n  # the ground is a support
    height = np.array([np.ptp(b.vertices[:, 1]) for b in scenario.assembly.blocks])
    top = np.array([0, 5], dtype=np.int64)
    q0 = m.body_q0
    for drop, support_drop in ((0.0, 0.0), (0.05, 0.03), (0.05, -0.03), (0.05, np.nan)):
        q = sim.state.body_q.copy()
        q[:n, 1] -= drop
        q[n:, 1] -= support_drop
        settlement = max(0.0, float(np.max(q0[n:, 1] - q[n:, 1])))
        lowered = q0[:n, 1] - settlement
        _, _, fall, _, _ = watch_step(s, q, sim.state.body_v, q0, height, top)
        assert fall == np.max((lowered - q[:n, 1]) / height)


def test_the_step_kernels_read_no_private_attribute_of_the_solver():
    # fused.py and watch.py get the Solver's arrays as arguments or through its documented public views
    # (contact_body, contact_pack, contact_status), never through its private attributes.
    import inspect
    import re

    from masonrycli.engine import fused, watch

    for module in (fused, watch):
        assert not re.findall(r"solver\._\w+", inspect.getsource(module)), module.__name__
