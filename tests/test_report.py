"""The terminal tables (masonrycli/report.py): the summary names the solver that ran; inspect's rows."""

import pytest
from rich.console import Console

from masonrycli.report import SOLVER_NOTES, recording_table, summary_table
from masonrycli.run import simulate
from masonrycli.scenario import SOLVERS
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


def test_every_solver_has_a_note():
    assert set(SOLVER_NOTES) == set(SOLVERS)


def test_inspect_rows_spell_spans_and_missing_values():
    info = {"steps": [0, 40], "time_span": (0.0, 0.2), "sim_time": None, "entities": ["a"], "metadata": {"k": 1}}
    rows = _rows(recording_table("r.rrd", info))
    assert rows == {"steps": "0 … 40", "time_span": "0.0 … 0.2 s", "sim_time": "—", "entities": "a"}
