"""From what ``masonry sweep`` was given to a checked study: base scenario, request, report files.

:func:`plan_study` takes the command's options as they come (None: not given) and checks them together
before anything runs or is written: the axes (``--param``, ``--records``, ``--scale``), the options that
only go together (``--outcome`` / ``--rtol`` with ``--find``, ``--workers`` without ``--scheduler``,
``--recording`` without ``--no-recording``), and the files beside the table. A bad option raises a one-line
:class:`~masonrycli.errors.InputError` (exit 2) naming it. What it returns is what
:func:`~masonrycli.study.study.run_study` and the report of :mod:`masonrycli.cli.sweep` take; the table and
the histories are checked by ``run_study``, which knows which rows are this study's and which runs are
still to make.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from masonrycli.errors import InputError
from masonrycli.outputs.files import OutputFile, safe_name
from masonrycli.records.motion import unused_baseline
from masonrycli.scenario.builtin import override_run
from masonrycli.scenario.record_option import check_baseline, check_record_dt
from masonrycli.scenario.target import is_built_in, target_scenario
from masonrycli.scenario.values import option_text
from masonrycli.study import store
from masonrycli.study.axes import Axis, StudyBase, apply_point, check_axes, check_find, parse_axis
from masonrycli.study.files import check_picture
from masonrycli.study.record_set import read_record_set, same_file
from masonrycli.study.study import StudyRequest, points_to_check

SWEEP_DURATION = {"wall": 1.0, "arch": 2.0, "aqueduct": 2.0}
"""s: default simulated time of a built-in structure in a study."""


@dataclass(frozen=True)
class StudyPlan:
    """A study checked before its first run: what :func:`~masonrycli.study.study.run_study` takes, and the
    report files written after it."""

    base: StudyBase
    request: StudyRequest
    name: str
    """The scenario's name (the titles of the plot and the recording)."""
    picture: OutputFile
    """The PNG (``--plot``, default beside ``--out``)."""
    recording: OutputFile | None
    """The Rerun recording (``--recording``, default beside ``--out``), None with ``--no-recording``."""


MAX_WORKERS_PER_CORE = 4
"""``--workers`` beyond this many per core is refused as a likely typo (each worker is a process of ~200 MB)."""
MIN_RTOL = 1e-9
"""``--rtol`` below this is refused as a likely typo: each halving of a bracket is one more run per point (30 from
a bracket as wide as its value down to 1e-9), and a bracket narrower than float64's 2.2e-16 of its value has no
middle, so the bisection never ended (``--rtol 1e-300`` ran the same point over and over: no row after 4 min)."""


