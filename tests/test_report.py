"""The end-of-run summary table (masonrycli/report.py): its solver row names the solver that ran."""

import pytest
from rich.console import Console

from masonrycli.report import SOLVER_NOTES, summary_table
from masonrycli.run import simulate
from masonrycli.scenario import SOLVERS
from tests.engine_helpers import scenario


def _rows(result) -> dict[str, str]:
    console = Console(record=True, width=400)
    console.print(summary_table(result, None, None))
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
