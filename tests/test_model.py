"""masonrycli.model: a scenario flattened into arrays, checked against the textbook mass properties of a
rectangle and a right triangle and against the imposed motion's formula."""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import Polygon, box

from geometry_library.blocks import Assembly, Block, Support
from masonrycli.model import build_model, initial_state
from masonrycli.scenario.motion import Sine
from masonrycli.scenario.scenario import Material, RunConfig, Scenario

AMP, FREQ, DT = 0.3, 2.0, 1e-3
SHAKE = Sine(amplitude=AMP, frequency=FREQ, phase=math.pi / 2)  # v(0) = AMP along x


def _model(n_steps: int = 10):
    rect = Block(box(0.0, 0.0, 0.4, 0.2), "rect", density=2000.0, thickness=0.5)
    tri = Block(Polygon([(0.0, 0.2), (0.3, 0.2), (0.0, 0.5)]), "tri", velocity=(0.1, 0.0, 0.5))
    ground = Support(box(-1.0, -0.1, 1.0, 0.0), "ground")
    run = RunConfig(duration=n_steps * DT, dt=DT)
    return build_model(Scenario("m", run, Material(), Assembly((rect, tri), (ground,)), (SHAKE,)))


def test_mass_properties_are_the_textbook_ones():
    m = _model()
    # rectangle a × b: m = ρ a b t, I = m (a² + b²) / 12; right triangle of legs a, b: I = m (a² + b²) / 18
    rect_mass, tri_mass = 2000.0 * 0.4 * 0.2 * 0.5, 2500.0 * 0.5 * 0.3 * 0.3 * 1.0
    assert m.body_mass[:2] == pytest.approx([rect_mass, tri_mass], rel=1e-12)
    assert m.body_inertia[:2] == pytest.approx(
        [rect_mass * (0.4**2 + 0.2**2) / 12, tri_mass * (0.3**2 + 0.3**2) / 18], rel=1e-12
    )
    assert m.block_volume == pytest.approx([0.4 * 0.2 * 0.5, 0.045], rel=1e-12)
    assert m.body_q0[:, :2] == pytest.approx(np.array([[0.2, 0.1], [0.1, 0.3], [0.0, -0.05]]), abs=1e-12)
    assert np.all(m.body_q0[:, 2] == 0.0)
    # the farthest vertex: the rectangle's corners, the triangle's acute corners at √(0.2² + 0.1²)
    assert m.body_radius == pytest.approx([math.hypot(0.2, 0.1), math.hypot(0.2, 0.1), math.hypot(1.0, 0.05)])


def test_supports_have_no_inverse_mass_and_start_at_their_imposed_velocity():
    m = _model()
    assert (m.block_count, m.support_count, m.body_count) == (2, 1, 3)
    assert m.body_dynamic.tolist() == [True, True, False]
    assert m.body_inv_mass[2] == 0.0 and m.body_inv_inertia[2] == 0.0 and m.body_mass[2] == np.inf
    assert m.body_inv_mass[:2] == pytest.approx(1.0 / m.body_mass[:2], rel=1e-15)
    assert m.body_v0.tolist()[:2] == [[0.0, 0.0, 0.0], [0.1, 0.0, 0.5]]
    assert m.body_v0[2] == pytest.approx([AMP, 0.0, 0.0], abs=1e-15)
    assert (m.block_name, m.support_name) == (("rect", "tri"), ("ground",))


def test_vertices_are_csr_and_centred_on_each_body():
    m = _model()
    assert m.body_vert_start.tolist() == [0, 4, 7, 11]
    for b in range(3):
        local = m.vert_local[m.body_vert_start[b] : m.body_vert_start[b + 1]]
        assert local.mean(axis=0) == pytest.approx([0.0, 0.0], abs=1e-12)  # a box's and a triangle's
        x, y = local[:, 0], local[:, 1]
        assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0.0  # counter-clockwise


def test_support_velocity_rows_follow_the_sine_past_a_chunk():
    n_steps = 2 * 4096 + 5  # three chunks of the lazily evaluated table
    m = _model(n_steps)
    assert len(m.support_velocity) == n_steps + 1
    for k in (0, 1, 4095, 4096, 8191, n_steps, 3):  # back to the first chunk last
        v = AMP * math.sin(2 * math.pi * FREQ * k * DT + math.pi / 2)
        assert m.support_velocity[k][0] == pytest.approx([v, 0.0], abs=1e-12)
    with pytest.raises(IndexError):
        m.support_velocity[n_steps + 1]


def test_initial_state_is_a_copy():
    m = _model()
    state = initial_state(m)
    state.body_q[0, 0] += 1.0
    copied = state.copy()
    copied.body_v[1, 2] = 9.0
    assert m.body_q0[0, 0] == pytest.approx(0.2) and state.body_v[1, 2] == 0.5
    assert (state.step, state.time) == (0, 0.0)


def test_block_depth_is_the_vertical_extent_over_the_median_block_height():
    # rect 0 … 0.2 m high, tri 0.2 … 0.5 (0.3 high): extent 0.5 m over the median height 0.25 m = 2
    assert _model().block_depth == pytest.approx(2.0)
    # a built running-bond wall: its courses, whatever its length
    from masonrycli.scenario.scenario import scenario_from_builder

    for courses, length in ((5, 2.1), (5, 6.0), (12, 2.1)):
        options = {"blocks": None, "courses": courses, "length": length}
        sc = scenario_from_builder("wall", options, RunConfig(duration=DT), Material(), {})
        assert build_model(sc).block_depth == pytest.approx(courses)