def plan_study(
    target: str,
    *,
    params: list[str] | None = None,
    records: list[Path] | None = None,
    record_dt: float | None = None,
    baseline: str | None = None,
    scale: str | None = None,
    find: str | None = None,
    outcome: str | None = None,
    rtol: float | None = None,
    out: Path | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    stop_at_collapse: bool = True,
    duration: float | None = None,
    dt: float | None = None,
    im: str = "pga",
    plot: Path | None = None,
    recording: Path | None = None,
    no_recording: bool = False,
    histories: Path | None = None,
    force: bool = False,
    warn: Callable[[str], None] | None = None,
    survey: dict | None = None,
    settle: float | None = None,
) -> StudyPlan:
    """The study of ``target`` (``wall``, ``arch``, ``aqueduct``, a scenario file or a geometry file) that
    ``masonry sweep`` runs with these options, each named as the command line names it; ``warn`` gets
    the warnings (runs shorter than records) once ``run_study`` has checked the table. Raises
    :class:`InputError`, the first problem in one line, before any run or file. ``survey``: how a geometry
    file is read (--units, --flip-y, --convex-hull, --trim-overlaps, as ``masonry run`` reads it); ``settle``: s
    each variant of the structure comes to rest under its own weight first (:func:`~masonrycli.study.axes.settled_variant`)."""
    from masonrycli.execute import command_line
    from masonrycli.records.intensity import INTENSITY_MEASURES
    from masonrycli.study.scheduler import check_scheduler
    from masonrycli.study.task import check_outcome

    # a built-in swept over records runs as long as they last (below): its default duration is not the
    # runs', so a --dt need not divide it ('--records recs --dt 0.003' said "does not divide duration = 1.0")
    # a geometry file has no [run] duration of its own either: swept over records, it runs them whole too
    lasting = bool(records) and duration is None and (is_built_in(target) or _is_geometry(target))
    base = StudyBase(_base_scenario(target, duration, dt, lasting, survey), {}, settle)  # each variant settled (axes)
    name = base.scenario.name
    # the name reduced as recordings name it: "../../evil" made a folder "study-.." and wrote beside it
    out = store.check_out(out or Path(f"study-{safe_name(name)}.parquet"))
    axes = [parse_axis(p) for p in params or []]
    late: list[str] = []  # warnings about records longer than the runs
    if check_record_dt(record_dt) is not None and not records:
        raise InputError("--record-dt: goes with --records (the time between the samples of its one-column files)")
    if check_baseline(baseline) is not None and not records:  # a scenario file's record has its table's baseline
        raise InputError('--baseline: goes with --records (a scenario file\'s own record takes baseline = "none")')
    if records:
        motions, unread = read_record_set(records, out, record_dt, baseline or "quadratic")
        unread += unused_baseline(baseline, motions)
        scenario, late = _record_duration(base.scenario, motions, lasting)  # a file's [run] duration stands
        late = [*unread, *late]
        base = StudyBase(scenario, motions, settle)
        axes.insert(0, Axis("record", tuple(motions)))
    if scale is not None:
        axes.append(parse_axis(f"scale={scale}", where=f"--scale {scale}"))  # it said "--param scale=..."
    if not axes:
        raise InputError("nothing to sweep: give --param NAME=..., or --records DIR")
    # before the files beside --out: "--param amp: given twice" came after "--out's plot s.png: the file exists"
    check_axes(axes)
    for option, value in (("duration", duration), ("dt", dt)):  # "--duration 2 --param duration=0.5,1" ran
        if value is not None and option in {a.name for a in axes}:  # 0.5 and 1 s, the 2 s said nowhere
            raise InputError(
                f"--{option} {option_text(value)} and --param {option}: the axis sets every run's {option}; give one"
            )
    check_find(axes, find)
    for point in points_to_check(axes):  # before the files: "-p Amp=0.1" said "--out's plot … exists" first
        apply_point(base, point)
    if im not in INTENSITY_MEASURES or im == "d5_95":
        raise InputError(f"--im {im}: expected one of pga, pgv, arias, sa")
    if workers is not None and workers < 0:
        raise InputError(f"--workers {workers}: must be >= 0")
    cores = os.cpu_count() or 1
    if workers is not None and workers > MAX_WORKERS_PER_CORE * cores:
        # "--workers 100" (10 meant) started 100 processes of ~200 MB on a 2-core laptop: a run is
        # single-threaded, so workers beyond the cores only wait, holding their memory
        raise InputError(
            f"--workers {workers}: more than {MAX_WORKERS_PER_CORE} per core ({cores} cores here; a run uses one "
            "core, the default is one worker per core)"
        )
    scheduler = check_scheduler(scheduler)
    if workers is not None and scheduler is not None:
        raise InputError("--workers with --scheduler: the existing cluster has its own workers")
    outcome = None if outcome is None else check_outcome(outcome)
    for option, value in (("--outcome", outcome), ("--rtol", rtol)):
        if value is not None and find is None:
            raise InputError(f"{option} {option_text(value)}: goes with --find (a grid reports every run's state)")
    outcome, rtol = outcome or "collapse", 0.005 if rtol is None else rtol
    if not (0 < rtol < 1):
        raise InputError(f"--rtol {option_text(rtol)}: must be in (0, 1)")
    if rtol < MIN_RTOL:
        raise InputError(
            f"--rtol {option_text(rtol)}: must be >= {MIN_RTOL:g} (each halving is one more run per point; a likely typo)"
        )
    _check_out_reads_nothing(out, base)
    if no_recording and recording is not None:
        raise InputError(f"--recording {recording} with --no-recording: choose one")
    # the default files beside --out are named as such: "--plot s.png: the file exists" named an option
    # the user had not given
    picture = check_picture(plot or out.with_suffix(".png"), "--plot" if plot else "--out's plot", ".png", force)
    recorded = check_picture(
        None if no_recording else recording or out.with_suffix(".rrd"),
        "--recording" if recording else "--out's recording",
        ".rrd",
        force,
    )
    request = StudyRequest(
        axes=axes,
        out=out,
        find=find,
        outcome=outcome,
        rtol=rtol,
        scheduler=scheduler,
        workers=workers,
        stop_at_collapse=stop_at_collapse,
        histories=histories,
        force=force,
        warnings=(
            *_scenario_warnings(base.scenario, base.records),
            *_settled_lines(base),
            *late,
            *_set_warnings(base, axes),
        ),
        warn=warn,
        command=command_line().get("command", ""),  # each history names it (masonry report: what was run)
    )
    return StudyPlan(base, request, name, picture, recorded)


