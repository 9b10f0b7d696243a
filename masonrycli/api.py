"""masonry from Python (a notebook, a script): :func:`scenario`, :func:`simulate`, :func:`read_history`, :func:`view`.

Each is the command line's own code called as the commands call it, not a second implementation:

==============================================  ===============================================================
Python                                          the command line's code
==============================================  ===============================================================
``scenario("wall", amp=0.5, blocks=248)``       ``masonry check wall --amp 0.5 --blocks 248`` (builtin.builtin)
``scenario("my.toml", dt=2e-4)``                ``masonry run my.toml --dt 2e-4`` (target.file_scenario)
``simulate(s, history="h.npz")``                ``masonry simulate / run … --history h.npz`` (output_plan.check_run,
                                                execute.execute)
``read_history("h.npz")``                       ``masonry inspect h.npz``'s checks, then every array
``Run.table(top=True)``                         ``masonry export h.npz --top`` (outputs.export.export_table)
``Run.report()``                                ``masonry report h.npz`` (outputs.run_report.report_markdown)
==============================================  ===============================================================

So a bad value raises :class:`masonrycli.errors.InputError` carrying the line the command prints before its exit
code 2, its options named by the keywords typed here (``amp=float("nan")``: "amp=: amplitude = nan: must be a
finite number", where the command line says "--amp: …"; :mod:`masonrycli.option_spelling`; warnings too), and a run's arrays are bit for bit those of the history ``masonry simulate … --history``
writes. The keywords are the commands' options under their Python names (``--record-every`` is
``record_every=``). Nothing is written unless asked: ``recording=`` and ``history=`` name the files (the
command line's rules: an existing file is refused without ``force=True``), so a loop over parameters leaves no
files behind. No state is kept between calls.

Why a module of its own and not names in ``masonrycli/__init__.py``: that package is imported by every
``masonry`` command, sweep worker and the compile-ahead process, and these functions import the engine (numba);
``from masonrycli import api`` costs that only to those who use it.
"""

from __future__ import annotations

import io
import os
import warnings
import weakref

import numpy as np

from masonrycli.api_keywords import all_keywords as _keywords  # noqa: F401 (tests read them as api._keywords)
from masonrycli.api_keywords import check_names as _check_names
from masonrycli.api_keywords import one_value_each as _one_value_each
from masonrycli.api_keywords import option_names as _option_names  # noqa: F401 (and api._option_names)
from masonrycli.api_keywords import path_value as _path
from masonrycli.api_keywords import pga_value as _pga
from masonrycli.api_keywords import python_spelled as _python_spelled
from masonrycli.api_run import Run  # api.Run: what simulate returns
from masonrycli.errors import InputError


@_python_spelled
def scenario(target, **options):
    """The :class:`~masonrycli.scenario.scenario.Scenario` that :func:`simulate` would run: ``target`` is a
    built-in's name (``"wall"``, ``"arch"``, ``"aqueduct"``, with ``masonry simulate NAME``'s options:
    ``blocks=248, amp=0.5, freq=2``), a scenario or geometry file (``masonry run``'s options), or a Scenario
    already made (its run settings and friction replaced). Raises :class:`InputError` (one line)."""
    from geometry_library.blocks import GeometryError
    from masonrycli.records.pga import with_pga
    from masonrycli.scenario.builtin import builtin, override_run
    from masonrycli.scenario.scenario import Scenario
    from masonrycli.scenario.target import file_scenario, is_built_in
    from masonrycli.settle import settled_scenario

    if not isinstance(target, (str, os.PathLike, Scenario)):
        raise InputError(
            f"{target!r}: give wall, arch, aqueduct, a scenario / geometry file's path or a Scenario, not a "
            f"{type(target).__name__}"
        )
    _check_names(target, options)
    _one_value_each(options)
    options = {k: v for k, v in options.items() if v is not None}
    call = _call("scenario", target, options)  # as given: the record's path before it is read as a path
    if "record" in options:
        options["record"] = _path(options["record"], "--record")
    try:
        if isinstance(target, Scenario):
            return _made(override_run(target, **options), call)
        settle = options.pop("settle", None)  # the engine, as the command line: `masonry simulate` / `run --settle`
        pga = _pga(options.pop("pga", None))  # the record's scale, once the scenario is built
        if is_built_in(target):
            made = builtin(os.fspath(target), **options)
        else:
            survey = {k: options.pop(k) for k in ("units", "flip_y", "convex_hull", "trim_overlaps") if k in options}
            made = file_scenario(target, survey=survey, **options)  # as `masonry run` loads it
        return _made(settled_scenario(with_pga(made, pga, options.get("scale")), settle), call)
    except GeometryError as exc:  # the command line's one line, as the one error type of bad input
        raise InputError(str(exc).splitlines()[0] if str(exc) else type(exc).__name__) from None


