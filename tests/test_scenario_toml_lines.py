"""The line of a scenario error (masonrycli/scenario/toml_lines.py): ``s.toml:4: [run] duration = "1 s": …`` where the
key is found unambiguously — proved by tomllib on a renamed copy — and no line at all otherwise. Dotted keys,
inline tables, arrays of tables, look-alikes in strings and comments never give a wrong line."""

from __future__ import annotations

import re
import time

import pytest

from masonrycli.errors import InputError
from masonrycli.scenario.toml_file import load_scenario
from masonrycli.scenario.toml_lines import key_line, message_key

SQUARE = "[[0.0, 0.0], [0.4, 0.0], [0.4, 0.2], [0.0, 0.2]]"
GROUND = "[[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]"


def block(name: str, y: float, extra: str = "") -> str:
    poly = f"[[0.0, {y}], [0.4, {y}], [0.4, {y + 0.2}], [0.0, {y + 0.2}]]"
    return f'[[block]]\nname = "{name}"\npolygon = {poly}\n{extra}'


def error(tmp_path, text: str) -> tuple[int | None, str]:
    """(line or None, the message after "<file>[:line]: ") of loading ``text``."""
    path = tmp_path / "s.toml"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        load_scenario(path)
    message = str(info.value)
    found = re.match(rf"{re.escape(str(path))}(?::(\d+))?: ", message)
    assert found, message
    return (int(found.group(1)) if found.group(1) else None), message[found.end() :]


def line_of(text: str, fragment: str, nth: int = 1) -> int:
    """The line (from 1) of the ``nth`` line containing ``fragment`` (what the test means to point at)."""
    hits = [i for i, line in enumerate(text.split("\n"), start=1) if fragment in line]
    return hits[nth - 1]


def test_a_run_setting(tmp_path):
    text = 'name = "t"\n\n[run]\ndt = 1e-3\nduration = "1 s"\n' + block("b1", 0.0)
    line, message = error(tmp_path, text)
    assert (line, message) == (
        5,
        '[run] duration = "1 s": must be a number, not a string (write 1, in s, without the unit)',
    )


def test_look_alikes_in_strings_comments_and_other_tables_are_not_taken(tmp_path):
    text = (
        'name = "t"\n# duration = "1 s" (a comment)\n'
        "[material]\ndensity = 2500.0\n"
        '[run]\n# duration = 1\ndt = 1e-3   # duration = "1 s"\nduration = "1 s"\n' + block("b1", 0.0)
    )
    line, _ = error(tmp_path, text)
    assert line == line_of(text, 'duration = "1 s"', nth=3) == 8
    # a multi-line string holding TOML-like lines (no scenario key takes one: the finder alone)
    decoy = 'note = """\n[run]\nduration = 2\n"""\n[run]\nduration = "1 s"\n[x]\nduration = 3\n'
    assert key_line(decoy, ("run",), "duration") == 6
    assert key_line(decoy, ("x",), "duration") == 8


def test_dotted_keys_and_inline_tables(tmp_path):
    dotted = 'run.duration = "1 s"\n' + block("b1", 0.0)
    assert error(tmp_path, dotted)[0] == 1
    inline = 'name = "t"\nrun = { dt = 1e-3, duration = "1 s" }\n' + block("b1", 0.0)
    assert error(tmp_path, inline)[0] == 2
    quoted = '[material]\n"density" = "2500 kg/m3"\n' + block("b1", 0.0)
    assert error(tmp_path, quoted) == (
        2,
        '[material] density = "2500 kg/m3": must be a number, not a string (write 2500, in kg/m³, without the unit)',
    )


def test_the_entry_of_an_array_of_tables(tmp_path):
    # every [[block]] has a density; the 2nd's is wrong: its line, not the first's
    text = (
        block("b1", 0.0, "density = 2400.0\n")
        + block("b2", 0.2, 'density = "2.5 t/m3"\n')
        + block("b3", 0.4, 'density = "2.5 t/m3"\n')
    )
    line, message = error(tmp_path, text)
    assert message.startswith('[[block]] #2 ("b2"): density = "2.5 t/m3"')
    assert line == line_of(text, 'density = "2.5 t/m3"', nth=1) == 8
    # the same key in [material] (valid) and in a block (not): the block's line
    text = "[material]\nthickness = 1.0\n" + block("b1", 0.0, 'thickness = "1m"\n')
    assert error(tmp_path, text)[0] == 6


