"""The axes of a study and how a point of the grid changes the base scenario.

An axis is written ``name=LO:HI:N`` (N values evenly spaced from LO to HI), ``name=a,b,c`` (a list) or
``name=v`` (one value). The names a study understands:

=================================== ===========================================================
``amp``, ``freq``, ``phase``        the sine motion (m/s, Hz, rad) of every sine-driven support;
                                    ``ground.amp`` addresses one support by name
``scale``                           the scale of every record motion (``ground.scale`` for one)
``record``                          the record file (``--records DIR`` makes this axis): every
                                    shaking support (sine or record) is driven by it
``pga_g``                           every record scaled so the ground motion as applied peaks at this
                                    PGA, in g (:mod:`masonrycli.records.pga`; instead of ``scale``)
``friction``                        the Coulomb coefficient of every contact
``duration``, ``dt``, ``theta``,    the run settings of :class:`~masonrycli.scenario.scenario.RunConfig`
``tolerance``, ``max_iterations``
a builder option (``blocks``, ...)  the structure is rebuilt (builder scenarios only)
=================================== ===========================================================
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass

import numpy as np

from geometry_library.values import unit_hint, unit_of
from masonrycli.errors import InputError
from masonrycli.scenario.values import did_you_mean

MOTION_PARAMS = {"amp": ("sine", "amplitude"), "freq": ("sine", "frequency"), "phase": ("sine", "phase")}
MOTION_PARAMS["scale"] = ("record", "scale")
RUN_PARAMS = ("duration", "dt", "theta", "tolerance", "max_iterations")
INT_PARAMS = ("max_iterations",)
PGA_PARAM = "pga_g"
"""The PGA a point's records are scaled to, in g: its own name, as the rows hold ``pga``, the PGA as applied (m/s²)."""
MAX_RUNS = 10**6
"""Most values on an axis, and most runs in a grid: more is a likely typo (``amp=0:1:1000000000``
used to allocate the values for minutes before anything was said)."""


@dataclass(frozen=True)
class Axis:
    """One swept parameter: its name and its values (floats, or file names for ``record``)."""

    name: str
    values: tuple

    @property
    def bracket(self) -> tuple[float, float]:
        """(LO, HI): the range ``--find`` bisects in."""
        return float(min(self.values)), float(max(self.values))


def parse_axis(text: str, where: str = "") -> Axis:
    """``amp=0.1:1.0:10`` / ``amp=0.2,0.8`` / ``blocks=51`` -> :class:`Axis`. Raises :class:`InputError`
    naming ``where`` (default ``--param TEXT``; ``--scale 0.5:2:4`` for the option that makes the axis)."""
    where = where or f"--param {text}"
    name, sep, spec = text.partition("=")
    name = name.strip()
    if not sep or not name or not spec.strip():
        raise InputError(f"{where}: expected NAME=LO:HI:N, NAME=a,b,c or NAME=value")
    if ":" in spec:
        parts = spec.split(":")
        if len(parts) != 3:
            raise InputError(f"{where}: a range is LO:HI:N (e.g. amp=0.1:1.0:10)")
        lo, hi = (_number(p, where, name) for p in parts[:2])
        try:
            n = int(parts[2]) if "_" not in parts[2] else None
        except ValueError:
            n = None
        if n is None:
            raise InputError(f"{where}: N = {parts[2]!r} must be a whole number of values") from None
        if n < 1 or (n == 1 and lo != hi):
            raise InputError(f"{where}: N must be >= 2 for a range (or give one value)")
        if not hi >= lo:
            raise InputError(f"{where}: HI must be >= LO")
        if n > MAX_RUNS:
            raise InputError(f"{where}: N = {n} values, more than {MAX_RUNS} (a likely typo)")
        # to 15 significant digits, which a value typed with up to 15 keeps: linspace's 0.6000000000000001 (of
        # friction=0.4:0.8:5) was the table's and the CSV's value, so df[df.friction == 0.6] found no row
        values = tuple(float(f"{v:.15g}") for v in np.linspace(lo, hi, n))
    else:
        values = tuple(_number(p, where, name) for p in spec.split(","))
    if name.split(".")[-1] in INT_PARAMS or _is_builder_int(name):
        if not all(float(v).is_integer() for v in values):
            raise InputError(f"{where}: {name} takes whole numbers")
        values = tuple(int(v) for v in values)
    return Axis(name, values)


