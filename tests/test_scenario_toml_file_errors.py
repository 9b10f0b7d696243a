"""The TOML reader's error messages: one line naming the section, the key and what is wrong."""

from __future__ import annotations

import pytest
from scenario_helpers import BLOCK, BLOCK2, DATA, GROUND, XY_CSV, load_error, write

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
    ("dt = 1e-12", "[run] dt = 1e-12: gives 1,000,000,000,000 steps"),
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
    import geometry_library.checks as checks

    def overlapping(assembly):
        raise GeometryError('block 1 ("b1") overlaps block 2 ("b2")')

    monkeypatch.setattr(checks, "validate_assembly", overlapping)
    assert load_error(tmp_path, BLOCK + BLOCK2) == 'block 1 ("b1") overlaps block 2 ("b2")'

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
    # it ran: 1 m/s · sin(2π·0·t) is 0, the ground never moved, "intact" (--freq 0 --amp 1 is refused)
    (
        '{ kind = "sine", amplitude = 1.0, frequency = 0.0 }',
        "motion.frequency = 0.0: the velocity 1 m/s · sin(2π·0·t + 0) is 0, nothing moves (amplitude = 0 for no "
        'shaking; a steady velocity is kind = "constant")',
    ),
    # these said "must be 2 numbers [x, y]" (a window is [start, end]; a 1-component value a number) and
    # file = "." "not a regular file (a device, a pipe or a socket)" (a folder)
    (
        '{ kind = "record", time = [0.0, 1.0], value = [1.0, 2.0], window = [0.5] }',
        "motion.window = [0.5]: must be 2 numbers [start, end]",
    ),
    ('{ kind = "record", time = [0.0, 1.0], value = ["a", "b"] }', 'motion.value[0] = "a": must be a number'),
    ('{ kind = "record", time = [0.0, 1.0], value = [1.0, "b"] }', 'motion.value[1] = "b": must be a number'),
    (
        '{ kind = "record", time = [0.0, 1.0], value = [[1.0, 2.0], [3.0]] }',
        "motion.value[1] = [3.0]: must be 2 numbers [x, y]",
    ),
    ('{ kind = "record", file = "." }', 'motion.file = ".": is a directory (looked for '),
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


@pytest.mark.parametrize(
    "motion, expected",
    [
        (
            'kind = "sine", amplitude = 1.0, frequency = "2 Hz"',
            'frequency = "2 Hz": must be a number, not a string (write 2, in Hz, without the unit)',
        ),
        (
            'kind = "sine", amplitude = "1 m/s", frequency = 2.0',
            'amplitude = "1 m/s": must be a number, not a string (write 1, in m/s, without the unit)',
        ),
        (
            'kind = "sine", amplitude = 1.0, frequency = 2.0, phase = "90°"',
            'phase = "90°": must be a number, not a string (it is read in rad: convert 90° to rad and write the '
            "number alone)",
        ),
        (
            'kind = "ramp", acceleration = [1.0, 0.0], until = "0.5 s"',
            'until = "0.5 s": must be a number, not a string (write 0.5, in s, without the unit)',
        ),
        (
            'kind = "record", file = "q.csv", time_step = "10 ms"',
            'time_step = "10 ms": must be a number, not a string (it is read in s: convert 10 ms to s and write the '
            "number alone)",
        ),
    ],
    ids=["frequency", "amplitude", "phase-degrees", "until", "time-step-ms"],
)
def test_motion_numbers_written_with_units(tmp_path, motion, expected):
    (tmp_path / "q.csv").write_text("0.1\n0.2\n0.3\n")
    msg = load_error(tmp_path, BLOCK + GROUND + f"motion = {{ {motion} }}\n")
    assert msg.startswith('[[support]] #1 ("ground"): ') and msg.endswith(expected), msg


def test_block_density_written_with_its_unit(tmp_path):
    msg = load_error(tmp_path, BLOCK + BLOCK2 + 'density = "2400 kg/m3"\n')
    assert msg == (
        '[[block]] #2 ("b2"): density = "2400 kg/m3": must be a number, not a string (write 2400, in kg/m³, '
        "without the unit)"
    )