def _scenario_warnings(scenario, records) -> list[str]:
    """The warnings ``masonry run`` prints for the study's base scenario (a block touching nothing, a GeoJSON
    property not used, gravity pointing up: the sweep ran every point without a word); with ``--records``
    its own record is not run, so not its records' (the set's are in ``late``)."""
    from masonrycli.scenario.caveats import record_warnings, scenario_warnings
    from masonrycli.scenario.record_option import shaken_by

    if not records:
        return scenario_warnings(scenario)
    shaken = shaken_by(scenario, next(iter(records.values())))  # a file's driven supports: shaken, not idle
    return [w for w in scenario_warnings(shaken) if w not in record_warnings(shaken)]


def _set_warnings(base: StudyBase, axes: list[Axis]) -> list[str]:
    """What ``masonry run`` warns of each record of a ``--records`` set as the study applies it: sampled
    finer than the runs' dt, beyond 10 g at the largest scale, an .AT2 scaled by g. A set's record at
    DT 0.5 ms on the 1 ms steps, '--scale 9.81' on .AT2 files and '--scale 1,40' (16 g) ran without a word
    where 'simulate --record' says each. Its length is said by ``_record_duration`` (in one line)."""
    import dataclasses

    from masonrycli.records.read import G_STANDARD
    from masonrycli.scenario.caveats import record_warnings

    if not base.records:
        return []
    by_name = {a.name: a.values for a in axes}
    scales = [s for s in by_name.get("scale", ()) if isinstance(s, float)]
    said: list[str] = []
    # the largest scale (the 10 g line), any scale of g (an .AT2 converted twice) or of 0.01 (an ESM / K-NET file
    # in cm/s² converted twice); a dt axis at its largest
    picked = ({max(scales, key=abs)} if scales else set()) | {
        s for s in scales if any(abs(abs(s) / g - 1) < 0.02 for g in (G_STANDARD, 100 * G_STANDARD, 0.01))
    }
    dts = [d for d in by_name.get("dt", ()) if isinstance(d, float)]
    for name in base.records:
        for scale in sorted(picked) or [None]:
            point = {"record": name} | ({} if scale is None else {"scale": scale})
            point |= {"dt": max(dts)} if dts else {}
            scenario = apply_point(base, point)
            longest = max(m.end_time for m in scenario.motions if m.kind == "record")
            run = dataclasses.replace(scenario.run, duration=max(scenario.run.duration, longest))  # not its length
            shown = record_warnings(dataclasses.replace(scenario, run=run), upright=False)  # the set names those
            said += [w for w in shown if w not in said]
    return said + _converted_twice(base.records, scales)


def _converted_twice(records: dict, scales: list[float]) -> list[str]:
    """A scale that is the conversion of a CSV read in its header's unit (``acc (g)`` at ``--scale 9.81``, how
    ``--record`` read such a file before it converted it too): converted twice, 9.81 times too strong. A warning
    here, where ``--record`` refuses it (:func:`~masonrycli.records.units.check_csv_header`): an axis may hold the
    value among others (``--scale 1,9.81,20``), and no study read such a file that way (a set refused it)."""
    from masonrycli.records.read import read_as_csv
    from masonrycli.records.units import NEAR_CONVERSION, converts_again, header_factor

    said = []
    for name, m in records.items():
        # read as a CSV: a .csv, and a .txt or a plain table named .asc given by name or in the folder
        as_csv = m.source and read_as_csv(m.source)
        unit = header_factor(m.source, m.quantity) if as_csv else None
        twice = [s for s in scales if unit and converts_again(s, unit[1], NEAR_CONVERSION)]
        if twice:
            said.append(
                f"--records: {name} is read in {unit[0]}, as its header says, and converted to SI already; "
                f"--scale {twice[0]:g} converts it again (the scale multiplies the record, 1 is as recorded)"
            )
    return said


