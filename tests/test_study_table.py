"""The study's terminal table (masonrycli.study.table): one line per row and no line over the console's
width at 80 columns, whatever the study (long record names, failed rows, threshold searches); more
columns on a wider console; every value in the unit its legend names."""

from __future__ import annotations

import io
import math

from rich.console import Console

from masonrycli.study.table import find_columns, grid_columns, study_table

from cli_helpers import words


def _render(rows, columns, names, width: int) -> list[str]:
    console = Console(width=width, file=io.StringIO(), markup=False, highlight=False)
    console.print(study_table(rows, columns, names, console, "ida.parquet"))
    return console.file.getvalue().splitlines()


def _row(record: str, scale: float, state: str = "damaged", **more) -> dict:
    row = {"record": record, "scale": scale, "state": state, "collapse_time": math.nan, "residual_drift": -1e-9}
    row |= {"pga": 3.2345, "max_opening": 0.03025, "hinges": 2, "wall_time": 12.34, "peak_drift": 0.0123}
    return row | {"sweeps_mean": 41.6, "status": "completed", "error": ""} | more


ROWS = [_row(f"synthetic-record-{k}.AT2", s) for k in range(3) for s in (0.5, 1.75, 3.0)]
ROWS[4] |= {"state": "collapsed", "collapse_time": 0.5349, "residual_drift": 0.0775}
ROWS[7] |= {"state": "", "status": "error", "error": "ValueError: " + "a long reason " * 12}


def test_at_80_columns_every_row_is_one_line_within_the_width():
    lines = _render(ROWS, grid_columns(["record", "scale"], "pga"), ["record", "scale"], 80)
    assert max(len(line) for line in lines) <= 80
    body = [line for line in lines if line.startswith("│")]
    assert len(body) == len(ROWS)  # no cell folded onto a second line
    assert "│ synthetic-record-1.AT2 │ 1.75  │ collapsed │ 0.53 " in body[4]  # what a user needs is there
    assert "7.75" in body[4] and "0.00 " in body[0]  # drift in % of height; -1e-9 is not "-0.00"
    legend = words(" ".join(lines[len(body) + 5 :]))
    assert "collapse: time of collapse, s" in legend and "drift: residual, % of height" in legend
    assert "not shown at this width: hinges, took, peak, sweeps" in legend and "every column in ida.parquet" in legend
    # the file's drifts are fractions of the height, its openings metres (before: only the terminal's % and mm named)
    assert "in SI units (drifts × height, openings m)" in legend
    assert "failed: record=synthetic-record-2.AT2 scale=1.75: ValueError: a long reason" in legend


def test_a_long_record_name_leaves_room_for_the_state(tmp_path):
    # A PEER-style name of 60 characters took the whole 80 columns: "state" read "inta…", every other column
    # was dropped ("not shown at this width: collapse, drift, pga, open, …")
    name = "RSN6_IMPVALL.I_I-ELC180_very_long_station_name_component.AT2"
    rows = [_row(name, 0.5, "intact"), _row("b.AT2", 1.0, "collapsed", collapse_time=0.5349)]
    lines = _render(rows, grid_columns(["record", "scale"], "pga"), ["record", "scale"], 80)
    assert max(len(line) for line in lines) <= 80
    body = [line for line in lines if line.startswith("│")]
    assert "│ intact " in body[0] and "│ collapsed │ 0.53 " in body[1], lines
    assert body[0].startswith("│ RSN6_IMPVALL") and "component.AT2 │" in body[0]  # both ends of the name kept
    assert "every column in ida.parquet" in words(" ".join(lines))


def test_a_wide_console_shows_every_column_and_the_units():
    lines = _render(ROWS, grid_columns(["record", "scale"], "pga"), ["record", "scale"], 200)
    header = next(line for line in lines if "record" in line and "state" in line)
    for name in ("collapse", "drift", "pga", "open", "hinges", "took", "peak", "sweeps"):
        assert f" {name} " in header
    # a student's study of the wall read a column "wall" (the run time, s) as something of the wall
    assert " wall " not in header and "took: run time, s" in " ".join(lines)
    said = " ".join(lines)
    assert "not shown" not in said and "pga m/s²" in said and "open: largest opening, mm" in said
    assert " 30.2 " in lines[7] and " 1.23 " in lines[7] and " 12.3 " in lines[7]  # mm, % of height, s


def test_threshold_rows_fit_80_columns():
    rows = [
        {"freq": f, "amp_threshold": 1.3125, "holds": "above", "evaluations": 9, "note": "", "status": "completed"}
        | {"error": ""}
        for f in (1.0, 2.0)
    ]
    rows[1] |= {"amp_threshold": math.nan, "holds": "", "note": "no collapse up to amp = 1.5 " * 3}
    lines = _render(rows, find_columns(["freq"], "amp"), ["freq"], 80)
    assert max(len(line) for line in lines) <= 80
    assert any("│ 1    │ 1.312         │ above │ 9    │" in line for line in lines)
    assert "amp_threshold m/s" in " ".join(lines)
    # no drift, no opening in a threshold table: the file's are not named ("(drifts × height, openings m)")
    assert words(" ".join(lines)).endswith("every column in ida.parquet, in SI units")


def test_a_unitless_threshold_has_no_empty_legend_entry():
    # --find friction printed "friction_threshold  · runs: evaluations": a name with no unit after it
    rows = [{"blocks": 51, "friction_threshold": 0.42, "evaluations": 7, "note": "", "status": "completed"}]
    legend = " ".join(_render(rows, find_columns(["blocks"], "friction"), ["blocks"], 120))
    assert "friction_threshold  ·" not in legend and "runs: evaluations" in legend


def test_the_title_counts_the_rows_in_the_singular_and_plural():
    # `masonry sweep block.toml --param amp=0.05:1.0:3 --find amp --outcome sliding` (docs/sweep.md) titled its
    # one row "study (1 rows)"
    columns, names = grid_columns(["record", "scale"], "pga"), ["record", "scale"]
    assert _render(ROWS[:1], columns, names, 80)[0].strip() == "study (1 row)"
    assert _render(ROWS, columns, names, 80)[0].strip() == f"study ({len(ROWS)} rows)"


def test_a_parameter_of_one_value_is_said_once_not_a_column_a_row(tmp_path):
    # 'sweep wall --param courses=6 --param length=0.6 --param density=2200 --records recs/ --param pga_g=… --param
    # friction=…' at 80 columns: courses, length and density took 3 of its 7 columns, the same value on every row,
    # and collapse and drift were left out
    from typer.testing import CliRunner

    from masonrycli.cli.app import app

    args = ["sweep", "wall", "--param", "courses=4", "--param", "length=0.6", "--param", "density=2200"]
    args += ["--param", "amp=0.1,0.2", "--param", "freq=1,2", "--duration", "0.01", "--workers", "0"]
    result = CliRunner().invoke(app, [*args, "--no-recording", "--out", str(tmp_path / "s.csv")], terminal_width=80)
    assert result.exit_code == 0, result.output
    header = next(line for line in result.output.splitlines() if line.startswith("┃"))
    assert [h.strip() for h in header.strip("┃").split("┃")][:5] == ["amp", "freq", "state", "collapse", "drift"]
    assert "every row: courses = 4, length = 0.6, density = 2200 · " in words(result.output)
    lines = _render(ROWS, grid_columns(["scale"], "pga"), ["record", "scale"], 80)  # a failed row keeps its point
    assert "failed: record=synthetic-record-2.AT2 scale=1.75: ValueError" in words("\n".join(lines))
