"""Scenario data classes and constructors: loading the example files, defaults, config checks. The sampling
check (too fast a sine or a support): test_scenario_sampling.py."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scenario_helpers import BLOCK, DATA, GROUND, write

from geometry_library.blocks import Assembly, Block, Support
from masonrycli.errors import InputError
from masonrycli.scenario.motion import Fixed, Sine
from masonrycli.scenario.scenario import (
    Material,
    RunConfig,
    scenario_summary,
)
from masonrycli.scenario.toml_file import load_scenario, loads_scenario

# ------------------------------------------------------------------------------------------- loading


def test_block_on_ground_example():
    s = load_scenario(DATA / "block_on_ground.toml")
    assert s.name == "block-on-harmonic-ground"
    assert s.source == str(DATA / "block_on_ground.toml")
    assert s.run == RunConfig()
    assert s.run.n_steps == 1000
    assert s.material == Material(density=2000.0, thickness=1.0, friction=0.6)
    assert s.friction == 0.6
    assert [b.name for b in s.assembly.blocks] == ["block"]
    (block,) = s.assembly.blocks
    assert block.density == 2000.0 and block.thickness == 1.0 and tuple(block.velocity) == (0.0, 0.0, 0.0)
    assert block.polygon.area == pytest.approx(0.08)
    (ground,) = s.assembly.supports
    assert ground.name == "ground" and ground.role == "driven"
    assert s.motions == (Sine(direction=(1.0, 0.0), amplitude=1.0, frequency=2.0),)
    assert s.structure == {}


def test_column_example_and_summary():
    s = load_scenario(DATA / "column_5.toml")
    assert [b.name for b in s.assembly.blocks] == ["k5", "k4", "k3", "k2", "k1"]
    assert s.run.duration == 0.2 and s.run.n_steps == 200 and s.run.theta == 0.5
    assert s.motions == (Fixed(),) and s.assembly.supports[0].role == "fixed"
    summary = scenario_summary(s)
    assert summary["blocks"] == 5 and summary["supports"] == 1
    assert summary["total_mass"] == pytest.approx(5 * 0.4 * 0.2 * 2000.0, rel=1e-12)
    assert summary["bounding_box"] == pytest.approx((-1.0, -0.2, 1.0, 1.0))
    assert summary["support_motions"] == [{"name": "ground", "role": "fixed", "motion": "fixed"}]
    assert summary["n_steps"] == 200 and summary["friction"] == 0.6 and summary["warnings"] == []


def test_defaults_and_default_names(tmp_path):
    path = write(
        tmp_path,
        "[[block]]\npolygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\n"
        "[[block]]\npolygon = [[0, 1], [1, 1], [1, 2], [0, 2]]\ndensity = 1000\n"
        "[[support]]\npolygon = [[-1, -1], [2, -1], [2, 0], [-1, 0]]\n",
        "my_wall.toml",
    )
    s = load_scenario(path)
    assert s.name == "my_wall"
    assert s.run == RunConfig(1.0, 1e-3, 0.5, (0.0, -9.81), 1e-5, 100000, 10, 1e-3)
    assert s.material == Material(2500.0, 1.0, 0.6)
    assert [b.name for b in s.assembly.blocks] == ["block-1", "block-2"]
    assert [b.density for b in s.assembly.blocks] == [2500.0, 1000.0]
    assert isinstance(s.assembly.blocks[1].density, float)
    assert [x.name for x in s.assembly.supports] == ["support-1"]
    assert s.motions == (Fixed(),) and s.warnings == ()


def test_ints_accepted_for_floats_and_vertices_oriented_ccw(tmp_path):
    path = write(
        tmp_path,
        "[run]\nduration = 2\ndt = 1\ngravity = [0, -10]\n"
        "[[block]]\npolygon = [[0, 0], [0, 1], [1, 1], [1, 0]]\nvelocity = [1, 2, 3]\n",
    )
    s = load_scenario(path)
    assert s.run.duration == 2.0 and isinstance(s.run.duration, float) and s.run.gravity == (0.0, -10.0)
    assert s.run.n_steps == 2
    v = s.assembly.blocks[0].vertices
    area2 = np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1])
    assert area2 > 0  # counter-clockwise
    assert tuple(s.assembly.blocks[0].velocity) == (1.0, 2.0, 3.0)


def test_run_config_n_steps():
    assert RunConfig(duration=1.0, dt=1e-3).n_steps == 1000
    assert RunConfig(duration=5.0, dt=1e-3).n_steps == 5000
    assert RunConfig(duration=0.3, dt=0.1).n_steps == 3  # 0.3/0.1 = 2.9999999999999996


def test_programmatic_config_errors():
    with pytest.raises(InputError, match=r"^dt = -0\.001: must be > 0$"):
        RunConfig(dt=-0.001)
    with pytest.raises(InputError, match=r"^friction = -1\.0: must be >= 0$"):
        Material(friction=-1.0)
    with pytest.raises(InputError, match=r"^friction = 1001\.0: must be <= 1000 \(a likely typo"):
        Material(friction=1001.0)
    assert Material(friction=1000.0).friction == 1000.0
    with pytest.raises(InputError, match=r"^thickness = 1e\+300: must be between 1e-06 and 1000 m \(a likely typo\)$"):
        Material(thickness=1e300)
    with pytest.raises(InputError, match=r"^density = 1e-300: must be between 0.001 and 100000 kg/m³"):
        Material(density=1e-300)
    with pytest.raises(InputError, match=r"^theta = 0\.2: must be >= 0\.5$"):
        dataclasses.replace(RunConfig(), theta=0.2)


def test_a_hand_made_block_is_simulated_as_validate_assembly_checked_it():
    """A Block made in Python with a vertex 0.2 mm inside its bottom edge (within the 0.33 mm shape
    tolerance of a 0.3 × 0.2 m block) passes validate_assembly, which checks the cleaned polygon; the
    engine was given the non-convex 5-vertex one. Now the scenario holds the cleaned rectangle, so the
    model (what the engine and the recording get) has its 4 corners; a real 1 mm dent is refused."""
    from shapely.geometry import Polygon, box

    from geometry_library import validate_assembly
    from masonrycli.run import Simulation
    from masonrycli.scenario.scenario import Scenario

    def scenario(dent):
        block = Block(Polygon([(0, 0), (0.15, dent), (0.3, 0), (0.3, 0.2), (0, 0.2)]), "dented")
        ground = Support(box(-1, -0.1, 1, 0), "ground")
        return Scenario("hand-made", RunConfig(duration=0.01), Material(), Assembly((block,), (ground,)), (Fixed(),))

    dented = scenario(2e-4)
    assert validate_assembly(dented.assembly) == []
    model = Simulation(dented).model
    corners = model.vert_local[model.body_vert_start[0] : model.body_vert_start[1]] + model.body_q0[0, :2]
    assert sorted(map(tuple, np.round(corners, 12).tolist())) == [(0, 0), (0, 0.2), (0.3, 0), (0.3, 0.2)]
    assert len(dented.assembly.blocks[0].vertices) == 4
    with pytest.raises(
        InputError, match=r'^block 1 \("dented"\): polygon is not convex \(reflex vertex at \(0.15, 0.001\)\)$'
    ):
        scenario(1e-3)


def test_an_initial_velocity_faster_than_a_diverged_block_is_refused(tmp_path):
    # velocity = [1e9, 0, 0] ran and ended as exit 3, "diverged at step 1": refused like a support that fast,
    # by the speed of the block's fastest point |v| + |ω|·r (r: farthest vertex from the centroid)
    from masonrycli import run as run_module
    from masonrycli.scenario.scenario import MAX_BLOCK_SPEED, scenario_from_geometry_file

    assert MAX_BLOCK_SPEED == run_module.DIVERGENCE_SPEED
    r = math.hypot(0.2, 0.1)  # the 0.4 m × 0.2 m block: centroid (0.2, 0.1), a corner at r from it

    def scenario(velocity: str):
        return loads_scenario(BLOCK + f"velocity = {velocity}\n" + GROUND, source=str(tmp_path / "v.toml"))

    for fine in ("[1000.0, 0.0, 0.0]", "[600.0, -800.0, 0.0]", f"[0.0, 0.0, {0.999 * 1000 / r}]"):
        scenario(fine)
    for fast in ("[1e9, 0.0, 0.0]", "[800.0, 800.0, 0.0]", f"[0.0, 0.0, {1.001 * 1000 / r}]", "[999.0, 0.0, -10.0]"):
        with pytest.raises(
            InputError, match=r'v\.toml:4: \[\[block\]\] #1 \("b1"\): velocity = \[.*\]: a point of the '
        ):
            scenario(fast)
    with pytest.raises(InputError) as info:
        scenario("[1e9, 0.0, 0.0]")
    assert str(info.value) == (
        f'{tmp_path / "v.toml"}:4: [[block]] #1 ("b1"): velocity = [1000000000.0, 0.0, 0.0]: a point of the block '
        "would move at 1e+09 m/s, more than 1000 m/s (a likely typo: a block that fast is a diverged run)"
    )
    # a GeoJSON block's velocity: the same check, the block numbered from 1 as in the file
    geo = tmp_path / "g.geojson"
    square = [[[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]]
    features = [
        {"type": "Feature", "properties": {"role": "block", "name": n, "velocity": v}, "geometry": g}
        for n, v, g in (
            ("a", [0, 0, 0], {"type": "Polygon", "coordinates": square}),
            ("b", [0, 0, 5000], {"type": "Polygon", "coordinates": [[[x, y + 1] for x, y in square[0]]]}),
        )
    ]
    import json

    geo.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    with pytest.raises(InputError) as info:
        scenario_from_geometry_file(geo)
    assert str(info.value).startswith(f'{geo}: block 2 ("b"): velocity = [0.0, 0.0, 5000.0]: a point of the block')


def test_an_alert_distance_longer_than_the_structure_is_refused(tmp_path):
    # alert_distance = 1e9 was accepted: a gap longer than the blocks' extent is no contact
    # b2: 0.4 m × 0.2 m, 0.1 m above b1; the two span 0.4 m × 0.5 m
    two = BLOCK + '[[block]]\nname = "b2"\npolygon = [[0.0, 0.3], [0.4, 0.3], [0.4, 0.5], [0.0, 0.5]]\n'

    def scenario(alert: float, blocks: str = two):
        text = f"[run]\nalert_distance = {alert!r}\n" + blocks + GROUND
        return loads_scenario(text, source=str(tmp_path / "a.toml"))

    assert scenario(0.5).run.alert_distance == 0.5  # the extent itself: accepted
    assert scenario(0.4, BLOCK).run.alert_distance == 0.4  # one block: its width
    with pytest.raises(InputError) as info:
        scenario(0.41, BLOCK)
    assert str(info.value) == (
        f"{tmp_path / 'a.toml'}:2: [run] alert_distance = 0.41: longer than the structure (0.4 m, the larger side "
        "of its blocks' bounding box); a likely typo: contacts closer than this are kept (default 0.001 m)"
    )
    with pytest.raises(InputError, match=r"\[run\] alert_distance = 1000000000.0: longer than the structure \(0.5 m"):
        scenario(1e9)


def test_too_many_steps_says_how_many_exactly():
    # 1.001e8 steps was "gives 1e+08 steps ... (at most 1e+08)": the refusal read like a contradiction
    with pytest.raises(InputError) as exc:
        RunConfig(duration=1001.0, dt=1e-5)
    assert str(exc.value) == "duration = 1001.0 at dt = 1e-05 is 100,100,000 steps (at most 100,000,000)"