def test_a_motion_inline_or_in_its_sub_table(tmp_path):
    ok = 'motion = { kind = "sine", amplitude = 1.0, frequency = 2.0 }\n'
    inline = (
        block("b1", 0.0)
        + f'[[support]]\nname = "g"\npolygon = {GROUND}\n{ok}'
        + '[[support]]\nname = "h"\npolygon = [[6.0, -0.5], [7.0, -0.5], [7.0, 0.0], [6.0, 0.0]]\n'
        + 'motion = { kind = "sine", amplitude = 1.0, frequency = "2 Hz" }\n'
    )
    line, message = error(tmp_path, inline)
    assert message.startswith('[[support]] #2 ("h"): ') and "frequency" in message
    assert line == line_of(inline, 'frequency = "2 Hz"') == 11
    table = (
        block("b1", 0.0)
        + f'[[support]]\nname = "g"\npolygon = {GROUND}\n[support.motion]\nkind = "sine"\namplitude = 1.0\nfrequency = 2.0\n'
        + '[[support]]\nname = "h"\npolygon = [[6.0, -0.5], [7.0, -0.5], [7.0, 0.0], [6.0, 0.0]]\n'
        + '[support.motion]\nkind = "sine"\namplitude = 1.0\nfrequency = "2 Hz"\n'
    )
    assert error(tmp_path, table)[0] == line_of(table, 'frequency = "2 Hz"') == 17
    unknown = (
        block("b1", 0.0) + f'[[support]]\nname = "g"\npolygon = {GROUND}\nmotion = {{ kind = "sine", freq = 2.0 }}\n'
    )
    line, message = error(tmp_path, unknown)
    assert message.startswith('[[support]] #1 ("g"): motion: unknown key "freq"')
    assert line == line_of(unknown, "freq = 2.0") == 7


def test_unknown_keys_top_level_keys_and_vertices(tmp_path):
    assert error(tmp_path, "[run]\ndt = 1e-3\ndtt = 0.1\n" + block("b1", 0.0)) == (
        3,
        '[run] unknown key "dtt" (did you mean "dt"?)',
    )
    assert error(tmp_path, "\nname = 3\n" + block("b1", 0.0)) == (2, "name = 3: must be a string")
    text = '[[block]]\nname = "b1"\npolygon = [\n  [0.0, 0.0],\n  [1.0],\n  [1.0, 1.0],\n]\n'
    assert error(tmp_path, text) == (3, '[[block]] #1 ("b1"): polygon[1] = [1.0]: must be 2 numbers [x, y]')


def test_no_line_when_the_key_is_not_written_or_none_is_named(tmp_path):
    # a missing key, a block's geometry, a builder's own message: no key line to give
    missing = (
        block("b1", 0.0)
        + f'[[support]]\nname = "g"\npolygon = {GROUND}\nmotion = {{ kind = "sine", frequency = 2.0 }}\n'
    )
    assert error(tmp_path, missing) == (
        None,
        '[[support]] #1 ("g"): motion.amplitude: missing (required for kind "sine")',
    )
    concave = '[[block]]\nname = "b1"\npolygon = [[0, 0], [2, 0], [1, 0.2], [2, 2], [0, 2]]\n'
    assert error(tmp_path, concave)[0] is None
    assert error(tmp_path, "[run]\ndt = 1e-3\n")[0] is None  # no blocks


