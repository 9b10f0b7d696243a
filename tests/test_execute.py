"""masonrycli.execute: a run with its outputs. A one-block scenario of 20 steps is executed into temporary
outputs: the history and the recording are renamed into place whole; an engine error still closes them
as "failed"; a stop before step 1 leaves no file at all. Also the output plan, the size estimate and the
summary's last line (the command that opens the recording)."""

from __future__ import annotations

import dataclasses
import io
import json
import math
import os
import re
import signal
import time
from pathlib import Path

import numpy as np
import pytest
from rich.console import Console
from shapely.geometry import box

from geometry_library.blocks import Assembly, Block, Support
from masonrycli import SOURCE_DIGEST, viewer_command
from masonrycli import execute as execute_module
from masonrycli.errors import InputError
from masonrycli.execute import execute
from masonrycli.interrupt import StopRun
from masonrycli.output_plan import check_run, output_sizes, plan_outputs
from masonrycli.outputs.files import OutputFile
from masonrycli.recording import inspect_recording
from masonrycli.run import Simulation
from masonrycli.run_summary import unconverged_warning
from masonrycli.scenario.motion import Sine
from masonrycli.scenario.scenario import SOLVERS, Material, RunConfig, Scenario
from masonrycli.source_digest import source_commit

from cli_helpers import invoke, signal_inside_a_ctypes_callback, words

AMP, FREQ, DT, STEPS, EVERY = 0.01, 2.0, 1e-3, 20, 5
# v(t) = AMP cos(2π FREQ t): the ground's peak speed is AMP, at t = 0
SHAKE = Sine(amplitude=AMP, frequency=FREQ, phase=math.pi / 2)


def _scenario() -> Scenario:
    block = Block(box(-0.2, 0.0, 0.2, 0.2), "b")
    ground = Support(box(-1.0, -0.1, 1.0, 0.0), "ground")
    run = RunConfig(duration=STEPS * DT, dt=DT, record_every=EVERY)
    return Scenario("one-block", run, Material(), Assembly((block,), (ground,)), (SHAKE,))


def _quiet() -> Console:
    return Console(file=io.StringIO(), width=120)


def _planned(tmp_path: Path, force: bool = False):
    sc = _scenario()
    return sc, plan_outputs(sc, tmp_path / "r.rrd", tmp_path / "h.npz", no_recording=False, force=force)


def test_a_run_leaves_a_whole_history_and_recording_in_place(tmp_path):
    sc, outputs = _planned(tmp_path)
    outcome = execute(sc, outputs, console=_quiet())
    assert outcome.result.status == "completed" and outcome.errors == [] and outcome.signum is None
    assert [o.option for o in outcome.written] == ["--out", "--history"]
    assert sorted(os.listdir(tmp_path)) == ["h.npz", "r.rrd"]  # renamed into place, no temporary file
    h = np.load(tmp_path / "h.npz")
    assert str(h["status"]) == "completed"
    assert h["step"].tolist() == list(range(0, STEPS + 1, EVERY))  # the initial state and every 5th step
    assert h["time"] == pytest.approx(h["step"] * DT, abs=1e-15)
    # the ground's intensity, written into the history after the run: the peak of A cos(2π f t) is A (t = 0),
    # its peak step-to-step acceleration the largest difference quotient over the run's steps
    t = np.arange(STEPS + 1) * DT
    assert float(h["intensity_pgv"]) == pytest.approx(AMP, rel=1e-12)
    pga = np.abs(np.diff(AMP * np.cos(2 * math.pi * FREQ * t))).max() / DT
    assert float(h["intensity_pga"]) == pytest.approx(pga, rel=1e-9)
    info = inspect_recording(tmp_path / "r.rrd")
    # the same frames in both, the initial state first (it was in the history only: the recording began at step 5)
    assert info["complete"] and info["frames"] == len(h["step"]) and info["steps"] == (0, STEPS)
    assert "completed" in info["metadata"]
    # both files name the code that made them (before: "masonry 0.1.0" only, the same for every commit)
    run = json.loads(str(h["run"]))
    assert run["scenario"] == "one-block" and run["dt_s"] == DT and run["source_digest"] == SOURCE_DIGEST
    assert run["commit"] == source_commit() and run["commit"] in info["metadata"]
    head = f"**solver:** {SOLVERS[0]} · **masonry** {run['masonry']}, commit {run['commit']}, source {SOURCE_DIGEST}"
    assert head in info["metadata"].split("## Parameters")[0]


