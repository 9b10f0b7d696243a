"""masonry from Python (a notebook, a script): :func:`scenario`, :func:`simulate`, :func:`read_history`, :func:`view`.

Each is the command line's own code called as the commands call it, not a second implementation:

==============================================  ===============================================================
Python                                          the command line's code
==============================================  ===============================================================
``scenario("wall", amp=0.5, blocks=248)``       ``masonry check wall --amp 0.5 --blocks 248`` (builtin.builtin)
``scenario("my.toml", dt=2e-4)``                ``masonry run my.toml --dt 2e-4`` (target.file_scenario)
``simulate(s, history="h.npz")``                ``masonry simulate / run … --history h.npz`` (execute.check_run,
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

import difflib
import functools
import io
import os
import warnings
import weakref
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from masonrycli.errors import InputError

_SIMULATE_GROUPS = {  # the option groups of `masonry simulate NAME` (cli/app.py), by built-in
    "wall": ("WALL", "WALL_LOADING"),
    "arch": ("ARCH", "SETTLED_LOADING"),
    "aqueduct": ("AQUEDUCT", "SETTLED_LOADING"),
}


def _option_names(target) -> list[str]:
    """The keywords ``target`` takes: the options of ``masonry simulate NAME`` for a built-in, of ``masonry run``
    for a file, and the run settings and friction for a :class:`Scenario` already made (its loading is made with
    it: a record given to it would run for its duration, where ``simulate("wall", record=…)`` runs the record)."""
    from masonrycli.cli import options
    from masonrycli.scenario.target import is_built_in

    groups = ["RUN", "FRICTION"]
    if isinstance(target, (str, os.PathLike)) and is_built_in(target):
        groups += ["RECORD", *_SIMULATE_GROUPS[os.fspath(target)], "BLOCK_MATERIAL", "SIMULATE_SETTLE"]
    elif isinstance(target, (str, os.PathLike)):
        groups += ["RECORD", "SURVEY", "SETTLE"]
    return [name for group in groups for name in getattr(options, group)]


@functools.cache
def _keywords() -> frozenset[str]:
    """Every keyword of :func:`scenario` and :func:`simulate`, whatever the target: the options the messages name."""
    from masonrycli.cli import options

    groups = ["RUN", "FRICTION", "RECORD", "SURVEY", "SETTLE", "BLOCK_MATERIAL", "WALL", "WALL_LOADING", "ARCH"]
    groups += ["SETTLED_LOADING", "AQUEDUCT", "SIMULATE_SETTLE"]
    names = {name for group in groups for name in getattr(options, group)}
    return frozenset(names | set(_OUTPUTS) | {"recording"})


def _python_spelled(function=None, *, keywords=None, renamed=None):
    """``function`` with the options its errors and warnings name spelled as its keywords (``duration=``, where
    the command line says ``--duration``): the same messages (:mod:`masonrycli.option_spelling`). Its warnings
    are said as it returns or raises, from the caller's line. ``keywords`` / ``renamed``: a method's own (default:
    scenario's and simulate's, ``--out`` as ``recording=``)."""
    from masonrycli.option_spelling import RENAMED, python_spelling

    if function is None:
        return functools.partial(_python_spelled, keywords=keywords, renamed=renamed)

    def spell(text: str) -> str:
        return python_spelling(
            text, _keywords() if keywords is None else keywords, RENAMED if renamed is None else renamed
        )

    @functools.wraps(function)
    def spelled(*args, **kwargs):
        caught: list = []
        try:
            # the caller's filters kept: what they hide (a library's DeprecationWarning) is not said again below,
            # from the caller's line, where Python shows a DeprecationWarning of __main__
            with warnings.catch_warnings(record=True) as caught:
                return function(*args, **kwargs)
        except InputError as exc:
            raise InputError(spell(str(exc))) from None
        finally:
            for said in caught:
                warnings.warn(spell(str(said.message)), said.category, stacklevel=2)

    return spelled


_OUTPUTS = {  # the command line's output options, which simulate() names otherwise
    "out": "the recording is simulate(recording=PATH)",
    "no_recording": "simulate() writes no recording unless recording= names one",
    "force": "force= is simulate()'s, with recording= or history=",
    "history": "history= is simulate()'s",
    "magnify": "magnify= is simulate()'s, with recording=",
    "stop_at_collapse": "stop_at_collapse= is simulate()'s",
}


def _check_names(target, given: dict) -> None:
    """Refuse a keyword the command does not take, as its command line refuses the option (one line)."""
    known = _option_names(target)
    for key in given:
        if key not in known:
            close = difflib.get_close_matches(key, known, n=3)
            what = os.fspath(target) if isinstance(target, (str, os.PathLike)) else "a Scenario already made"
            hint = f"did you mean {', '.join(close)}?" if close else f"its options: {', '.join(known)}"
            if not isinstance(target, (str, os.PathLike)):
                hint = "it takes run settings and friction; its structure and loading are given to api.scenario()"
            hint = _OUTPUTS.get(key, hint)
            raise InputError(f"no such option: {key}= for {what} ({hint})")


def _one_value_each(options: dict) -> None:
    """Refuse several values for one keyword (``freq=[1, 2, 3]``: a run takes one), saying how to run them all:
    it said "--freq: frequency = [1, 2, 3]: must be a number", and a student took it for a wrong type."""
    for key, value in options.items():
        if isinstance(value, (list, tuple, range, np.ndarray)) and np.size(value) > 1:
            values = [f"{v:g}" if isinstance(v, float) else str(v) for v in np.ravel(value)]
            listed = ",".join(values[:3]) + (",…" if len(values) > 3 else "")
            raise InputError(
                f"{key}: {len(values)} values ({listed}): one run takes one value; loop over them (for {key} in …: "
                f"api.simulate(…, {key}={key})) or run a study, masonry sweep --param {key}={listed} (masonry docs "
                "python, 'Looping over parameters')"
            )


def _path(value, option: str, *, output: bool = False) -> Path:
    """A path keyword read by the command line's own parser of ``option`` (``~`` expanded, an empty one refused;
    an output's "x.rrd/" names a folder, where Path("x.rrd/") would have written the file x.rrd)."""
    import typer

    from masonrycli.cli.option_values import file_path_value, path_value

    if not isinstance(value, (str, os.PathLike)):
        raise InputError(f"{option} {value!r}: a path (str or pathlib.Path), not a {type(value).__name__}")
    try:
        return (file_path_value if output else path_value)(os.fspath(value))
    except typer.BadParameter as exc:
        raise InputError(f"{option}: {exc.message}") from None


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


