"""The TOML reader's error messages: one line naming the section, the key and what is wrong. A [[block]] or
[[support]] table's and a motion's: test_scenario_toml_bodies.py; a too fast support's: test_scenario_sampling.py."""

from __future__ import annotations

import pytest
from scenario_helpers import BLOCK, BLOCK2, DATA, GROUND, load_error, write

from geometry_library.blocks import GeometryError
from masonrycli.errors import InputError
from masonrycli.scenario.scenario import (
    scenario_summary,
)
from masonrycli.scenario.toml_file import load_scenario

# ------------------------------------------------------------------------------------------- errors

RUN_ERRORS = [
    ("dt = -0.001", "[run] dt = -0.001: must be > 0"),
    ("dt = 0", "[run] dt = 0: must be > 0"),
    ("dt = 2.0", "[run] dt = 2.0: must be <= duration (1.0)"),
    ("dt = 1e-12", "[run] duration = 1.0 at dt = 1e-12 is 1,000,000,000,000 steps (at most 100,000,000)"),
    ("duration = 0.0", "[run] duration = 0.0: must be > 0"),
    ("duration = -1", "[run] duration = -1: must be > 0"),
    ("duration = 1e6", "[run] duration = 1000000.0: must be <= 100000"),
    ("duration = inf", "[run] duration = inf: must be a finite number"),
    ("duration = nan", "[run] duration = nan: must be a finite number"),
    ('duration = "1 s"', '[run] duration = "1 s": must be a number, not a string (write 1, in s, without the unit)'),
    (
        'dt = "20 ms"',
        '[run] dt = "20 ms": must be a number, not a string (it is read in s: convert 20 ms to s and write the number alone)',
    ),
    (
        'tolerance = "1e-5 m/s"',
        '[run] tolerance = "1e-5 m/s": must be a number, not a string (write 1e-5, in m/s, without the unit)',
    ),
    (
        'record_every = "10 steps"',
        '[run] record_every = "10 steps": must be an integer, not a string (write 10, without "steps": this setting has no unit)',
    ),
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
    (
        'thickness = "1m"',
        '[material] thickness = "1m": must be a number, not a string (write 1, in m, without the unit)',
    ),
    (
        'density = "2500 kg/m3"',
        '[material] density = "2500 kg/m3": must be a number, not a string (write 2500, in kg/m³, without the unit)',
    ),
    (
        'density = "2.5 t/m3"',
        '[material] density = "2.5 t/m3": must be a number, not a string (it is read in kg/m³: convert 2.5 t/m3 to '
        "kg/m³ and write the number alone)",
    ),
    ("mu = 0.6", '[material] unknown key "mu" (expected one of: density, thickness, friction)'),
]


@pytest.mark.parametrize("line, expected", MATERIAL_ERRORS, ids=[e[0] for e in MATERIAL_ERRORS])
def test_material_errors(tmp_path, line, expected):
    assert load_error(tmp_path, f"[material]\n{line}\n" + BLOCK) == expected


def test_real_overlap_check(tmp_path):
    text = BLOCK + '[[block]]\nname = "b2"\npolygon = [[0.1, 0.1], [0.5, 0.1], [0.5, 0.3], [0.1, 0.3]]\n'
    msg = load_error(tmp_path, text)
    assert "overlap" in msg and '"b1"' in msg and '"b2"' in msg


def test_overlapping_blocks_are_numbered_as_the_reader_numbers_them(tmp_path):
    # the third and fourth [[block]] tables, unnamed: it said 'blocks 2 ("block-3") and 3 ("block-4")'
    # where every other message of the reader says [[block]] #3 ("block-3")
    square = "[[block]]\npolygon = [[{x}, {y}], [{x1}, {y}], [{x1}, {y1}], [{x}, {y1}]]\n"
    blocks = "".join(square.format(x=x, y=y, x1=x + 1, y1=y + 1) for x, y in ((0, 0), (1, 0), (0, 1), (0.5, 1.5)))
    msg = load_error(tmp_path, blocks + GROUND)
    assert msg.endswith(
        'blocks 3 ("block-3") and 4 ("block-4") overlap by 0.25 m², 0.5 m deep (tolerance 0.001 m², 0.5 mm deep)'
    ), msg


def test_validate_assembly_errors_and_warnings(tmp_path, monkeypatch):
    import geometry_library.assembly_checks as checks

    def overlapping(assembly):
        raise GeometryError('block 1 ("b1") overlaps block 2 ("b2")')

    monkeypatch.setattr(checks, "validate_assembly", overlapping)
    assert load_error(tmp_path, BLOCK + BLOCK2) == 'block 1 ("b1") overlaps block 2 ("b2")'

    monkeypatch.setattr(checks, "validate_assembly", lambda a: ["blocks b1 and b2 are 2 mm apart", "multi\nline"])
    s = load_scenario(write(tmp_path, BLOCK + BLOCK2))
    assert s.warnings == ("blocks b1 and b2 are 2 mm apart", "multi line")
    assert scenario_summary(s)["warnings"] == list(s.warnings)


@pytest.mark.parametrize(
    "text, expected",
    [
        ("[runn]\ndt = 0.1\n" + BLOCK, 'unknown key "runn" (did you mean "run"?)'),
        ("run = 3\n" + BLOCK, "run = 3: must be a table [run]"),
        ("[block]\npolygon = [[0, 0], [1, 0], [1, 1]]\n", "block: must be an array of tables [[block]]"),
        ("support = [1, 2]\n" + BLOCK, "support: must be an array of tables [[support]]"),
        ("name = 3\n" + BLOCK, "name = 3: must be a string"),
        ("[run]\ndt = 0.01\n", "no blocks: add [[block]] tables or a [structure] builder"),
        ("", "the file is empty (or only comments): a scenario needs [[block]] tables or a [structure] builder"),
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
    with pytest.raises(InputError, match=r"latin\.toml:1: not a UTF-8 text file .*; save it as UTF-8$"):
        load_scenario(tmp_path / "latin.toml")
    utf16 = tmp_path / "utf16.toml"  # Windows' Notepad "Unicode": "not a UTF-8 text file (byte 0)" before
    utf16.write_bytes(BLOCK.encode("utf-16"))
    with pytest.raises(
        InputError, match=r"utf16\.toml: a UTF-16 text file \(it starts with UTF-16's byte-order mark\)"
    ):
        load_scenario(utf16)


def test_a_number_given_as_a_string_says_so(tmp_path):
    # density = "2500" said '[material] density = "2500": must be a number'
    text = (DATA / "block_on_ground.toml").read_text().replace("density = 2000.0", 'density = "2500"')
    message = load_error(tmp_path, text)
    assert message.endswith('[material] density = "2500": must be a number, not a string (write 2500, without quotes)')
