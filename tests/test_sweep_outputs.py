"""The files ``masonry sweep`` writes (masonrycli.study.files, plan, store): nothing when it is refused, an
existing output refused without --force and replaced whole with it, a record never taken for the table
(nor the table for a record), a record edited since its rows were made run again, names kept in the
working folder."""

from __future__ import annotations

from pathlib import Path

import pytest

from masonrycli.errors import InputError
from masonrycli.study.store import read_rows

from cli_helpers import words
from sweep_helpers import BLOCK, invoke, velocity_csv, write_block


@pytest.fixture
def block(tmp_path) -> Path:
    return write_block(tmp_path)


def test_a_scheduler_that_cannot_be_reached_leaves_no_file(block, tmp_path, monkeypatch):
    # The table (header only) was written before the cluster was reached: the corrected command then
    # said "--out s.csv: the file exists". Connecting to a closed port takes Dask's 20 s timeout, so the
    # refusal is simulated here; the real one was checked by hand (tcp://127.0.0.1:18787: the same line).
    from masonrycli.study import runner

    def unreachable(scheduler, workers, runs):
        raise InputError(f"--scheduler {scheduler}: cannot connect (OSError: Timed out)")

    monkeypatch.setattr(runner, "open_cluster", unreachable)
    result = invoke("sweep", block, "-p", "amp=0.1", "--scheduler", "tcp://127.0.0.1:1", "-o", tmp_path / "s.csv")
    assert result.exit_code == 2 and "--scheduler tcp://127.0.0.1:1: cannot connect" in result.output
    assert [p.name for p in tmp_path.iterdir()] == ["block.toml"]


def test_a_study_table_in_its_records_folder_is_not_read_as_a_record(block, tmp_path):
    # `--records recs --out recs/ida.csv`: the first run wrote recs/ida.csv; the same command again (to resume,
    # as the docs say) read the table as a record: "error: recs/ida.csv:2: not a number: "a.csv"", exit 2.
    folder = tmp_path / "recs"
    folder.mkdir()
    velocity_csv(folder / "a.csv"), velocity_csv(folder / "b.csv")
    args = ("sweep", block, "--records", folder, "--workers", 0, "--duration", 0.1, "--no-recording")
    first = invoke(*args, "--out", folder / "ida.csv")
    assert first.exit_code == 0, first.output
    again = invoke(*args, "--out", folder / "ida.csv", "--force")
    assert again.exit_code == 0, again.output
    said = words(again.output)
    assert "2 rows in" in said and "(0 runs now, 2 rows already there, 0 failed)" in said, said
    assert {r["record"] for r in read_rows(folder / "ida.csv")} == {"a.csv", "b.csv"}


def test_a_record_edited_since_the_table_was_written_is_not_taken_as_done(block, tmp_path):
    # A study's fingerprint knew a --records file by its path, scale and sample count: a record whose values
    # were corrected (0.05 -> 0.45 m/s) kept its rows, "0 runs now, 1 row already there", pgv still 0.05 m/s.
    folder = tmp_path / "recs"
    folder.mkdir()
    record = velocity_csv(folder / "a.csv")
    args = ("sweep", block, "--records", folder, "--workers", 0, "--duration", 0.1, "--no-recording", "--out")
    out = tmp_path / "s.csv"
    assert invoke(*args, out).exit_code == 0
    assert read_rows(out)[0]["pgv"] == pytest.approx(0.05)
    record.write_text(record.read_text().replace(",0.05\n", ",0.45\n"))
    forced = invoke(*args, out, "--force")
    assert forced.exit_code == 0 and "(1 run now, 0 rows already there" in words(forced.output)
    assert read_rows(out)[0]["pgv"] == pytest.approx(0.45)


