"""What a valid scenario may still have wrong (masonrycli.scenario.caveats): records the run does not follow
whole, a gravity pointing up or in other units, densities in t/m³; and that every command prints them."""

from __future__ import annotations

import dataclasses

import pytest
from scenario_helpers import BLOCK, DATA, GROUND

from masonrycli.scenario.caveats import record_warnings, scenario_warnings, setting_warnings
from masonrycli.scenario.toml_file import load_scenario, loads_scenario

from cli_helpers import invoke, words


def test_record_warnings_name_a_record_that_outlasts_the_run():
    scenario = load_scenario(DATA / "quake_record.toml")  # quake_velocity.csv: samples 0 ... 0.4 s; run 0.5 s
    assert record_warnings(scenario) == []
    short = dataclasses.replace(scenario, run=dataclasses.replace(scenario.run, duration=0.2))
    assert record_warnings(short) == [
        'support "ground": the record quake_velocity.csv lasts 0.4 s but the run 0.2 s; its shaking after '
        "t = 0.2 s is not applied (--duration 0.4 runs it all)"
    ]
    windowed = dataclasses.replace(short, motions=(dataclasses.replace(short.motions[0], window=(0.2, 0.4)),))
    assert record_warnings(windowed) == []  # the window moves 0.2 ... 0.4 s to 0 ... 0.2 s: all of it is run


def test_record_warnings_name_a_record_that_starts_after_the_run_ends(tmp_path):
    # A CSV stamped with clock times (100.0, 100.1, 100.2 s) run for 1 s: the ground never saw a sample, the
    # run said "completed ... intact", and the only warning read "the record lasts 100.2 s but the run 1 s;
    # its shaking after t = 1 s is not applied".
    (tmp_path / "late.csv").write_text("time,v\n100.0,0.0\n100.1,0.1\n100.2,0.0\n")
    text = BLOCK + GROUND + 'motion = { kind = "record", file = "late.csv" }\n'
    scenario = loads_scenario(text, source=str(tmp_path / "s.toml"), base_dir=tmp_path)
    assert record_warnings(scenario) == [
        'support "ground": the record late.csv starts at t = 100 s, after the run\'s 1 s: none of its shaking is '
        "applied (record times count from the run's t = 0; a scenario file's window = [100, 100.2] moves it there)"
    ]


def test_record_warnings_name_a_record_sampled_finer_than_dt():
    scenario = load_scenario(DATA / "quake_record.toml")  # samples every 0.1 s; dt = 1e-3
    coarse = dataclasses.replace(scenario, run=dataclasses.replace(scenario.run, dt=0.25))
    assert record_warnings(coarse) == [
        'support "ground": the record quake_velocity.csv is sampled every 0.1 s, finer than dt = 0.25 s: the steps '
        "skip samples and alias its content above 2 Hz (dt = 0.1 follows every sample)"
    ]
    exact = dataclasses.replace(scenario, run=dataclasses.replace(scenario.run, dt=0.1))
    assert record_warnings(exact) == []


def test_record_warnings_name_a_record_beyond_10_g_as_scaled(tmp_path):
    # A CSV of velocity in cm/s read as m/s (no header to say so), or an .AT2 given --scale 9.81 "to convert g",
    # ran "completed … collapsed" at hundreds of g without a word.
    (tmp_path / "cms.csv").write_text("time,v\n0,0\n0.01,0.5\n0.02,0\n0.03,-0.5\n0.04,0\n")  # 50 m/s² as m/s
    text = BLOCK + GROUND + 'motion = { kind = "record", file = "cms.csv", scale = 3.0 }\n'
    scenario = loads_scenario(text, source=str(tmp_path / "s.toml"), base_dir=tmp_path)
    assert scenario.motions[-1].peak_acceleration == pytest.approx(150.0)  # 0.5 m/s in 0.01 s, times 3
    late = 'support "ground": the record cms.csv lasts 0.04 s'
    assert [w for w in record_warnings(scenario) if not w.startswith(late)] == [
        'support "ground": the record cms.csv peaks at 15.3 g as applied (scale 3); the strongest earthquakes '
        "reach 3–4 g: check its units and the scale"
    ]
    gentle = dataclasses.replace(scenario, motions=(dataclasses.replace(scenario.motions[-1], scale=1.0),))
    assert not any("peaks" in w for w in record_warnings(gentle))  # 5.1 g: strong, not absurd
    from masonrycli.records.motion import Record

    accel = Record(
        time=(0.0, 0.1, 0.2), value=((0.0, 0.0), (3.0, 4.0), (-1.0, 0.0)), quantity="acceleration", scale=2.0
    )
    assert accel.peak_acceleration == pytest.approx(10.0)  # |(3, 4)| × 2, of the samples themselves