def test_an_engine_error_closes_the_outputs_as_failed_and_is_raised(tmp_path, monkeypatch):
    """Raised in the first step: the history and the recording hold the initial state, both whole."""
    error = FloatingPointError("synthetic engine error")

    def failing(self):
        raise error

    monkeypatch.setattr(Simulation, "step", failing)
    sc, outputs = _planned(tmp_path)
    with pytest.raises(FloatingPointError) as info:
        execute(sc, outputs, console=_quiet())
    assert info.value is error  # re-raised as it was, after the outputs were closed
    assert sorted(os.listdir(tmp_path)) == ["h.npz", "r.rrd"]
    h = np.load(tmp_path / "h.npz")
    assert str(h["status"]) == "failed" and str(h["note"]) == "the run stopped on an unexpected error"
    assert h["step"].tolist() == [0]
    rec = inspect_recording(tmp_path / "r.rrd")
    assert rec["complete"] and rec["frames"] == 1 and rec["steps"] == (0, 0) and "failed" in rec["metadata"]


def test_a_stop_before_step_one_leaves_no_file_and_keeps_the_previous_one(tmp_path, monkeypatch):
    """A Ctrl-C while the simulation is set up raises StopRun; the temporary files are removed, and the
    file that --force would have replaced is untouched."""
    (tmp_path / "r.rrd").write_bytes(b"the previous recording")

    def interrupted(scenario):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(1.0)  # the handler raises StopRun here
        raise AssertionError("no StopRun in the setup phase")

    monkeypatch.setattr(execute_module, "Simulation", interrupted)
    sc, outputs = _planned(tmp_path, force=True)
    with pytest.raises(StopRun) as info:
        execute(sc, outputs, console=_quiet())
    assert info.value.signum == signal.SIGINT
    assert os.listdir(tmp_path) == ["r.rrd"]
    assert (tmp_path / "r.rrd").read_bytes() == b"the previous recording"


def test_a_stop_inside_numbas_compiler_is_a_stop_not_an_internal_error(tmp_path, monkeypatch, capfd):
    """Walk-through, 2026-11-28: a Ctrl-C landing in a ctypes callback of the first compile was dropped (a
    StopRun traceback on stderr) and the compile failed with a RuntimeError: `masonry simulate` said
    "internal error … the recording and history hold every frame computed before it" and exited 1. Now it is
    the stop before step 1: StopRun, no file left, nothing on stderr."""

    def compile_interrupted(scenario):
        signal_inside_a_ctypes_callback(signal.SIGINT)
        raise RuntimeError("no compiled object yet for <Library '_narrowphase'>")

    monkeypatch.setattr(execute_module, "Simulation", compile_interrupted)
    sc, outputs = _planned(tmp_path)
    with pytest.raises(StopRun) as info:
        execute(sc, outputs, console=_quiet())
    assert info.value.signum == signal.SIGINT
    assert os.listdir(tmp_path) == []
    assert "Traceback" not in capfd.readouterr().err


def test_the_plan_names_the_outputs_asked_for(tmp_path, monkeypatch):
    sc = _scenario()
    with pytest.raises(InputError, match="--out .* with --no-recording: choose one"):
        plan_outputs(sc, tmp_path / "r.rrd", None, no_recording=True, force=False)
    none = plan_outputs(sc, None, None, no_recording=True, force=False)
    assert none.files() == []
    monkeypatch.chdir(tmp_path)
    default = plan_outputs(sc, None, tmp_path / "h.npz", no_recording=False, force=False)
    assert default.recording.path.parent.name == "recordings" and default.recording.path.name.startswith("one-block-")
    assert default.recording.path.suffix == ".rrd" and default.history.path == tmp_path / "h.npz"
    assert os.listdir(tmp_path) == []  # planning writes nothing


def test_a_file_where_the_default_recordings_folder_goes_is_bad_input(tmp_path, monkeypatch):
    # "internal error: NotADirectoryError: … 'recordings/.wall-….rrd.<pid>.part'", exit 1: the default path was
    # not checked, and removing its part file raised over the InputError that said why.
    monkeypatch.chdir(tmp_path)
    (tmp_path / "recordings").write_text("notes")
    with pytest.raises(InputError) as info:
        plan_outputs(_scenario(), None, None, no_recording=False, force=False)
    assert re.fullmatch(
        r"the default recording recordings/one-block-\d{8}-\d{6}\.rrd: recordings is not a folder "
        r"\(give --out R\.rrd, or --no-recording\)",
        str(info.value),
    )
    OutputFile(tmp_path / "recordings" / "x.rrd", "--out").discard()  # nothing to remove, nothing raised
    assert os.listdir(tmp_path) == ["recordings"]