def _number(text: str, where: str, name: str) -> float:
    if "_" in text:  # float() reads "1_0" as 10: on the command line a typo, refused as every option refuses it
        raise InputError(f"{where}: {text.strip()!r} is not a number (an underscore is not a digit separator here)")
    try:
        value = float(text)
    except ValueError:
        hint = unit_hint(text, unit_of(name.split(".")[-1]))  # "0.1m/s": what to write
        raise InputError(f"{where}: {text.strip()!r} is not a number{hint}") from None
    if not math.isfinite(value):
        raise InputError(f"{where}: values must be finite")
    return value


def _is_builder_int(name: str) -> bool:
    from geometry_library.builders import BUILDERS

    for spec in BUILDERS.values():
        for f in dataclasses.fields(spec):
            if f.name == name and f.type in (int, "int", "int | None"):
                return True
    return False


def grid(axes: list[Axis]) -> list[dict]:
    """Every combination of the axes' values, first axis slowest: ``[{name: value, ...}, ...]``."""
    names = [a.name for a in axes]
    return [dict(zip(names, combo)) for combo in itertools.product(*(a.values for a in axes))]


def check_find(axes: list[Axis], find: str | None) -> None:
    """Raise :class:`InputError` unless ``--find NAME`` (None: no search) has a numeric range among the axes."""
    if find is None:
        return
    names = [a.name for a in axes]
    if find not in names:
        raise InputError(f"--find {find}: give its range too, e.g. --param {find}=0.1:1.0:4")
    axis = axes[names.index(find)]
    if isinstance(axis.values[0], str) or len(axis.values) < 2:
        raise InputError(f"--find {find}: needs a numeric range LO:HI:N with N >= 2")


def check_axes(axes: list[Axis]) -> None:
    names = [a.name for a in axes]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise InputError(f"--param {sorted(dup)[0]}: given twice")
    if PGA_PARAM in names:
        from masonrycli.records.pga import MAX_PGA_G

        if any(n.rpartition(".")[2] == "scale" for n in names):
            raise InputError(f"--param {PGA_PARAM}: sets each record's scale, which --scale sets too (give one)")
        values = axes[names.index(PGA_PARAM)].values
        bad = [v for v in values if isinstance(v, str) or not 0.0 < v <= MAX_PGA_G]
        if bad:
            raise InputError(
                f"--param {PGA_PARAM}={bad[0]}: a peak ground acceleration in g, above 0 and at most {MAX_PGA_G:g}"
            )
    for axis in axes:  # each point runs once: a repeated value ran twice into two rows of one key
        seen = set()
        for v in axis.values:  # a set: an axis may hold a million values
            if v in seen:
                raise InputError(f"--param {axis.name}: the value {v} is given twice (each point runs once)")
            seen.add(v)
    runs = math.prod(len(a.values) for a in axes)
    if runs > MAX_RUNS:
        sizes = " × ".join(f"{len(a.values)} {a.name}" for a in axes)
        raise InputError(f"--param: the grid has {runs} points ({sizes}), more than {MAX_RUNS} (a likely typo)")


_OTHER_NAMES = {
    "mu": "friction",
    "μ": "friction",
    "coulomb": "friction",
    "friction_coefficient": "friction",
    "amplitude": "amp",
    "velocity": "amp",
    "pga": PGA_PARAM,
    "pgv": "scale",
    "intensity": "scale",
    "factor": "scale",
    "scale_factor": "scale",
}
"""Names an engineer gives a parameter -> masonry's (did_you_mean found none of them: ``--param mu=0.5,0.7``)."""


def _also_called(key: str) -> str:
    """' (the Coulomb coefficient is "friction")'-like hint for another name of a parameter, or ""."""
    name = _OTHER_NAMES.get(key.rpartition(".")[2].lower())
    if name is None:
        return ""
    if name == "scale":
        return ' (records are scaled by "scale": --scale LO:HI:N; pga and pgv are in every row, as applied)'
    if name == PGA_PARAM:  # the row's "pga" is the PGA as applied, m/s²: the axis has its own name
        return f' (records are scaled to a PGA in g by "{PGA_PARAM}": --param {PGA_PARAM}=0.1:0.4:7)'
    return f' (did you mean "{name}"?)'


