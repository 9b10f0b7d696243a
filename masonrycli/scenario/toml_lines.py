"""The line of a scenario file an error is about: ``wall.toml:4: [run] duration = "1 s": …``.

tomllib gives no positions, so the line is found in the text and then proved by tomllib itself: each
place where the key is written (``duration =``, ``run.duration =``, inside ``motion = { …, frequency =
… }``) is renamed in a copy of the text, the copy parsed, and the place is the key's only if the key has
moved, under the new name, to the table the message names (``[run]``, the 2nd ``[[block]]``, the motion of
the 1st ``[[support]]``). A look-alike in a string, a comment, another table or another ``[[block]]`` does
not move it; TOML allows a key once per table, so a place that moves it is the one. A key written as the
header of a plain table (a misspelt ``[runn]``, ``[[blocks]]``) is found the same way, the header renamed.
When none is found (the key is missing, or a header under an array of tables), or the message names no
key, no line is given — a wrong line would be worse than none.
"""

from __future__ import annotations

import re
import tomllib

_PROBE = "masonry_probe_key_7f3a"
_MAX_PROBES = 8  # parses of the text at most, the likely places first: an error message stays quick
_MAX_PROBED_CHARS = 4_000_000  # text x probes: a scenario of 100 000 inline blocks is not parsed 8 times

# the message after "<file>: ": where (a table, an array table's entry) then what
_WHERE = re.compile(r'\[(\[?)([A-Za-z_][\w-]*)\]\]?(?: #(\d+))?(?: \("(?:[^"\\]|\\.)*"\))?:? ')
_KEY = re.compile(r"(?:motion\.)?([A-Za-z_][\w-]*)(?:\[\d+\])*(?: = |: )")
_NAMED = re.compile(r'(motion: )?unknown (?:key|option) "([A-Za-z_][\w-]*)"')
_HEADER = re.compile(r"^[ \t]*\[(\[?)[ \t]*([A-Za-z_][\w.-]*)[ \t]*\]", re.M)


def message_key(message: str) -> tuple[tuple, str] | None:
    """(table path, key) that ``message`` (the part after ``<file>: ``) is about, or None.

    ``[run] dt = 0: …`` -> (("run",), "dt"); ``[[block]] #2 ("b2"): density = …`` -> (("block", 1),
    "density"); ``[[support]] #1: motion.frequency = …`` -> (("support", 0, "motion"), "frequency");
    ``[run] unknown key "dtt" …`` -> (("run",), "dtt"); ``name = 3: …`` -> ((), "name")."""
    path: tuple = ()
    where = _WHERE.match(message)
    rest = message
    if where:
        is_array, table, index = where.groups()
        if bool(is_array) != (index is not None):
            return None
        path = (table, int(index) - 1) if index is not None else (table,)
        rest = message[where.end() :]
    named = _NAMED.match(rest)
    if named:
        return (path + ("motion",) if named.group(1) else path), named.group(2)
    key = _KEY.match(rest)
    if key is None:  # "polygon is not convex", "no blocks: …": about no one key
        return None
    if rest.startswith("motion."):
        path += ("motion",)
    return path, key.group(1)


def _table(doc, path: tuple):
    node = doc
    for part in path:
        if isinstance(part, int):
            if not isinstance(node, list) or part >= len(node):
                return None
        elif not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node if isinstance(node, dict) else None


def _contexts(text: str, offsets: list[int]) -> list[tuple[str, int]]:
    """The table header above each of the ascending ``offsets`` as a naive reader sees it (its name, the
    count of its ``[[name]]`` so far, from 0), in one pass: only to try the likely places first (tomllib
    decides)."""
    out, name, counts = [], "", {}
    headers = _HEADER.finditer(text)
    header = next(headers, None)
    for offset in offsets:
        while header is not None and header.start() < offset:
            name = header.group(2)
            if header.group(1):
                counts[name] = counts.get(name, 0) + 1
            header = next(headers, None)
        out.append((name, counts.get(name.split(".")[0], 0) - 1))
    return out