def _pga(value) -> float | None:
    """``pga=``: a number in g, or a string as ``--pga`` takes it ("0.25g", "2.45m/s2"); None: not given."""
    from masonrycli.records.pga import pga_in_g

    if value is None:
        return None
    try:
        return pga_in_g(value)
    except InputError as exc:
        raise InputError(f"--pga {exc}") from None


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

    from masonrycli.execute import check_run, execute, result_warning
    from masonrycli.interrupt import StopRun
    from masonrycli.outputs.live_line import LiveLine
    from masonrycli.outputs.report import summary_table
    from masonrycli.scenario.caveats import scenario_warnings

    sc = scenario(target, **options)
    asked = {"recording": recording, "history": history, "force": force or None, "stop_at_collapse": stop_at_collapse}
    asked |= {"magnify": magnify, "on_frame": on_frame}
    call = _call("simulate", target, options | {k: v for k, v in asked.items() if v not in (None, False)})
    out = _path(recording, "--out", output=True) if recording not in (None, False, True) else None
    hist = _path(history, "--history", output=True) if history is not None else None
    outputs = check_run(sc, out, hist, no_recording=recording in (None, False), force=force, magnify=magnify)
    for warning in scenario_warnings(sc):
        warnings.warn(warning, UserWarning, stacklevel=2)
    # force_jupyter=False: in a notebook rich shows every console's output under the cell whatever its file (the
    # summary table, which goes to Run.summary, was shown after every run of a loop)
    quiet = Console(file=io.StringIO(), quiet=True, force_jupyter=False)
    sinks = [_FrameCallback(on_frame)] if on_frame is not None else []
    # which run of a loop the line is: the scenario and the options given ('wall (freq=2.0, friction=0.8)')
    given = ", ".join(f"{k}={_argument(v)}" for k, v in options.items() if v is not None)
    live = LiveLine(f"{sc.name} ({given})" if given else sc.name) if progress else None
    if live is not None:
        live.start()
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

    from masonrycli.execute import rerun_command
    from masonrycli.recording import recording_path_problem

    path = _path(recording, "recording")
    problem = recording_path_problem(path)
    if problem:
        raise InputError(problem)
    return subprocess.Popen([rerun_command(), os.fspath(path)])


