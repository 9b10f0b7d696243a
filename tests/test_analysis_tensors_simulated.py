"""The paper's tensors computed from real simulations at rest, against the exact statics.

DESIGN.md §6 case 3 (column of 5) and the 51-block wall's course-averaged σ_yy = −ρ g H (k − ½).
"""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.outputs.history import History
from masonrycli.run import simulate
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

from engine_helpers import run_history, scenario

G = 9.81


def test_column_block_stress_from_simulation():
    h, _ = run_history(scenario("column5.toml", duration=0.2))
    sigma = h["block_stress"][-1]  # blocks bottom (k5) to top (k1)
    rho, height = 2000.0, 0.2
    for index in range(5):
        k = 5 - index  # k from the top
        expected = -rho * G * height * (k - 0.5)
        assert sigma[index, 1, 1] == pytest.approx(expected, rel=5e-3)
        assert abs(sigma[index, 0, 1]) <= 5e-3 * abs(expected)
        assert abs(sigma[index, 1, 0]) <= 5e-3 * abs(expected)
    # Exact references of DESIGN.md: −1962, −5886, −9810, −13734, −17658 Pa (top to bottom).
    assert sigma[::-1, 1, 1] == pytest.approx([-1962, -5886, -9810, -13734, -17658], rel=5e-3)
    # The cell of an interior block (itself and its two neighbours) averages a linear field: equal.
    cell = h["cell_stress"][-1]
    for index in (1, 2, 3):
        assert cell[index, 1, 1] == pytest.approx(sigma[index, 1, 1], rel=5e-3)


def test_wall_at_rest_course_stress():
    density = 2500.0
    sc = scenario_from_builder(
        "wall", {"blocks": 51}, RunConfig(duration=0.1, record_every=100), Material(density=density), {}
    )
    hist = History([b.name for b in sc.assembly.blocks], [s.name for s in sc.assembly.supports])
    result = simulate(sc, sinks=[hist])
    assert result.status == "completed"
    h = hist.arrays()
    sigma = h["block_stress"][-1]
    y0 = h["block_q"][0, :, 1]
    from masonrycli.model import build_model

    volume = build_model(sc).block_volume
    courses = np.unique(np.round(y0, 6))
    height = 0.2
    assert len(courses) >= 3
    for k, y in enumerate(courses[::-1], start=1):  # k = 1 is the top course
        sel = np.isclose(y0, y, atol=1e-6)
        mean = (volume[sel] * sigma[sel, 1, 1]).sum() / volume[sel].sum()
        expected = -density * G * height * (k - 0.5)
        assert mean == pytest.approx(expected, rel=5e-3), (k, mean, expected)


@pytest.mark.parametrize("builder", ["arch", "aqueduct"])
def test_cells_cover_piers_spandrels_and_end_voussoirs(builder):
    """The fans (Fig. I.1, no touching rule between the neighbours) give every pier and spandrel block
    and the springing voussoirs a strain; a cell's fan never overlaps itself (checked with shapely,
    independently); in the bare arch every voussoir is in a one-block chain."""
    from shapely.geometry import Polygon
    from shapely.ops import unary_union

    from masonrycli.run import Simulation

    sc = scenario_from_builder(builder, {}, RunConfig(duration=0.01), Material(), {})
    sim = Simulation(sc)
    n = sim.model.block_count
    tri = sim.triangles
    xy = sim.model.body_q0[:n, :2]
    for i in range(n):
        fan = [Polygon(xy[t]) for t in tri[tri[:, 0] == i]]
        assert unary_union(fan).area == pytest.approx(sum(p.area for p in fan), rel=1e-9, abs=1e-12)
    has = sim.tensors.has_triangle
    names = [b.name for b in sc.assembly.blocks]
    voussoirs = [k for k, name in enumerate(names) if name.startswith("v")]
    assert len(voussoirs) == 30
    assert has[[k for k, name in enumerate(names) if not name.startswith("v")]].all()
    assert has[[voussoirs[0], voussoirs[-1]]].all()
    if builder == "arch":
        assert (sim.tensors.chain[voussoirs] >= 0).all()
    else:
        assert has.all()


@pytest.mark.parametrize("builder", ["arch", "aqueduct"])
def test_affine_velocity_is_exact_on_cells_with_non_touching_triangles(builder):
    """v = L x + c gives sym(L) in every cell, the cells whose fan joins two blocks that do not touch
    included (there are some: the springing voussoirs' and the pier blocks' beside them)."""
    from masonrycli.analysis.tensors import cell_strain_rate
    from masonrycli.run import Simulation

    sc = scenario_from_builder(builder, {}, RunConfig(duration=0.01), Material(), {})
    sim = Simulation(sc)
    n = sim.model.block_count
    count = sim.solver.detect(sim.state.body_q)
    body = sim.solver.contact_body[:count]
    touching = {(min(a, b), max(a, b)) for a, b in body.tolist()}
    tri = sim.triangles
    loose = np.array([(min(j, k), max(j, k)) not in touching for _, j, k in tri.tolist()])
    assert loose.sum() >= 2
    rng = np.random.default_rng(9)
    l0, c0 = rng.normal(size=(2, 2)), rng.normal(size=2)
    q = sim.model.body_q0.copy()
    q[:n, :2] += rng.normal(scale=0.01, size=(n, 2))  # a deformed configuration
    v = np.zeros_like(q)
    v[:n, :2] = q[:n, :2] @ l0.T + c0
    rate = cell_strain_rate(n, q, v, tri)
    has = sim.tensors.has_triangle
    assert np.unique(tri[loose, 0]).size >= 2 and has[tri[loose, 0]].all()
    np.testing.assert_allclose(rate[has], np.broadcast_to(0.5 * (l0 + l0.T), (has.sum(), 2, 2)), atol=1e-12)