def test_the_default_table_name_stays_in_the_working_folder(tmp_path, monkeypatch):
    # name = "../../evil" in the scenario file: the default --out "study-../../evil.parquet" made a folder
    # "study-.." and wrote evil.parquet and evil.png beside it (a name with more "../" left the folder)
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    (work / "e.toml").write_text('name = "../../evil"\n' + BLOCK)
    result = invoke("sweep", "e.toml", "-p", "amp=0.1", "--duration", 0.01, "--workers", 0, "--no-recording")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in work.iterdir()) == ["e.toml", "study-evil.parquet", "study-evil.png"]
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == [
        "e.toml",
        "study-evil.parquet",
        "study-evil.png",
    ]


def test_a_record_given_as_the_study_table_is_refused_not_replaced(block, tmp_path):
    # `--records rec.csv --out rec.csv --force` replaced the record with the study's table (the record lost).
    record = velocity_csv(tmp_path / "rec.csv")
    kept = record.read_bytes()
    result = invoke("sweep", block, "--records", record, "--workers", 0, "--out", record, "--force", "--no-recording")
    assert result.exit_code == 2
    assert result.output.strip() == f"error: --out {record}: is the record {record} (the table would replace it)"
    assert record.read_bytes() == kept and sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "rec.csv"]


def test_a_scenario_record_file_given_as_the_study_table_is_refused(tmp_path):
    record = velocity_csv(tmp_path / "quake.csv")
    kept = record.read_bytes()
    scenario = tmp_path / "quake.toml"
    scenario.write_text(
        BLOCK.replace('{ kind = "sine", amplitude = 0.1, frequency = 2.0 }', '{ kind = "record", file = "quake.csv" }')
    )
    result = invoke(
        "sweep", scenario, "-p", "scale=0.5,1", "--workers", 0, "--out", record, "--force", "--no-recording"
    )
    assert result.exit_code == 2
    assert result.output.strip() == f"error: --out {record}: is the record {record} (the table would replace it)"
    assert record.read_bytes() == kept


def _files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def test_a_histories_folder_that_cannot_be_made_leaves_no_file(block, tmp_path):
    # it said "error: /proc/x: No such file or directory" (no option) after writing a header-only table,
    # which the corrected command then refused as existing
    # Not a skip (the project runs on Linux): without /proc this test would prove nothing, so it fails.
    assert Path("/proc/self").is_dir(), "needs Linux's /proc, where no folder can be made"
    out, histories = tmp_path / "s.csv", Path("/proc/masonry-histories")
    result = invoke("sweep", block, "-p", "amp=0.1", "--workers", 0, "-o", out, "--histories", histories)
    said = words(result.output)
    # refused before the folder is made: /proc is no disk (root may write there, yet no file can be made)
    assert result.exit_code == 2 and said.startswith(f"error: --histories {histories}"), said
    assert "cannot make the folder (" in said or ": cannot write in /proc (" in said, said
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml"]