def apply_point(base, params: dict):
    """The scenario of one grid point: ``base`` (a :class:`StudyBase`) changed by ``params``.

    Order: builder options (rebuild), run and material settings, the record, then motion parameters
    (so ``scale`` applies to the record chosen on the same point). Raises :class:`InputError`.
    """
    from masonrycli.scenario.sampling import check_sampling
    from masonrycli.scenario.scenario import scenario_from_builder

    scenario = base.scenario
    builder = scenario.structure.get("builder")
    options = {k: v for k, v in params.items() if k not in RUN_PARAMS and _builder_option(builder, k)}
    if options:
        names = [s.name for s in scenario.assembly.supports]
        structure = {k: v for k, v in scenario.structure.items() if k != "builder"}
        structure = _count_follows(builder, structure, options)
        try:
            scenario = scenario_from_builder(
                builder, structure | options, scenario.run, scenario.material, dict(zip(names, scenario.motions))
            )
        except InputError as exc:  # say which point: "--param span=7: builder ...", not the builder alone
            raise InputError(f"--param {_point(options)}: {exc}") from None
    run_changes = {k: v for k, v in params.items() if k in RUN_PARAMS}
    if run_changes:
        # "--param dt=0.003: dt = 0.003: does not divide …" (it said "--param: dt = …", no point)
        run = _replace(scenario.run, run_changes, where=f"--param {_point(run_changes)}")
        scenario = dataclasses.replace(scenario, run=run)
    if "friction" in params:
        friction = {"friction": params["friction"]}
        scenario = dataclasses.replace(
            scenario, material=_replace(scenario.material, friction, where=f"--param {_point(friction)}")
        )
    if base.settle is not None:  # each variant of the structure comes to rest as itself (settled_variant)
        friction = {"friction": params["friction"]} if "friction" in params else {}
        scenario = settled_variant(base, scenario, options | run_changes | friction)
    motions = list(scenario.motions)
    if "record" in params:
        record = base.records[params["record"]]
        from masonrycli.scenario.record_option import no_shaking_support, shaken_supports

        shaking = [j for j, shaken in enumerate(shaken_supports(scenario)) if shaken]
        if not shaking:
            raise no_shaking_support(scenario, "--records")
        for j in shaking:
            motions[j] = record
    names = [s.name for s in scenario.assembly.supports]
    set_by: dict[tuple[int, str], str] = {}  # (support, field) -> the parameter that set it
    for key, value in params.items():
        support, _, short = key.rpartition(".")
        if short not in MOTION_PARAMS:
            if key not in RUN_PARAMS and key not in ("friction", "record", PGA_PARAM) and key not in options:
                known = [*MOTION_PARAMS, *RUN_PARAMS, "friction", "record", PGA_PARAM, *_builder_options(builder)]
                hint = _also_called(key) or did_you_mean(key, known) or _not_built(builder, key)
                raise InputError(f"--param {key}: unknown parameter{hint} (see masonry sweep --help)")
            continue
        kind, attr = MOTION_PARAMS[short]
        targets = [j for j, m in enumerate(motions) if m.kind == kind and (not support or names[j] == support)]
        if support and support not in names:
            raise InputError(f"--param {key}: no support named {support!r} (supports: {', '.join(names)})")
        if not targets:
            # '--records recs --param amp=0.5,1': the record replaced the sine, and its intensity is --scale
            instead = " (--records drives it by the records: their axis is --scale)" if "record" in params else ""
            raise InputError(
                f"--param {key}: {scenario.name} has no {kind} motion{' on ' + support if support else ''}{instead}"
            )
        for j in targets:
            # "-p amp=1,2 -p ground.amp=0.5" ran both rows at 0.5 m/s under the names amp=1 and amp=2
            other = set_by.setdefault((j, attr), key)
            if other != key:
                raise InputError(
                    f"--param {key}: sets the {attr} of support {names[j]!r}, which --param {other} sets too "
                    "(give one of them)"
                )
            motions[j] = _replace(motions[j], {attr: value}, where=f"--param {key}")
    for name, m in zip(names, motions):
        if m.kind == "sine" and m.frequency == 0.0 and m.amplitude and abs(math.sin(m.phase)) < 1e-12:
            # 'freq=0:2:3' ran its first point with the ground at rest ("intact"), where simulate --freq 0
            # and a scenario file's frequency = 0 are refused
            raise InputError(
                f"--param {_point(params)}: support {name!r}: the velocity {m.amplitude:g} m/s · sin(2π·0·t) is 0, "
                "nothing moves (amp=0 is the point without shaking)"
            )
    scenario = dataclasses.replace(scenario, motions=tuple(motions))
    if PGA_PARAM in params:  # once the point's record, dt and duration are set: the PGA as its run applies it
        from masonrycli.records.pga import scaled_to_pga

        scenario = scaled_to_pga(
            scenario,
            params[PGA_PARAM],
            option=f"--param {_point({PGA_PARAM: params[PGA_PARAM]})}",
            give="--records FILE",
        )
    try:
        check_sampling(scenario)
    except InputError as exc:  # the point, not only the support: "--param amp=1e+30: support ..."
        raise InputError(f"--param {_point(params)}: {exc}") from None
    return scenario


