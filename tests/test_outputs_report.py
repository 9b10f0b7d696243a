"""The terminal tables (masonrycli/outputs/report.py): the summary names the solver that ran; inspect's rows."""

import io
import time

import pytest
from rich.console import Console

from masonrycli.outputs.report import SLOW_START, SOLVER_NOTES, recording_table, slow_start_notice, summary_table
from masonrycli.run import simulate
from masonrycli.scenario.scenario import SOLVERS
from tests.engine_helpers import scenario


def _rows(result_or_table) -> dict[str, str]:
    console = Console(record=True, width=400)
    table = result_or_table if hasattr(result_or_table, "add_row") else summary_table(result_or_table, None, None)
    console.print(table)
    rows = {}
    for line in console.export_text().splitlines():
        cells = [c.strip() for c in line.strip("│ ").split("│")]
        if len(cells) == 2:
            rows[cells[0]] = cells[1]
    return rows


@pytest.mark.parametrize("solver", SOLVERS)
def test_the_summary_names_the_solver_that_ran(solver):
    result = simulate(scenario("column5.toml", duration=0.01, solver=solver))
    assert result.solver == solver
    assert _rows(result)["solver"] == f"{solver} ({SOLVER_NOTES[solver]})"


def test_the_run_time_is_not_called_wall_time():
    # "wall time 25.62 s" in the summary of `masonry simulate wall` read, to a class, as a time of the wall
    rows = _rows(simulate(scenario("column5.toml", duration=0.01)))
    assert "wall time" not in rows and rows["run time"].endswith(" steps/s)")


def test_a_dissipation_below_zero_at_round_off_is_said_to_be_zero():
    # walk-through 2026-11-28: `masonry run tests/data/validation/column5.toml` (five blocks at rest) printed
    # "dissipated at contacts  -6.394e-14 J"; a real value is printed as it is
    result = simulate(scenario("column5.toml", duration=0.05))
    assert abs(result.energy_dissipated) < 1e-9 * abs(result.energy_initial)
    result.energy_dissipated = -6.394e-14
    assert _rows(result)["dissipated at contacts"] == "0 J (round-off: -6.4e-14 J)"
    result.energy_dissipated = 722.4
    assert _rows(result)["dissipated at contacts"] == "722.4 J"


def test_every_solver_has_a_note():
    assert set(SOLVER_NOTES) == set(SOLVERS)


def test_inspect_rows_spell_spans_and_missing_values():
    info = {"steps": [0, 40], "time_span": (0.0, 0.2), "sim_time": None, "entities": ["a"], "metadata": {"k": 1}}
    rows = _rows(recording_table("r.rrd", info))
    assert rows == {"steps": "0 … 40", "time_span": "0.0 … 0.2 s", "sim_time": "—", "entities": "a"}


class _Terminal(io.StringIO):
    def __init__(self, tty: bool):
        super().__init__()
        self.tty = tty

    def isatty(self) -> bool:
        return self.tty


def test_a_slow_start_on_a_terminal_says_why():
    # a first run sat 15 s with no line, then 15 s on a progress bar at step 0: taken for hung
    slow, fast, piped = _Terminal(True), _Terminal(True), _Terminal(False)
    with slow_start_notice(after=0.01, stream=slow):
        time.sleep(0.2)
    with slow_start_notice(after=5.0, stream=fast):
        pass
    with slow_start_notice(after=0.01, stream=piped):
        time.sleep(0.2)
    assert slow.getvalue() == SLOW_START + "\n" and "translates the solver to machine code" in SLOW_START
    assert fast.getvalue() == "" and piped.getvalue() == ""  # quick, or not a terminal: nothing


def test_the_summary_is_titled_with_the_scenario_not_masonry_run(tmp_path, monkeypatch):
    # `masonry simulate arch …` ended under "masonry run — completed" (a bridge engineer's report)
    from tests.cli_helpers import invoke

    monkeypatch.chdir(tmp_path)
    result = invoke("simulate", "arch", "--duration", "0.002", "--no-recording")
    assert result.exit_code == 0, result.output
    assert "masonry run —" not in result.output
    assert "arch — completed" in result.output


def test_the_energy_row_says_its_change():
    """A file read moved from a map grid stands hundreds of metres up: its summary said '2.475e+08 J → 2.475e+08 J'
    and the few joules its stones lost (the balance: support work = change + dissipated) could not be read."""
    result = simulate(scenario("column5.toml", duration=0.01))
    result.energy_initial, result.energy_final = 2.475123e8, 2.475123e8 - 2.1
    assert _rows(result)["energy (kinetic + potential)"] == "2.475e+08 J → 2.475e+08 J (change -2.1 J)"


def test_a_long_path_is_whole_in_the_summary_and_build_s_line(tmp_path):
    # off a terminal (80 columns) the summary's history row read '/tmp/…/course-2026/assignment-3-frict…': cut,
    # the file it names lost; build's '→ PATH' line was broken in two inside the path
    from cli_helpers import invoke

    deep = tmp_path / "course-2026" / "assignment-3-friction-and-frequency" / "histories-of-every-run-of-the-wall"
    result = invoke("simulate", "wall", "--duration", 0.01, "--no-recording", "--history", deep / "h.npz")
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("│ history "))
    folded = "".join(line.split("│")[2].strip() for line in lines[start:] if line.startswith("│ ") and "│" in line[2:])
    assert folded.startswith(str(deep / "h.npz")) and "…" not in folded
    built = invoke("build", "wall", "--out", deep / "w.geojson")
    assert f"wall: 51 blocks and 1 support → {deep / 'w.geojson'}" in built.output.splitlines()