def test_existing_outputs_are_refused_without_force_and_replaced_with_it(block, tmp_path):
    out, h = tmp_path / "s.csv", tmp_path / "h"
    grid = ["-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", out, "--histories", h]
    assert invoke("sweep", block, *grid).exit_code == 0
    before, png = _files(tmp_path), (tmp_path / "s.png").stat().st_ino
    assert {"s.csv", "s.png", "s.rrd", "amp=0.05.npz", "amp=0.1.npz"} <= set(before)
    other = ["-p", "amp=0.05,0.1", "--duration", 0.04, "--workers", 0, "-o", out]  # another study (duration)
    cases = [
        (other + ["--no-recording", "--plot", tmp_path / "o.png"], f"--out {out}: the file exists"),
        # the same study: resumable, but its plot exists (it said "--plot s.png", an option not given)
        (grid, f"--out's plot {tmp_path / 's.png'}: the file exists"),
        (grid + ["--plot", tmp_path / "n.png", "--recording", tmp_path / "s.rrd"], "--recording"),
        (grid + ["--plot", tmp_path / "n.png"], f"--out's recording {tmp_path / 's.rrd'}: the file exists"),
        (grid[:-1] + [h] + ["-p", "friction=0.8", "--no-recording", "--plot", tmp_path / "n.png"], "--out"),
    ]
    for args, fragment in cases:
        result = invoke("sweep", block, *args)
        assert result.exit_code == 2, result.output
        lines = result.output.strip().splitlines()
        assert len(lines) == 1 and fragment in lines[0] and "(add --force to replace it)" in lines[0], lines
        assert _files(tmp_path) == before  # untouched, no temporary file left
    # the histories of runs still to make: one of them exists
    more = ["-p", "amp=0.1,0.2", "--duration", 0.02, "--workers", 0, "-o", tmp_path / "t.csv", "--histories", h]
    result = invoke("sweep", block, *more)
    assert result.exit_code == 2 and f"--histories {h / 'amp=0.1.npz'}: the file exists" in result.output
    assert _files(tmp_path) == before
    # --force replaces: the other study's rows go, the plot and the recording are new; it says whose rows
    # went (it replaced another study's table without a word of whose it was)
    study = read_rows(out)[0]["study"]
    result = invoke("sweep", block, *other, "--force")
    assert result.exit_code == 0, result.output
    assert f"--out {out}: --force replaces 2 rows over amp of study {study[:12]}" in words(result.output)
    assert [r["time"] for r in read_rows(out)] == [pytest.approx(0.04)] * 2
    after = _files(tmp_path)
    assert (tmp_path / "s.png").stat().st_ino != png and after["s.rrd"] != before["s.rrd"]  # a new file each
    assert not [name for name in after if name.endswith(".part") or "journal" in name]


def test_a_table_in_a_folder_that_is_a_file_names_out(block, tmp_path):
    # it said "--out's plot t.sh/s.png: t.sh is not a folder": an option not given, for the table's own folder
    (tmp_path / "notes.txt").write_text("x")
    out = tmp_path / "notes.txt" / "s.csv"
    result = invoke("sweep", block, "-p", "amp=0.1", "--workers", 0, "--out", out)
    assert result.exit_code == 2
    assert result.output.strip() == f"error: --out {out}: {tmp_path / 'notes.txt'} is not a folder"


@pytest.mark.parametrize("content", [b"garbage", b"PAR1 not a table"], ids=["short", "magic"])
def test_an_unreadable_table_is_refused_naming_out_and_force_replaces_it(block, tmp_path, content):
    # walk-through 2026-11-28: "error: s.parquet: cannot read the existing study (ArrowInvalid: …)" named no
    # option and no way out, though --force replaces it as it replaces any existing output
    out = tmp_path / "s.parquet"
    out.write_bytes(content)
    grid = ["-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", out]
    result = invoke("sweep", block, *grid)
    assert result.exit_code == 2, result.output
    line = words(result.output)
    assert line.startswith(f"error: --out {out}: cannot read the existing study (ArrowInvalid: "), line
    assert line.endswith("(add --force to replace it)") and out.read_bytes() == content
    assert invoke("sweep", block, *grid, "--force").exit_code == 0
    assert len(read_rows(out)) == 2


def test_each_run_of_a_fine_search_keeps_its_own_history(block, tmp_path):
    # Histories were named with 6 significant digits: a search with --rtol 1e-6 (23 runs) left 22 files, a
    # later run's history written over an earlier one of another amplitude under a name that was neither's.
    import json

    import numpy as np

    from masonrycli.study.task import history_name

    assert history_name({"amp": 0.5, "freq": 2.0}) == "amp=0.5_freq=2.npz"  # the documented names stay
    assert history_name({"amp": float(np.linspace(0.1, 1.0, 10)[2])}) == "amp=0.3.npz"  # not 0.30000000000000004
    h = tmp_path / "h"
    grid = ["-p", "amp=0.1:0.1000001:3", "--duration", 0.02, "--workers", 0, "--no-recording"]
    result = invoke("sweep", block, *grid, "-o", tmp_path / "s.csv", "--histories", h)
    assert result.exit_code == 0, result.output
    stored = sorted(json.loads(str(np.load(p)["run"]))["study_point"]["amp"] for p in h.iterdir())
    assert len(stored) == 3 and stored == sorted({r["amp"] for r in read_rows(tmp_path / "s.csv")}), stored