@pytest.mark.parametrize(
    "options, message",
    [
        # --magnify is checked before the outputs: its message, not "--out ... with --no-recording"
        ({"magnify": 1e7}, "--magnify 1e+07: must be between 1 and 1e+06"),
        ({"magnify": 2.0}, "--magnify 2 with --no-recording: choose one (it draws in the recording)"),
        ({"magnify": None}, "--out r.rrd with --no-recording: choose one"),
    ],
)
def test_check_run_says_the_first_bad_option_in_one_line(options, message, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError) as info:
        check_run(_scenario(), Path("r.rrd"), None, no_recording=True, force=False, **options)
    assert str(info.value) == message


def test_check_run_refuses_a_step_too_long_for_the_motion(tmp_path):
    fast = dataclasses.replace(_scenario(), motions=(Sine(amplitude=AMP, frequency=600.0),))  # dt = 1 ms
    with pytest.raises(InputError, match=r"frequency = 600 Hz is above 1/\(2 dt\) = 500 Hz"):
        check_run(fast, tmp_path / "r.rrd", None, no_recording=False, force=False, magnify=None)
    outputs = check_run(_scenario(), tmp_path / "r.rrd", None, no_recording=False, force=False, magnify=10.0)
    assert outputs.recording.path == tmp_path / "r.rrd" and outputs.history is None


@pytest.mark.parametrize(
    "args",
    [
        ("simulate", "wall", "--duration", 0.01),  # a short run: the recording is mostly its static part
        ("simulate", "wall", "--duration", 0.3, "--record-every", 100),  # few frames, many per-step series
        ("simulate", "arch", "--duration", 0.002, "--voussoirs", 60),
        ("simulate", "wall", "--duration", 0.05, "--record-every", 1),
    ],
)
def test_the_size_estimate_is_an_upper_bound(args, tmp_path):
    """The estimate left out the recording's static part: the 51-block wall's 0.1 s was let start on a 1 MB
    disk (estimate ~0.6 MB; it wrote 0.63 MB of recording + its history) and failed there, exit 4."""
    from masonrycli.scenario.builtin import builtin

    rrd, npz = tmp_path / "r.rrd", tmp_path / "h.npz"
    result = invoke(*args, "--out", rrd, "--history", npz)
    assert result.exit_code == 0, result.output
    options = dict(zip(args[2::2], args[3::2]))
    scenario = builtin(args[1], **{k.lstrip("-").replace("-", "_"): v for k, v in options.items()})
    recording, history = output_sizes(scenario)
    assert rrd.stat().st_size <= recording <= 4 * rrd.stat().st_size + 10**6
    assert npz.stat().st_size <= history <= 4 * npz.stat().st_size + 10**5


def test_last_line_opens_the_recording(tmp_path):
    """Finding 12: the README says the last line of a run is the command that opens the recording."""
    rrd = tmp_path / "w.rrd"
    result = invoke("simulate", "wall", "--duration", 0.11, "--out", rrd)
    assert result.exit_code == 0, result.output
    last = result.output.strip().splitlines()[-1]
    assert last.startswith("Open the recording:") and last.endswith(f"rerun {rrd}"), last


def test_the_last_line_is_a_command_the_shell_runs(tmp_path):
    """A recording path with a space or a quote was printed as is: pasted into a shell, "rerun my runs/w.rrd"
    asked rerun for two files."""
    import shlex

    rrd = tmp_path / "my runs" / "it's.rrd"
    rrd.parent.mkdir()
    result = invoke("simulate", "wall", "--duration", 0.01, "--out", rrd)
    assert result.exit_code == 0, result.output
    last = result.output.strip().splitlines()[-1]
    words = shlex.split(last.removeprefix("Open the recording:"))
    assert words[0].endswith("rerun") and words[1:] == [str(rrd)], last


def test_the_open_command_runs_where_the_student_is(tmp_path, monkeypatch):
    """A class on Windows, the venv not activated: the last line said "rerun 'recordings\\wall-….rrd'" — no
    rerun on PATH, and '…' are no quotes to cmd.exe (shlex quoted every default path for its backslash);
    its viewer is Scripts\\rerun.exe. On any system the viewer below the working folder is named from there."""
    monkeypatch.setattr(viewer_command.shutil, "which", lambda name: None)
    for system, folder, viewer in ((True, "Scripts", "rerun.exe"), (False, "bin", "rerun")):
        scripts = tmp_path / "class" / ".venv" / folder
        scripts.mkdir(parents=True)
        (scripts / viewer).touch()
        monkeypatch.setattr(viewer_command.sys, "executable", str(scripts / "python"))
        monkeypatch.chdir(tmp_path / "class")
        rrd = os.path.join("recordings", "wall-20261129-082048.rrd")
        command = viewer_command.open_command(rrd, windows=system)
        shown = os.path.join(os.curdir, ".venv", folder, viewer) if system else os.path.join(".venv", folder, viewer)
        assert command == f"{shown} {rrd}"
        assert viewer_command.open_command("my runs/w.rrd", windows=system).endswith(
            ' "my runs/w.rrd"' if system else " 'my runs/w.rrd'"
        )
        monkeypatch.chdir(tmp_path)  # elsewhere: the viewer's whole path
        elsewhere = tmp_path / "elsewhere"
        elsewhere.mkdir(exist_ok=True)
        monkeypatch.chdir(elsewhere)
        assert viewer_command.open_command("w.rrd", windows=system) == f"{scripts / viewer} w.rrd"