def _scenario(tmp_path, run="", density=2000.0):
    text = f"[run]\nduration = 0.1\n{run}\n[material]\ndensity = {density}\n" + BLOCK + GROUND
    return loads_scenario(text, source=str(tmp_path / "s.toml"), base_dir=tmp_path)


def test_gravity_pointing_up_or_in_other_units_is_warned_about(tmp_path):
    # gravity = [0, 9.81] ran "completed … damaged" (the block flew 0.2 m up); limit said "no equilibrium"
    assert setting_warnings(_scenario(tmp_path)) == []
    assert setting_warnings(_scenario(tmp_path, "gravity = [0.0, 9.81]")) == [
        "[run] gravity = [0, 9.81] points up (y is up: the blocks fall towards -y, [0, -9.81]; a tilting test "
        "turns it by less than 90°)"
    ]
    assert setting_warnings(_scenario(tmp_path, "gravity = [0.0, -981.0]")) == [
        "[run] gravity = [0, -981] is 981 m/s², 100 g: gravity is in m/s² ([0, -9.81]; not cm/s², not g)"
    ]
    assert "is 1 m/s²" in setting_warnings(_scenario(tmp_path, "gravity = [0.0, -1.0]"))[0]
    # a tilting table (30°) and no gravity at all are what they say
    assert setting_warnings(_scenario(tmp_path, "gravity = [4.905, -8.4957]")) == []
    assert setting_warnings(_scenario(tmp_path, "gravity = [0.0, 0.0]")) == []
    assert setting_warnings(_scenario(tmp_path, "gravity = [0.0, -1e-300]")) == []  # none, on purpose


def test_a_density_in_tonnes_per_cubic_metre_is_warned_about(tmp_path):
    # density = 2.5 (t/m³) ran as 2.5 kg/m³: the same motion, every stress and force 1000× too small
    (light,) = setting_warnings(_scenario(tmp_path, density=2.5))
    assert light == (
        'block "b1": density 2.5 kg/m³, lighter than any masonry unit (stone 2000–2800 kg/m³): a density in t/m³ '
        "or g/cm³ makes the stresses and forces 1000× too small"
    )
    assert setting_warnings(_scenario(tmp_path, density=450.0)) == []  # timber blocks of a lab model


def test_every_command_prints_the_warnings(tmp_path):
    # sweep printed none of them: a block touching nothing, gravity up, a GeoJSON property not used
    path = tmp_path / "up.toml"
    path.write_text("[run]\nduration = 0.01\ngravity = [0.0, 9.81]\n" + BLOCK + GROUND)
    scenario = load_scenario(path)
    assert scenario_warnings(scenario) == setting_warnings(scenario)
    out = tmp_path / "s.csv"
    for args in (
        ["check", path],
        ["run", path, "--no-recording"],
        ["sweep", path, "-p", "friction=0.5", "--workers", 0, "--no-recording", "--out", out],
    ):
        said = words(invoke(*args).output)
        assert "warning: [run] gravity = [0, 9.81] points up" in said, (args, said)
    # limit cannot stand the block on a ground above it: its one-line refusal gives the reason
    said = words(invoke("limit", path).output)
    assert said.startswith("error: no equilibrium") and "([run] gravity = [0, 9.81] points up" in said