@dataclass(frozen=True, eq=False)
class Run:
    """A run's history: ``run["block_q"]`` is the array of that name in the ``.npz`` (T frames, N blocks, S
    supports, J joints; ``run.unit(name)`` its unit), and a few views of them."""

    arrays: dict
    """Every array of the history, by name, as the ``.npz`` holds them (``units`` and ``run`` too)."""
    outcome: dict | None = None
    """The structure's state (``state``: intact, damaged or collapsed; ``collapse_time`` s, NaN if none;
    ``peak_drift``, ``residual_drift`` × height; ``hinges``; ``max_opening`` m; …: docs/collapse.md); of a
    history read from a file, the keys it keeps (:func:`read_history`), or None for an older file."""
    recording: Path | None = None
    """The recording written, or None."""
    history: Path | None = None
    """The history file written (or read), or None."""
    summary: str = field(default="", repr=False)
    """The command line's end-of-run table, as text ("" for a history read from a file)."""

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self.arrays:
            close = difflib.get_close_matches(name, list(self.arrays), n=3)
            raise KeyError(f"{name!r}: no such array" + (f" (did you mean {', '.join(close)}?)" if close else ""))
        return self.arrays[name]

    def __repr__(self) -> str:
        state = f", {self.outcome['state']}" if self.outcome else ""
        return (
            f"<masonry Run: {self.status}{state}, {len(self.block_names)} blocks, {len(self.time)} frames to "
            f"t = {self.time[-1] if len(self.time) else 0:g} s>"
        )

    def unit(self, name: str) -> str:
        """The unit / meaning of array ``name`` (the history's ``units`` table)."""
        self[name]  # noqa: B018 (an unknown name is a KeyError that says so)
        return self.units.get(name, "")

    @property
    def units(self) -> dict[str, str]:
        return {str(k): str(v) for k, v in self.arrays.get("units", np.zeros((0, 2), dtype=str))}

    @property
    def time(self) -> np.ndarray:
        """(T,) s, the recorded frames' times."""
        return self.arrays["time"]

    @property
    def status(self) -> str:
        """completed, interrupted, diverged or failed."""
        return str(self.arrays.get("status", ""))

    @property
    def note(self) -> str:
        """Where and why the run stopped ("" when it ran all its steps)."""
        return str(self.arrays.get("note", ""))

    @property
    def block_names(self) -> list[str]:
        return [str(n) for n in self.arrays["block_name"]]

    @property
    def support_names(self) -> list[str]:
        return [str(n) for n in self.arrays["support_name"]]

    @property
    def displacement(self) -> np.ndarray:
        """(T, N, 3) each block's centroid displacement from t = 0, x and y (m), and rotation (rad, CCW)."""
        q = self.arrays["block_q"]
        return q - q[:1]

    def block(self, name: str) -> int:
        """The index of block ``name`` on every block axis."""
        names = self.block_names
        if name not in names:
            close = difflib.get_close_matches(name, names, n=3)
            raise InputError(f"no block {name!r}" + (f" (did you mean {', '.join(close)}?)" if close else ""))
        return names.index(name)

    def hinged_joints(self, frame: int = -1) -> list[str]:
        """The joints hinged at ``frame`` (default the last), named ``"a|b"`` as the run's summary names them."""
        from masonrycli.model import JOINT_SEPARATOR

        names = self.block_names + self.support_names
        body = self.arrays["joint_body"][self.arrays["joint_hinged"][frame]]
        return [f"{names[a]}{JOINT_SEPARATOR}{names[b]}" for a, b in body]

    @_python_spelled(
        keywords={"blocks", "courses", "top", "ground", "relative"},
        renamed={"course": "courses", "absolute": "relative"},
    )
    def table(self, *, blocks=(), courses=(), top: bool = False, ground: str | None = None, relative: bool = True):
        """``masonry export``'s columns, name (with its unit) → (T,) array: the ground's motion, each target's
        (a block by name, a course by number from the bottom, the top course) displacement, velocity and
        acceleration relative to the ground (``relative=False``: absolute), ``drift ratio (-)``, base shear,
        overturning moment, hinges, energies (``masonry docs readme``, "Export a history as CSV"). Without
        targets, the top course. ``pandas.DataFrame(run.table())`` makes it a frame."""
        from masonrycli.outputs.export import export_table

        table = export_table(
            self.arrays, blocks=list(blocks), course_numbers=list(courses), top=top, ground=ground, relative=relative
        )
        for note in table.notes:
            warnings.warn(note, UserWarning, stacklevel=2)
        return dict(zip(table.names, table.values))

    @_python_spelled(keywords={"out", "force"}, renamed={})
    def report(self, out=None, *, force: bool = False) -> str:
        """``masonry report``'s one-page Markdown of the run (what was run, the ground motion as applied, the
        state, peak and residual drift, hinged joints, unconverged steps: the summary's numbers). ``out``: a
        ``.md`` path to write it to, with its figure beside it (``.png``), refused if it exists unless
        ``force=True``, as ``masonry report H.npz --out R.md``."""
        from masonrycli.outputs.run_report import check_outputs, report_markdown, write_report

        shown = str(self.history) if self.history is not None else "the run"
        if out is None:
            return report_markdown(self.arrays, shown)
        page, picture = check_outputs(_path(out, "--out", output=True), force)
        write_report(self.arrays, shown, page, picture)
        return page.path.read_text(encoding="utf-8")