def test_the_unconverged_warning_names_only_the_causes_there_were():
    # "20 at the 2-sweep cap, the others stalled: every method … gave up" when none had stalled.
    run = RunConfig(max_iterations=2, tolerance=1e-5)
    capped_only = unconverged_warning(20, 20, 20, run)
    assert "(contact-law residual above --tolerance 1e-05 m/s; 20 at the 2-sweep cap); their" in capped_only
    assert "stalled" not in capped_only and "Raise --max-iterations for capped steps" in capped_only
    both = unconverged_warning(141, 500, 32, run)
    assert "32 at the 2-sweep cap, the other 109 stalled: every method of the stalled-step round-robin" in both
    stalled_only = unconverged_warning(3, 500, 0, dataclasses.replace(run, solver="nlgs"))
    assert "m/s; 3 stalled: no lower residual in 10 000 sweeps by faces); " in stalled_only
    assert "cap" not in stalled_only and stalled_only.endswith("Check the history's nlgs_residual.")


def test_the_unconverged_warning_says_how_far_off_and_when():
    # "1 of 300 steps ended unconverged" left the user to find the step in the history; the worst residual
    # (the tally's maximum and its step) is said with its time and its multiple of the tolerance
    run = RunConfig(max_iterations=100_000, tolerance=1e-5, dt=1e-3)
    text = unconverged_warning(1, 300, 1, run, (1.44e-5, 212))
    assert "1 at the 100000-sweep cap, the worst 1.44e-05 m/s (1.4× the tolerance) at t = 0.212 s);" in text
    assert "the worst" not in unconverged_warning(1, 300, 1, run, (math.nan, 212))
    assert "the worst" not in unconverged_warning(1, 300, 1, run)


def _frames_in(rrd: Path) -> int:
    """Frames shown in the recording (the initial state, t = 0, first: the history's frames)."""
    info = inspect_recording(rrd)
    assert info["application_id"] == "masonry"
    return info["frames"]


def test_divergence_leaves_complete_outputs(tmp_path, monkeypatch):
    import masonrycli.run as run_module

    monkeypatch.setattr(run_module, "DIVERGENCE_SPEED", 0.05)  # the shaken wall exceeds it quickly
    rrd, npz = tmp_path / "div.rrd", tmp_path / "div.npz"
    result = invoke("simulate", "wall", "--duration", 0.5, "--out", rrd, "--history", npz)
    assert result.exit_code == 3, result.output
    assert "diverged" in result.output
    h = np.load(npz)
    assert str(h["status"]) == "diverged"
    assert _frames_in(rrd) == len(h["time"])


def test_engine_error_mid_run_keeps_frames(tmp_path, monkeypatch):
    original = Simulation.step

    def failing(self):
        if self.state.step == 25:
            raise FloatingPointError("synthetic failure")
        return original(self)

    monkeypatch.setattr(Simulation, "step", failing)
    rrd, npz = tmp_path / "err.rrd", tmp_path / "err.npz"
    result = invoke("simulate", "wall", "--duration", 0.1, "--out", rrd, "--history", npz)
    assert result.exit_code == 1, result.output
    assert "Traceback" not in result.output and "synthetic failure" in result.output
    h = np.load(npz)
    assert str(h["status"]) == "failed"
    assert list(h["step"]) == [0, 10, 20]
    assert _frames_in(rrd) == 3


