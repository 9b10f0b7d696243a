"""masonrycli/cli/inspect_file.py as a user drives it: masonry inspect summarises a recording and names a
file it cannot read in one line."""

from __future__ import annotations

from cli_helpers import assert_one_line_error, invoke


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
