"""masonrycli/cli/inspect_file.py as a user drives it: masonry inspect summarises a recording and a study's
table (its rows, each column's unit; none yet) and names a file it cannot read in one line."""

from __future__ import annotations

from pathlib import Path

import pytest

from cli_helpers import assert_one_line_error, invoke, words
from sweep_helpers import invoke as invoke_wide
from sweep_helpers import write_block


def test_inspect_summarises_a_recording(tmp_path):
    rrd = tmp_path / "w.rrd"
    assert invoke("simulate", "wall", "--duration", 0.03, "--out", rrd).exit_code == 0
    result = invoke("inspect", rrd)
    assert result.exit_code == 0, result.output
    assert "masonry" in result.output and "/structure/plane/xy/blocks" in result.output
    assert "steps          │ 0 … 30" in result.output  # from the initial frame (it began at 10)
    bad = tmp_path / "bad.rrd"
    bad.write_bytes(b"not a recording")
    assert_one_line_error(invoke("inspect", bad), "bad.rrd")
    assert_one_line_error(invoke("inspect", tmp_path / "missing.rrd"), "missing.rrd")


@pytest.fixture
def block(tmp_path) -> Path:
    return write_block(tmp_path)


def test_inspect_a_study_table_gives_its_rows_values_and_each_columns_unit(block, tmp_path):
    # 'masonry inspect study.csv' said "a table (.csv), not a recording": the table's numbers had no unit anywhere
    # but the docs (pga 1.70: m/s² or g?)
    for suffix in (".csv", ".parquet"):
        out = tmp_path / f"s_{suffix[1:]}{suffix}"  # its own plot beside it
        args = ["--param", "amp=0.05,0.1", "--param", "friction=0.5", "--duration", 0.1, "--workers", 0]
        assert invoke_wide("sweep", block, *args, "--out", out, "--no-recording").exit_code == 0
        result = invoke_wide("inspect", out)
        assert result.exit_code == 0, result.output
        said = words(result.output)
        assert "study table" in said and "rows │ 2 (" in said and "amp │ 0.05, 0.1 m/s" in said, said
        lines = result.output.splitlines()
        assert any(ln.split() == ["pga", "m/s²,", "peak", "ground", "acceleration", "as", "applied"] for ln in lines)
        assert any(ln.startswith("max_opening") and "m, largest joint opening" in ln for ln in lines)
    record = tmp_path / "q.csv"
    record.write_text("time,velocity\n0,0\n1,1\n")
    assert_one_line_error(invoke_wide("inspect", record), "q.csv: not a study's table")


def test_inspect_a_study_table_with_its_header_and_no_rows_says_none_yet(block, tmp_path):
    # its header has the study and status columns, yet inspect said "not a study's table (no study and status
    # columns)"; a table with its rows filtered away in a spreadsheet (or pandas) and saved again is one
    import pyarrow as pa
    import pyarrow.parquet as pq

    out = tmp_path / "s.csv"
    args = ["--param", "amp=0.05,0.1", "--duration", 0.1, "--workers", 0]
    assert invoke_wide("sweep", block, *args, "--out", out, "--no-recording").exit_code == 0
    header = out.read_text().splitlines()[0]
    empty_csv = tmp_path / "e.csv"
    empty_csv.write_text(header + "\n")
    empty_parquet = tmp_path / "e.parquet"
    pq.write_table(pa.table({c: pa.array([], pa.float64()) for c in header.split(",")}), empty_parquet)
    for table in (empty_csv, empty_parquet):
        result = invoke_wide("inspect", table)
        assert result.exit_code == 0, result.output
        said = words(result.output.replace("│", " "))  # the table's cells, wrapped within their column
        assert "not a study's table" not in said
        assert "rows 0 — no rows yet: masonry sweep writes its rows here when the study ends or is stopped" in said
        assert f"kept in the journal {table.name}.journal.jsonl meanwhile" in said, said
        assert "amp no value yet" in said
        assert any(ln.startswith("pga") and "m/s²" in ln for ln in result.output.splitlines())
    # a study under way: its finished rows are in the journal
    (tmp_path / "e.csv.journal.jsonl").write_text('{"amp": 0.05}\n{"amp": 0.1}\n')
    said = words(invoke_wide("inspect", empty_csv).output.replace("│", " "))
    assert "2 finished rows wait in e.csv.journal.jsonl, written here when the study ends" in said, said