def _is_geometry(target) -> bool:
    from masonrycli.scenario.structure import GEOMETRY_SUFFIXES

    return Path(target).suffix.lower() in GEOMETRY_SUFFIXES


def _settled_lines(base) -> list[str]:
    """What ``--settle`` did: the line ``masonry run --settle`` says, one a variant of the structure the points
    checked settled (its values first: ``blocks=20: settled 0.5 s …``), at most :data:`SETTLED_LINES`."""
    lines = [
        (f"{' '.join(f'{k}={v:g}' if isinstance(v, float) else f'{k}={v}' for k, v in key)}: " if key else "")
        + scenario.warnings[-1].replace("before the run: it starts", "before its runs: each starts")
        for key, scenario in base.settled.items()
    ]
    more = len(lines) - SETTLED_LINES
    return lines[:SETTLED_LINES] + ([f"… and {more} more variants settled so (--settle)"] if more > 0 else [])


SETTLED_LINES = 5


def _base_scenario(target: str, duration, dt, lasting: bool = False, survey: dict | None = None):
    """The study's scenario before its axes, as drawn (``--settle`` settles each variant: axes.settled_variant);
    ``lasting``: its duration is set later (by the records), so a ``dt`` is applied with a duration it divides."""
    scenario = target_scenario(target, _shaken, survey)  # a GeoJSON / WKT file as `masonry run` takes it
    if lasting and dt is not None and dt > 0:
        import math

        duration = max(1, math.ceil(scenario.run.duration / dt - 1e-9)) * dt
        try:
            return override_run(scenario, duration=duration, dt=dt)
        except InputError:  # refused on its own (1e-9: too many steps): said as the option alone says it
            duration = None
    return override_run(scenario, duration=duration, dt=dt)  # names the wrong option (--dt 0: --dt)


def _shaken(name: str):
    """The built-in structure ``name`` of a study: 1 m/s at 2 Hz on the ground (wall) or both foundations
    (arch, aqueduct), for ``SWEEP_DURATION``."""
    from masonrycli.scenario.motion import Sine
    from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

    shaken = ("ground",) if name == "wall" else ("left-foundation", "right-foundation")
    motions = {s: Sine(amplitude=1.0, frequency=2.0) for s in shaken}
    options = {"blocks": 51} if name == "wall" else {}
    return scenario_from_builder(name, options, RunConfig(duration=SWEEP_DURATION[name]), Material(), motions)


def _record_duration(scenario, motions: dict, whole: bool):
    """``(scenario, warnings)``: the scenario lasting the longest record (whole steps of its dt) if
    ``whole`` (a built-in without --duration: its 1 s cut every record of an IDA to its first second);
    else, if the runs are shorter than some records, one line saying so (printed once the request is
    checked)."""
    import dataclasses
    import math

    from masonrycli.scenario.scenario import MAX_DURATION

    run = scenario.run
    # named by the longest: the first late record ("longest 3 s, quake1.csv" for a 2 s quake1.csv) misled
    longest_name = max(motions, key=lambda name: motions[name].end_time)
    longest = motions[longest_name].end_time
    if whole:
        steps = max(1, math.ceil(longest / run.dt - 1e-9))
        run = dataclasses.replace(run, duration=min(steps * run.dt, MAX_DURATION))
        return dataclasses.replace(scenario, run=run), []
    late = [name for name, m in motions.items() if m.end_time > run.duration + 0.5 * run.dt]
    if not late:
        return scenario, []
    return scenario, [
        f"the runs' {run.duration:g} s are shorter than {len(late)} of {len(motions)} records (longest "
        f"{longest:g} s, {longest_name}): their shaking after t = {run.duration:g} s is not applied"
    ]


def _check_out_reads_nothing(out: Path, base) -> None:
    """Refuse an ``--out`` that is a record file the study reads: with ``--force`` the table replaced it
    (``--records rec.csv --out rec.csv --force``: the record was lost)."""
    motions = (*base.scenario.motions, *base.records.values())
    for source in (s for m in motions for s in (getattr(m, "source", ""), getattr(m, "vertical_source", ""))):
        if source and same_file(out, source):
            raise InputError(f"--out {out}: is the record {source} (the table would replace it)")
