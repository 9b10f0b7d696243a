"""The TOML reader and writer: round trip through dump_scenario, record files beside the scenario."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from scenario_helpers import BLOCK, DATA, GROUND, XY_CSV, assert_same_scenario, load_error, write

from geometry_library.blocks import Assembly, Support
from masonrycli.errors import InputError
from masonrycli.records.read import record_motion
from masonrycli.scenario.motion import Fixed
from masonrycli.scenario.scenario import (
    Material,
    RunConfig,
    Scenario,
)
from masonrycli.scenario.toml_file import dump_scenario, load_scenario, loads_scenario

# ----------------------------------------------------------------------------------------- round trip

RECORD_CSV = "t,v\n0.0,0.1\n0.05,0.3333333333333333\n0.2,-0.7\n"

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
    assert s.motions[5].value.tolist() == [0.1, 0.3333333333333333, -0.7]
    assert s.motions[6].value.tolist() == [[0.0, 0.0], [1e-3, -2e-3], [0.25, 0.125]]

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


def test_a_geometry_file_under_the_home_folder(tmp_path, monkeypatch):
    # [structure] file = "~/walls/w.geojson" was looked for as <scenario folder>/~/walls/w.geojson
    from geometry_library.builders import build_wall
    from geometry_library.io import write_geojson

    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    (tmp_path / "home" / "walls").mkdir(parents=True)
    write_geojson(build_wall(blocks=3), tmp_path / "home" / "walls" / "w.geojson")
    s = loads_scenario('[structure]\nfile = "~/walls/w.geojson"\n', source="s.toml", base_dir=tmp_path)
    assert s.block_count == 3 and s.structure == {"file": str(tmp_path / "home" / "walls" / "w.geojson")}


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


def test_solver_quantity_and_baseline_are_read_in_any_case(tmp_path):
    # solver = "NLGS" was 'must be one of nlgs-accel, nlgs' (--solver NLGS ran), quantity = "Acceleration"
    # 'must be "velocity" or "acceleration"', baseline = "None" 'must be "quadratic" or "none"'
    (tmp_path / "q.csv").write_text("t,a\n0,0\n0.1,1\n0.2,0\n")
    record = 'motion = { kind = "record", file = "q.csv", quantity = "Acceleration", baseline = "None" }\npolygon'
    path = tmp_path / "s.toml"
    path.write_text('[run]\nsolver = "NLGS"\n' + BLOCK + GROUND.replace("polygon", record))
    scenario = load_scenario(path)
    assert scenario.run.solver == "nlgs"
    assert (scenario.motions[0].quantity, scenario.motions[0].baseline) == ("acceleration", "none")


def test_motion_kind_is_read_in_any_case(tmp_path):
    # kind = "Sine" was 'unknown motion kind (expected one of fixed, constant, sine, ramp, record)'
    text = Path(DATA / "block_on_ground.toml").read_text().replace('kind = "sine"', 'kind = "Sine"')
    path = tmp_path / "s.toml"
    path.write_text(text)
    assert load_scenario(path).motions[0].kind == "sine"
