"""What made a history: a command line's run keeps its ``masonry …`` line (test_outputs_run_report), a Python API
run its ``api.simulate(…)`` call, a sweep's history the ``masonry sweep …`` line; ``masonry report`` names it
first and ``masonry inspect`` shows it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from test_outputs_run_report import rows

from masonrycli import api

from cli_helpers import invoke


def _command(npz: Path) -> str | None:
    with np.load(npz) as history:
        return json.loads(str(history["run"])).get("command")


def test_an_api_run_names_its_call(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    # a numpy number and a Path as a notebook gives them: the call's text says 0.5 and 'w.npz', not np.float64(…)
    run = api.simulate("wall", blocks=12, amp=np.float64(0.5), duration=0.01, history=Path("w.npz"))
    call = "api.simulate('wall', blocks=12, amp=0.5, duration=0.01, history='w.npz')"
    assert _command(tmp_path / "w.npz") == call
    assert json.loads(str(run["run"]))["command"] == call  # the run in memory says the same
    assert rows(run.report())["command"] == call
    assert rows(invoke("report", "w.npz").output)["command"] == call
    assert rows(api.read_history("w.npz").report())["command"] == call


def test_a_run_of_a_scenario_names_the_call_that_made_it():
    arch = api.scenario("arch", voussoirs=12, settlement=0, amp=0.3)
    seen = []
    run = api.simulate(arch, duration=0.01, on_frame=seen.append)
    made = "api.scenario('arch', voussoirs=12, settlement=0, amp=0.3)"
    # a function by its name: its repr holds an address, another at every run
    assert json.loads(str(run["run"]))["command"] == f"api.simulate({made}, duration=0.01, on_frame=<function append>)"


def test_a_sweep_s_histories_name_the_sweep(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    args = ["sweep", "wall", "-p", "blocks=12", "-p", "amp=0.1,0.2", "--duration", "0.01", "--workers", "0"]
    args += ["-o", "s.csv", "--histories", "h", "--no-recording"]
    monkeypatch.setattr("sys.argv", ["/venv/bin/masonry", *args])  # as the masonry entry point runs it
    assert invoke(*args).exit_code == 0
    line = "masonry " + " ".join(args)
    for point in ("blocks=12_amp=0.1", "blocks=12_amp=0.2"):
        assert _command(tmp_path / "h" / f"{point}.npz") == line
        page = rows(invoke("report", f"h/{point}.npz").output)
        assert page["command"] == line and page["study point"] == point.replace("=", " = ").replace("_", ", ")


def test_inspect_shows_the_command_first_and_the_report_once(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    api.simulate("wall", blocks=12, duration=0.01, history="w.npz")
    call = "api.simulate('wall', blocks=12, duration=0.01, history='w.npz')"
    table = invoke("inspect", "w.npz").output
    first = next(line for line in table.splitlines() if line.startswith("│"))
    assert first.split("│")[1].strip() == "command" and call.startswith(first.split("│")[2].strip())
    page = invoke("report", "w.npz").output
    assert page.count("| command |") == 1 and page.count("| state |") == 1  # inspect's rows, taken once each


def test_a_recording_s_parameters_name_the_command(tmp_path, monkeypatch):
    # the history named its command, the recording (what a colleague opens in the viewer) did not
    from masonrycli.recording.readback import recording_rows

    monkeypatch.chdir(tmp_path)
    args = ["simulate", "wall", "--blocks", "12", "--duration", "0.01", "--out", "c.rrd"]
    monkeypatch.setattr("sys.argv", ["/venv/bin/masonry", *args])
    assert invoke(*args).exit_code == 0
    api.simulate("wall", blocks=12, duration=0.01, recording="a.rrd")
    for rrd, command in (("c.rrd", "masonry " + " ".join(args)), ("a.rrd", _call("recording='a.rrd'"))):
        (document,) = recording_rows(rrd)["static /run/metadata"]
        assert f"| command | {command} |" in document.encode().decode("unicode_escape")


def _call(output: str) -> str:
    return f"api.simulate('wall', blocks=12, duration=0.01, {output})"