def key_line(text: str, path: tuple, key: str) -> int | None:
    """The line (from 1) where ``key`` of the table at ``path`` is written in the TOML ``text``, or None."""
    spelled = re.escape(key)
    places = [
        m
        for m in re.finditer(rf"(?<![\w\"'-])(?:{spelled}|\"{spelled}\"|'{spelled}')(?=[ \t]*=(?!=))", text)
        if not text[text.rfind("\n", 0, m.start()) + 1 : m.start()].lstrip().startswith("#")
    ]

    def unlikely(match, context) -> bool:
        name, count = context
        if not path:
            return name != ""
        if name.split(".")[0] != path[0] and not (name == "" and text[match.start() - 1 : match.start()] == "."):
            return True
        return len(path) > 1 and isinstance(path[1], int) and count != path[1]

    contexts = _contexts(text, [m.start() for m in places])
    places = [m for _, m in sorted(zip(contexts, places), key=lambda cm: unlikely(cm[1], cm[0]))]
    budget = min(_MAX_PROBES, _MAX_PROBED_CHARS // max(len(text), 1))
    for match in places[:budget]:
        probe = text[: match.start()] + _PROBE + text[match.end() :]
        try:
            table = _table(tomllib.loads(probe), path)
        except (tomllib.TOMLDecodeError, RecursionError):
            continue
        if table is not None and _PROBE in table and key not in table:
            return text.count("\n", 0, match.start()) + 1
    return _header_line(text, path, key, budget - min(len(places), budget))


def _header_line(text: str, path: tuple, key: str, budget: int) -> int | None:
    """The line of the first table header naming ``key`` of the plain table at ``path`` — ``[runn]``,
    ``[run.extra]``, ``[[blocks]]`` (a misspelt section: ``wall.toml:1: unknown key "runn"``) — proved as a
    key is: renamed in a copy, the header must make a table of the new name there (one in a string does
    not). Not under an array of tables (``[support.motion]`` is the motion of the last ``[[support]]``
    above it)."""
    if not all(isinstance(part, str) for part in path):
        return None
    name = ".".join((*path, key))
    headers = [m for m in _HEADER.finditer(text) if m.group(2) == name]
    for m in headers[: max(budget, 0)]:
        probe = text[: m.end(2) - len(key)] + _PROBE + text[m.end(2) :]  # the key's part of the dotted name
        try:
            table = _table(tomllib.loads(probe), path)
        except (tomllib.TOMLDecodeError, RecursionError):
            continue
        if table is not None and _PROBE in table:
            return text.count("\n", 0, m.start()) + 1
    return None


def with_line(message: str, fname: str, text: str) -> str:
    """``message`` (``<fname>: <what>``) as ``<fname>:<line>: <what>`` when the key it names is found
    (:func:`key_line`), else unchanged."""
    head = f"{fname}: "
    if not message.startswith(head):
        return message
    found = message_key(message[len(head) :])
    line = key_line(text, *found) if found else None
    return message if line is None else f"{fname}:{line}: {message[len(head) :]}"


def file_key_line(source: str, path: tuple, key: str, value) -> int | None:
    """The line of ``key`` of the table at ``path`` in the TOML file ``source`` if the file gives it
    ``value`` (or, ``value`` a function, if it holds for the file's value), else None: for checks made once the command line's values are applied (``--dt``, a sweep's
    ``--param freq=…``), where the line of the file's other value would mislead. An entry of an array of
    tables may be named by its ``name``: ``("support", "ground", "motion")`` (a builder's supports are
    listed by name, in any order; an unnamed ``[[support]]`` is ``support-<n>``)."""
    try:
        with open(source, "rb") as f:
            text = f.read().decode("utf-8-sig")
        node = tomllib.loads(text)
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError):
        return None
    concrete: list = []
    for part in path:
        if isinstance(node, list) and isinstance(part, str):
            named = [
                i
                for i, e in enumerate(node)
                if isinstance(e, dict) and e.get("name", f"{concrete[-1]}-{i + 1}") == part
            ]
            if len(named) != 1:
                return None
            part = named[0]
        if isinstance(node, list) and isinstance(part, int) and part < len(node):
            node = node[part]
        elif isinstance(node, dict) and isinstance(part, str) and part in node:
            node = node[part]
        else:
            return None
        concrete.append(part)
    given = node.get(key) if isinstance(node, dict) else None
    if callable(value):  # a test of the file's value: a record's file, resolved as the scenario reads it
        if given is None or not value(given):
            return None
    elif isinstance(given, bool) or given != value:  # true == 1: a boolean is no number
        return None
    return key_line(text, tuple(concrete), key)
