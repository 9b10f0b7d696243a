"""``masonry sweep --records`` as a user drives it (in process, --workers 0): the runs last the longest record on
a built-in and a shorter run is warned, a set's unread files are named, and the fragility line says which side
a study without a fit is on and gives one curve per friction. Over a LocalCluster: test_sweep_records.py."""

from __future__ import annotations

from pathlib import Path

import pytest

from masonrycli.records.read import G_STANDARD
from masonrycli.study.store import read_rows

from cli_helpers import words
from sweep_helpers import BLOCK, invoke, write_block
from synthetic_records import band_limited, write_at2


@pytest.fixture
def block(tmp_path) -> Path:
    return write_block(tmp_path)


def test_a_record_study_without_a_fit_says_which_side_and_what_to_change(tmp_path):
    # 'fragility: no fit (every run collapsed, or none did)' left the user to count which, and which way to go
    folder = tmp_path / "records"
    folder.mkdir()
    t, u, v, a = band_limited(0.2, 0.01, [2.0], [0.001], seed=0)
    write_at2(folder / "weak.AT2", a / G_STANDARD, 0.01)
    args = ["sweep", "wall", "--records", folder, "--workers", 0, "--no-recording", "--param", "blocks=12"]
    result = invoke(*args, "--scale", "0.5,1", "--out", tmp_path / "a.csv")
    assert result.exit_code == 0, result.output
    said = words(result.output)
    assert "fragility: no fit — none of the 2 runs collapsed (larger --scale values reach it)" in said, said
    result = invoke(*args, "--out", tmp_path / "b.csv")
    assert "fragility: no fit (1 run; a fit needs at least 2)" in words(result.output), result.output


def test_records_run_whole_on_a_built_in_and_a_shorter_run_is_warned(block, tmp_path):
    # the built-in wall's 1 s cut every record to its first second: without --duration the runs last the
    # longest record; a scenario file keeps its [run] duration, and a record longer than the runs is named
    folder = tmp_path / "records"
    folder.mkdir()
    t, u, v, a = band_limited(1.5, 0.01, [1.0, 2.5], [0.003, 0.001], seed=0)
    write_at2(folder / "long.AT2", a / G_STANDARD, 0.01)
    (folder / "short.csv").write_text("time,velocity\n0,0\n0.2,0.01\n0.4,0\n")
    out = tmp_path / "whole.csv"
    result = invoke("sweep", "wall", "--records", folder, "--workers", 0, "--out", out, "--no-recording")
    assert result.exit_code == 0, result.output
    assert {(r["record"], r["steps"]) for r in read_rows(out)} == {("long.AT2", 1500), ("short.csv", 1500)}
    assert "warning" not in result.output
    result = invoke("sweep", block, "--records", folder, "--workers", 0, "--out", tmp_path / "b.csv", "--no-recording")
    assert result.exit_code == 0, result.output
    assert {r["steps"] for r in read_rows(tmp_path / "b.csv")} == {500}  # the file's 1 s at dt = 2e-3
    assert (
        "warning: the runs' 1 s are shorter than 1 of 2 records (longest 1.5 s, long.AT2): their shaking after "
        "t = 1 s is not applied" in words(result.output)
    )
    # bad input stays one line: the warning comes once the request is checked, not beside its error
    fixed = tmp_path / "fixed.toml"
    fixed.write_text(BLOCK.replace('motion = { kind = "sine", amplitude = 0.1, frequency = 2.0 }', ""))
    result = invoke("sweep", fixed, "--records", folder, "--workers", 0, "--out", tmp_path / "f.csv")
    assert result.exit_code == 2 and result.output.strip().splitlines() == [
        "error: --records: fixed has no shaking support (give one a sine or record motion)"
    ]
    # a geometry file of several supports swept as it is, over records: the scenario file that says which one
    # shakes, as run --record says (one of a single support shakes it: test_cli_record)
    geo = tmp_path / "arch.geojson"
    assert invoke("build", "arch", "--out", geo).exit_code == 0
    result = invoke("sweep", geo, "--records", folder, "--workers", 0, "--out", tmp_path / "g.csv")
    assert result.exit_code == 2 and words(result.output) == (
        "error: --records: arch.geojson holds no motion and 2 supports (left-foundation, right-foundation); say "
        'which the record shakes: mark them "support_role": "driven" in the file (WKT: support NAME driven: …), or '
        'write a scenario file [structure] file = "arch.geojson" with a [[support]] name = "left-foundation" and '
        'motion = { kind = "record", file = ... } (masonry docs scenario-format)'
    )


def test_a_record_study_over_friction_says_one_fragility_per_friction(block, tmp_path):
    # 'masonry sweep rubble.toml --records recs --scale … --param friction=0.5,0.7' fitted one curve over the
    # runs of both frictions, and said one line: the fragility of neither wall
    folder = tmp_path / "records"
    folder.mkdir()
    for seed in range(2):
        a = band_limited(1.0, 0.01, [1.0 + 0.4 * seed, 2.5], [0.03, 0.01], seed=seed)[3]
        write_at2(folder / f"syn{seed}.AT2", a / G_STANDARD, 0.01)
    out = tmp_path / "ida.csv"
    args = ["sweep", block, "--records", folder, "--scale", "0.5:8:3", "--param", "friction=0.3,0.9"]
    result = invoke(*args, "--workers", 0, "--out", out, "--no-recording")
    assert result.exit_code == 0, result.output
    said = words(result.output)
    assert said.count("fragility") == said.count(": fragility") == 2, said  # one line a friction, none pooled
    rows = read_rows(out)
    for friction in (0.3, 0.9):  # each line counts its own runs
        own = [r for r in rows if r["friction"] == friction]
        fell = sum(r["state"] == "collapsed" for r in own)
        line = said.split(f"friction = {friction:g}: fragility")[1].split("friction =")[0]
        assert len(own) == 6 and (fell in (0, 6) or f"({fell} of 6 runs collapsed" in line), line


def test_a_records_folder_names_the_files_it_does_not_read(block, tmp_path):
    # a COSMOS file (.V2) and a one-column .txt accelerogram beside the set's .AT2 were left out without a word
    folder = tmp_path / "records"
    folder.mkdir()
    a = band_limited(0.3, 0.01, [2.0], [0.01], seed=1)[3]
    write_at2(folder / "syn.AT2", a / G_STANDARD, 0.01)
    (folder / "CE13122.V2").write_text("Corrected accelerogram\n")
    (folder / "quake.txt").write_text("0.1\n0.2\n")
    for own in ("syn.AT2.vt2", "notes.md", ".hidden", "old.png"):  # companions, notes, masonry's files: no word
        (folder / own).write_text("x")
    out = tmp_path / "s.csv"
    result = invoke("sweep", block, "--records", folder, "--workers", 0, "--out", out, "--no-recording")
    assert result.exit_code == 0, result.output
    assert (
        f"warning: --records {folder}: 2 files not read as records (CE13122.V2, quake.txt): a set reads "
        "PEER .AT2, ESM .ASC, K-NET (.NS, .EW, .UD) and .csv files" in words(result.output)
    )
    assert [r["record"] for r in read_rows(out)] == ["syn.AT2"]
