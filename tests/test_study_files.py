"""Which files a study may write (masonrycli.study.files): the table resumed only when it is this study's
and grid's, the histories of the runs still to make — with --find, whatever the bisected value."""

from __future__ import annotations

import pytest

from masonrycli.errors import InputError
from masonrycli.study import store
from masonrycli.study.files import check_histories, open_table

POINTS = [{"amp": 0.1}, {"amp": 0.2}]


def _journal(out, *rows):
    journal = store.Journal(out)
    for row in rows:
        journal.append(row)
    journal.close()


def test_table_of_this_study_is_resumed_and_any_other_refused(tmp_path):
    out = tmp_path / "s.csv"
    table, ours = open_table(out, "abc", False, ["amp"], POINTS)
    assert ours == [] and table.path == out and not table.force  # a new table: may not replace a newcomer
    store.write_rows(table, [{"amp": 0.1, "study": "abc"}], ["amp", "study"])
    table, ours = open_table(out, "abc", False, ["amp"], POINTS)
    assert [r["amp"] for r in ours] == [0.1] and table.force  # resumed: rewritten with its rows kept
    for study, points in (("xyz", POINTS), ("abc", [{"amp": 0.3}])):  # another study; a point not in the grid
        with pytest.raises(InputError, match=r"s\.csv: the file exists \(add --force to replace it\)"):
            open_table(out, study, False, ["amp"], points)
        assert open_table(out, study, True, ["amp"], points)[1] == []
    out.write_text("not, a study\n")
    with pytest.raises(InputError, match="the file exists"):  # no row: nothing of this study to resume
        open_table(out, "abc", False, ["amp"], POINTS)
    out.unlink()
    _journal(out, {"amp": 0.2, "study": "xyz"})  # the journal of an interrupted other study
    with pytest.raises(InputError, match=r"journal\.jsonl holds rows of another study or grid \(add --force"):
        open_table(out, "abc", False, ["amp"], POINTS)


def test_a_record_sets_row_is_of_this_study_by_its_own_record_or_the_whole_set(tmp_path):
    # rows written by record: "a:…" (a's fingerprint) or the set's "set" (tables written before) are kept;
    # a row of b whose samples changed ("b:old") is another study's
    out = tmp_path / "s.csv"
    points = [{"record": r, "scale": 1.0} for r in ("a", "b", "c")]
    rows = [{"record": "a", "scale": 1.0, "study": "a:1"}, {"record": "b", "scale": 1.0, "study": "set"}]
    store.write_rows(open_table(out, "set", False, ["record", "scale"], points)[0], rows, ["record", "scale", "study"])
    by_record = {"a": "a:1", "b": "b:1", "c": "c:1"}
    table, ours = open_table(out, "set", False, ["record", "scale"], points, row_study=lambda r: by_record[r["record"]])
    assert [r["record"] for r in ours] == ["a", "b"]
    # a new set (c added): the set's fingerprint changes, the rows of a keep theirs
    _, ours = open_table(out, "set+c", True, ["record", "scale"], points, row_study=lambda r: by_record[r["record"]])
    assert [r["record"] for r in ours] == ["a"]
    by_record["a"] = "a:edited"
    with pytest.raises(InputError, match="the file exists"):
        open_table(out, "set+c", False, ["record", "scale"], points, row_study=lambda r: by_record[r["record"]])


def test_histories_to_write_are_checked_and_find_matches_any_value(tmp_path):
    folder = tmp_path / "h"
    check_histories(folder, POINTS, None, False)  # a folder still to make
    folder.mkdir()
    (folder / "amp=0.1362_freq=2.npz").write_bytes(b"")  # a bisection point's history
    check_histories(folder, [{"amp": 0.1, "freq": 1.0}], "amp", False)
    with pytest.raises(InputError, match=r"--histories .*amp=0\.1362_freq=2\.npz: the file exists"):
        check_histories(folder, [{"amp": 0.1, "freq": 2.0}, {"amp": 0.5, "freq": 2.0}], "amp", False)
    check_histories(folder, [{"amp": 0.1, "freq": 2.0}], "amp", True)
    with pytest.raises(InputError, match="the file exists"):
        check_histories(folder, [{"amp": 0.1362, "freq": 2.0}], None, False)
    (tmp_path / "f").write_text("")
    with pytest.raises(InputError, match="--histories .*: is not a folder"):
        check_histories(tmp_path / "f", POINTS, None, False)


def test_a_history_an_interrupted_run_of_this_study_wrote_is_not_refused(tmp_path):
    # walk-through 2026-11-28: Ctrl-C left the histories of the runs in flight (the workers finish them) without
    # their rows; the same command refused to resume. Only this study's own histories are let through.
    import json

    import numpy as np

    folder = tmp_path / "h"
    folder.mkdir()
    np.savez(folder / "amp=0.1.npz", run=np.array(json.dumps({"study": "abc", "study_table": "/s.csv"})))
    np.savez(folder / "amp=0.2.npz", run=np.array(json.dumps({"study": "xyz", "study_table": "/s.csv"})))
    check_histories(folder, POINTS[:1], None, False, ("abc", "/s.csv"))
    with pytest.raises(InputError, match=r"amp=0\.2\.npz: the file exists \(add --force"):
        check_histories(folder, POINTS, None, False, ("abc", "/s.csv"))
    with pytest.raises(InputError, match=r"amp=0\.1\.npz: the file exists"):  # the same study, another table
        check_histories(folder, POINTS[:1], None, False, ("abc", "/t.csv"))
    with pytest.raises(InputError, match=r"amp=0\.1\.npz: the file exists"):
        check_histories(folder, POINTS[:1], None, False)  # no study named: any file is another's


def test_an_unwritable_journal_names_the_out_option(tmp_path):
    # "error: /proc/s.csv.journal.jsonl: No such file or directory" named no option
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(
        InputError, match=r"^--out .*file/sub/s\.csv: cannot write its journal s\.csv\.journal\.jsonl: "
    ):
        store.Journal(blocker / "sub" / "s.csv")


def test_the_half_written_histories_of_gone_workers_are_removed(tmp_path):
    # walk-through 2026-11-28: Ctrl-C on `masonry sweep wall … --histories hist` left .amp=….npz.<pid>.part files
    # and .part.rows folders of the LocalCluster's workers, which died inside their runs (2 and 4 in two tries)
    import os
    import subprocess
    import sys

    from masonrycli.study.files import remove_abandoned_parts

    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead = f".amp=0.5.npz.{gone.stdout.strip()}.part"
    live = f".amp=0.6.npz.{os.getpid()}.part"  # a run still going: kept
    (tmp_path / dead).write_bytes(b"")
    (tmp_path / (dead + ".rows")).mkdir()
    (tmp_path / (dead + ".rows") / "block_q.raw").write_bytes(b"x")
    (tmp_path / live).write_bytes(b"")
    (tmp_path / "amp=0.4.npz").write_bytes(b"a finished history")
    remove_abandoned_parts(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == [live, "amp=0.4.npz"]
    remove_abandoned_parts(None)
    remove_abandoned_parts(tmp_path / "missing")
