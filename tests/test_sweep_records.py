"""``masonry sweep --records`` over a set holding a CSV of one value per line, with ``--record-dt``: the
records reach the worker processes of a LocalCluster (pickled, their samples read-only arrays) and the
one-column file's rows are those of the same samples given with a time column; the time step is part of
the study (another one is another study)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from masonrycli.cli.app import app
from masonrycli.study.store import read_rows
from masonrycli.study.task import RESULT_COLUMNS

from cli_helpers import words
from synthetic_records import band_limited

pytestmark = pytest.mark.slow  # a LocalCluster of a worker process
BLOCK = Path(__file__).parent / "data" / "block_on_ground.toml"  # a sine-shaken block, 1 s


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args], terminal_width=200)


def test_a_set_with_a_one_column_file_sweeps_on_worker_processes(tmp_path):
    folder = tmp_path / "records"
    folder.mkdir()
    v = band_limited(0.2, 0.01, [3.0, 5.0], [0.004, 0.002], seed=4)[2].tolist()
    (folder / "one.csv").write_text("velocity\n" + "".join(f"{x!r}\n" for x in v))
    (folder / "two.csv").write_text("time,velocity\n" + "".join(f"{i * 0.01!r},{x!r}\n" for i, x in enumerate(v)))
    out = tmp_path / "s.csv"
    args = ["sweep", BLOCK, "--records", folder, "--scale", "1,10", "--duration", 0.2, "--out", out, "--no-recording"]
    result = invoke(*args, "--record-dt", 0.01, "--workers", 1)
    assert result.exit_code == 0, result.output
    rows = {(r["record"], r["scale"]): r for r in read_rows(out)}
    assert len(rows) == 4 and {r["status"] for r in rows.values()} == {"completed"}
    same = [c for c in RESULT_COLUMNS if c not in ("wall_time", "cpu_time")]
    for scale in (1.0, 10.0):
        one, two = rows["one.csv", scale], rows["two.csv", scale]
        assert [repr(one[c]) for c in same] == [repr(two[c]) for c in same], scale  # bit for bit, NaN as NaN
    assert rows["one.csv", 10.0]["pgv"] == pytest.approx(10 * max(abs(x) for x in v))
    # the same time step makes the same study (its rows reused); another is another record: its rows run again,
    # those of the file with its own times are kept (a row is of its own record's study)
    again = invoke(*args, "--record-dt", 0.01, "--workers", 0, "--force")
    assert again.exit_code == 0 and "(0 runs now, 4 rows already there, 0 failed)" in words(again.output), again.output
    again = invoke(*args, "--record-dt", 0.02, "--workers", 0, "--force")
    assert again.exit_code == 0 and "(2 runs now, 2 rows already there, 0 failed)" in words(again.output), again.output
    assert "--force replaces 2 rows over record, scale" in words(again.output)


def test_a_set_of_csv_accelerograms_is_swept(tmp_path):
    """CSV accelerograms in m/s² could not be swept: --records read every CSV as velocity and refused their
    "acc (m/s2)" header. Read as their header says, each row's PGA is that of its own samples."""
    folder = tmp_path / "records"
    folder.mkdir()
    t, _, _, a = band_limited(0.2, 0.01, [3.0, 5.0], [0.004, 0.002], seed=4)
    (folder / "acc.csv").write_text(
        "time (s),acc (m/s2)\n" + "".join(f"{x!r},{y!r}\n" for x, y in zip(t.tolist(), a.tolist()))
    )
    out = tmp_path / "s.csv"
    args = ["sweep", BLOCK, "--records", folder, "--scale", "1,2", "--duration", 0.2, "--out", out, "--no-recording"]
    result = invoke(*args, "--workers", 0)
    assert result.exit_code == 0, result.output
    rows = {r["scale"]: r for r in read_rows(out)}
    assert {r["status"] for r in rows.values()} == {"completed"}
    assert rows[2.0]["pga"] == pytest.approx(2 * rows[1.0]["pga"], rel=1e-9)
    assert rows[1.0]["pga"] == pytest.approx(np.abs(a).max(), rel=0.05)  # the record's samples, baseline-corrected


