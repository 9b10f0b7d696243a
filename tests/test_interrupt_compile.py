"""A stop signal while a step compiles numba kernels stops the run at once (masonrycli.interrupt, module doc).

A first run compiles some kernels in step 1 and others in the first step that stalls; with an empty cache on a
loaded machine that lasts minutes. The run polled its stop only after the step: a SIGTERM of ``timeout 120`` at
load 23 was acknowledged ("already stopping") and the run compiled 10 more minutes until SIGKILLed. Here a
step of a real ``masonry simulate`` compiles for 60 s (numba's own "numba:compile" event around a wait), and the
signal comes inside it."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from test_interrupt import frames_in_recording

COMPILING_STEP = """
import os, signal, sys, time
import numba.core.event as ev
import masonrycli.run as run

step = run.Simulation.step
WHERE = os.environ["WHERE"]

def compile_for(seconds):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        time.sleep(0.01)

def compiling(sim, seconds=60):
    # numba compiling a kernel the run calls first here, for a minute (a loaded machine, an empty cache)
    with ev.trigger_event("numba:compile", data={"dispatcher": None, "args": ()}):
        if os.environ.get("DROPPED"):  # the handler's raise lands in llvmlite's ctypes callback: dropped
            sys.path.insert(0, os.environ["TESTS"])
            from cli_helpers import signal_inside_a_ctypes_callback
            signal_inside_a_ctypes_callback(int(os.environ["SIGNAL"]))
            compile_for(2)
            with ev.trigger_event("numba:compile", data={"dispatcher": None, "args": ()}):  # a callee's
                compile_for(seconds)
        os.kill(os.getpid(), int(os.environ["SIGNAL"]))
        if os.environ.get("REPEAT"):
            time.sleep(0.5)
            os.kill(os.getpid(), int(os.environ["SIGNAL"]))
        compile_for(seconds)

def slow_step(sim):
    if WHERE == "step" and sim.state.step == 25:
        sim.state.body_v[:] += 1.0  # the step had begun: the solve had written the velocities
        compiling(sim)
    return step(sim)

frame = run.Simulation.frame

def slow_frame(sim):
    if WHERE == "frame" and sim.state.step == 30:
        compiling(sim)
    if WHERE == "first" and sim.state.step == 0:
        compiling(sim, 3)  # the first frame is waited for: a history holds at least t = 0
    return frame(sim)

run.Simulation.step = slow_step
run.Simulation.frame = slow_frame
sys.argv = ["masonry", *sys.argv[1:]]
from masonrycli.__main__ import main
main()
"""


def _run(tmp_path, sig, where: str, repeat: bool = False, dropped: bool = False):
    rrd, npz = tmp_path / "w.rrd", tmp_path / "w.npz"
    argv = ["simulate", "wall", "--duration", "100", "--out", str(rrd), "--history", str(npz)]
    env = dict(os.environ, RERUN_ANALYTICS="0", SIGNAL=str(int(sig)), WHERE=where, REPEAT="1" if repeat else "")
    env |= {"DROPPED": "1" if dropped else "", "TESTS": os.path.dirname(__file__)}
    t0 = time.monotonic()
    proc = subprocess.run(
        [sys.executable, "-c", COMPILING_STEP, *argv], env=env, capture_output=True, text=True, timeout=240
    )
    return proc, time.monotonic() - t0, rrd, npz


@pytest.mark.slow
@pytest.mark.parametrize(
    "sig, code, where, repeat",
    [
        (signal.SIGTERM, 143, "step", False),
        (signal.SIGINT, 130, "step", True),
        (signal.SIGTERM, 143, "frame", False),
    ],
    ids=["sigterm-step", "sigint-twice-step", "sigterm-frame"],
)
def test_a_signal_while_a_step_compiles_stops_the_run_at_once(sig, code, where, repeat, tmp_path):
    proc, took, rrd, npz = _run(tmp_path, sig, where, repeat)
    assert proc.returncode == code, proc.stdout + proc.stderr
    assert took < 45, f"{took:.0f} s: the run waited for the compilation"  # 60 s of "compiling" on main
    assert "Traceback" not in proc.stderr, proc.stderr
    h = np.load(npz)
    assert str(h["status"]) == "interrupted"
    # the state it ends at is one the solver reached whole: the step abandoned is not in it
    last = 25 if where == "step" else 30  # step 26 abandoned; or step 30 reached, its frame never handed on
    assert "while numba compiled the run's kernels" in str(h["note"]), h["note"]
    assert f"(step {last} of 100000)" in str(h["note"]), h["note"]
    assert f"interrupted at t = {last / 1000:.4f} s" in proc.stdout, proc.stdout
    np.testing.assert_allclose(h["time"], np.arange(0, 21, 10) / 1000)  # every 10th step's frame, whole
    # the velocities the abandoned step had written (+1 m/s, +1 rad/s: ~10 kJ of kinetic energy) put back
    change = re.search(r"\(change ([-+0-9.e]+) J\)", proc.stdout)
    assert change and abs(float(change[1])) < 1000, proc.stdout
    assert frames_in_recording(rrd) == len(h["time"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["w.npz", "w.rrd"]


@pytest.mark.slow
def test_a_stop_dropped_inside_the_compiler_stops_the_step_at_the_next_compilation(tmp_path):
    """The handler's raise landed in llvmlite's ctypes callback and was dropped (measured: a SIGTERM in a cold
    run's first compilations, and step 1 compiled 10 s more): the next kernel's compilation raises it."""
    proc, took, rrd, npz = _run(tmp_path, signal.SIGTERM, "step", dropped=True)
    assert proc.returncode == 143, proc.stdout + proc.stderr
    assert took < 45, f"{took:.0f} s: the run waited for the compilation"
    assert "Traceback" not in proc.stderr and "Exception ignored" not in proc.stderr, proc.stderr
    h = np.load(npz)
    assert "(step 25 of 100000) while numba compiled" in str(h["note"]), h["note"]
    assert frames_in_recording(rrd) == len(h["time"]) == 3


@pytest.mark.slow
def test_a_signal_while_the_first_frame_compiles_keeps_it(tmp_path):
    """The frame at t = 0 is waited for (a history without one cannot be read); the run stops after step 1."""
    proc, took, rrd, npz = _run(tmp_path, signal.SIGTERM, "first")
    assert proc.returncode == 143, proc.stdout + proc.stderr
    h = np.load(npz)
    assert str(h["status"]) == "interrupted" and h["time"][0] == 0.0, h["note"]
    assert frames_in_recording(rrd) == len(h["time"])
