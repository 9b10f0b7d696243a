"""masonrycli/scenario/target.py: a command's TARGET is a built-in name unless a file of that name is here, a
scenario or a geometry file; one that is none of them (missing, a folder, another of masonry's files, not
TOML) is named in one line; a file's scenario takes the command's record and run overrides."""

from pathlib import Path

import pytest

from masonrycli.errors import InputError
from masonrycli.records.read import record_motion
from masonrycli.scenario.target import file_scenario, is_built_in, target_scenario

RECORD = Path(__file__).parent / "data" / "quake_velocity.csv"


def motions_by_name(scenario):
    return {s.name: m for s, m in zip(scenario.assembly.supports, scenario.motions)}


def test_a_file_scenario_takes_the_record_and_the_run_overrides(tmp_path, monkeypatch):
    path = Path(__file__).parent / "data" / "block_on_ground.toml"  # 1 s in steps of 1 ms, μ = 0.6
    s = file_scenario(path, record=RECORD, scale=2.0, duration=0.5, dt=None, friction=0.3)
    assert (s.run.duration, s.run.dt, s.material.friction) == (0.5, 1e-3, 0.3)
    assert motions_by_name(s) == {"ground": record_motion(RECORD, scale=2.0, display=str(RECORD))}
    with pytest.raises(InputError) as info:
        file_scenario(path, scale=2.0)
    assert str(info.value) == "--scale 2 goes with --record (it multiplies the record)"
    monkeypatch.chdir(tmp_path)  # no file named wall here
    with pytest.raises(InputError) as info:
        file_scenario(Path("wall"))
    assert str(info.value) == "wall: not a file; the built-in structures are run with `masonry simulate wall`"


def test_a_target_is_a_built_in_name_unless_a_file_of_that_name_is_here(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    one_block = (Path(__file__).parent / "data" / "block_on_ground.toml").read_text()
    assert is_built_in("wall") and not is_built_in("wall.toml") and not is_built_in("Wall")
    assert target_scenario("arch", lambda name: f"the built-in {name}") == "the built-in arch"
    (tmp_path / "arch").mkdir()  # a folder of that name: still the built-in
    assert target_scenario("arch", lambda name: f"the built-in {name}") == "the built-in arch"
    (tmp_path / "wall").write_text(one_block)  # a file: the file, for every command
    assert not is_built_in("wall")
    assert target_scenario("wall", lambda name: None).name == "block-on-harmonic-ground"
    assert target_scenario(Path("./wall")).source == "wall"  # read as the commands read it before


@pytest.mark.parametrize(
    ("target", "message"),
    [
        ("wal", "wal: no such scenario or geometry file (did you mean wall?)"),
        ("WALL", "WALL: no such scenario or geometry file (did you mean wall?)"),
        ("arches", "arches: no such scenario or geometry file (did you mean arch?)"),
        # a file name or a path names no built-in
        ("arch.toml", "arch.toml: no such scenario or geometry file (built-in structures: wall, arch, aqueduct)"),
        ("runs/wal", "runs/wal: no such scenario or geometry file (built-in structures: wall, arch, aqueduct)"),
        ("bridge", "bridge: no such scenario or geometry file (built-in structures: wall, arch, aqueduct)"),
        (".", ".: is a directory, not a scenario or geometry file"),
        (" ", "the structure argument is empty (' '): give wall, arch, aqueduct or a scenario file"),
    ],
)
def test_a_bad_target_is_named_in_one_line(target, message, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError) as info:
        target_scenario(target, lambda name: pytest.fail(f"built {name}"))
    assert str(info.value) == message


@pytest.mark.parametrize(
    ("name", "content", "said"),
    [
        (
            "wall.rrd",
            b"RRF2\x00\x01",
            "a Rerun recording (.rrd), not a scenario (TOML) or a geometry file (GeoJSON / WKT); masonry inspect summarises it",
        ),
        ("wall.npz", b"PK\x03\x04\x14", "a run history (.npz), not a scenario"),
        (
            "quake.csv",
            b"time,v\n0,0\n0.1,1\n",
            "a CSV table, not a scenario (TOML) or a geometry file (GeoJSON / WKT); a record goes in --record",
        ),
        (
            "quake.AT2",
            b"PEER\nx\nACCELERATION\nNPTS= 2, DT= .01 SEC\n0 1\n",
            "an earthquake record (.AT2), not a scenario",
        ),
    ],
)
def test_another_of_masonrys_files_as_a_target_is_named(tmp_path, name, content, said):
    # "wall.rrd: not a UTF-8 text file (byte 31) (read as a scenario TOML: …)" for a recording given to run / check /
    # limit / sweep; a record CSV: "TOML syntax error: Expected '=' after a key …"
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(InputError) as raised:
        target_scenario(path)
    assert str(raised.value).startswith(f"{path}: {said}")
    assert "\n" not in str(raised.value)


def test_a_file_not_named_toml_that_is_no_toml_says_how_it_was_read(tmp_path):
    # "notes.txt: TOML syntax error …" did not say why a WKT saved as .txt was read as TOML
    wkt = tmp_path / "wall.wkt.txt"
    wkt.write_text("POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\n")
    with pytest.raises(InputError) as raised:
        target_scenario(wkt)
    message = str(raised.value)
    assert "\n" not in message and message.startswith(f"{wkt}: TOML syntax error")
    assert message.endswith("(read as a scenario TOML: a geometry file's name ends in .geojson, .json, .wkt)")
    toml = tmp_path / "bad.toml"  # a .toml file is a scenario by its name: no hint
    toml.write_text("POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\n")
    with pytest.raises(InputError, match=r"TOML syntax error[^(]*\(at line 1, column \d+\)$"):
        target_scenario(toml)


def test_a_target_with_a_tilde_the_shell_left_is_under_home(tmp_path, monkeypatch):
    # 'masonry check "~/w.toml"' said "~/w.toml: no such scenario or geometry file"; a scenario's file keys
    # and the path options read ~ as the home folder.
    monkeypatch.setenv("HOME", str(tmp_path))
    (tmp_path / "w.toml").write_text("[[block]]\npolygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\n")
    assert target_scenario("~/w.toml").assembly.block_count == 1
