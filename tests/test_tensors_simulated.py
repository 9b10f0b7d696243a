"""The paper's tensors computed from real simulations at rest, against the exact statics.

DESIGN.md §6 case 3 (column of 5) and the 51-block wall's course-averaged σ_yy = −ρ g H (k − ½).
"""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.history import History
from masonrycli.run import simulate
from masonrycli.scenario import Material, RunConfig, scenario_from_builder

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
def test_triangulation_covers_piers_and_spandrels_without_overlap(builder):
    """Delaunay alone loses the two-block piers (its diagonals join blocks that do not touch); the
    completed triangulation gives every block that has two touching neighbours that touch each other
    a triangle, and its triangles never overlap (checked with shapely, independently)."""
    from shapely.geometry import Polygon
    from shapely.strtree import STRtree

    from masonrycli.run import Simulation

    sc = scenario_from_builder(builder, {}, RunConfig(duration=0.01), Material(), {})
    sim = Simulation(sc)
    n = sim.model.block_count
    tri = sim.triangles
    xy = sim.model.body_q0[:n, :2]
    polys = [Polygon(xy[t]) for t in tri]
    tree = STRtree(polys)
    for i, p in enumerate(polys):
        for j in tree.query(p):
            if j != i:
                assert p.intersection(polys[j]).area < 1e-9, (tri[i], tri[j])
    has = np.zeros(n, bool)
    has[tri.ravel()] = True
    names = [b.name for b in sc.assembly.blocks]
    piers = [k for k, name in enumerate(names) if "pier" in name]
    assert has[piers].all()
    if builder == "aqueduct":
        assert has.all()