_CALLS: dict[int, tuple[weakref.ref, str]] = {}
"""id(Scenario) -> (the Scenario, weakly; the ``api.scenario(…)`` call that made it): what a run of it names."""


def _made(made, call: str):
    """``made``, remembered as made by ``call`` (its entry removed with it)."""
    key = id(made)
    _CALLS[key] = (weakref.ref(made, lambda _, key=key: _CALLS.pop(key, None)), call)
    return made


def _argument(value) -> str:
    """A keyword's value as the call's text: a path as its string, a numpy number as the number, a function by
    its name (its repr holds an address, another every run), a Scenario by the call that made it."""
    from masonrycli.scenario.scenario import Scenario

    if isinstance(value, os.PathLike):
        return repr(os.fspath(value))
    if isinstance(value, np.generic):
        return repr(value.item())
    if isinstance(value, Scenario):
        entry = _CALLS.get(id(value))
        return entry[1] if entry is not None and entry[0]() is value else f"<Scenario {value.name!r}>"
    if callable(value):
        return f"<function {getattr(value, '__name__', type(value).__name__)}>"
    return repr(value)


def _call(function: str, target, options: dict) -> str:
    """``api.simulate('wall', amp=0.5, freq=2.0)``: the call as its arguments were given (None ones left out), what
    a history of it keeps as its ``command`` (a command line's keeps the ``masonry …`` line)."""
    given = [f"{k}={_argument(v)}" for k, v in options.items() if v is not None]
    return f"api.{function}({', '.join([_argument(target), *given])})"


class _FirstUnconverged:
    """Warns of the run's first unconverged step as it ends (a RuntimeWarning): the count came only with the run's
    end, minutes later in a long run. The end's warning still says how many and the worst."""

    def __init__(self, run):
        self.run, self.said = run, False

    def on_frame(self, frame) -> None:
        """Frames are not its business (a sink's ``log_step`` is)."""

    def log_step(self, step: int, time: float, stats) -> None:
        if not stats.converged and not self.said:
            from masonrycli.run_summary import first_unconverged_warning

            self.said = True
            warnings.warn(first_unconverged_warning(step, time, stats.residual, self.run), RuntimeWarning, stacklevel=2)

    def close(self, status: str, note: str = "") -> None:
        """Nothing to close."""


class _FrameCallback:
    """``simulate(on_frame=f)``: ``f(frame)`` for every recorded :class:`~masonrycli.outputs.frame.Frame`."""

    def __init__(self, function):
        self.on_frame = function

    def close(self, status: str, note: str = "") -> None:
        """Nothing to close: the function's owner keeps what it gathered."""