def _point(params: dict) -> str:
    return " ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in params.items())


def _count_follows(builder, structure: dict, options: dict) -> dict:
    """The wall's ``structure`` without its block count when a point gives ``courses`` or ``length`` and not
    ``blocks``, and both are then known: the count follows from them, as ``simulate wall --courses 15 --length
    0.6`` builds it (37 blocks). The study's wall kept the built-in's 51 blocks, and every such point was
    refused: '51 blocks cannot be laid in running bond with 15 courses and length 0.6 m'."""
    if builder != "wall" or "blocks" in options or not options.keys() & {"courses", "length"}:
        return structure
    if not {"courses", "length"} <= (structure | options).keys():
        return structure
    return {k: v for k, v in structure.items() if k != "blocks"} | {"blocks": None}


def _builder_option(builder, name: str) -> bool:
    return name in _builder_options(builder)


def _not_built(builder, name: str) -> str:
    """`` (an option of builder "arch": …)`` when ``name`` is a builder's option but the study's structure is
    not built (a geometry file, explicit blocks): "--param voussoirs: unknown parameter" said nothing of why."""
    from geometry_library.builders import BUILDERS

    owners = [b for b in BUILDERS if name in _builder_options(b)]
    if builder or not owners:
        return ""
    return f" (an option of the {', '.join(owners)} builder{'s' if len(owners) > 1 else ''}: this structure is read, not built)"


def _builder_options(builder) -> list[str]:
    """The options of ``builder`` (None: not a builder scenario, no options)."""
    if not builder:
        return []
    from geometry_library.builders import BUILDERS

    return [f.name for f in dataclasses.fields(BUILDERS[builder])]


def _replace(obj, changes: dict, where: str = ""):
    try:
        return dataclasses.replace(obj, **changes)
    except InputError as exc:
        raise InputError(f"{where or '--param'}: {exc}") from None


@dataclass(frozen=True)
class StudyBase:
    """What every task of a study starts from: the base scenario and the records it may use (by name).

    ``settle``: s each variant of the structure comes to rest under its own weight before its runs (``--settle``;
    :func:`settled_variant`), the scenario being then as drawn; ``settled`` keeps each variant settled, by its
    point's structural values: filled while the command checks the points, it travels with the base to the
    workers, which settle only a variant it lacks (once a process)."""

    scenario: object
    records: dict = dataclasses.field(default_factory=dict)
    settle: float | None = None
    settled: dict = dataclasses.field(default_factory=dict, compare=False, repr=False)


def settled_variant(base: StudyBase, scenario, changes: dict):
    """``scenario`` (the base changed by a point's structural values ``changes``: builder options, run settings,
    friction) settled for ``base.settle`` s, kept in ``base.settled``. Settling the base alone started a point of
    another geometry or friction unsettled, its gaps closing under the shaking (a traced wall "damaged" at rest:
    masonrycli/settle.py), or from the base's resting place. A variant that does not stand is refused naming
    its point. The motions (amplitude, record, scale) do not change where a structure rests: not in the key."""
    from masonrycli.settle import settled_scenario

    key = tuple(sorted(changes.items()))
    if key not in base.settled:
        try:
            base.settled[key] = settled_scenario(scenario, base.settle)
        except InputError as exc:
            raise InputError(f"--param {_point(changes)}: {exc}" if changes else str(exc)) from None
    return base.settled[key]
