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

The same overrides serve the other commands' structures: :func:`masonrycli.scenario.target.file_scenario` (a
scenario or geometry file, ``masonry run`` / ``check``) and :func:`build_assembly` (the builders' assemblies,
``masonry build``). A ``--record`` option's record: :mod:`masonrycli.scenario.record_option`; a command's
TARGET (a built-in name or a file): :mod:`masonrycli.scenario.target`.
"""

from __future__ import annotations

import dataclasses
import math

from masonrycli.errors import InputError
from masonrycli.scenario.motion import Constant, Sine
from masonrycli.scenario.record_option import record_motion_option, record_options_alone
from masonrycli.scenario.scenario import MAX_DURATION, Material, RunConfig, Scenario, scenario_from_builder
from masonrycli.scenario.structure import BuilderError, as_options, build_structure
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


def _loading(name: str, amp, freq, settlement, record, scale, record_dt=None, baseline=None) -> dict:
    """Support name -> motion of the built-in loading, with the loading overrides applied."""
    if record is not None:
        if amp is not None or freq is not None or settlement:
            given = "--amp" if amp is not None else "--freq" if freq is not None else "--settlement"
            value = option_text(amp if amp is not None else freq if freq is not None else settlement)
            # a settlement is no sine: "(the record replaces the sine)" said of --settlement read wrong
            why = "shakes both foundations instead" if given == "--settlement" else "replaces the sine"
            raise InputError(f"--record {record} with {given} {value}: choose one loading (the record {why})")
        shaken = ("ground",) if name == "wall" else ("left-foundation", "right-foundation")
        motion = record_motion_option(record, scale, record_dt, baseline)
        return {support: motion for support in shaken}
    record_options_alone(scale, record_dt, baseline)
    loading_freq, freq = freq, SHAKE_FREQUENCY if freq is None else freq
    if name == "wall":
        if settlement:
            raise InputError(
                f"--settlement {option_text(settlement)}: the wall stands on one ground; settlement applies to arch "
                "and aqueduct"
            )
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
        raise InputError(
            f"--settlement {option_text(settlement)} with --amp {option_text(amp)}: choose one loading (settle or "
            "shake)"
        )
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
