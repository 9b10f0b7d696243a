"""What a TOML syntax error most likely is, said in the scenario's words.

tomllib names the place (``Expected newline or end of document after a statement (at line 8, column 13)``)
but not the mistake, and the usual mistakes of someone writing their first scenario by hand are few: a
comma as the decimal separator (``friction = 0,5``), a unit after the number (``duration = 1 s``), a
Windows path in a ``"…"`` string (``"C:\\Users\\…"``: ``\\U`` starts an escape), a word without quotes
(``name = wall``), a number written ``.5``. ``hint`` looks at the character the error points at and what
comes before it on that line, and returns the fix for the one it recognises, or "" (no guess rather than a
wrong one).
"""

from __future__ import annotations

import re

from masonrycli.errors import ESCAPED_PATH

_PLACE = re.compile(r"\(at line (\d+), column (\d+)\)")
_NUMBER_BEFORE = re.compile(r"(?:^|[=\[,{]\s*)([-+]?\d[\d_]*(?:\.\d+)?(?:[eE][-+]?\d+)?)\s*$")
_DIGITS_BEFORE = re.compile(r"(?:^|[=\[,{]\s*)([-+]?\d+)$")
_WORD = re.compile(r"[^\s,\]}#]+")
_COMMA_NUMBER = re.compile(r"=\s*([-+]?\d+),(\d+)\b")
_UNIT_START = re.compile(r"[A-Za-zµ°%'\"/]")
_UNIT_WORD = re.compile(r"[A-Za-zµ°%'\"/²³^*·.\d]{1,8}")  # s, ms, m/s, kg/m3, m/s^2, Hz; not "rd-wall"
_SPACED_NUMBER = re.compile(r"[-+]?\d+(?: +\d+)*(?:\.\d+)?(?:[eE][-+]?\d+)?")
_KEY_EQUALS = re.compile(r"^\s*[\w.\"'-]+\s*=\s*")


def _value_text(line: str, start: int) -> str:
    """The unquoted value from ``start``: the rest of a ``key = value`` line (up to a comment: a name or a
    path may hold spaces), else (in an array or inline table) up to the next space, comma or bracket."""
    if _KEY_EQUALS.fullmatch(line[:start]):
        return line[start:].split("#")[0].strip()
    return _WORD.match(line, start).group()


def hint(text: str, message: str) -> str:
    """The likely mistake behind tomllib's ``message`` on ``text`` and its fix, or ""."""
    place = _PLACE.search(message)
    if place is None:  # "(at end of document)": an unterminated string or table, named well enough
        return ""
    lines = text.splitlines()
    row, column = int(place.group(1)), int(place.group(2))
    if not 1 <= row <= len(lines):
        return ""
    line = lines[row - 1]
    before, at = line[: column - 1], line[column - 1 : column]
    after = line[column:]
    if "\\" in before and ("escape" in message.lower() or "hex value" in message or "Unescaped '\\'" in message):
        return ESCAPED_PATH
    digits = _DIGITS_BEFORE.search(before)
    if at == "," and digits and after[:1].isdigit():
        decimals = re.match(r"\d+", after).group()
        return f"the decimal separator is a point: write {digits.group(1)}.{decimals}"
    number = _NUMBER_BEFORE.search(before)
    if number and at.isdigit() and before.endswith(" "):  # "1 000", "1 000 000" (every group, not 1000)
        whole = _SPACED_NUMBER.match(line, number.start(1)).group()
        return f"no spaces within a number: write {whole.replace(' ', '')}"
    if number and at == "." and not after[:1].isdigit():  # "5." (not "0.5.": no fix to guess)
        return (
            ""
            if re.search(r"[.eE]", number.group(1))
            else f"a decimal point needs a digit after it: write {number.group(1)}.0"
        )
    if number and _UNIT_START.match(at):
        unit = _WORD.match(line, column - 1).group()
        if _UNIT_WORD.fullmatch(unit):
            return (
                f"write the number alone, without {unit}: a scenario's numbers are in SI units (m, s, kg, m/s, Hz, rad)"
            )
        if _KEY_EQUALS.fullmatch(line[: number.start(1)]):  # "name = 3rd-wall": a text
            return f'a text goes between quotes: "{_value_text(line, number.start(1))}"'
        return ""
    bare = re.match(r"([-+]?)\.(\d+)", line[column - 1 :])
    if bare and re.search(r"[=\[,{]\s*$", before):  # ".5", "-.5"
        return f"a number starts with a digit: write {bare.group(1)}0.{bare.group(2)}"
    if message.startswith("Invalid value") and re.search(r"=\s*$", before) and at and (at.isalpha() or at in "/~."):
        word = _value_text(line, column - 1)
        if "\\" in word or "/" in word or re.match(r"[A-Za-z]:", word):
            keep = " (single quotes keep its \\ as they are)" if "\\" in word else ""
            return f"a file name goes between quotes: '{word}'{keep}"
        return f'a text goes between quotes: "{word}"'
    comma = list(_COMMA_NUMBER.finditer(line[: column + 1]))  # in an inline table: "amplitude = 0,5, …"
    if comma:
        return f"the decimal separator is a point: write {comma[-1].group(1)}.{comma[-1].group(2)}"
    return ""