def others(warnings: list[str]) -> list[str]:
    """The warnings but the baseline correction's: these tests' few-sample pulses do not end at rest."""
    return [w for w in warnings if "does not end at rest where it started" not in w]


@pytest.mark.parametrize("scale", [9.81, 9.80665, 981.0])
def test_an_at2_record_scaled_by_g_is_warned_about(tmp_path, scale):
    # --scale 9.81 "to convert g" on an .AT2 (converted on reading): a 0.3 g record ran at 2.9 g, no word
    from synthetic_records import write_at2

    write_at2(tmp_path / "q.AT2", [0.0, 0.3, -0.2, 0.0], 0.01)
    text = (
        "[run]\nduration = 0.03\n"
        + BLOCK
        + GROUND
        + f'motion = {{ kind = "record", file = "q.AT2", scale = {scale} }}\n'
    )
    scenario = loads_scenario(text, source=str(tmp_path / "s.toml"), base_dir=tmp_path)
    peak = 0.3 * scale
    assert others(record_warnings(scenario)) == [
        f'support "ground": the record q.AT2 is read in g and converted to m/s² already; scale {scale:g} converts it '
        f"again ({peak:.3g} g as applied; the scale multiplies the record, 1 is as recorded)"
    ]
    text = text.replace(f"scale = {scale}", "scale = 2.0")  # a scale, not a unit
    assert others(record_warnings(loads_scenario(text, source=str(tmp_path / "s.toml"), base_dir=tmp_path))) == []


def test_a_drawing_in_millimetres_is_warned_about(tmp_path):
    # a 300 × 200 mm block drawn in mm ran as a 300 × 200 m block of 1.5e8 kg, "completed"
    text = (
        '[run]\nduration = 0.1\n[[block]]\nname = "b1"\npolygon = [[0, 0], [300, 0], [300, 200], [0, 200]]\n'
        '[[support]]\nname = "g"\npolygon = [[-100, -50], [400, -50], [400, 0], [-100, 0]]\n'
    )
    scenario = loads_scenario(text, source=str(tmp_path / "s.toml"), base_dir=tmp_path)
    assert setting_warnings(scenario) == [
        'block "b1": 300 × 200 m, larger than any cut stone (20 m): lengths are in metres (millimetres? divide the '
        "coordinates, or --block-length / --block-height, by 1000)"
    ]
    assert setting_warnings(_scenario(tmp_path)) == []  # 0.4 × 0.2 m
    from masonrycli.scenario.builtin import builtin

    assert any("300 × 200 m" in w for w in setting_warnings(builtin("wall", block_length=300.0, block_height=200.0)))


@pytest.mark.parametrize("first", [0, 1])
def test_sample_numbers_taken_for_times_are_warned_about(tmp_path, first):
    # a spreadsheet's row numbers as the time column: from 0 the 1000 samples ran as 1000 s at 1 Hz without a
    # word; from 1 the warning was "starts at t = 1 s, after the run's 0.5 s … window = [1, 1000] moves it there"
    rows = "".join(f"{i},{0.1 * (i % 3)}\n" for i in range(first, first + 100))
    (tmp_path / "idx.csv").write_text("n,acc\n" + rows)
    motion = 'motion = { kind = "record", file = "idx.csv", quantity = "acceleration" }\n'
    text = "[run]\nduration = 0.5\n" + BLOCK + GROUND + motion
    scenario = loads_scenario(text, source=str(tmp_path / "s.toml"), base_dir=tmp_path)
    assert others(record_warnings(scenario)) == [
        f'support "ground": the record idx.csv has its samples at t = {first}, {first + 1}, {first + 2}, … s: sample '
        "numbers, not times? (give its times in s, or its values alone with --record-dt / time_step)"
    ]
    short = "".join(f"{i},{0.1 * (i % 3)}\n" for i in range(10))  # a few breakpoints a second apart: a pulse
    (tmp_path / "idx.csv").write_text("t,acc\n" + short)
    assert not any("sample numbers" in w for w in record_warnings(loads_scenario(text, base_dir=tmp_path)))


