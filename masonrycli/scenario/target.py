"""A command's TARGET -> its scenario: a built-in name (run by the command's own ``built_in``), a scenario file
(TOML) or a geometry file (GeoJSON / WKT, every support fixed). A target that is none of them gets the same one
line from every command (they said "no such scenario file", "no such scenario or geometry file" or "cannot
read scenario: No such file or directory" for one missing file). :func:`file_scenario`: a file's scenario with
the command's record and run overrides (``masonry run`` / ``check``)."""

from __future__ import annotations

import difflib
import math
import os
from collections.abc import Callable
from pathlib import Path

from masonrycli.errors import NOT_A_FILE, InputError, file_kind, special_file
from masonrycli.scenario.builtin import BUILT_IN, DEFAULT_DURATION, override_run
from masonrycli.scenario.record_option import geometry_as_is, with_record
from masonrycli.scenario.scenario import MAX_DURATION, RunConfig, Scenario
from masonrycli.scenario.structure import GEOMETRY_SUFFIXES, survey_of


def is_built_in(target: str | os.PathLike) -> bool:
    """Whether a command's TARGET names a built-in structure: its name, unless a file of that name is
    here (a folder ``wall/`` of recordings is no scenario: ``masonry limit wall`` said "no such scenario
    or geometry file")."""
    return os.fspath(target) in DEFAULT_DURATION and not os.path.isfile(target)


def target_scenario(target: str | os.PathLike, built_in: Callable[[str], Scenario] | None = None, survey=None):
    """The scenario a command's TARGET names: ``built_in(name)`` for a built-in name (None: the command
    takes files only, and the message says where the built-ins run), else a scenario file (TOML) or a
    geometry file (GeoJSON / WKT, every support fixed). A target that is none of them raises the same
    one-line :class:`InputError` from every command, naming it. ``survey``: a geometry file's reading (survey_of)."""
    from masonrycli.scenario.scenario import scenario_from_geometry_file
    from masonrycli.scenario.toml_file import load_scenario

    target = os.fspath(target)
    survey = survey_of(survey or {}, target)
    if not target.strip():  # Path("") is the working folder: it said "error: : no such scenario …"
        raise InputError(f"the structure argument is empty ({target!r}): give wall, arch, aqueduct or a scenario file")
    if is_built_in(target):
        if built_in is None:
            raise InputError(f"{target}: not a file; the built-in structures are run with `masonry simulate {target}`")
        return built_in(target)
    if target.startswith("~"):  # quoted, the shell left it ('masonry run "~/w.toml"'): as --out and a file key
        target = os.path.expanduser(target)
    problem = _target_problem(target)
    if problem:
        raise InputError(f"{target}: {problem}")
    path = Path(target)  # as the commands read it before: "./s.toml" is the scenario "s.toml"
    if path.suffix.lower() in GEOMETRY_SUFFIXES:
        return scenario_from_geometry_file(path, survey)
    try:
        return load_scenario(path)
    except InputError as exc:
        if path.suffix.lower() == ".toml":
            raise
        other = file_kind(path, "a scenario (TOML) or a geometry file (GeoJSON / WKT)")
        if other is not None:
            raise other from None
        # "notes.txt: TOML syntax error …" left a user who meant a geometry file guessing why TOML
        raise InputError(
            f"{exc} (read as a scenario TOML: a geometry file's name ends in {', '.join(GEOMETRY_SUFFIXES)})"
        ) from None


def _target_problem(target: str) -> str:
    """Why ``target`` is no file to read ("" if it is one), checked before a reader opens it: each reader
    said it its own way ("cannot read scenario: is a directory", a folder named .geojson "not a regular
    file", an unreadable one "cannot read file (PermissionError: [Errno 13] …)")."""
    if special_file(target):  # checked without opening it: opening a named pipe waits for a writer
        return NOT_A_FILE
    if os.path.isdir(target):
        return "is a directory, not a scenario or geometry file"
    if not os.path.exists(target):
        bare = os.sep not in target and not Path(target).suffix  # "wal", not "wal.toml" or "runs/wal"
        close = difflib.get_close_matches(target.lower(), BUILT_IN, n=1) if bare else []
        hint = f"did you mean {close[0]}?" if close else f"built-in structures: {', '.join(BUILT_IN)}"
        return f"no such scenario or geometry file ({hint})"
    try:
        open(target, "rb").close()
    except OSError as exc:
        return f"cannot read file: {exc.strerror or exc}"
    return ""


def file_scenario(
    path: str | os.PathLike,
    *,
    record: Path | None = None,
    scale: float | None = None,
    record_dt: float | None = None,
    baseline: str | None = None,
    survey: dict | None = None,
    **overrides,
) -> Scenario:
    """The scenario of a TOML, GeoJSON or WKT file (``masonry run`` / ``check``, :func:`target_scenario`:
    a built-in's name is told where it runs) driven by ``record`` times ``scale`` if given
    (:func:`with_record`), with the run settings and the friction of ``overrides`` (:func:`override_run`).
    A geometry file has no run settings of its own: shaken by a record with no --duration it runs the whole
    record, as ``simulate`` does (it ran the default 1 s: 'masonry run wall.geojson --record q.AT2' of an 8 s
    record, its strong motion after 2 s, said "intact")."""
    scenario = with_record(target_scenario(path, survey=survey), record, scale, record_dt, baseline)
    if record is not None and geometry_as_is(scenario) and overrides.get("duration") is None:
        overrides = overrides | {"duration": whole_records(scenario.motions, overrides.get("dt"))}
    return override_run(scenario, **overrides)


def whole_records(motions, dt=None) -> float:
    """s: the longest record of ``motions`` in whole steps of ``dt`` (default: the run's 1e-3 s), at most
    ``MAX_DURATION``; a bad ``dt`` gives the default duration (:func:`override_run` names the option)."""
    ends = [m.end_time for m in motions if m.kind == "record"]
    dt = RunConfig.dt if dt is None else dt
    if not ends or not (isinstance(dt, (int, float)) and 0.0 < dt < math.inf):
        return RunConfig.duration
    return min(max(1, math.ceil(max(ends) / dt - 1e-9)) * dt, MAX_DURATION)
