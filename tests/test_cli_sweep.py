"""``masonry sweep`` as a user drives it (in process, --workers 0): records and a fragility curve, the
state map, the recording, resume, and one-line errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from masonrycli.cli import app
from masonrycli.records import G_STANDARD
from masonrycli.study.store import read_rows

from synthetic_records import band_limited, write_at2

runner = CliRunner()
BLOCK = """
[run]
duration = 1.0
dt = 2e-3
[material]
friction = 0.8
[[block]]
polygon = [[-0.1, 0.0], [0.1, 0.0], [0.1, 0.6], [-0.1, 0.6]]
[[support]]
name = "ground"
polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]
motion = { kind = "sine", amplitude = 0.1, frequency = 2.0 }
"""


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], terminal_width=200)


@pytest.fixture
def block(tmp_path) -> Path:
    (tmp_path / "block.toml").write_text(BLOCK)
    return tmp_path / "block.toml"


def test_records_sweep_fits_a_fragility_curve_and_records_the_study(block, tmp_path):
    folder = tmp_path / "records"
    folder.mkdir()
    for seed in range(3):
        t, u, v, a = band_limited(1.0, 0.01, [1.0 + 0.4 * seed, 2.5], [0.03, 0.01], seed=seed)
        write_at2(folder / f"syn{seed}.AT2", a / G_STANDARD, 0.01)
    out, rrd = tmp_path / "ida.csv", tmp_path / "ida.rrd"
    result = invoke(
        "sweep", block, "--records", folder, "--scale", "0.5:8:4", "--workers", 0, "--out", out, "--recording", rrd
    )
    assert result.exit_code == 0, result.output
    rows = read_rows(out)
    assert len(rows) == 12 and {r["record"] for r in rows} == {"syn0.AT2", "syn1.AT2", "syn2.AT2"}
    states = {r["state"] for r in rows}
    assert "collapsed" in states and states & {"intact", "damaged"}
    # the IM of a row is the record as applied: PGA grows with the scale, for each record
    for name in ("syn0.AT2", "syn1.AT2"):
        pga = [r["pga"] for r in rows if r["record"] == name]
        scale = [r["scale"] for r in rows if r["record"] == name]
        np.testing.assert_allclose(np.array(pga) / pga[0], np.array(scale) / scale[0], rtol=1e-6)
    said = " ".join(result.output.split())  # the console wraps long lines
    assert "fragility (pga): median θ =" in said and "dispersion β =" in said
    assert (tmp_path / "ida.png").stat().st_size > 0

    import rerun as rr

    paths = {ch.entity_path for ch in rr.chunk.RrdReader(str(rrd)).stream()}
    assert {"/study/fragility/runs", "/study/plot", "/study/rows"} <= paths
    again = invoke("sweep", block, "--records", folder, "--scale", "0.5:8:4", "--workers", 0, "--out", out)
    assert again.exit_code == 0 and "(0 runs now, 12 rows already there" in " ".join(again.output.split())
    # records given as files (repeatable) make the same study as their folder
    files = [a for f in sorted(folder.iterdir()) for a in ("--records", f)]
    again = invoke("sweep", block, *files, "--scale", "0.5:8:4", "--workers", 0, "--out", out)
    assert again.exit_code == 0 and "(0 runs now, 12 rows already there" in " ".join(again.output.split())
    twice = invoke("sweep", block, "--records", folder, "--records", folder / "syn0.AT2", "--out", out)
    assert twice.exit_code == 2 and "two records named syn0.AT2" in twice.output


def test_grid_sweep_state_map_and_histories(block, tmp_path):
    out = tmp_path / "grid.parquet"
    args = ["-p", "amp=0.05,0.6", "-p", "friction=0.3,0.8", "--duration", 0.3, "--workers", 0, "-o", out]
    result = invoke("sweep", block, *args, "--histories", tmp_path / "h", "--recording", tmp_path / "grid.rrd")
    assert result.exit_code == 0, result.output
    rows = read_rows(out)
    assert [(r["amp"], r["friction"]) for r in rows] == [(0.05, 0.3), (0.05, 0.8), (0.6, 0.3), (0.6, 0.8)]
    assert rows[0]["state"] == "intact" and rows[0]["time"] == pytest.approx(0.3)
    assert (tmp_path / "grid.png").stat().st_size > 0
    h = np.load(tmp_path / "h" / "amp=0.6_friction=0.3.npz")
    assert float(h["intensity_pga"]) == rows[2]["pga"] and h["time"][-1] == pytest.approx(rows[2]["time"])
    assert len(list((tmp_path / "h").glob("*.npz"))) == 4

    import rerun as rr

    paths = {ch.entity_path for ch in rr.chunk.RrdReader(str(tmp_path / "grid.rrd")).stream()}
    assert {"/study/state_map", "/study/plot", "/study/rows"} <= paths


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["-p", "bogus=1"], "--param bogus: unknown parameter"),
        (["-p", "amp=1:2"], "--param amp=1:2: a range is LO:HI:N"),
        ([], "nothing to sweep"),
        (["-p", "amp=0.1,0.2", "--find", "freq"], "--find freq: give its range too"),
        (["-p", "amp=0.1,0.2", "--outcome", "fall"], "--outcome fall: expected collapse, sliding"),
        (["-p", "amp=0.1,0.2", "--out", "x.txt"], "a study is written as .parquet or .csv"),
        (["-p", "scale=1,2"], "has no record motion"),
        (["-p", "amp=0.1", "--records", "nowhere"], "--records nowhere: no such file or folder"),
        (["-p", "amp=0.1", "--workers", "2", "--scheduler", "tcp://x:1"], "--workers with --scheduler"),
        (["-p", "amp=0.1", "--recording", "x.png"], "--recording x.png: a recording file must end in .rrd"),
    ],
)
def test_sweep_errors_are_one_line(block, args, fragment):
    result = invoke("sweep", block, *args)
    assert result.exit_code == 2, result.output
    lines = [ln for ln in result.output.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and fragment in lines[0], result.output