def test_a_driven_support_without_a_motion_is_warned_about(tmp_path):
    # support_role = "driven" in a GeoJSON run as it is: the support stayed fixed, "loading: none", no word
    import json

    from masonrycli.scenario.scenario import scenario_from_geometry_file

    ring = [[-2, -0.5], [2, -0.5], [2, 0], [-2, 0], [-2, -0.5]]
    block = {
        "type": "Feature",
        "properties": {"name": "a"},
        "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [0.3, 0], [0.3, 0.2], [0, 0.2], [0, 0]]]},
    }
    ground = {
        "type": "Feature",
        "properties": {"role": "support", "name": "g", "support_role": "driven"},
        "geometry": {"type": "Polygon", "coordinates": [ring]},
    }
    path = tmp_path / "w.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [ground, block]}))
    s = scenario_from_geometry_file(path)
    assert s.motions[0].kind == "fixed" and s.assembly.supports[0].role == "fixed"
    assert (
        'support "g": driven, but given no motion, so fixed (a scenario file\'s [[support]] table with its '
        "name and a motion drives it)" in s.warnings
    )
    # a scenario file naming the file and giving the motion: no warning
    (tmp_path / "s.toml").write_text(
        '[structure]\nfile = "w.geojson"\n[[support]]\nname = "g"\n'
        'motion = { kind = "sine", amplitude = 0.1, frequency = 2.0 }\n'
    )
    assert not any("driven" in w for w in load_scenario(tmp_path / "s.toml").warnings)
    (tmp_path / "n.toml").write_text('[structure]\nfile = "w.geojson"\n')  # naming it, no motion
    assert any(
        w.startswith('support "g": driven, but given no motion') for w in load_scenario(tmp_path / "n.toml").warnings
    )


def test_a_vertical_component_applied_horizontally_is_warned_about(tmp_path):
    # the UP file of an NGA-West2 zip given to `simulate --record` ran along x without a word (a sweep's
    # record set named it); along y, or as a scenario's vertical = …, it is where it belongs
    from synthetic_records import write_at2

    acc = [0.0, 0.02, -0.01, 0.0]
    write_at2(tmp_path / "RSN6_IMPVALL.I_I-ELCUP.AT2", acc, 0.01)
    write_at2(tmp_path / "RSN6_IMPVALL.I_I-ELC180.AT2", acc, 0.01)
    write_at2(tmp_path / "q.AT2", acc, 0.01, title="IMPERIAL VALLEY 10/15/79 2316, EL CENTRO ARRAY #6, UP")

    def said(motion: str) -> list[str]:
        text = "[run]\nduration = 0.03\n" + BLOCK + GROUND + f'motion = {{ kind = "record", {motion} }}\n'
        return others(record_warnings(loads_scenario(text, source=str(tmp_path / "s.toml"), base_dir=tmp_path)))

    up = "RSN6_IMPVALL.I_I-ELCUP.AT2"
    for motion, name in ((f'file = "{up}"', up), ('file = "q.AT2", direction = [1.0, 0.2]', "q.AT2")):
        assert said(motion) == [
            f"support \"ground\": the record {name} is a vertical component (PEER's UP / DWN, ESM's Z, K-NET's UD), applied horizontally: "
            "give a horizontal one (H1 / H2), or this one as a scenario file's vertical = … beside its horizontal"
        ]
    assert said(f'file = "{up}", vertical = "RSN6_IMPVALL.I_I-ELC180.AT2"')  # the pair given the wrong way round
    assert said(f'file = "{up}", direction = [0.0, 1.0]') == []
    assert said(f'file = "RSN6_IMPVALL.I_I-ELC180.AT2", vertical = "{up}"') == []
    assert said('file = "RSN6_IMPVALL.I_I-ELC180.AT2"') == []
    # on the command line: the same line from simulate
    output = words(invoke("simulate", "wall", "--record", tmp_path / up, "--duration", "0.03", "--no-recording").output)
    assert f'warning: support "ground": the record {up} is a vertical component' in output, output
