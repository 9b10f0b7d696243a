"""A call's keywords (:mod:`masonrycli.api`): which a function takes (the options of its command), refused as the
command line refuses them (one line), and its messages and warnings with the options named as typed
(``duration=``, where the command line says ``--duration``: :mod:`masonrycli.option_spelling`)."""

from __future__ import annotations

import difflib
import functools
import os
import sys
import warnings
from pathlib import Path

import numpy as np

from masonrycli.errors import InputError

SIMULATE_GROUPS = {  # the option groups of `masonry simulate NAME` (cli/app.py), by built-in
    "wall": ("WALL", "WALL_LOADING"),
    "arch": ("ARCH", "SETTLED_LOADING"),
    "aqueduct": ("AQUEDUCT", "SETTLED_LOADING"),
}


def option_names(target) -> list[str]:
    """The keywords ``target`` takes: the options of ``masonry simulate NAME`` for a built-in, of ``masonry run``
    for a file, and the run settings and friction for a :class:`Scenario` already made (its loading is made with
    it: a record given to it would run for its duration, where ``simulate("wall", record=…)`` runs the record)."""
    from masonrycli.cli import options
    from masonrycli.scenario.target import is_built_in

    groups = ["RUN", "FRICTION"]
    if isinstance(target, (str, os.PathLike)) and is_built_in(target):
        groups += ["RECORD", *SIMULATE_GROUPS[os.fspath(target)], "BLOCK_MATERIAL", "SIMULATE_SETTLE"]
    elif isinstance(target, (str, os.PathLike)):
        groups += ["RECORD", "SURVEY", "SETTLE"]
    return [name for group in groups for name in getattr(options, group)]


@functools.cache
def all_keywords() -> frozenset[str]:
    """Every keyword of :func:`scenario` and :func:`simulate`, whatever the target: the options the messages name."""
    from masonrycli.cli import options

    groups = ["RUN", "FRICTION", "RECORD", "SURVEY", "SETTLE", "BLOCK_MATERIAL", "WALL", "WALL_LOADING", "ARCH"]
    groups += ["SETTLED_LOADING", "AQUEDUCT", "SIMULATE_SETTLE"]
    names = {name for group in groups for name in getattr(options, group)}
    return frozenset(names | set(OUTPUTS) | {"recording"})


def python_spelled(function=None, *, keywords=None, renamed=None):
    """``function`` with the options its errors and warnings name spelled as its keywords (``duration=``, where
    the command line says ``--duration``): the same messages (:mod:`masonrycli.option_spelling`). Its warnings
    are said as they happen, from the caller's line (they were held until the call returned: a record's warning
    came minutes later, at the end of the run). ``keywords`` / ``renamed``: a method's own (default:
    scenario's and simulate's, ``--out`` as ``recording=``)."""
    from masonrycli.option_spelling import RENAMED, python_spelling

    if function is None:
        return functools.partial(python_spelled, keywords=keywords, renamed=renamed)

    @functools.wraps(function)
    def spelled(*args, **kwargs):
        caller = sys._getframe(1)  # the notebook's line, which the warnings name
        given = {k: v for k, v in kwargs.items() if v is not None}  # "--blocks and --courses:" said no values

        def spell(text: str) -> str:
            known = all_keywords() if keywords is None else keywords
            return python_spelling(text, known, RENAMED if renamed is None else renamed, given)

        # the caller's filters kept: what they hide (a library's DeprecationWarning) reaches no showwarning, so
        # is not said again from the caller's line, where Python shows a DeprecationWarning of __main__
        with warnings.catch_warnings():  # showwarning restored on the way out
            warnings.showwarning = _said_from(caller, warnings.showwarning, spell)
            try:
                return function(*args, **kwargs)
            except InputError as exc:
                raise InputError(spell(str(exc))) from None
            except Warning as exc:  # a warning the caller's filters make an error ("error"): spelled as warned
                raise type(exc)(spell(str(exc))) from None

    return spelled


