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

import os
import re
from collections.abc import Iterable

RENAMED = {"out": "recording", "no_recording": "recording"}
"""Options whose keyword is another word: ``--out`` is ``recording=PATH``, ``--no-recording`` ``recording=None``."""

SWITCHES = {
    "force": "True",
    "convex_hull": "True",
    "flip_y": "True",
    "stop_at_collapse": "True",
    "no_recording": "None",
}
"""Flags that take no value, and the keyword's value that says the same: "add --force" is "add force=True"."""

_FLAG = re.compile(r"(?<![\w-])--(?P<name>[a-z][a-z0-9]*(?:-[a-z0-9]+)*)(?![\w-])")
_SETTING = re.compile(r": (?P<setting>[a-z][a-z_ ]*?) = (?P<value>[^\s:]+)(?=:)")
"""An option, then the setting it gives and its value: "--amp: amplitude = nan: must be a finite number"."""
_LEAD = re.compile(r"(?P<flags>--[a-z][a-z0-9-]*(?: and --[a-z][a-z0-9-]*)*): ")
"""The options a message is about, first: "--duration and --dt: duration = 4.99 is not …"."""
_ASSIGNED = re.compile(r"(?<![\w-])(?P<name>[a-z][a-z0-9_]*) = (?P<value>\"[^\"]*\"|[^\s:;,()]+)")
"""A setting and its value in a message: "dt = 0.02" (a scenario file's spelling, the message's own)."""
_COMMAND = re.compile(r"masonry [a-z][^();\]]*")  # a shell line quoted in a message, to its closing bracket
_VALUE = re.compile(
    r" (?P<value>(?:[-+]?[\d.]|nan\b|inf\b)\S*?|[\w~/.-]*[/.][\w~/.-]*?|[A-Z]+|\S+?(?=:))(?=[:,;)]?(?:\s|$))"
)
"""The value after a flag: a number ("--dt 0.02", "--amp 1.5" before a comma), a path ("--record q.AT2"), a
placeholder ("give --amp A"), or any word the message ends with a colon ("--pga x: must be a number")."""


def python_spelling(
    text: str, keywords: Iterable[str], renamed: dict[str, str] = RENAMED, given: dict | None = None
) -> str:
    """``text`` with each ``--name`` of a ``keywords`` entry spelled ``name=`` (``--record-every`` →
    ``record_every=``; ``renamed``: the options whose keyword is another word, ``--out`` → ``recording=``), its
    value joined to it (``--duration 4.99`` → ``duration=4.99``; ``--baseline none goes with`` → ``baseline=none
    goes with`` when ``given``, the call's keyword → value, holds it), a flag the message gives no value as its
    value in ``given`` (``--blocks and --courses: 51 blocks …`` → ``blocks=51 and courses=5: 51 blocks …``) or as
    the keyword's value that says it (``add --force`` → ``add force=True``), flags in a row as a list (``--settlement 0 --amp A`` →
    ``settlement=0, amp=A``), and an option followed by its setting's value as the keyword's (``--amp: amplitude
    = nan:`` → ``amp=nan (amplitude):``). A message about options whose settings it names drops the flags it
    starts with: ``--duration and --dt: duration = 4.99 is not a whole number of steps of dt = 0.02`` is
    ``duration=4.99 is not a whole number of steps of dt=0.02``."""
    keywords, given = set(keywords), given or {}
    text = _settings_named(text, keywords, renamed)
    commands = [m.span() for m in _COMMAND.finditer(text)]
    lead = (lead := _LEAD.match(text)) and lead.end()  # the flags a message is about ("Raise --max-iterations": not)
    out, at, spelled_to = [], 0, -1
    for match in _FLAG.finditer(text):
        name = match["name"].replace("-", "_")
        keyword = renamed.get(name, name)
        if keyword not in keywords or any(lo <= match.start() < hi for lo, hi in commands):
            continue
        end = match.end()
        word = _shown(given[keyword]) if keyword in given else None
        if (setting := _SETTING.match(text, end)) is not None:  # "--dt: dt = 0.02:" is "dt=0.02:"
            named = "" if setting["setting"] == name else f" ({setting['setting']})"  # "amp=nan (amplitude):"
            spelled, end = f"{keyword}={setting['value']}{named}", setting.end("value")
        elif word is not None and text.startswith(f" {word}", end) and not text[end + len(word) + 1 :][:1].isalnum():
            spelled, end = f"{keyword}={word}", end + len(word) + 1
        elif name in SWITCHES:
            spelled = f"{keyword}={SWITCHES[name]}"
        elif (value := _VALUE.match(text, end)) is not None:
            spelled, end = f"{keyword}={value['value']}", value.end("value")
        else:  # "--blocks and --courses: …": the value typed, when known
            spelled = f"{keyword}={word if word is not None and lead and match.start() < lead else ''}"
        gap = text[at : match.start()]
        out += [", " if gap == " " and at == spelled_to else gap, spelled]  # "settlement=0, amp=A"
        at = spelled_to = end
    return "".join(out) + text[at:]


def _shown(value) -> str:
    """A keyword's value as the message shows it: a path or a word as it is, a number as Python writes it."""
    text = os.fspath(value) if isinstance(value, (str, os.PathLike)) else repr(value)
    return text or "''"  # an empty path: record=''


def _settings_named(text: str, keywords: set[str], renamed: dict[str, str]) -> str:
    """``text`` without the flags it starts with when it names their settings (``--duration and --dt: duration =
    4.99 is …``), each keyword's setting then spelled as the keyword (``duration=4.99 is …``); else ``text``."""
    lead = _LEAD.match(text)
    if lead is None:
        return text
    names = {renamed.get(n, n) for n in (f.removeprefix("--").replace("-", "_") for f in lead["flags"].split(" and "))}
    rest = text[lead.end() :]
    if not names <= keywords or not any(m["name"] in names for m in _ASSIGNED.finditer(rest)):
        return text
    commands = [m.span() for m in _COMMAND.finditer(rest)]
    return _ASSIGNED.sub(
        lambda m: (
            m[0]
            if m["name"] not in keywords or any(lo <= m.start() < hi for lo, hi in commands)
            else f"{m['name']}={m['value']}"
        ),
        rest,
    )
