"""A scenario written by hand for the first time: the usual mistakes each get one line that says the fix.

Before, a comma decimal (``friction = 0,5``) or a unit (``duration = 1 s``) said only "Expected newline or end
of document after a statement (at line 8, column 13)", a Windows path between double quotes "Invalid hex
value", a [run] setting written without its ``[run]`` header 'unknown key "duration" (expected one of: name,
run, …)', an empty file "no blocks", a UTF-16 file without its byte-order mark "Expected '=' after a key",
and ``"C:\\temp\\new.csv"`` (a valid TOML string holding a tab and a line break) "no such file (looked for
…/C: emp ew.csv)".
"""

from __future__ import annotations

import tomllib

import pytest
from scenario_helpers import BLOCK, GROUND, load_error

from masonrycli.scenario.toml_syntax import hint

from cli_helpers import assert_one_line_error, invoke

SCENARIO = "[run]\nduration = 0.5\n\n[material]\nfriction = 0.6\n\n" + BLOCK + GROUND
SINE = 'motion = { kind = "sine", amplitude = 1.0, frequency = 2.0 }\n'

TYPOS = [  # what a student writes -> the fix the message gives
    ("friction = 0,5", "the decimal separator is a point: write 0.5"),
    ("duration = 1 s", "write the number alone, without s: a scenario's numbers are in SI units"),
    ("duration = 1s", "write the number alone, without s:"),
    ("dt = 1e-3 s", "without s:"),
    ("dt = 20 ms", "without ms:"),
    ("duration = .5", "a number starts with a digit: write 0.5"),
    ("phase = -.5", "write -0.5"),
    ("duration = 5.", "a decimal point needs a digit after it: write 5.0"),
    ("density = 2 500", "no spaces within a number: write 2500"),
    ("max_iterations = 1 000 000", "no spaces within a number: write 1000000"),  # it said 1000: a wrong number
    ("density = 2 500.5", "write 2500.5"),
    ('motion = { kind = "sine", amplitude = 1 m/s, frequency = 2 }', "without m/s:"),
    ('motion = { kind = "sine", amplitude = 0,5, frequency = 2 }', "the decimal separator is a point: write 0.5"),
    ("name = wall", 'a text goes between quotes: "wall"'),
    ("name = my wall  # the first", 'a text goes between quotes: "my wall"'),  # it said "my"
    ("name = 3rd-wall", 'a text goes between quotes: "3rd-wall"'),  # it said "without rd-wall", a unit
    ("file = C:\\Users\\Ana Silva\\q.AT2", "quotes: 'C:\\Users\\Ana Silva\\q.AT2'"),  # it said 'C:\\Users\\Ana'
    ("file = C:\\q.AT2", "a file name goes between quotes: 'C:\\q.AT2' (single quotes keep its \\ as they are)"),
    ("file = records/q.AT2", "a file name goes between quotes: 'records/q.AT2'"),
    ('file = "C:\\Users\\ana\\q.AT2"', 'write the path with / ("C:/Users/ana/quake.AT2") or between single quotes'),
    ('file = "records\\q.AT2"', "a \\ between double quotes starts an escape"),
]


@pytest.mark.parametrize("line, fix", TYPOS)
def test_a_syntax_error_says_the_likely_fix(line, fix):
    with pytest.raises(tomllib.TOMLDecodeError) as exc:
        tomllib.loads(f"[run]\n{line}\n")
    assert fix in hint(f"[run]\n{line}\n", str(exc.value))


@pytest.mark.parametrize(
    "text", ["duration = 0.5.", 'name = "abc', "[run\ndt = 1", "x = = 1", "a = 1\na = 2", "dt = \n", "dt ="]
)
def test_no_guess_where_the_mistake_is_none_of_those(text):
    with pytest.raises(tomllib.TOMLDecodeError) as exc:
        tomllib.loads(text)
    assert hint(text, str(exc.value)) == ""


