"""masonrycli.errors: the exit codes the README documents, one-line messages with their place, the path
that is no file (a pipe, a device) and the text that is not UTF-8."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from masonrycli import errors
from masonrycli.errors import InputContext, InputError, not_utf8, one_line, special_file

README = Path(__file__).parent.parent / "README.md"


def test_exit_codes_are_the_readme_troubleshooting_table():
    table = README.read_text(encoding="utf-8").split("## Troubleshooting", 1)[1].split("\n\n", 2)[1]
    documented = {int(m) for m in re.findall(r"^\| (\d+) \|", table, flags=re.M)}
    constants = {v for k, v in vars(errors).items() if k.startswith("EXIT_")}
    assert documented == constants and len(constants) == len([k for k in vars(errors) if k.startswith("EXIT_")])
    row = {int(m[0]): m[1] for m in re.findall(r"^\| (\d+) \| (.*)$", table, flags=re.M)}
    assert "completed" in row[errors.EXIT_OK] and "internal error" in row[errors.EXIT_INTERNAL]
    assert "bad input" in row[errors.EXIT_BAD_INPUT] and "diverged" in row[errors.EXIT_DIVERGED]
    assert "an output failed" in row[errors.EXIT_OUTPUT_FAILED]


def test_one_line_joins_every_run_of_whitespace():
    assert one_line("a\n  b\t\tc\r\n d ") == "a b c d"
    assert one_line(ValueError("x\ny")) == "x y"  # exceptions are said through str()


def test_the_context_puts_file_and_table_before_the_message():
    ctx = InputContext("wall.toml", "/data")
    err = ctx.error("[run]", "dt = 0:\nmust be > 0")
    assert isinstance(err, InputError) and isinstance(err, ValueError)  # callers catch ValueError too
    assert str(err) == "wall.toml: [run] dt = 0: must be > 0"
    assert str(ctx.error("", "no [[block]]")) == "wall.toml: no [[block]]"
    assert ctx.base_dir == "/data"


def test_special_file_is_a_pipe_or_a_device_not_a_file_or_folder(tmp_path):
    regular = tmp_path / "r.csv"
    regular.write_text("0 0\n")
    pipe = tmp_path / "p"
    os.mkfifo(pipe)  # opening it would wait for a writer: special_file must not
    assert special_file(pipe) and special_file("/dev/null")
    assert not special_file(regular) and not special_file(tmp_path) and not special_file(tmp_path / "missing")


def test_text_that_is_not_utf8_says_where_or_that_it_is_utf16():
    raw = "t;v\n0;é".encode("latin-1")
    with pytest.raises(UnicodeDecodeError) as info:
        raw.decode("utf-8")
    assert str(not_utf8("q.csv", raw, info.value)) == (
        "q.csv:2: not a UTF-8 text file (byte 6, 0xe9: a character saved in another encoding, such as Windows-1252); "
        "save it as UTF-8"
    )
    for encoding in ("utf-16-le", "utf-16-be"):
        raw = "\ufefft v\n0 0\n".encode(encoding)
        with pytest.raises(UnicodeDecodeError) as info:
            raw.decode("utf-8")
        msg = str(not_utf8("q.csv", raw, info.value))
        assert msg.startswith("q.csv: a UTF-16 text file") and "save it as UTF-8" in msg