def test_a_csv_whose_header_gives_g_is_swept_in_g(tmp_path):
    # a set has no scale per file (--scale is the axis): 'acc (g)' was refused, "a scale of 9.81 converts them",
    # which the set could not give. Now it reads as an .AT2 file's g: the rows of the same samples in m/s².
    t = (np.arange(41) * 0.005).tolist()
    a_g = (0.3 * np.sin(2 * np.pi * 5 * np.array(t))).tolist()
    folder = tmp_path / "records"
    folder.mkdir()
    (folder / "in_g.csv").write_text("time (s),acc (g)\n" + "".join(f"{x!r},{y!r}\n" for x, y in zip(t, a_g)))
    si = "time (s),acc (m/s2)\n" + "".join(f"{x!r},{y * 9.80665!r}\n" for x, y in zip(t, a_g))
    (folder / "in_si.csv").write_text(si)
    (folder / "in_gal.csv").write_text(
        "time (s),acc (gal)\n" + "".join(f"{x!r},{y * 980.665!r}\n" for x, y in zip(t, a_g))
    )
    out = tmp_path / "s.csv"
    args = ["sweep", BLOCK, "--records", folder, "--duration", 0.2, "--out", out, "--no-recording", "--workers", 0]
    result = invoke(*args, "--scale", "1,2")
    assert result.exit_code == 0, result.output
    rows = {(r["record"], r["scale"]): r for r in read_rows(out)}
    same = [c for c in RESULT_COLUMNS if c not in ("wall_time", "cpu_time")]
    for scale in (1.0, 2.0):
        g, ref = rows["in_g.csv", scale], rows["in_si.csv", scale]
        assert [repr(g[c]) for c in same] == [repr(ref[c]) for c in same], scale
        assert rows["in_gal.csv", scale]["pga"] == pytest.approx(ref["pga"], rel=1e-12)
    # the old way to read such a file (--record refuses it now), a scale of 9.81, would convert it twice: said
    result = invoke(*args, "--scale", "1,9.81", "--force")
    assert "--records: in_g.csv is read in g, as its header says, and converted to SI already; --scale 9.81" in words(
        result.output
    )
    # so is a plain table named .asc (read as a CSV is): it was left out of the warning (.csv alone)
    (folder / "in_g.csv").rename(folder / "in_g.asc")
    result = invoke(*args, "--scale", "1,9.81", "--force")
    assert "--records: in_g.asc is read in g, as its header says, and converted to SI already" in words(result.output)


def test_a_record_added_to_the_set_keeps_the_finished_rows_of_the_others(tmp_path):
    # a fragility study grows as records are downloaded: adding one to the folder made the whole study
    # "another study" (every record's samples in one fingerprint), each finished row refused or run again
    folder = tmp_path / "records"
    folder.mkdir()
    t = [i * 0.01 for i in range(21)]
    for k, name in enumerate(("a.csv", "b.csv", "c.csv")):
        v = band_limited(0.2, 0.01, [3.0 + k], [0.004], seed=k)[2].tolist()
        text = "time,velocity\n" + "".join(f"{x!r},{y!r}\n" for x, y in zip(t, v))
        (tmp_path / name).write_text(text)
    for name in ("a.csv", "b.csv"):
        (folder / name).write_text((tmp_path / name).read_text())
    out = tmp_path / "s.csv"
    args = ["sweep", BLOCK, "--records", folder, "--scale", "1,2", "--duration", 0.2, "--out", out, "--workers", 0]
    result = invoke(*args, "--no-recording")
    assert result.exit_code == 0 and "(4 runs now, 0 rows already there" in words(result.output), result.output
    (folder / "c.csv").write_text((tmp_path / "c.csv").read_text())
    result = invoke(*args, "--no-recording", "--force")  # --force: the plot exists
    assert result.exit_code == 0 and "(2 runs now, 4 rows already there" in words(result.output), result.output
    assert "--force replaces" not in result.output
    # a record edited since: its rows are another study's, run again; the others kept
    (folder / "a.csv").write_text((tmp_path / "a.csv").read_text().replace("0.0,", "0.0,0.001\n#", 1))
    result = invoke(*args, "--no-recording", "--force")
    assert result.exit_code == 0 and "(2 runs now, 4 rows already there" in words(result.output), result.output
    assert "--force replaces 2 rows over record, scale" in words(result.output)
