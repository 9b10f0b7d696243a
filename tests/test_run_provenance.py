"""What made a history: a command line's run keeps its ``masonry …`` line (test_outputs_run_report), a Python API
run its ``api.simulate(…)`` call, a sweep's history the ``masonry sweep …`` line; ``masonry report`` names it
first and ``masonry inspect`` shows it. A sweep's table keeps it in a ``command`` column, row by row."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
from test_outputs_run_report import rows

from masonrycli import api

from cli_helpers import invoke, words
from sweep_helpers import invoke as invoke_wide


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


def _sweep(monkeypatch, *args):
    args = ["sweep", "wall", "-p", "blocks=12", *args, "--duration", "0.01", "--workers", "0", "--no-recording"]
    monkeypatch.setattr("sys.argv", ["/venv/bin/masonry", *args])  # as the masonry entry point runs it
    result = invoke(*args)
    assert result.exit_code == 0, result.output
    return "masonry " + " ".join(args)


def test_a_sweep_s_table_names_the_sweep_row_by_row_and_inspect_shows_it(tmp_path, monkeypatch):
    # only the histories named the sweep; the table (what a colleague is sent) did not say what made it
    monkeypatch.chdir(tmp_path)
    first = _sweep(monkeypatch, "-p", "amp=0.1", "-o", "s.csv")
    # resumed (its plot replaced: --force), the first row kept, one more run
    resumed = _sweep(monkeypatch, "-p", "amp=0.1,0.2", "-o", "s.csv", "--force")
    with open("s.csv", newline="") as fh:  # a plain CSV reader: the header first, one column more
        rows = list(csv.DictReader(fh))
    assert [(r["amp"], r["command"]) for r in rows] == [("0.1", first), ("0.2", resumed)]
    cells = _cells(invoke_wide("inspect", "s.csv").output)
    assert list(cells)[:2] == ["command", "rows"] and cells["rows"] == "2 (2 intact)"
    assert cells["command"] == f"{first} {resumed}"  # one a line, wrapped at spaces
    # a table written before rows named their command resumes; its rows say so
    with open("s.csv", newline="") as fh:
        old = [{k: v for k, v in r.items() if k != "command"} for r in csv.DictReader(fh)]
    with open("s.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(old[0]))
        writer.writeheader()
        writer.writerows(old)
    again = _sweep(monkeypatch, "-p", "amp=0.1,0.2,0.3", "-o", "s.csv", "--force")
    with open("s.csv", newline="") as fh:
        assert [r["command"] for r in csv.DictReader(fh)] == ["", "", again]
    assert _cells(invoke_wide("inspect", "s.csv").output)["command"] == f"{again} 2 rows: not recorded"


def _cells(output: str) -> dict[str, str]:
    """The rows of inspect's table, name → its cell's words (the lines a cell wraps to joined by spaces)."""
    cells: dict[str, str] = {}
    for line in output.splitlines():
        if line.startswith("│"):
            name, cell = (part.strip() for part in line.split("│")[1:3])
            key = name or list(cells)[-1]
            cells[key] = words(f"{cells.get(key, '')} {cell}")
    return cells
