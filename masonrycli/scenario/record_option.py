"""A ground-motion record given on the command line (``--record`` with ``--scale``, ``--record-dt``,
``--baseline``; a sweep's ``--records``): the options checked, the record read as a support motion, and which
supports of a scenario it shakes (those with a sine or record motion; of a GeoJSON / WKT file run as it is, the
supports it marks driven, else its one support), or the one line saying none does."""

from __future__ import annotations

import dataclasses
import os
import warnings
from pathlib import Path
from types import SimpleNamespace

from masonrycli.errors import InputError, RecordWarning
from masonrycli.records.motion import BASELINE_PROBLEM, BASELINES, Record, time_step_problem, unused_baseline
from masonrycli.records.read import record_motion
from masonrycli.records.text import NoTimeStep, TimeStepNotUsed
from masonrycli.scenario.motion import Fixed
from masonrycli.scenario.scenario import Scenario
from masonrycli.scenario.structure import GEOMETRY_SUFFIXES
from masonrycli.scenario.values import option_text


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
        record_options_alone(scale, record_dt, baseline)
        return scenario
    if not any(shaken_supports(scenario)):
        raise no_shaking_support(scenario, "--record")
    return shaken_by(scenario, record_motion_option(record, scale, record_dt, baseline))


def geometry_as_is(scenario: Scenario) -> bool:
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
    if any(shaking) or not geometry_as_is(scenario):
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
    if not geometry_as_is(scenario):
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


def record_options_alone(scale: float | None, record_dt: float | None, baseline: str | None = None) -> None:
    """Refuse --scale, --record-dt and --baseline given without --record (each named with its value: the API
    says "scale=2 goes with record=", where "--scale: goes with" read "scale=: goes with")."""
    if scale is not None:
        raise InputError(f"--scale {option_text(scale)} goes with --record (it multiplies the record)")
    if record_dt is not None:
        raise InputError(
            f"--record-dt {option_text(record_dt)} goes with --record (the time between the samples of a one-column "
            "file)"
        )
    if baseline is not None:
        raise InputError(
            f'--baseline {baseline} goes with --record (a scenario file\'s own record takes baseline = "none" in its '
            "table)"
        )
