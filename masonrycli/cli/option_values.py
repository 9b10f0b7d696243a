"""How an option's text becomes its value: numbers that remember how they were typed and refuse digits with
underscores, choices in any case, paths neither empty nor naming a folder, --pga with its unit. The parsers
every command's options use (the groups: :mod:`masonrycli.cli.options`), and the Python API's paths."""

from __future__ import annotations

import os
from pathlib import Path

import typer
from pydantic import TypeAdapter
from pydantic_core import PydanticCustomError

from geometry_library.values import TypedNumber


def choice_value(text: str) -> str:
    """A choice option's value (--im, --outcome, --solver, --load, --direction, --baseline) in lower case, the
    spelling its help lists: "--im PGV" said "expected one of pga, pgv, arias, sa"."""
    return str(text).strip().lower()


_FLOAT = TypeAdapter(float)


_INT = TypeAdapter(int)


def _no_underscore(text: str, kind: str) -> None:
    """Refuse "1_0": Python's float() and int() (so pydantic's lax ones) read it as 10, but on the command
    line it is a typo ("--dt 1_0" ran with dt = 10). A scenario file's TOML 1_0 stays its syntax."""
    if "_" in str(text):
        raise PydanticCustomError(kind, "Input should be a valid number")


def number_value(text: str) -> TypedNumber:
    """A float option's value that remembers how it was typed, for the messages that echo it ("--rtol 0:
    must be in (0, 1)", was "0.0"). Parsed as typer parses a float (pydantic's lax float), so a value that
    is not a number fails as before (cli/messages.py: "--dt 20ms: must be a number ..."), except digits with
    underscores (:func:`_no_underscore`)."""
    _no_underscore(text, "float_parsing")
    return TypedNumber(_FLOAT.validate_python(text), str(text))


def pga_value(text: str) -> float:
    """``--pga``'s value in g, a unit converted (:func:`masonrycli.records.pga.pga_in_g`)."""
    from masonrycli.errors import InputError
    from masonrycli.records.pga import pga_in_g

    try:
        return TypedNumber(pga_in_g(text), str(text))
    except InputError as exc:
        raise typer.BadParameter(str(exc)) from None


def whole_value(text: str) -> int:
    """An int option's value, parsed as typer parses an int (pydantic's lax int), without underscores."""
    _no_underscore(text, "int_parsing")
    return _INT.validate_python(text)


def path_value(text: str) -> Path:
    """A path option's value: ``""`` is refused as empty (``Path("")`` is ".", so ``--out ""`` said
    "--out .: the file name must end in .rrd" and ``--record ""`` ".: is a directory"); ``~`` is the home
    folder: the shell leaves it in ``--out=~/runs/w.rrd``, which made a folder named "~" in the working one."""
    if not str(text).strip():
        raise typer.BadParameter("the path is empty")
    return Path(text).expanduser()


def file_path_value(text: str) -> Path:
    """An output file's path (``--out``, ``--history``, ``--plot``, ``--recording``): as :func:`path_value`,
    and one whose last part is empty or "." names a folder, not a file: ``Path("x.rrd/")`` is ``x.rrd``, so
    ``--out x.rrd/`` wrote the file x.rrd without a word."""
    path = path_value(text)
    last = str(text).replace(os.altsep or os.sep, os.sep).rsplit(os.sep, 1)[-1]
    # an existing folder is left to check_output, which says "is a folder (name a file in it: d/NAME.rrd)"
    if last in ("", ".") and not path.is_dir():
        ending = os.sep + last
        raise typer.BadParameter(
            f'{text}: a path ending in "{ending}" names a folder, not a file (give the file\'s name, without '
            f'the "{ending}")'
        )
    return path
