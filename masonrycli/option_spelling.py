"""An option's name in a message, as its reader typed it: ``--record-every`` on the command line, ``record_every=``
in Python (:mod:`masonrycli.api`).

The messages are written once, in the modules that check the values, naming the options the command line's way
(``--duration: duration = -1: must be > 0``). :func:`python_spelling` gives the same message with the options the
Python API takes named by their keywords (``duration=-1: must be > 0``): a notebook user read ``--tolerance`` in
a RuntimeWarning of ``api.simulate(…, tolerance=1e-7)`` and searched the API's page for a flag it does not have.

Only the given keywords are respelled (a flag no keyword has, ``--param``, stays), and never inside a command
quoted in the message (``masonry sweep --param amp=1``, ``masonry check wall --record q.AT2``): those are lines
to type at a shell.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

RENAMED = {"out": "recording", "no_recording": "recording"}
"""Options whose keyword is another word: ``--out`` is ``recording=PATH``, ``--no-recording`` ``recording=None``."""

_FLAG = re.compile(r"(?<![\w-])--(?P<name>[a-z][a-z0-9]*(?:-[a-z0-9]+)*)(?![\w-])")
_SETTING = re.compile(r": (?P<setting>[a-z][a-z_ ]*?) = (?P<value>[^\s:]+)(?=:)")
"""An option, then the setting it gives and its value: "--amp: amplitude = nan: must be a finite number"."""
_COMMAND = re.compile(r"masonry [a-z][^();\]]*")  # a shell line quoted in a message, to its closing bracket
_VALUE = re.compile(r" (?P<value>(?:[-+]?[\d.]|nan\b|inf\b)\S*?|[\w~/.-]*[/.][\w~/.-]*?|\S+?(?=:))(?=[:,;)]?(?:\s|$))")
"""The value after a flag: a number ("--dt 0.02", "--amp 1.5" before a comma), a path ("--record q.AT2"), or any
word the message ends with a colon ("--pga x: must be a number")."""


def python_spelling(text: str, keywords: Iterable[str], renamed: dict[str, str] = RENAMED) -> str:
    """``text`` with each ``--name`` of a ``keywords`` entry spelled ``name=`` (``--record-every`` →
    ``record_every=``; ``renamed``: the options whose keyword is another word, ``--out`` → ``recording=``), its value joined to it (``--duration 4.99`` →
    ``duration=4.99``), and an option followed by its setting's value as the keyword's (``--dt: dt = 0.02:`` →
    ``dt=0.02:``, ``--amp: amplitude = nan:`` → ``amp=nan (amplitude):``)."""
    keywords = set(keywords)
    commands = [m.span() for m in _COMMAND.finditer(text)]
    out, at = [], 0
    for match in _FLAG.finditer(text):
        name = match["name"].replace("-", "_")
        keyword = renamed.get(name, name)
        if keyword not in keywords or any(lo <= match.start() < hi for lo, hi in commands):
            continue
        end = match.end()
        if (setting := _SETTING.match(text, end)) is not None:  # "--dt: dt = 0.02:" is "dt=0.02:"
            named = "" if setting["setting"] == name else f" ({setting['setting']})"  # "amp=nan (amplitude):"
            spelled, end = f"{keyword}={setting['value']}{named}", setting.end("value")
        elif (value := _VALUE.match(text, end)) is not None:
            spelled, end = f"{keyword}={value['value']}", value.end("value")
        else:
            spelled = f"{keyword}="
        out += [text[at : match.start()], spelled]
        at = end
    return "".join(out) + text[at:]