def test_the_file_error_carries_the_fix_after_tomllibs_place(tmp_path):
    message = load_error(tmp_path, SCENARIO.replace("friction = 0.6", "friction = 0,6"))
    assert message == (
        "TOML syntax error: Expected newline or end of document after a statement (at line 5, column 13); "
        "the decimal separator is a point: write 0.6"
    )


def test_a_run_setting_without_its_header_names_the_table(tmp_path):
    message = load_error(tmp_path, SCENARIO.replace("[run]\n", ""))
    assert message == 'unknown key "duration" at the top of the file (a [run] setting: write it below a [run] line)'
    message = load_error(tmp_path, "friction = 0.5\n" + BLOCK)
    assert (
        message
        == 'unknown key "friction" at the top of the file (a [material] setting: write it below a [material] line)'
    )
    assert load_error(tmp_path, "frcition = 0.5\n" + BLOCK).startswith('unknown key "frcition" (expected one of:')


@pytest.mark.parametrize("text", ["", "\n  \n", "# my wall\n# to do\n"])
def test_an_empty_file_is_called_empty(tmp_path, text):
    assert load_error(tmp_path, text).startswith("the file is empty (or only comments): a scenario needs [[block]]")


def test_utf16_without_its_byte_order_mark_is_named(tmp_path):
    for encoding in ("utf-16-le", "utf-16-be"):
        path = tmp_path / f"{encoding}.toml"
        path.write_bytes((SCENARIO + SINE).encode(encoding))
        assert_one_line_error(invoke("check", str(path)), "a UTF-16 text file (a 0 byte beside every character)")
    binary = tmp_path / "binary.toml"  # zeros at even and odd bytes alike: not UTF-16
    binary.write_bytes(b'name = "x"\n' + bytes(64))
    assert_one_line_error(invoke("check", str(binary)), "not a text file")


def test_a_path_that_toml_read_as_escapes_says_so(tmp_path):
    # "C:\temp\new.csv" is valid TOML: a tab and a line break in the name
    text = SCENARIO + 'motion = { kind = "record", file = "C:\\temp\\new.csv" }\n'
    (tmp_path / "s.toml").write_text(text)
    assert_one_line_error(
        invoke("check", str(tmp_path / "s.toml")),
        'motion.file = "C:\\temp\\new.csv": no such file: its name holds a tab or a line break',
        "between single quotes ('C:\\Users\\ana\\quake.AT2')",
    )
    for geometry in ("C:\\temp\\new.geojson", "temp\\new.geojson"):
        (tmp_path / "g.toml").write_text(f'[structure]\nfile = "{geometry}"\n')
        assert_one_line_error(invoke("check", str(tmp_path / "g.toml")), "its name holds a tab or a line break")


def test_each_typical_mistake_through_masonry_check_is_one_line_exit_2(tmp_path):
    mistakes = {
        "misspelt.toml": SCENARIO.replace("friction", "frcition") + SINE,
        "unit.toml": SCENARIO.replace("duration = 0.5", 'duration = "1 s"') + SINE,
        "comma.toml": SCENARIO.replace("friction = 0.6", "friction = 0,5") + SINE,
        "path.toml": SCENARIO + 'motion = { kind = "record", file = "C:\\Users\\ana\\elcentro.AT2" }\n',
        "norun.toml": SCENARIO.replace("[run]\n", "") + SINE,
        "empty.toml": "",
    }
    for name, text in mistakes.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
        assert_one_line_error(invoke("check", str(tmp_path / name)), name)
    (tmp_path / "bom.toml").write_bytes((SCENARIO + SINE).encode("utf-8-sig"))  # Notepad's "UTF-8 with BOM"
    (tmp_path / "tabs.toml").write_text((SCENARIO + SINE).replace(" = ", "\t=\t").replace("\n", "\r\n"))
    for name in ("bom.toml", "tabs.toml"):
        assert invoke("check", str(tmp_path / name)).exit_code == 0