def test_records_in_subfolders_of_a_record_folder_are_named(block, tmp_path):
    # A set kept by station (recs/ELC/q.AT2 beside recs/top.csv) ran top.csv alone without a word; a folder
    # holding records in subfolders only said "no .AT2 or .csv record in it".
    recs = tmp_path / "recs"
    (recs / "ELC").mkdir(parents=True)
    velocity_csv(recs / "ELC" / "q.csv")
    alone = invoke("sweep", block, "--records", recs, "--workers", 0, "-o", tmp_path / "s.csv")
    said = f"--records {recs}: its subfolders are not read; {recs / 'ELC'} holds records (give them too)"
    assert alone.exit_code == 2 and words(alone.output) == f"error: {said}", alone.output
    velocity_csv(recs / "top.csv")
    args = ["--duration", 0.02, "--workers", 0, "--no-recording", "-o", tmp_path / "s.csv"]
    mixed = invoke("sweep", block, "--records", recs, *args)
    assert mixed.exit_code == 0 and f"warning: {said}" in words(mixed.output), mixed.output
    (recs / "STN").mkdir()
    velocity_csv(recs / "STN" / "q.csv")  # two of them: "hold"
    both = invoke("sweep", block, "--records", recs, *args, "--force")
    assert f"{recs / 'ELC'}, {recs / 'STN'} hold records" in words(both.output), both.output
    assert [r["record"] for r in read_rows(tmp_path / "s.csv")] == ["top.csv"]


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (("-p", "duration=0.02,0.04", "--duration", "2"), "--duration 2 and --param duration"),
        (("-p", "dt=0.001,0.002", "--dt", "5e-4", "--duration", "0.02"), "--dt 5e-4 and --param dt"),
    ],
)
def test_a_run_setting_given_as_option_and_axis_is_refused(block, tmp_path, args, said):
    # '--duration 2 --param duration=0.02,0.04' ran 0.02 and 0.04 s, the 2 s said nowhere
    result = invoke("sweep", block, *args, "--workers", 0, "-o", tmp_path / "s.csv")
    name = said.split()[-1]
    line = f"error: {said}: the axis sets every run's {name}; give one"
    assert result.exit_code == 2 and words(result.output) == line, result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml"]


def test_the_summary_says_where_the_histories_are(block, tmp_path):
    # it named the table, the plot and the recording, not the folder of the runs' histories
    h = tmp_path / "h"
    grid = ["-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "--no-recording", "-o", tmp_path / "s.csv"]
    result = invoke("sweep", block, *grid, "--histories", h)
    assert result.exit_code == 0, result.output
    assert f"histories: {h} (2 histories, one a run; as CSV: masonry export {h} --top)" in words(result.output)
    assert sorted(p.name for p in h.iterdir()) == ["amp=0.05.npz", "amp=0.1.npz"]


def test_the_summary_s_paths_and_commands_are_never_broken_over_lines(block, tmp_path):
    # off a terminal (a pipe, a log, a notebook's subprocess) the console is 80 columns wide: the histories line
    # of a long folder was wrapped inside its path and its 'masonry export … --top' command
    deep = tmp_path / "course-2026" / "assignment-3-friction-and-frequency" / "histories-of-every-run"
    out = deep.parent / "study-of-the-wall-at-several-frequencies.csv"
    grid = ["-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "--no-recording", "-o", out]
    result = invoke("sweep", block, *grid, "--histories", deep)
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert f"histories: {deep} (2 histories, one a run; as CSV: masonry export {deep} --top)" in lines
    assert f"plot: {out.with_suffix('.png')}" in lines
    assert any(line.startswith(f"2 rows in {out} (2 runs now, 0 rows already there, 0 failed) in ") for line in lines)