def test_unconverged_steps_are_counted_and_warned(tmp_path):
    """A sweep cap too low for the tolerance: the summary, the history and a warning say how many steps."""
    npz = tmp_path / "h.npz"
    r = invoke("simulate", "wall", "--duration", "0.02", "--max-iterations", "2", "--no-recording", "--history", npz)
    assert r.exit_code == 0, r.output
    assert "warning: 20 of 20 steps ended unconverged" in words(r.output)
    assert "20 at the 2-sweep cap, the worst " in words(r.output)  # none stalled: not said
    # (what stalled steps go through, by solver: test_execute.py, unconverged_warning)
    h = np.load(npz)
    assert h["nlgs_unconverged"][-1] == 20
    assert np.all(h["nlgs_iterations"][1:] == 2) and np.all(h["nlgs_residual"][1:] > 1e-5)
    # the worst step's residual is at least the largest the history's frames kept, said at a step's time
    worst = re.search(r"the worst (\S+) m/s \((\S+)× the tolerance\) at t = (\S+) s\); their", words(r.output))
    residual, times, t = float(worst[1]), float(worst[2]), float(worst[3])
    assert residual >= h["nlgs_residual"][1:].max() and times == pytest.approx(residual / 1e-5, rel=0.05)
    assert 0 < t <= 0.02 and round(t / 1e-3) == pytest.approx(t / 1e-3, abs=1e-9)
    npz = tmp_path / "h_default.npz"
    r = invoke("simulate", "wall", "--duration", "0.02", "--no-recording", "--history", npz)
    assert r.exit_code == 0 and "unconverged" in r.output and "warning" not in r.output, r.output
    h = np.load(npz)
    assert h["nlgs_unconverged"][-1] == 0 and np.all(h["nlgs_residual"] <= 1e-5)


POWERSHELL_MODULES = (
    r"C:\Users\Ana Silva\Documents\WindowsPowerShell\Modules;C:\Program Files\WindowsPowerShell\Modules"
)
MACHINE_MODULES = r"C:\Program Files\WindowsPowerShell\Modules;C:\WINDOWS\system32\WindowsPowerShell\v1.0\Modules"


@pytest.mark.parametrize(
    "modules, call",
    [
        (POWERSHELL_MODULES, "& "),  # Windows PowerShell 5.1: its own user folder first
        (r"c:\users\ana silva\Documents\PowerShell\Modules;" + MACHINE_MODULES, "& "),  # pwsh 7, any case
        (MACHINE_MODULES, ""),  # cmd.exe from the Start menu: the machine's value only
        (None, ""),
    ],
)
def test_the_open_command_calls_a_quoted_viewer_in_powershell(tmp_path, monkeypatch, modules, call):
    """A student in "C:\\Users\\Ana Silva" whose venv is not below the working folder: the line was
    '"C:\\…\\Scripts\\rerun.exe" "my runs\\w.rrd"', right in cmd.exe, but in PowerShell a quoted path is a
    string ("Unexpected token"): it runs after the call operator, '& "…\\rerun.exe" "…"', which cmd.exe refuses."""
    monkeypatch.setattr(viewer_command.shutil, "which", lambda name: None)
    scripts = tmp_path / "Ana Silva" / ".venv" / "Scripts"
    scripts.mkdir(parents=True)
    (scripts / "rerun.exe").touch()
    monkeypatch.setattr(viewer_command.sys, "executable", str(scripts / "python.exe"))
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("USERPROFILE", r"C:\Users\Ana Silva")
    if modules is None:
        monkeypatch.delenv("PSModulePath", raising=False)
    else:
        monkeypatch.setenv("PSModulePath", modules)
    viewer = os.path.join(os.curdir, "Ana Silva", ".venv", "Scripts", "rerun.exe")
    rrd = r"recordings\wall-20261129-082048.rrd"
    assert viewer_command.open_command(rrd, windows=True) == f'{call}"{viewer}" {rrd}'
    assert viewer_command.open_command(r"my runs\w.rrd", windows=True) == f'{call}"{viewer}" "my runs\\w.rrd"'
    # a viewer that needs no quotes needs no operator: the line runs in either shell
    monkeypatch.chdir(tmp_path / "Ana Silva")
    assert (
        viewer_command.open_command(rrd, windows=True)
        == f"{os.path.join(os.curdir, '.venv', 'Scripts', 'rerun.exe')} {rrd}"
    )


def test_the_open_command_quotes_what_either_windows_shell_would_read_otherwise(monkeypatch):
    # list2cmdline quoted only spaces: "rerun it's.rrd" is an unclosed string to PowerShell, "rerun a&b.rrd"
    # two commands to cmd.exe
    monkeypatch.setattr(viewer_command.shutil, "which", lambda name: "rerun")
    for name in ("it's.rrd", "a&b.rrd", "w (2).rrd", "x;y.rrd"):
        assert viewer_command.open_command(name, windows=True) == f'rerun "{name}"'
    assert viewer_command.open_command(r"C:\runs\w-1_a.rrd", windows=True) == r"rerun C:\runs\w-1_a.rrd"
