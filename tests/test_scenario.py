"""Scenario files: parsing, defaults, round trip through dump_scenario, builder scenarios, error messages."""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path

import numpy as np
import pytest

import geometry_library.builders as builders_pkg
from geometry_library.blocks import Assembly, Block, GeometryError, Support
from masonrycli.errors import InputError
from masonrycli.motion import Constant, Fixed, Sine
from masonrycli.records import record_motion
from masonrycli.scenario import (
    Material,
    RunConfig,
    Scenario,
    scenario_from_builder,
    scenario_summary,
)
from masonrycli.scenario_toml import dump_scenario, load_scenario, loads_scenario

DATA = Path(__file__).parent / "data"

BLOCK = '[[block]]\nname = "b1"\npolygon = [[0.0, 0.0], [0.4, 0.0], [0.4, 0.2], [0.0, 0.2]]\n'
BLOCK2 = '[[block]]\nname = "b2"\npolygon = [[0.0, 0.2], [0.4, 0.2], [0.4, 0.4], [0.0, 0.4]]\n'
GROUND = '[[support]]\nname = "ground"\npolygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]\n'


def write(tmp_path: Path, text: str, name: str = "wall.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def load_error(tmp_path: Path, text: str, name: str = "wall.toml") -> str:
    path = write(tmp_path, text, name)
    with pytest.raises(InputError) as exc:
        load_scenario(path)
    msg = str(exc.value)
    assert "\n" not in msg and msg == msg.strip()
    assert msg.startswith(f"{path}: "), msg
    return msg[len(str(path)) + 2 :]  # the part after "<file>: "


def assert_same_scenario(a: Scenario, b: Scenario):
    """Same run, material, motions, names, roles, vertices (1e-12), densities, thicknesses, velocities."""
    assert a.name == b.name
    assert a.run == b.run
    assert a.material == b.material
    assert a.motions == b.motions
    assert a.assembly.block_count == b.assembly.block_count
    assert a.assembly.support_count == b.assembly.support_count
    for x, y in zip(a.assembly.blocks, b.assembly.blocks):
        assert x.name == y.name
        assert x.vertices.shape == y.vertices.shape
        np.testing.assert_allclose(x.vertices, y.vertices, rtol=0, atol=1e-12)
        assert (x.density, x.thickness, tuple(x.velocity)) == (y.density, y.thickness, tuple(y.velocity))
    for x, y in zip(a.assembly.supports, b.assembly.supports):
        assert (x.name, x.role) == (y.name, y.role)
        np.testing.assert_allclose(x.vertices, y.vertices, rtol=0, atol=1e-12)


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
    assert s.run == RunConfig(1.0, 1e-3, 0.5, (0.0, -9.81), 1e-5, 50000, 10, 1e-3)
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


# ----------------------------------------------------------------------------------------- round trip

RECORD_CSV = "t,v\n0.0,0.1\n0.05,0.3333333333333333\n0.2,-0.7\n"
XY_CSV = "0 0 0\n0.5 1e-3 -2e-3\n1.5 0.25 0.125\n"

ROUND_TRIP = """
name = "odd \\"name\\" é \\\\ 1"

[run]
duration = 2.4
dt = 3.0000000000000004e-4
theta = 0.7
gravity = [1.2345678901234567, -9.81]
tolerance = 1e-6
max_iterations = 77
record_every = 3
alert_distance = 2.5e-3

[material]
density = 2400.5
thickness = 0.45
friction = 0.75

[[block]]
name = "third"
polygon = [[0.0, 0.0], [0.3333333333333333, 0.0], [0.3333333333333333, 0.1], [0.0, 0.1]]

[[block]]
name = "heavy"
polygon = [[1.0, 0.0], [1.4, 0.0], [1.4, 0.2], [1.0, 0.2]]
density = 2600.0
thickness = 0.5
velocity = [0.1, -0.2, 0.30000000000000004]

[[block]]
polygon = [[3.0, 0.0], [3.2, 0.0], [3.3, 0.1732], [3.2, 0.3464], [3.0, 0.3464], [2.9, 0.1732]]

[[block]]
name = "clockwise"
polygon = [[5.0, 0.0], [5.0, 0.2], [5.4, 0.2], [5.4, 0.0]]

[[support]]
name = "fixed pad"
polygon = [[-1.0, -0.5], [0.9, -0.5], [0.9, 0.0], [-1.0, 0.0]]

[[support]]
name = "settling"
polygon = [[0.9, -0.5], [1.9, -0.5], [1.9, 0.0], [0.9, 0.0]]
motion = { kind = "constant", velocity = [0.0, -0.01] }

[[support]]
name = "shaker"
polygon = [[1.9, -0.5], [2.5, -0.5], [2.5, 0.0], [1.9, 0.0]]
motion = { kind = "sine", direction = [3.0, 4.0], amplitude = 0.3, frequency = 2.5, phase = 0.1 }

[[support]]
name = "pulse"
polygon = [[2.5, -0.5], [3.5, -0.5], [3.5, 0.0], [2.5, 0.0]]
motion = { kind = "ramp", acceleration = [0.5, 0.0], until = 0.25 }

[[support]]
name = "ramp"
polygon = [[3.5, -0.5], [4.5, -0.5], [4.5, 0.0], [3.5, 0.0]]
[support.motion]
kind = "ramp"
acceleration = [0.0, -0.1]

[[support]]
name = "quake"
polygon = [[4.5, -0.5], [5.5, -0.5], [5.5, 0.0], [4.5, 0.0]]
motion = { kind = "record", file = "records/quake.csv", scale = 1.5, direction = [0.0, 1.0] }

[[support]]
name = "quake-xy"
polygon = [[5.5, -0.5], [6.5, -0.5], [6.5, 0.0], [5.5, 0.0]]
motion = { kind = "record", file = "records/xy.csv", quantity = "acceleration" }

[[support]]
name = "inline"
polygon = [[6.5, -0.5], [7.5, -0.5], [7.5, 0.0], [6.5, 0.0]]
motion = { kind = "record", time = [0.0, 0.1, 0.3], value = [0.0, 1.0, 0.5], quantity = "acceleration" }

[[support]]
name = "inline-xy"
polygon = [[7.5, -0.5], [8.5, -0.5], [8.5, 0.0], [7.5, 0.0]]
motion = { kind = "record", time = [0.0, 1.0], value = [[0.1, 0.2], [0.3, 0.4]] }
"""


@pytest.fixture
def round_trip_file(tmp_path):
    (tmp_path / "records").mkdir()
    (tmp_path / "records" / "quake.csv").write_text(RECORD_CSV)
    (tmp_path / "records" / "xy.csv").write_text(XY_CSV)
    return write(tmp_path, ROUND_TRIP, "trip.toml")


def test_round_trip_explicit(round_trip_file, tmp_path, monkeypatch):
    s = load_scenario(round_trip_file)
    assert s.name == 'odd "name" é \\ 1'
    assert [m.kind for m in s.motions] == [
        "fixed",
        "constant",
        "sine",
        "ramp",
        "ramp",
        "record",
        "record",
        "record",
        "record",
    ]
    assert [x.role for x in s.assembly.supports] == ["fixed"] + ["driven"] * 8
    assert s.assembly.blocks[2].name == "block-3"
    assert s.motions[5].source == str(tmp_path / "records" / "quake.csv")
    assert s.motions[5].value == (0.1, 0.3333333333333333, -0.7)
    assert s.motions[6].value == ((0.0, 0.0), (1e-3, -2e-3), (0.25, 0.125))

    text = dump_scenario(s)
    # load from elsewhere: record files are written as absolute paths
    other = tmp_path / "elsewhere"
    other.mkdir()
    monkeypatch.chdir(other)
    again = loads_scenario(text, source="dumped.toml", base_dir=other)
    assert_same_scenario(s, again)
    for x, y in zip(s.assembly.blocks, again.assembly.blocks):
        np.testing.assert_array_equal(x.vertices, y.vertices)  # repr() floats: bit for bit
    assert dump_scenario(again).split("\n")[3:] == text.split("\n")[3:]  # idempotent (header comments differ)

    inline = dump_scenario(s, inline_records=True)
    assert "file =" not in inline
    again = loads_scenario(inline, base_dir=other)
    assert [m.source for m in again.motions[5:7]] == ["", ""]
    strip = [dataclasses.replace(m, source="") if m.kind == "record" else m for m in s.motions]
    assert again.motions == tuple(strip)


def test_round_trip_examples():
    for name in ("block_on_ground.toml", "column_5.toml", "quake_record.toml"):
        s = load_scenario(DATA / name)
        assert_same_scenario(s, loads_scenario(dump_scenario(s), base_dir="/"))


def test_dump_is_toml_with_expected_sections():
    import tomllib

    s = load_scenario(DATA / "block_on_ground.toml")
    doc = tomllib.loads(dump_scenario(s))
    assert set(doc) == {"name", "run", "material", "block", "support"}
    assert doc["support"][0]["motion"] == {
        "kind": "sine",
        "direction": [1.0, 0.0],
        "amplitude": 1.0,
        "frequency": 2.0,
        "phase": 0.0,
    }
    assert "density" not in doc["block"][0]  # equal to the material default: not repeated


def test_programmatic_scenario_round_trip_and_role_fix():
    base = load_scenario(DATA / "block_on_ground.toml")
    fixed_ground = Support(polygon=base.assembly.supports[0].polygon, name="ground", role="fixed")
    asm = Assembly(blocks=base.assembly.blocks, supports=(fixed_ground,))
    rec = record_motion(DATA / "accel_constant.csv", quantity="acceleration", scale=-1.0)
    s = Scenario(name="prog", run=RunConfig(duration=0.5), material=Material(friction=0.3), assembly=asm, motions=[rec])
    assert s.assembly.supports[0].role == "driven"  # made consistent with the motion
    assert isinstance(s.motions, tuple)
    assert_same_scenario(s, loads_scenario(dump_scenario(s)))
    with pytest.raises(InputError, match="2 motions for 1 supports"):
        Scenario(name="bad", run=RunConfig(), material=Material(), assembly=asm, motions=(Fixed(), Fixed()))


# ------------------------------------------------------------------------------------- record files


def test_relative_record_path_resolves_against_scenario_folder(tmp_path, monkeypatch):
    sub = tmp_path / "project" / "scenarios"
    (sub / "records").mkdir(parents=True)
    (sub / "records" / "q.csv").write_text("0,0\n1,2\n")
    write(
        sub,
        BLOCK + GROUND.replace("polygon", 'motion = { kind = "record", file = "records/q.csv" }\npolygon'),
        "scen.toml",
    )
    monkeypatch.chdir(tmp_path)
    for path in (Path("project/scenarios/scen.toml"), sub / "scen.toml"):
        s = load_scenario(path)
        assert s.motions[0].source == str(sub / "records" / "q.csv")
        assert s.motions[0].velocity_at([0.5])[0, 0] == pytest.approx(1.0)
    # the example file in tests/data, loaded from another working directory
    s = load_scenario(DATA / "quake_record.toml")
    assert s.motions[0].source == str(DATA / "quake_velocity.csv")
    assert s.motions[0].velocity_at([0.1])[0, 0] == pytest.approx(0.4)  # scale 2
    # an absolute file path is used as is
    text = BLOCK + GROUND.replace(
        "polygon", f'motion = {{ kind = "record", file = "{DATA / "ground_xy.csv"}" }}\npolygon'
    )
    s = load_scenario(write(tmp_path, text, "abs.toml"))
    assert s.motions[0].is_vector


def test_missing_record_file_names_resolved_path(tmp_path):
    text = BLOCK + GROUND.replace("polygon", 'motion = { kind = "record", file = "nope.csv" }\npolygon')
    msg = load_error(tmp_path, text)
    assert msg == (
        f'[[support]] #1 ("ground"): motion.file = "nope.csv": no such file (looked for {tmp_path / "nope.csv"})'
    )


def test_bad_record_row_names_scenario_csv_and_line(tmp_path):
    (tmp_path / "q.csv").write_text("t,v\n0,0\n0.1,x\n")
    text = BLOCK + GROUND.replace("polygon", 'motion = { kind = "record", file = "q.csv" }\npolygon')
    assert load_error(tmp_path, text) == '[[support]] #1 ("ground"): motion.file: q.csv:3: not a number: "x"'


# ------------------------------------------------------------------------------------------- errors

RUN_ERRORS = [
    ("dt = -0.001", "[run] dt = -0.001: must be > 0"),
    ("dt = 0", "[run] dt = 0: must be > 0"),
    ("dt = 2.0", "[run] dt = 2.0: must be <= duration (1.0)"),
    ("dt = 1e-12", "[run] dt = 1e-12: gives 1e+12 steps"),
    ("duration = 0.0", "[run] duration = 0.0: must be > 0"),
    ("duration = -1", "[run] duration = -1: must be > 0"),
    ("duration = 1e6", "[run] duration = 1000000.0: must be <= 100000"),
    ("duration = inf", "[run] duration = inf: must be a finite number"),
    ("duration = nan", "[run] duration = nan: must be a finite number"),
    ('duration = "1 s"', '[run] duration = "1 s": must be a number'),
    ("theta = 0.4", "[run] theta = 0.4: must be >= 0.5"),
    ("theta = 1.01", "[run] theta = 1.01: must be <= 1"),
    ("tolerance = 0.0", "[run] tolerance = 0.0: must be > 0"),
    ("tolerance = -1e-4", "[run] tolerance = -0.0001: must be > 0"),
    ("max_iterations = 0", "[run] max_iterations = 0: must be >= 1"),
    ("max_iterations = 10.5", "[run] max_iterations = 10.5: must be an integer"),
    ("max_iterations = true", "[run] max_iterations = true: must be an integer"),
    ("record_every = 0", "[run] record_every = 0: must be >= 1"),
    ("record_every = -3", "[run] record_every = -3: must be >= 1"),
    ("gravity = [0.0]", "[run] gravity = [0.0]: must be 2 numbers [x, y]"),
    ("gravity = -9.81", "[run] gravity = -9.81: must be 2 numbers [x, y]"),
    ("gravity = [0.0, -9.81, 0.0]", "[run] gravity = [0.0, -9.81, 0.0]: must be 2 numbers [x, y]"),
    ('gravity = ["0", 1]', '[run] gravity = ["0", 1]: must be 2 numbers [x, y]'),
    ("gravity = [nan, -9.81]", "[run] gravity = [nan, -9.81]: must be finite numbers"),
    ("alert_distance = -1e-3", "[run] alert_distance = -0.001: must be > 0"),
    ("dtt = 0.1", '[run] unknown key "dtt" (did you mean "dt"?)'),
]


@pytest.mark.parametrize("line, expected", RUN_ERRORS, ids=[e[0] for e in RUN_ERRORS])
def test_run_errors(tmp_path, line, expected):
    msg = load_error(tmp_path, f"[run]\n{line}\n" + BLOCK)
    assert msg == expected or msg.startswith(expected + " ")


MATERIAL_ERRORS = [
    ("friction = -0.1", "[material] friction = -0.1: must be >= 0"),
    ("friction = nan", "[material] friction = nan: must be a finite number"),
    ("density = 0.0", "[material] density = 0.0: must be > 0"),
    ("density = -inf", "[material] density = -inf: must be a finite number"),
    ("thickness = -1", "[material] thickness = -1: must be > 0"),
    ('thickness = "1m"', '[material] thickness = "1m": must be a number'),
    ("mu = 0.6", '[material] unknown key "mu" (expected one of: density, thickness, friction)'),
]


@pytest.mark.parametrize("line, expected", MATERIAL_ERRORS, ids=[e[0] for e in MATERIAL_ERRORS])
def test_material_errors(tmp_path, line, expected):
    assert load_error(tmp_path, f"[material]\n{line}\n" + BLOCK) == expected


BLOCK_ERRORS = [
    ("velocty = [0.0, 0.0, 0.0]", '[[block]] #2 ("b2"): unknown key "velocty" (did you mean "velocity"?)'),
    ("density = 0", '[[block]] #2 ("b2"): density = 0: must be > 0'),
    ("density = nan", '[[block]] #2 ("b2"): density = nan: must be a finite number'),
    ("thickness = -0.5", '[[block]] #2 ("b2"): thickness = -0.5: must be > 0'),
    ("velocity = [1.0, 2.0]", '[[block]] #2 ("b2"): velocity = [1.0, 2.0]: must be 3 numbers [vx, vy, omega]'),
    ("velocity = [1.0, 2.0, inf]", '[[block]] #2 ("b2"): velocity = [1.0, 2.0, inf]: must be finite numbers'),
]


@pytest.mark.parametrize("line, expected", BLOCK_ERRORS, ids=[e[0] for e in BLOCK_ERRORS])
def test_block_errors(tmp_path, line, expected):
    assert load_error(tmp_path, BLOCK + BLOCK2 + line + "\n") == expected


@pytest.mark.parametrize(
    "block, expected",
    [
        (
            '[[block]]\nname = "b3"\n',
            '[[block]] #1 ("b3"): polygon: missing (e.g. polygon = [[0.0, 0.0], [0.4, 0.0], [0.4, 0.2], [0.0, 0.2]])',
        ),
        (
            '[[block]]\nname = "b3"\npolygon = [[0, 0], [1, 0]]\n',
            '[[block]] #1 ("b3"): polygon = [[0, 0], [1, 0]]: needs at least 3 vertices, got 2',
        ),
        (
            '[[block]]\nname = "b3"\npolygon = [[0, 0], [1], [1, 1]]\n',
            '[[block]] #1 ("b3"): polygon[1] = [1]: must be 2 numbers [x, y]',
        ),
        (
            '[[block]]\nname = "b3"\npolygon = [[0, 0], [1, nan], [1, 1]]\n',
            '[[block]] #1 ("b3"): polygon[1] = [1, nan]: must be finite numbers',
        ),
        (
            '[[block]]\nname = "b3"\npolygon = "POLYGON ((0 0, 1 0, 1 1))"\n',
            '[[block]] #1 ("b3"): polygon = "POLYGON ((0 0, 1 0, 1 1))": must be a list of [x, y] vertices',
        ),
        ("[[block]]\nname = 3\npolygon = [[0, 0], [1, 0], [1, 1]]\n", "[[block]] #1: name = 3: must be a string"),
        ('[[block]]\nname = ""\npolygon = [[0, 0], [1, 0], [1, 1]]\n', '[[block]] #1: name = "": must not be empty'),
    ],
)
def test_block_polygon_and_name_errors(tmp_path, block, expected):
    assert load_error(tmp_path, block) == expected


def test_duplicate_names(tmp_path):
    msg = load_error(tmp_path, BLOCK + BLOCK2.replace('"b2"', '"b1"'))
    assert msg == '[[block]] #2 ("b1"): name = "b1": already used by [[block]] #1 ("b1") (names must be unique)'
    msg = load_error(tmp_path, BLOCK + GROUND.replace('"ground"', '"b1"'))
    assert msg.startswith('[[support]] #1 ("b1"): name = "b1": already used by [[block]] #1')


def test_geometry_errors_become_input_errors(tmp_path):
    # geometry_library's message, with our locator instead of its "block 1 (...)" label
    text = BLOCK + '[[block]]\nname = "dart"\npolygon = [[0, 1], [2, 1], [1, 1.5], [1, 3]]\n'
    msg = load_error(tmp_path, text)
    assert msg.startswith('[[block]] #2 ("dart"): ') and "not convex" in msg
    text = BLOCK + '[[support]]\nname = "flat"\npolygon = [[0, 0], [1, 0], [2, 0]]\n'
    msg = load_error(tmp_path, text)
    assert msg.startswith('[[support]] #1 ("flat"): ') and "area" in msg
    text = '[[block]]\nname = "bow"\npolygon = [[0, 0], [1, 1], [1, 0], [0, 1]]\n'
    msg = load_error(tmp_path, text)
    assert msg.startswith('[[block]] #1 ("bow"): ') and "self-intersects" in msg


def test_real_overlap_check(tmp_path):
    text = BLOCK + '[[block]]\nname = "b2"\npolygon = [[0.1, 0.1], [0.5, 0.1], [0.5, 0.3], [0.1, 0.3]]\n'
    msg = load_error(tmp_path, text)
    assert "overlap" in msg and '"b1"' in msg and '"b2"' in msg


def test_validate_assembly_errors_and_warnings(tmp_path, monkeypatch):
    import geometry_library.checks as checks

    def overlapping(assembly):
        raise GeometryError('block 0 ("b1") overlaps block 1 ("b2")')

    monkeypatch.setattr(checks, "validate_assembly", overlapping)
    assert load_error(tmp_path, BLOCK + BLOCK2) == 'block 0 ("b1") overlaps block 1 ("b2")'

    monkeypatch.setattr(checks, "validate_assembly", lambda a: ["blocks b1 and b2 are 2 mm apart", "multi\nline"])
    s = load_scenario(write(tmp_path, BLOCK + BLOCK2))
    assert s.warnings == ("blocks b1 and b2 are 2 mm apart", "multi line")
    assert scenario_summary(s)["warnings"] == list(s.warnings)


MOTION_ERRORS = [
    (
        '{ kind = "shake" }',
        'motion.kind = "shake": unknown motion kind (expected one of fixed, constant, sine, ramp, record)',
    ),
    ("{ amplitude = 1.0 }", "motion.kind: missing (one of fixed, constant, sine, ramp, record)"),
    ('{ kind = "sine", frequency = 2.0 }', 'motion.amplitude: missing (required for kind "sine")'),
    ('{ kind = "sine", amplitude = 1.0 }', 'motion.frequency: missing (required for kind "sine")'),
    (
        '{ kind = "sine", amplitude = 1.0, frequency = 2.0, direction = [0.0, 0.0] }',
        "motion.direction = [0.0, 0.0]: must not be the zero vector",
    ),
    ('{ kind = "sine", amplitude = 1.0, frequency = -2.0 }', "motion.frequency = -2.0: must be >= 0"),
    ('{ kind = "sine", amplitude = nan, frequency = 2.0 }', "motion.amplitude = nan: must be a finite number"),
    (
        '{ kind = "sine", amplitude = 1.0, frequency = 2.0, velocity = [1.0, 0.0] }',
        'motion.velocity: not used by kind "sine" (its keys: kind, direction, amplitude, frequency, phase)',
    ),
    (
        '{ kind = "sine", amplitude = 1.0, frequncy = 2.0 }',
        'motion: unknown key "frequncy" (did you mean "frequency"?)',
    ),
    ('{ kind = "constant" }', 'motion.velocity: missing (required for kind "constant")'),
    (
        '{ kind = "constant", velocity = [0.0, -0.01, 0.0] }',
        "motion.velocity = [0.0, -0.01, 0.0]: must be 2 numbers [x, y]",
    ),
    ('{ kind = "ramp" }', 'motion.acceleration: missing (required for kind "ramp")'),
    ('{ kind = "ramp", acceleration = [1.0, 0.0], until = -1.0 }', "motion.until = -1.0: must be > 0"),
    ('{ kind = "ramp", acceleration = [1.0, 0.0], until = nan }', "motion.until = nan: must be a finite number"),
    ('{ kind = "fixed", amplitude = 1.0 }', 'motion.amplitude: not used by kind "fixed" (its keys: kind)'),
    ('{ kind = "record" }', 'motion.time: missing (kind "record" needs file, or time and value)'),
    ('{ kind = "record", time = [0.0, 1.0] }', 'motion.value: missing (kind "record" needs file, or time and value)'),
    ('{ kind = "record", time = [0.0, 1.0], value = [1.0] }', "motion.value = [1.0]: has 1 samples but"),
    ('{ kind = "record", time = [1.0, 0.0], value = [1.0, 2.0] }', "motion.time[1] = 0.0: must be > the previous"),
    (
        '{ kind = "record", time = [0.0, 1.0], value = [1.0, 2.0], quantity = "displacement" }',
        'motion.quantity = "displacement": must be "velocity" or "acceleration"',
    ),
    (
        '{ kind = "record", time = [0.0, 1.0], value = [1.0, 2.0], scale = inf }',
        "motion.scale = inf: must be a finite number",
    ),
    (
        '{ kind = "record", time = [0.0, 1.0], value = [[1.0, 2.0], [3.0, 4.0]], direction = [0.0, 1.0] }',
        "motion.direction: not used by a vector record",
    ),
    (
        '{ kind = "record", file = "q.csv", time = [0.0, 1.0], value = [1.0, 2.0] }',
        "motion.file: give either file or inline time and value, not both",
    ),
    ('{ kind = "record", file = 3 }', "motion.file = 3: must be a file name"),
    ('"sine"', 'motion = "sine": must be a table'),
]


@pytest.mark.parametrize("motion, expected", MOTION_ERRORS, ids=[e[0] for e in MOTION_ERRORS])
def test_motion_errors(tmp_path, motion, expected):
    text = BLOCK + GROUND + f"motion = {motion}\n"
    msg = load_error(tmp_path, text)
    assert msg.startswith('[[support]] #1 ("ground"): ')
    assert expected in msg


def test_three_column_record_file_rejects_direction(tmp_path):
    (tmp_path / "xy.csv").write_text(XY_CSV)
    text = BLOCK + GROUND + 'motion = { kind = "record", file = "xy.csv", direction = [1.0, 0.0] }\n'
    assert (
        load_error(tmp_path, text)
        == '[[support]] #1 ("ground"): motion.direction: not used by a 3-column record (xy.csv gives x and y)'
    )


@pytest.mark.parametrize(
    "text, expected",
    [
        ("[runn]\ndt = 0.1\n" + BLOCK, 'unknown key "runn" (did you mean "run"?)'),
        ("run = 3\n" + BLOCK, "run = 3: must be a table [run]"),
        ("[block]\npolygon = [[0, 0], [1, 0], [1, 1]]\n", "block: must be an array of tables [[block]]"),
        ("support = [1, 2]\n" + BLOCK, "support: must be an array of tables [[support]]"),
        ("name = 3\n" + BLOCK, "name = 3: must be a string"),
        ("[run]\ndt = 0.01\n", "no blocks: add [[block]] tables or a [structure] builder"),
        ("", "no blocks: add [[block]] tables or a [structure] builder"),
        (BLOCK + GROUND + "mass = 3\n", '[[support]] #1 ("ground"): unknown key "mass"'),
        (BLOCK + '[[support]]\nname = "g"\n', '[[support]] #1 ("g"): polygon: missing'),
    ],
)
def test_structure_errors(tmp_path, text, expected):
    assert load_error(tmp_path, text).startswith(expected)


def test_toml_syntax_error_has_line_number(tmp_path):
    msg = load_error(tmp_path, "[run]\nduration = 1.0\ndt = \n" + BLOCK)
    assert msg.startswith("TOML syntax error: ") and "line 3" in msg
    msg = load_error(tmp_path, "[run]\ndt = 0.1\ndt = 0.2\n" + BLOCK)
    assert msg.startswith("TOML syntax error: ") and "line 3" in msg


def test_unreadable_files(tmp_path):
    with pytest.raises(InputError) as exc:
        load_scenario(tmp_path / "missing.toml")
    msg = str(exc.value)
    assert "\n" not in msg and msg == f"{tmp_path / 'missing.toml'}: cannot read scenario: No such file or directory"
    (tmp_path / "bom.toml").write_bytes("\ufeff".encode() + BLOCK.encode())
    assert load_scenario(tmp_path / "bom.toml").assembly.block_count == 1
    with pytest.raises(InputError, match="is a directory"):
        load_scenario(tmp_path)
    (tmp_path / "latin.toml").write_bytes(b'name = "caf\xe9"\n')
    with pytest.raises(InputError, match=r"latin\.toml: not a UTF-8 text file"):
        load_scenario(tmp_path / "latin.toml")


def test_programmatic_config_errors():
    with pytest.raises(InputError, match=r"^dt = -0\.001: must be > 0$"):
        RunConfig(dt=-0.001)
    with pytest.raises(InputError, match=r"^friction = -1\.0: must be >= 0$"):
        Material(friction=-1.0)
    with pytest.raises(InputError, match=r"^theta = 0\.2: must be >= 0\.5$"):
        dataclasses.replace(RunConfig(), theta=0.2)


# ----------------------------------------------------------------------------------------- builders


def _rect(x0, y0, x1, y1):
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


@dataclasses.dataclass(frozen=True)
class FakeSpec:
    """A tiny builder spec with the geometry_library conventions (frozen dataclass, ``build()`` -> Assembly)."""

    bays: int = 2
    height: float = 0.2
    density: float = 2500.0
    thickness: float = 1.0
    label: str = "b"

    def build(self) -> Assembly:
        from geometry_library.checks import polygon_from_coords

        bays, label = self.bays, self.label
        if bays < 1:
            raise GeometryError(f"bays = {bays}: must be >= 1")
        blocks = tuple(
            Block(
                polygon_from_coords(_rect(0.4 * i, 0.0, 0.4 * i + 0.4, self.height), i, f"{label}{i}"),
                f"{label}{i}",
                self.density,
                self.thickness,
            )
            for i in range(bays)
        )
        supports = (
            Support(polygon_from_coords(_rect(-1.0, -0.5, 0.4, 0.0), 0, "ground"), "ground"),
            Support(polygon_from_coords(_rect(0.4, -0.5, 0.4 * bays + 1.0, 0.0), 1, "pad"), "pad"),
        )
        return Assembly(blocks=blocks, supports=supports)


@pytest.fixture
def fake_builders(monkeypatch):
    registry = {**builders_pkg.BUILDERS, "fake": FakeSpec}
    monkeypatch.setattr(builders_pkg, "BUILDERS", registry)
    return registry


def test_builder_scenario_file(tmp_path, fake_builders):
    text = (
        '[material]\ndensity = 2000.0\nthickness = 0.5\n[structure]\nbuilder = "fake"\nbays = 3\n'
        '[[support]]\nname = "pad"\nmotion = { kind = "constant", velocity = [0.0, -0.01] }\n'
    )
    s = load_scenario(write(tmp_path, text))
    assert s.structure == {"builder": "fake", "bays": 3}
    assert [b.name for b in s.assembly.blocks] == ["b0", "b1", "b2"]
    assert all(b.density == 2000.0 and b.thickness == 0.5 for b in s.assembly.blocks)  # from [material]
    assert [x.name for x in s.assembly.supports] == ["ground", "pad"]
    assert [x.role for x in s.assembly.supports] == ["fixed", "driven"]
    assert s.motions == (Fixed(), Constant(velocity=(0.0, -0.01)))

    # builder options override the material defaults; dumped as explicit blocks
    s2 = load_scenario(write(tmp_path, '[structure]\nbuilder = "fake"\ndensity = 1800\nheight = 1\n', "b.toml"))
    assert all(b.density == 1800.0 for b in s2.assembly.blocks) and s2.material.density == 2500.0
    text = dump_scenario(s2)
    assert '# generated by builder "fake" with density = 1800, height = 1' in text
    again = loads_scenario(text)
    assert_same_scenario(s2, again)
    assert again.structure == {}


BUILDER_ERRORS = [
    ("bayz = 3", '[structure] unknown option "bayz" of builder "fake" (did you mean "bays"?)'),
    ("bays = 2.5", "[structure] bays = 2.5: must be an integer"),
    ("bays = true", "[structure] bays = true: must be an integer"),
    ('height = "tall"', '[structure] height = "tall": must be a number'),
    ("height = nan", "[structure] height = nan: must be a finite number"),
    ("label = 3", "[structure] label = 3: must be a string"),
    ("bays = 0", '[structure] builder "fake": bays = 0: must be >= 1'),
]


@pytest.mark.parametrize("line, expected", BUILDER_ERRORS, ids=[e[0] for e in BUILDER_ERRORS])
def test_builder_option_errors(tmp_path, fake_builders, line, expected):
    assert load_error(tmp_path, f'[structure]\nbuilder = "fake"\n{line}\n') == expected


@pytest.mark.parametrize(
    "text, expected",
    [
        ('[structure]\nbuilder = "tower"\n', '[structure] builder = "tower": unknown builder (expected one of '),
        (
            "[structure]\nblocks = 51\n",
            '[structure] builder: missing (e.g. builder = "wall", or file = "my-wall.geojson")',
        ),
        ("[structure]\nbuilder = 3\n", "[structure] builder = 3: must be a string"),
        (
            '[structure]\nbuilder = "fake"\n' + BLOCK,
            '[[block]] #1 ("b1"): not allowed together with a [structure] builder',
        ),
        (
            '[structure]\nbuilder = "fake"\n[[support]]\nname = "moat"\n',
            '[[support]] #1 ("moat"): name = "moat": no such support in builder "fake" (supports: ground, pad)',
        ),
        (
            '[structure]\nbuilder = "fake"\n[[support]]\nmotion = { kind = "fixed" }\n',
            '[[support]] #1: name: missing (builder "fake" supports: ground, pad)',
        ),
        (
            '[structure]\nbuilder = "fake"\n' + GROUND,
            '[[support]] #1 ("ground"): polygon: not allowed with a [structure] (builder "fake" makes the supports',
        ),
        (
            '[structure]\nbuilder = "fake"\n[[support]]\nname = "pad"\n[[support]]\nname = "pad"\n',
            '[[support]] #2 ("pad"): name = "pad": support given twice',
        ),
        (
            '[structure]\nbuilder = "fake"\n[[support]]\nname = "pad"\nmotion = { kind = "sine" }\n',
            '[[support]] #1 ("pad"): motion.amplitude: missing (required for kind "sine")',
        ),
    ],
)
def test_builder_structure_errors(tmp_path, fake_builders, text, expected):
    assert load_error(tmp_path, text).startswith(expected)


def test_scenario_from_builder(fake_builders):
    shake = Sine(amplitude=1.0, frequency=2.0)
    s = scenario_from_builder("fake", {"bays": 4}, RunConfig(duration=0.5), Material(density=2200.0), {"ground": shake})
    assert s.name == "fake" and s.source == "builder:fake" and s.structure == {"builder": "fake", "bays": 4}
    assert s.assembly.block_count == 4 and all(b.density == 2200.0 for b in s.assembly.blocks)
    assert s.motions == (shake, Fixed())
    assert [x.role for x in s.assembly.supports] == ["driven", "fixed"]
    assert s.run.n_steps == 500
    summary = scenario_summary(s)
    assert summary["total_mass"] == pytest.approx(4 * 0.4 * 0.2 * 2200.0)
    assert summary["support_motions"][0] == {
        "name": "ground",
        "role": "driven",
        "motion": "sine 1 m/s · sin(2π·2 Hz·t) along (1, 0)",
    }

    with pytest.raises(InputError) as exc:
        scenario_from_builder("fake", {}, RunConfig(), Material(), {"moat": shake})
    assert str(exc.value) == 'builder "fake": no support named "moat" (supports: ground, pad)'
    with pytest.raises(InputError) as exc:
        scenario_from_builder("fake", {"bayz": 1}, RunConfig(), Material(), {})
    assert str(exc.value) == 'builder "fake": unknown option "bayz" of builder "fake" (did you mean "bays"?)'
    with pytest.raises(InputError) as exc:
        scenario_from_builder("fake", {"bays": 0}, RunConfig(), Material(), {})
    assert str(exc.value) == 'builder "fake": bays = 0: must be >= 1'
    with pytest.raises(InputError, match=r'^builder "fake": height = nan: must be a finite number$'):
        scenario_from_builder("fake", {"height": math.nan}, RunConfig(), Material(), {})


@pytest.mark.parametrize("name", ["wall", "arch", "aqueduct"])
def test_real_builders_round_trip(name):
    s = scenario_from_builder(name, {}, RunConfig(), Material(), {})
    assert s.assembly.block_count > 0 and len(s.motions) == s.assembly.support_count
    text = dump_scenario(s)
    assert_same_scenario(s, loads_scenario(text))
    summary = scenario_summary(s)
    assert summary["blocks"] == s.assembly.block_count and summary["total_mass"] > 0


def test_real_wall_builder_from_file(tmp_path):
    s = load_scenario(write(tmp_path, '[structure]\nbuilder = "wall"\n'))
    assert s.structure == {"builder": "wall"} and s.assembly.block_count > 0
    assert os.path.basename(s.source) == "wall.toml"


@pytest.mark.parametrize(
    "file, builder, blocks, motions",
    [
        ("wall_shaken.toml", "wall", 248, {"ground": Sine(amplitude=1.0, frequency=2.0)}),
        ("arch_settlement.toml", "arch", 98, {"right-foundation": Constant(velocity=(0.0, -0.01))}),
    ],
)
def test_paper_builder_scenarios(file, builder, blocks, motions):
    s = load_scenario(DATA / file)
    assert s.structure["builder"] == builder and s.assembly.block_count == blocks
    for support, motion in zip(s.assembly.supports, s.motions):
        assert motion == motions.get(support.name, Fixed())
        assert support.role == ("driven" if support.name in motions else "fixed")
    options = {k: v for k, v in s.structure.items() if k != "builder"}
    same = scenario_from_builder(builder, options, s.run, s.material, motions)
    assert_same_scenario(dataclasses.replace(same, name=s.name), s)


@dataclasses.dataclass(frozen=True)
class BrokenSpec:
    bays: int = 1

    def build(self) -> Assembly:
        raise TypeError("'float' object is not iterable")


@dataclasses.dataclass(frozen=True)
class NullableSpec:
    bays: int | None = 2

    def build(self) -> Assembly:
        return FakeSpec(bays=self.bays or 1).build()


def test_builder_bug_is_not_disguised_as_input_error(fake_builders):
    fake_builders["broken"] = BrokenSpec
    with pytest.raises(TypeError):
        scenario_from_builder("broken", {}, RunConfig(), Material(), {})

    # None passes where the spec's annotation allows it
    fake_builders["nullable"] = NullableSpec
    assert scenario_from_builder("nullable", {"bays": None}, RunConfig(), Material(), {}).block_count == 1


def test_every_builder_option_has_a_checked_type():
    for name, spec_cls in builders_pkg.BUILDERS.items():
        for f in dataclasses.fields(spec_cls):
            with pytest.raises(InputError, match=rf'^builder "{name}": {f.name} = \[\]: must be '):
                scenario_from_builder(name, {f.name: []}, RunConfig(), Material(), {})