@pytest.mark.parametrize(
    "message, expected",
    [
        ("[run] dt = 0: must be > 0", (("run",), "dt")),
        ('[[block]] #2 ("b\\"2"): density = 0: must be > 0', (("block", 1), "density")),
        ('[[support]] #1: motion.frequency = "2 Hz": …', (("support", 0, "motion"), "frequency")),
        ('[[support]] #1 ("g"): motion.kind: missing (one of …)', (("support", 0, "motion"), "kind")),
        ('[[support]] #3 ("g"): motion: unknown key "freq"', (("support", 2, "motion"), "freq")),
        ('[structure] unknown option "blokcs" of builder "wall"', (("structure",), "blokcs")),
        ("name = 3: must be a string", ((), "name")),
        ('[structure] builder "wall": wall: length 1e+05 m is absurd', None),
        ('[[block]] #1 ("b1"): polygon is not convex', None),
        ("no blocks: add [[block]] tables", None),
        ("TOML syntax error: Expected '=' (at line 3, column 5)", None),
        ("[[run]] #1: dt = 0: x", (("run", 0), "dt")),
        ("[run] #1: dt = 0: x", None),  # an index on a plain table: not a message of the reader
    ],
)
def test_message_key(message, expected):
    assert message_key(message) == expected


def test_a_key_that_is_a_table_header_gives_no_line():
    text = '[[support]]\nname = "g"\n[support.motion]\nkind = "sine"\n'
    assert key_line(text, ("support", 0), "motion") is None
    assert key_line(text, ("support", 0, "motion"), "kind") == 4
    assert key_line(text, ("support", 1, "motion"), "kind") is None  # no 2nd support


def test_a_misspelt_section_gives_the_line_of_its_header(tmp_path):
    """docs/scenario-format.md: ``wall.toml:1: unknown key "runn"``; a header in a string is not taken."""
    text = "# settings\n\n[runn]\nduration = 1.0\n" + block("b1", 0.0)
    assert error(tmp_path, text) == (3, 'unknown key "runn" (did you mean "run"?)')
    twice = block("b1", 0.0).replace("[[block]]", "[[blocks]]") * 2
    assert error(tmp_path, twice) == (1, 'unknown key "blocks" (did you mean "block"?)')
    sub = "[run]\ndt = 1e-3\n[run.extra]\nx = 1\n" + block("b1", 0.0)
    line, message = error(tmp_path, sub)
    assert line == 3 and message.startswith('[run] unknown key "extra"')
    look_alike = 'name = """\n[runn]\n"""\n[runn]\nx = 1\n' + block("b1", 0.0)
    assert error(tmp_path, look_alike)[0] == line_of(look_alike, "[runn]", nth=2) == 4


def test_a_large_file_answers_quickly(tmp_path):
    """20 000 blocks, the last one wrong: the line, found in a few parses of the text."""
    rows = "".join(block(f"b{i}", 0.2 * i, "density = 2400.0\n") for i in range(19_999))
    text = rows + block("last", 0.2 * 19_999, 'density = "2.5 t/m3"\n')
    start = time.process_time()
    line = key_line(text, ("block", 19_999), "density")
    spent = time.process_time() - start
    assert line == text.count("\n") and spent < 5.0, spent


def test_file_key_line_only_where_the_file_gives_the_value(tmp_path):
    """The line of a value checked after the command line applied its own (``--dt``, ``--param freq=``):
    the key's line where the file gives the value the run has, None elsewhere (the file's other value's
    line would mislead); an [[support]] entry found by its name."""
    from masonrycli.scenario.toml_lines import file_key_line

    text = (
        '[run]\ndt = 1e-3\n\n[[support]]\nname = "left"\nmotion = { kind = "sine", frequency = 3.0 }\n'
        '[[support]]\nname = "ground"\nmotion = { kind = "sine", frequency = 2.0 }\n'
    )
    path = tmp_path / "s.toml"
    path.write_text(text)
    ground = ("support", "ground", "motion")
    assert file_key_line(str(path), ground, "frequency", 2.0) == line_of(text, "frequency = 2.0")
    assert file_key_line(str(path), ground, "frequency", 600.0) is None  # a sweep's freq=600 point
    assert file_key_line(str(path), ("support", "nobody", "motion"), "frequency", 2.0) is None
    assert file_key_line(str(path), ("run",), "dt", 1e-3) == 2
    assert file_key_line(str(path), ("run",), "dt", 0.5) is None  # --dt 0.5
    assert file_key_line(str(tmp_path / "missing.toml"), ("run",), "dt", 1e-3) is None