def _said_from(caller, show, spell):
    """A ``warnings.showwarning`` that says a warning again now, spelled, as if warned at ``caller``'s line
    (through the caller's filters, shown by ``show``: the caller's own showwarning)."""

    def say(message, category, filename, lineno, file=None, line=None):
        mine = warnings.showwarning
        warnings.showwarning = show  # its own showing: not this one again
        try:
            module = caller.f_globals.get("__name__", "__main__")
            registry = caller.f_globals.setdefault("__warningregistry__", {})
            text = spell(str(message))
            warnings.warn_explicit(text, category, caller.f_code.co_filename, caller.f_lineno, module, registry)
        finally:
            warnings.showwarning = mine

    return say


OUTPUTS = {  # the command line's output options, which simulate() names otherwise
    "out": "the recording is simulate(recording=PATH)",
    "no_recording": "simulate() writes no recording unless recording= names one",
    "force": "force= is simulate()'s, with recording= or history=",
    "history": "history= is simulate()'s",
    "magnify": "magnify= is simulate()'s, with recording=",
    "stop_at_collapse": "stop_at_collapse= is simulate()'s",
}


def check_names(target, given: dict) -> None:
    """Refuse a keyword the command does not take, as its command line refuses the option (one line)."""
    known = option_names(target)
    for key in given:
        if key not in known:
            close = difflib.get_close_matches(key, known, n=3)
            what = os.fspath(target) if isinstance(target, (str, os.PathLike)) else "a Scenario already made"
            hint = f"did you mean {', '.join(close)}?" if close else f"its options: {', '.join(known)}"
            if not isinstance(target, (str, os.PathLike)):
                hint = "it takes run settings and friction; its structure and loading are given to api.scenario()"
            hint = OUTPUTS.get(key, hint)
            raise InputError(f"no such option: {key}= for {what} ({hint})")


def one_value_each(options: dict) -> None:
    """Refuse several values for one keyword (``freq=[1, 2, 3]``: a run takes one), saying how to run them all:
    it said "--freq: frequency = [1, 2, 3]: must be a number", and a student took it for a wrong type."""
    for key, value in options.items():
        if isinstance(value, (list, tuple, range, np.ndarray)) and np.size(value) > 1:
            values = [f"{v:g}" if isinstance(v, float) else str(v) for v in np.ravel(value)]
            listed = ",".join(values[:3]) + (",…" if len(values) > 3 else "")
            raise InputError(
                f"{key}: {len(values)} values ({listed}): one run takes one value; loop over them (for {key} in …: "
                f"api.simulate(…, {key}={key})) or run a study, masonry sweep --param {key}={listed} (masonry docs "
                "python, 'Looping over parameters')"
            )


def path_value(value, option: str, *, output: bool = False) -> Path:
    """A path keyword read by the command line's own parser of ``option`` (``~`` expanded, an empty one refused;
    an output's "x.rrd/" names a folder, where Path("x.rrd/") would have written the file x.rrd)."""
    import typer

    from masonrycli.cli.option_values import file_path_value, path_value

    if not isinstance(value, (str, os.PathLike)):
        kind = type(value).__name__
        raise InputError(
            f"{option} {value!r}: a path (str or pathlib.Path), not {'an' if kind[0] in 'aeiou' else 'a'} {kind}"
        )
    try:
        return (file_path_value if output else path_value)(os.fspath(value))
    except typer.BadParameter as exc:
        said = exc.message  # "x.rrd/: a path ending in "/" …": the value once, the keyword's (recording=x.rrd/: …)
        raise InputError(f"{option} {said}" if said.startswith(f"{value}: ") else f"{option}: {said}") from None


def pga_value(value) -> float | None:
    """``pga=``: a number in g, or a string as ``--pga`` takes it ("0.25g", "2.45m/s2"); None: not given."""
    from masonrycli.records.pga import pga_in_g

    if value is None:
        return None
    try:
        return pga_in_g(value)
    except InputError as exc:
        raise InputError(f"--pga {exc}") from None
