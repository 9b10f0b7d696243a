"""Built-in scenarios: the paper's structures with their loadings, and run settings given as overrides.

``builtin(name, **overrides)`` is what ``masonry simulate wall|arch|aqueduct`` runs:

============  ==============  =====================================================  ===============
name          structure       loading (default)                                      duration
============  ==============  =====================================================  ===============
wall          51-block wall   ground shaken horizontally, v = 1 m/s · sin(2π · 2 t)  1 s
arch          98-block arch   right foundation settles at 1 cm/s                     5 s
aqueduct      346 blocks      right foundation settles at 1 cm/s                     5 s
============  ==============  =====================================================  ===============

The overrides are the command line's options, under their Python names (None = not given): the
builder's own options (``blocks``, ``voussoirs``...), the loading (``amp`` m/s, ``freq`` Hz,
``settlement`` m/s, or a ground motion ``record`` file times ``scale``), the material (``density``, ``thickness``, ``friction``) and the run settings
(``duration``, ``dt``, ``theta``, ``record_every``, ``tolerance``, ``max_iterations``, ``solver``). Errors name them
as the command line spells them (``--settlement -1: must be >= 0 ...``).

The same overrides serve the other commands' structures: :func:`file_scenario` (a scenario or geometry
file, ``masonry run`` / ``check``) and :func:`build_assembly` (the builders' assemblies, ``masonry build``).

:func:`target_scenario` resolves the TARGET of ``run`` / ``check``, ``sweep`` and ``limit`` (a built-in
name, a scenario TOML or a GeoJSON / WKT file): a target that is none of them gets the same one line from
every command (they said "no such scenario file", "no such scenario or geometry file" or "cannot read
scenario: No such file or directory" for one missing file).
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import os
import warnings
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace

from masonrycli.errors import NOT_A_FILE, InputError, RecordWarning, file_kind, special_file
from masonrycli.records.motion import BASELINE_PROBLEM, BASELINES, Record, time_step_problem, unused_baseline
from masonrycli.records.read import record_motion
from masonrycli.records.text import NoTimeStep, TimeStepNotUsed
from masonrycli.scenario.motion import Constant, Fixed, Sine
from masonrycli.scenario.scenario import MAX_DURATION, Material, RunConfig, Scenario, scenario_from_builder
from masonrycli.scenario.structure import GEOMETRY_SUFFIXES, BuilderError, as_options, build_structure, survey_of
from masonrycli.scenario.values import option_text

DEFAULT_DURATION = {"wall": 1.0, "arch": 5.0, "aqueduct": 5.0}
"""s, simulated time of each built-in scenario."""
BUILT_IN = tuple(DEFAULT_DURATION)
"""The built-in structures' names, as a command's TARGET spells them."""
SHAKE_AMPLITUDE, SHAKE_FREQUENCY = 1.0, 2.0
"""m/s and Hz: the wall's ground velocity (the paper's shaking)."""
SETTLEMENT = 0.01
"""m/s: downward velocity of the right foundation of the arch and the aqueduct (the paper's settlement)."""
PAPER_INSTANT = {"wall": ("III.2–III.5", 0.1), "arch": ("III.7–III.10", 5.0), "aqueduct": ("III.7–III.10", 5.0)}
"""The instant of the paper's figures for each built-in structure: (figures, t in s)."""

RUN_OVERRIDES = ("duration", "dt", "theta", "record_every", "tolerance", "max_iterations", "solver")
MATERIAL_OVERRIDES = ("density", "thickness", "friction")
LOADING_OVERRIDES = ("freq", "amp", "settlement", "record", "scale", "record_dt", "baseline")


def _given(values: dict, keys) -> dict:
    return {k: values[k] for k in keys if values.get(k) is not None}


def _replace(obj, where: str, **changes):
    """dataclasses.replace with the option name in the error message."""
    try:
        return dataclasses.replace(obj, **changes)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def override_run(scenario: Scenario, *, friction: float | None = None, **run_values) -> Scenario:
    """``scenario`` with the run settings (RunConfig fields) and the friction that are not None replaced.

    The values are applied together (``--duration 0.3 --dt 0.3`` is fine whatever the file's duration);
    if that fails, the message names the option wrong on its own (``--dt: dt = -1.0: must be > 0``), else
    the options together (``--duration and --dt: ...``). An option is wrong on its own when, applied
    alone, it fails with the very message of the whole set: ``--dt 1e-9 --duration 0.5`` fails alone
    against the file's 1 s ("1,000,000,000 steps for duration 1.0") but together on 500,000,000 steps for
    0.5 s, which is what the message must say.
    """
    run_changes = _given(run_values, RUN_OVERRIDES)
    try:
        run = dataclasses.replace(scenario.run, **run_changes)
    except InputError as together:
        for key, value in run_changes.items():
            try:
                dataclasses.replace(scenario.run, **{key: value})
            except InputError as alone:
                if str(alone) == str(together):
                    raise InputError(f"--{key.replace('_', '-')}: {together}") from None
        names = " and ".join(f"--{k.replace('_', '-')}" for k in run_changes)
        raise InputError(f"{names}: {together}") from None
    material = scenario.material
    if friction is not None:
        material = _replace(material, "--friction", friction=friction)
    return dataclasses.replace(scenario, run=run, material=material)


def _sine(amp: float, freq: float) -> Sine:
    try:
        sine = Sine(direction=(1.0, 0.0), amplitude=amp, frequency=freq)
    except InputError as exc:  # the option of the field: "--amp nan" said "--amp/--freq: amplitude = nan: …"
        field = str(exc).split(" ", 1)[0]
        option = {"amplitude": "--amp", "frequency": "--freq"}.get(field, "--amp/--freq")
        raise InputError(f"{option}: {exc}") from None
    if amp and freq == 0.0:  # it ran: amp·sin(0) = 0, the ground never moved ("intact", exit 0)
        raise InputError(
            f"--freq 0: the velocity {amp:g} m/s · sin(2π·0·t) is 0, nothing moves (--amp 0 for no shaking; a "
            'constant velocity is a scenario file\'s motion = { kind = "constant", ... })'
        )
    return sine


def check_record_dt(record_dt: float | None) -> float | None:
    """``--record-dt`` (simulate, run, check, sweep) checked as a record's time step; None: not given."""
    if record_dt is not None:
        problem = time_step_problem(record_dt)
        if problem:
            raise InputError(f"--record-dt {option_text(record_dt)}: {problem}")
    return record_dt


def check_baseline(baseline: str | None) -> str | None:
    """``--baseline`` (simulate, run, check, sweep) checked as a record table's ``baseline``; None: not given."""
    if baseline is not None and baseline not in BASELINES:
        raise InputError(f"--baseline {baseline}: {BASELINE_PROBLEM}")
    return baseline


def record_motion_option(
    path: Path, scale: float | None, record_dt: float | None = None, baseline: str | None = None
) -> Record:
    """The ground motion of a ``--record`` file (.AT2, ESM .ASC or CSV), multiplied by ``scale``; ``record_dt``: the
    spacing of a one-column CSV's samples, s; ``baseline``: the drift correction of an acceleration record."""
    check_record_dt(record_dt)
    check_baseline(baseline)
    try:
        motion = record_motion(
            path,
            scale=1.0 if scale is None else scale,
            display=str(path),
            time_step=record_dt,
            baseline=baseline or "quadratic",
        )
    except NoTimeStep as exc:
        raise exc.give("--record-dt SECONDS") from None
    except TimeStepNotUsed as exc:  # the message named time_step, a scenario's key, not the option given
        raise exc.named("--record-dt") from None
    except InputError as exc:
        msg = str(exc)
        raise InputError(msg if msg.startswith(str(path)) else f"--record {path}: {msg}") from None
    for line in unused_baseline(baseline, {str(path): motion}):
        warnings.warn(RecordWarning(line), stacklevel=2)
    return motion


def with_record(
    scenario: Scenario,
    record: Path | None,
    scale: float | None,
    record_dt: float | None = None,
    baseline: str | None = None,
) -> Scenario:
    """``scenario`` with the supports a record shakes (:func:`shaken_supports`) driven by the ``record`` file."""
    if record is None:
        _record_options_alone(scale, record_dt, baseline)
        return scenario
    if not any(shaken_supports(scenario)):
        raise no_shaking_support(scenario, "--record")
    return shaken_by(scenario, record_motion_option(record, scale, record_dt, baseline))


def _geometry_as_is(scenario: Scenario) -> bool:
    """Whether ``scenario`` is a GeoJSON / WKT file run as it is (every support fixed, no scenario file). By
    the suffix of its source, not its absolute path: a study's worker started in another folder resolved the
    command's relative ``rubble.geojson`` elsewhere, and every row of a --scheduler study was refused."""
    return Path(scenario.source or "").suffix.lower() in GEOMETRY_SUFFIXES and "file" in scenario.structure


def shaken_supports(scenario: Scenario) -> list[bool]:
    """Which supports a record (``--record``, ``sweep --records``) shakes: those with a sine or record motion.
    A GeoJSON / WKT file run as it is has none (it holds no motion): there, the supports it marks driven
    (``"support_role": "driven"``, WKT ``support NAME driven:``), the others staying fixed, else its support when
    it has one — ``masonry run wall.geojson --record q.AT2`` of a wall on its ground was refused, and a scenario
    file had to be written to say the obvious; of several unmarked, none (refused: which one is not obvious)."""
    shaking = [m.kind in ("sine", "record") for m in scenario.motions]
    if any(shaking) or not _geometry_as_is(scenario):
        return shaking
    if scenario.marked_driven:
        return [s.name in scenario.marked_driven for s in scenario.assembly.supports]
    return [True] if len(shaking) == 1 else shaking


def shaken_by(scenario: Scenario, motion) -> Scenario:
    """``scenario`` with its :func:`shaken_supports` moved by ``motion``; a geometry file's warning that the
    support it marks driven stays fixed (it has no motion) is left out: the record drives it now."""
    from masonrycli.scenario.caveats import idle_driven_supports

    shaking = shaken_supports(scenario)
    motions = tuple(motion if shake else m for shake, m in zip(shaking, scenario.motions))
    # the line the file's mark made (the scenario's roles follow its motions: the mark is not kept)
    marked = [dataclasses.replace(s, role="driven") for s, shake in zip(scenario.assembly.supports, shaking) if shake]
    stale = idle_driven_supports(SimpleNamespace(supports=marked), [Fixed()] * len(marked))
    return dataclasses.replace(
        scenario, motions=motions, warnings=tuple(w for w in scenario.warnings if w not in stale)
    )


def no_shaking_support(scenario: Scenario, option: str) -> InputError:
    """The refusal of a record (``--record``, ``sweep --records``: ``option``) for a scenario none of whose
    supports shakes (:func:`shaken_supports`). A GeoJSON / WKT file of several supports holds no motion and no
    way to say which one shakes ("give one a sine" was no way out): the message writes the scenario file."""
    if not _geometry_as_is(scenario):
        return InputError(f"{option}: {scenario.name} has no shaking support (give one a sine or record motion)")
    file = os.path.basename(scenario.source)
    supports = scenario.assembly.supports
    if not supports:
        return InputError(f"{option}: {file} has no support to shake (every body in it is a block)")
    names = ", ".join(s.name for s in supports[:4]) + (" …" if len(supports) > 4 else "")
    return InputError(
        f"{option}: {file} holds no motion and {len(supports)} supports ({names}); say which the record shakes: "
        'mark them "support_role": "driven" in the file (WKT: support NAME driven: …), or write a scenario file '
        f'[structure] file = "{file}" with a [[support]] name = "{supports[0].name}" and motion = {{ kind = "record", '
        "file = ... } (masonry docs scenario-format)"
    )


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


def _record_options_alone(scale: float | None, record_dt: float | None, baseline: str | None = None) -> None:
    """Refuse --scale, --record-dt and --baseline given without --record."""
    if scale is not None:
        raise InputError("--scale: goes with --record (it multiplies the record)")
    if record_dt is not None:
        raise InputError("--record-dt: goes with --record (the time between the samples of a one-column file)")
    if baseline is not None:
        raise InputError(
            '--baseline: goes with --record (a scenario file\'s own record takes baseline = "none" in its table)'
        )


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
    if record is not None and _geometry_as_is(scenario) and overrides.get("duration") is None:
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


def _loading(name: str, amp, freq, settlement, record, scale, record_dt=None, baseline=None) -> dict:
    """Support name -> motion of the built-in loading, with the loading overrides applied."""
    if record is not None:
        if amp is not None or freq is not None or settlement:
            given = "--amp" if amp is not None else "--freq" if freq is not None else "--settlement"
            # a settlement is no sine: "(the record replaces the sine)" said of --settlement read wrong
            why = "shakes both foundations instead" if given == "--settlement" else "replaces the sine"
            raise InputError(f"--record with {given}: choose one loading (the record {why})")
        shaken = ("ground",) if name == "wall" else ("left-foundation", "right-foundation")
        motion = record_motion_option(record, scale, record_dt, baseline)
        return {support: motion for support in shaken}
    _record_options_alone(scale, record_dt, baseline)
    loading_freq, freq = freq, SHAKE_FREQUENCY if freq is None else freq
    if name == "wall":
        if settlement:
            raise InputError("--settlement: the wall stands on one ground; settlement applies to arch and aqueduct")
        amp = SHAKE_AMPLITUDE if amp is None else amp
        return {"ground": _sine(amp, freq)} if amp else {}
    if settlement is not None and not math.isfinite(settlement):
        raise InputError(f"--settlement {option_text(settlement)}: must be a finite number (a downward velocity, m/s)")
    if settlement is not None and settlement < 0:
        raise InputError(f"--settlement {option_text(settlement)}: must be >= 0 (a downward velocity, m/s)")
    # the messages name what was given: "--amp 1" alone said "--settlement with --amp" (the default
    # settlement), and "--freq 3" without --amp was ignored without a word
    _sine(0.0 if amp is None else amp, freq)  # a bad --amp / --freq is named first
    settles = f"the {name} settles its right foundation" + (" by default" if settlement is None else "")
    if settlement is None and amp:
        raise InputError(f"--amp {amp:g}: {settles}; shake both foundations with --settlement 0 --amp {amp:g}")
    if settlement and amp:
        raise InputError("--settlement with --amp: choose one loading (settle or shake)")
    if amp is None and loading_freq is not None:
        if settlement == 0:
            raise InputError(f"--freq {freq:g} without --amp: nothing shakes the {name} (give --amp A)")
        raise InputError(
            f"--freq {freq:g}: {settles}; shake both foundations with --settlement 0 --amp A --freq {freq:g}"
        )
    settlement = SETTLEMENT if settlement is None else settlement
    amp = 0.0 if amp is None else amp
    motions = {}
    if amp:
        motions = {"left-foundation": _sine(amp, freq), "right-foundation": _sine(amp, freq)}
    if settlement:
        motions["right-foundation"] = Constant(velocity=(0.0, -settlement))
    return motions


def builder_options(name: str, options: dict) -> dict:
    """The builder options of ``simulate``/``build``: the wall without --blocks is the paper's 51 blocks
    (laid in --courses courses, or --length long, if one is given); with both --courses and --length the
    builder solves for the count instead."""
    if name != "wall" or "blocks" in options:
        return options
    if {"courses", "length"} <= options.keys():
        return {**options, "blocks": None}
    return options if options.keys() & {"courses", "length"} else {"blocks": 51, **options}  # spec default: 51


def build_assembly(name: str, **overrides):
    """The assembly of builder ``name`` that ``masonry build`` writes, from the builder's options and
    ``density`` / ``thickness`` (None: not given), built and checked as ``simulate`` builds them
    (:func:`~masonrycli.scenario.structure.build_structure`): the same mistake gets the same line (build said
    "wall: block count …" where simulate and sweep said 'builder "wall": block count …')."""
    material = Material()
    for key in ("density", "thickness"):
        if overrides.get(key) is not None:
            material = _replace(material, f"--{key}", **{key: overrides[key]})
    given = {k: v for k, v in overrides.items() if v is not None and k not in ("density", "thickness")}
    try:
        return build_structure(name, builder_options(name, given), material.density, material.thickness)
    except BuilderError as exc:  # named as typed, as simulate names them
        raise as_options(exc, given) from None


def builtin(name: str, **overrides) -> Scenario:
    """The built-in scenario ``name`` ("wall", "arch" or "aqueduct"), with ``overrides`` (see the module doc).

    Raises :class:`InputError` (one line) for a bad override.
    """
    if name not in DEFAULT_DURATION:
        raise InputError(f"unknown built-in scenario {name!r} (expected one of {', '.join(DEFAULT_DURATION)})")
    material = Material()
    for key, value in _given(overrides, MATERIAL_OVERRIDES).items():
        material = _replace(material, f"--{key}", **{key: value})
    loading = {k: overrides.get(k) for k in LOADING_OVERRIDES}
    motions = _loading(name, **loading)
    reserved = (*RUN_OVERRIDES, *MATERIAL_OVERRIDES, *LOADING_OVERRIDES)
    given = {k: v for k, v in overrides.items() if k not in reserved and v is not None}
    run = RunConfig(duration=_duration(name, motions, overrides))
    try:
        scenario = scenario_from_builder(name, builder_options(name, given), run, material, motions)
    except BuilderError as exc:  # named as typed: --ring-thickness, not the builder's ring_thickness
        raise as_options(exc, given) from None
    return override_run(scenario, **_given(overrides, RUN_OVERRIDES))


def _duration(name: str, motions: dict, overrides: dict) -> float:
    """s: the built-in's default duration, or with a ground-motion record and no --duration the whole
    record, in whole steps of the run's dt (the default 1 s of the wall cut a 40 s record to its first
    second)."""
    ends = [m.end_time for m in motions.values() if m.kind == "record"]
    if not ends or overrides.get("duration") is not None:
        return DEFAULT_DURATION[name]
    dt = RunConfig.dt if overrides.get("dt") is None else overrides["dt"]
    if not (isinstance(dt, (int, float)) and 0.0 < dt < math.inf):
        return DEFAULT_DURATION[name]  # override_run names the bad --dt
    return min(max(1, math.ceil(max(ends) / dt - 1e-9)) * dt, MAX_DURATION)


def paper_loading(name: str) -> dict[str, str]:
    """Support name -> ``Motion.describe()`` of the paper's loading of built-in ``name`` (its default; the
    supports not named are fixed)."""
    return {support: m.describe() for support, m in _loading(name, None, None, None, None, None).items()}


def is_paper_loading(name: str, supports: dict[str, str]) -> bool:
    """Whether ``supports`` (support name -> ``Motion.describe()``, as in a recording's metadata) is the
    paper's loading of built-in ``name``: the paper's figures describe that loading only (a wall shaken by
    an earthquake record is at rest at the paper's 0.1 s)."""
    if name not in DEFAULT_DURATION:
        return False
    return {k: v for k, v in supports.items() if v != "fixed"} == paper_loading(name)


def paper_instant_hint(
    name: str, run: RunConfig, supports: dict[str, str] | None = None, reached: float | None = None
) -> str:
    """Where the paper's figures of ``name`` are in the run (the recording's tabs pinned there), or "" (none,
    after the run, or ``supports`` — support name -> ``Motion.describe()`` — not the paper's loading).
    ``reached``: the time the run reached, s; one stopped before the instant (Ctrl-C, --stop-at-collapse) said
    "the recording opens on them, pinned there" over a recording without those tabs."""
    if name not in PAPER_INSTANT or (supports is not None and not is_paper_loading(name, supports)):
        return ""
    figs, t = PAPER_INSTANT[name]
    step = round(t / run.dt)
    if step > run.n_steps:
        return ""
    if reached is not None and reached < t - 0.5 * run.dt:
        return (
            f"The paper's Figs. {figs} are at t = {t:g} s; the run stopped before, at t = {reached:.4g} s: the "
            "recording has no tabs pinned there."
        )
    missed = paper_instant_missed(t, run.dt, run.record_every, run.n_steps)
    if missed:
        return f"The paper's Figs. {figs} are at t = {t:g} s, {missed}: the recording has no tabs pinned there."
    return f"The paper's Figs. {figs} are at t = {t:g} s (step {step}): the recording opens on them, pinned there."


def paper_instant_missed(t: float, dt: float, record_every: int, n_steps: int) -> str:
    """Why a run of ``n_steps`` steps of ``dt`` recording every ``record_every`` steps (and the last) has no
    frame at the paper's instant ``t``, or "" when it has one. Without a frame there the tabs pinned to ``t``
    showed the frame before it under the paper's instant (``--record-every 30``: t = 0.09 s; ``--record-every
    200``: the structure as built, no stress) and the paper's figure numbers."""
    k = round(t / dt)
    if abs(t / dt - k) > 1e-6 * max(1.0, k):
        return f"not a step of --dt {dt:g}"
    if k % record_every and k != n_steps:
        return f"step {k}, which --record-every {record_every} does not record (a divisor of {k} does)"
    return ""