@_python_spelled
def simulate(
    target,
    *,
    recording=None,
    history=None,
    force: bool = False,
    stop_at_collapse: bool = False,
    magnify: float | None = None,
    on_frame=None,
    progress: bool = False,
    **options,
) -> Run:
    """Run ``target`` (as :func:`scenario` takes it, with its ``options``) and return its :class:`Run`: every
    array of the history in memory. ``recording``: a ``.rrd`` path to write, or True for the command line's
    default name (``recordings/<name>-<time>.rrd``); ``history``: a ``.npz`` path to write. By default nothing is
    written. ``on_frame(frame)`` is called with every recorded frame (the contacts' points, normals and forces,
    which the history does not keep). The run's own warnings (a record cut short, a setting's caveat) are Python
    warnings; Ctrl-C (a notebook's "interrupt") ends the run "interrupted" with the frames it reached.
    ``progress=True`` shows the run's progress as one line changing in place (:mod:`masonrycli.outputs.live_line`:
    in a notebook a display under the cell; else stderr), first saying why a first run waits."""
    from rich.console import Console

    from masonrycli.execute import execute
    from masonrycli.interrupt import StopRun
    from masonrycli.output_plan import check_magnify, check_run
    from masonrycli.outputs.live_line import LiveLine
    from masonrycli.outputs.report import summary_table
    from masonrycli.run_summary import result_warning
    from masonrycli.scenario.caveats import scenario_warnings

    sc = scenario(target, **options)
    asked = {"recording": recording, "history": history, "force": force or None, "stop_at_collapse": stop_at_collapse}
    asked |= {"magnify": magnify, "on_frame": on_frame}
    call = _call("simulate", target, options | {k: v for k, v in asked.items() if v not in (None, False)})
    out = _path(recording, "--out", output=True) if recording not in (None, False, True) else None
    hist = _path(history, "--history", output=True) if history is not None else None
    if magnify is not None and recording in (None, False):  # the command line's "--magnify 5 with --no-recording"
        check_magnify(magnify, no_recording=False)  # its range first, as the command line's
        raise InputError(f"magnify={_argument(magnify)} draws in the recording: give recording= too (a path, or True)")
    outputs = check_run(sc, out, hist, no_recording=recording in (None, False), force=force, magnify=magnify)
    for warning in scenario_warnings(sc):
        warnings.warn(warning, UserWarning, stacklevel=2)
    # force_jupyter=False: in a notebook rich shows every console's output under the cell whatever its file (the
    # summary table, which goes to Run.summary, was shown after every run of a loop)
    quiet = Console(file=io.StringIO(), quiet=True, force_jupyter=False)
    sinks = [_FirstUnconverged(sc.run), *([_FrameCallback(on_frame)] if on_frame is not None else [])]
    # which run of a loop the line is: the scenario and the options given ('wall (freq=2.0, friction=0.8)')
    given = ", ".join(f"{k}={_argument(v)}" for k, v in options.items() if v is not None)
    live = LiveLine(f"{sc.name} ({given})" if given else sc.name) if progress else None
    if live is not None:
        live.start()
        warnings.showwarning = live.under(warnings.showwarning)  # python_spelled's catch_warnings restores it
    try:
        outcome = execute(
            sc,
            outputs,
            console=quiet,
            stop_at_collapse=stop_at_collapse,
            magnify=magnify,
            keep_history=True,
            sinks_also=sinks,
            command=call,
            on_progress=live.on_progress if live is not None else None,
        )
    except StopRun:  # a signal before the first step: nothing was written
        if live is not None:
            live.stopped("interrupted before its first step, nothing written")
        raise KeyboardInterrupt from None
    except BaseException as exc:  # the line said 'starting: …' under the cell's traceback, as if still going
        if live is not None:
            live.stopped(f"stopped: {type(exc).__name__}: {exc}".split("\n")[0])
        raise
    if live is not None:
        result = outcome.result
        live.end(result.status, result.steps, result.time, (result.outcome or {}).get("state", ""))
    for error in outcome.errors:
        warnings.warn(f"cannot write {error}", RuntimeWarning, stacklevel=2)
    if (unconverged := result_warning(outcome.result, sc.run)) is not None:  # the command line's warning line
        warnings.warn(unconverged, RuntimeWarning, stacklevel=2)
    paths = {o.option: o.path for o in outcome.written}
    text = Console(file=io.StringIO(), width=100, record=True, force_jupyter=False)
    shown = {k: str(v) for k, v in paths.items()}
    text.print(summary_table(outcome.result, shown.get("--out"), shown.get("--history"), sc.name))
    return Run(
        outcome.history.arrays(),
        outcome=dict(outcome.result.outcome),
        recording=paths.get("--out"),
        history=paths.get("--history"),
        summary=text.export_text(),
    )


@_python_spelled
def read_history(path) -> Run:
    """The :class:`Run` of a history file (``--history``, ``simulate(history=…)``, ``masonry sweep
    --histories``), checked as ``masonry inspect`` checks it. Its ``outcome`` is the verdict the file keeps
    (``result_*``: state, collapse_time, collapse_reason, peak_drift, residual_drift, max_opening,
    max_displacement, hinges), or None for a history written before it kept them (2026-11-29)."""
    from masonrycli.outputs.inspect_history import inspect_history
    from masonrycli.outputs.run_report import outcome

    path = _path(path, "history")
    inspect_history(path)  # one line for a missing, damaged or foreign file
    with np.load(path, allow_pickle=False) as npz:
        arrays = {name: npz[name] for name in npz.files}
    kept = outcome(arrays)  # it said None whatever the file held: r.outcome["state"] was a TypeError
    return Run(arrays, outcome=kept[0] if kept is not None else None, history=path)


@_python_spelled
def view(recording):
    """Open ``recording`` (a ``.rrd``) in the Rerun viewer, as the line a run's summary ends with does; returns
    the viewer's process (:class:`subprocess.Popen`)."""
    import subprocess

    from masonrycli.recording import recording_path_problem
    from masonrycli.viewer_command import rerun_command

    path = _path(recording, "recording")
    problem = recording_path_problem(path)
    if problem:
        raise InputError(problem)
    return subprocess.Popen([rerun_command(), os.fspath(path)])
