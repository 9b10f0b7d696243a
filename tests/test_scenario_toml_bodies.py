"""masonrycli/scenario/toml_bodies.py's errors: a [[block]] or [[support]] table's keys, name, polygon and
numbers, and a support's motion table, each one line at the table's locator. The document's other errors:
test_scenario_toml_file_errors.py."""

from __future__ import annotations

import pytest
from scenario_helpers import BLOCK, BLOCK2, GROUND, XY_CSV, load_error

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
