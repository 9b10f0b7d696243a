"""``masonry sweep`` stopped by Ctrl-C or SIGTERM: every finished row kept and the same command resuming,
no partial file left, the line saying what was not written; a second signal on the way out ignored."""

from __future__ import annotations

from pathlib import Path

import pytest

from masonrycli.study.store import read_rows

from cli_helpers import words
from sweep_helpers import invoke, write_block


@pytest.fixture
def block(tmp_path) -> Path:
    return write_block(tmp_path)


def test_ctrl_c_while_the_scheduler_is_reached_says_nothing_was_written(block, tmp_path, monkeypatch):
    # Ctrl-C during the (up to 30 s) wait for a --scheduler said "interrupted: every finished row is in s.csv;
    # run the same command again to resume", and there was no s.csv.
    from masonrycli.study import runner

    def interrupted(scheduler, workers, runs):
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "open_cluster", interrupted)
    result = invoke("sweep", block, "-p", "amp=0.1", "--scheduler", "tcp://127.0.0.1:1", "-o", tmp_path / "s.csv")
    said = words(result.output)
    assert result.exit_code == 130 and "interrupted: stopped before any row was finished; nothing was written" in said
    assert [p.name for p in tmp_path.iterdir()] == ["block.toml"]


def test_ctrl_c_leaves_no_partial_file_and_the_same_command_resumes(block, tmp_path, monkeypatch):
    from masonrycli.outputs.history import HistoryFile

    out, h = tmp_path / "s.parquet", tmp_path / "h"
    args = ["-p", "amp=0.05,0.1,0.2", "--duration", 0.02, "--workers", 0, "-o", out, "--histories", h]
    frame = HistoryFile.on_frame
    calls = []

    def interrupted_third_run(self, f):  # Ctrl-C in the middle of the third run, its history half written
        calls.append(int(f.step))
        if calls.count(0) == 3 and int(f.step) > 0:
            raise KeyboardInterrupt
        frame(self, f)

    monkeypatch.setattr(HistoryFile, "on_frame", interrupted_third_run)
    result = invoke("sweep", block, *args)
    assert result.exit_code == 130 and "run the same command again to resume" in result.output
    assert sorted(p.name for p in h.iterdir()) == ["amp=0.05.npz", "amp=0.1.npz"]  # no .part, no .rows
    assert [r["amp"] for r in read_rows(out)] == [0.05, 0.1]
    table = out.read_bytes()

    import pyarrow.parquet as pq

    def cut_short(table, where):  # Ctrl-C while the table is being written: half a file on disk
        Path(where).write_bytes(b"PAR1 half")
        raise KeyboardInterrupt

    monkeypatch.setattr(HistoryFile, "on_frame", frame)
    monkeypatch.setattr(pq, "write_table", cut_short)
    result = invoke("sweep", block, *args)
    assert result.exit_code == 130
    assert out.read_bytes() == table and not [p for p in tmp_path.iterdir() if p.name.endswith(".part")]
    assert len(read_rows(out)) == 3  # the third row is in the journal
    monkeypatch.undo()
    result = invoke("sweep", block, *args)
    assert result.exit_code == 0 and "(0 runs now, 3 rows already there" in words(result.output)
    assert [r["amp"] for r in read_rows(out)] == [0.05, 0.1, 0.2]


def test_a_signal_while_the_pictures_are_written_says_what_is_missing(block, tmp_path, monkeypatch):
    # The study is done, the plot and recording are being written. SIGTERM there killed the command
    # outright (exit -15, a hidden .s.png.<pid>.part beside the table); Ctrl-C said "stopped before any
    # output was written" with the whole table written.
    import os
    import signal

    import masonrycli.recording.study as recording_study
    import masonrycli.study.plots as plots

    out = tmp_path / "s.csv"
    args = ["sweep", block, "-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", out]
    drawn = plots.state_map

    def ctrl_c_in_the_plot(rows, x, y, path, title, by=()):
        Path(path).write_bytes(b"half a PNG")
        raise KeyboardInterrupt

    monkeypatch.setattr(plots, "state_map", ctrl_c_in_the_plot)
    result = invoke(*args)
    said = words(result.output)
    assert result.exit_code == 130, result.output
    assert f"interrupted: every row is in {out}, but not written: {tmp_path / 's.png'}, {tmp_path / 's.rrd'}" in said
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "s.csv"]  # no .part left
    monkeypatch.setattr(plots, "state_map", drawn)

    def sigterm_in_the_recording(*args):
        os.kill(os.getpid(), signal.SIGTERM)  # the command's handler turns it into Ctrl-C's way out
        raise AssertionError("not stopped")

    monkeypatch.setattr(recording_study, "record_study", sigterm_in_the_recording)
    result = invoke(*args)
    said = words(result.output)
    assert result.exit_code == 143, result.output
    assert f"interrupted (SIGTERM): every row is in {out}, but not written: {tmp_path / 's.rrd'}; " in said
    assert "run the same command with --force (no run is made again)" in said  # the plot is there now
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "s.csv", "s.png"]
    monkeypatch.undo()
    result = invoke(*args, "--force")
    assert result.exit_code == 0 and "(0 runs now, 2 rows already there" in words(result.output)
    assert (tmp_path / "s.rrd").stat().st_size > 0


def test_a_second_ctrl_c_while_the_table_is_written_is_ignored(block, tmp_path, monkeypatch, capfd):
    # A second Ctrl-C during the shutdown cut the table being written (only the journal left, under
    # "every finished row is in s.parquet"). Now only the first signal stops; a repeat is acknowledged.
    import os
    import signal
    import time

    from masonrycli.study import runner, store

    out = tmp_path / "s.parquet"
    ran, written = runner.run_task, store.write_rows

    def ctrl_c_in_the_second_run(base, params, *args):
        if params["amp"] == 0.1:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5)  # the handler raises here
            raise AssertionError("not stopped")
        return ran(base, params, *args)

    def ctrl_c_again_while_written(*args):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.2)  # the handler runs here (it raised KeyboardInterrupt: no table)
        return written(*args)

    monkeypatch.setattr(runner, "run_task", ctrl_c_in_the_second_run)
    monkeypatch.setattr(store, "write_rows", ctrl_c_again_while_written)
    result = invoke("sweep", block, "-p", "amp=0.05,0.1,0.2", "--duration", 0.02, "--workers", 0, "-o", out)
    assert result.exit_code == 130, result.output
    assert f"interrupted: every finished row is in {out}; run the same command again" in words(result.output)
    assert [r["amp"] for r in read_rows(out)] == [0.05]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "s.parquet"]  # the journal went with it
    assert "Ctrl-C: already stopping — finishing the output files" in capfd.readouterr().err


@pytest.mark.slow
def test_a_second_ctrl_c_on_the_way_out_ends_like_the_first(block, tmp_path):
    # A real process, two real Ctrl-C: the first mid-study, the second as the "interrupted" line comes out
    # (Python puts its handlers back to the default when it exits: that one killed the process, exit -2).
    import os
    import signal
    import subprocess
    import sys
    import time

    root = Path(__file__).resolve().parent.parent
    env = os.environ | {"RERUN_ANALYTICS": "0", "PYTHONUNBUFFERED": "1", "PYTHONPATH": str(root)}
    out = tmp_path / "s.csv"
    journal = tmp_path / "s.csv.journal.jsonl"
    sweep = [sys.executable, "-m", "masonrycli", "sweep", "wall", "--param", "blocks=12", "--duration", "5"]
    sweep += ["--param", "amp=0.1:0.25:6", "--workers", "0", "--out", out]
    proc = subprocess.Popen(
        sweep, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env, cwd=tmp_path, text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # as in a terminal
    )  # fmt: skip
    try:
        end = time.monotonic() + 240
        while not (journal.exists() and journal.read_text().endswith("}\n")):  # a finished row
            assert proc.poll() is None and time.monotonic() < end, proc.stdout.read()
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        lines = []
        for line in proc.stdout:
            lines.append(line)
            if line.startswith("interrupted"):
                proc.send_signal(signal.SIGINT)
                break
        lines += proc.stdout.readlines()
        assert proc.wait(timeout=120) == 130, lines
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    said = [ln for ln in lines if ln.strip() and not ln.startswith("Ctrl-C: already stopping")]  # the 2nd's
    assert said[-1].startswith("interrupted: every finished row is in"), lines
    assert not any("Traceback" in ln or "KeyboardInterrupt" in ln for ln in lines), lines
    assert 1 <= len(read_rows(out)) < 6 and not journal.exists()


def test_a_signal_just_after_the_plot_is_renamed_does_not_call_it_missing(block, tmp_path, monkeypatch):
    # A signal between the plot's rename and the command's record of it said "not written: s.png, s.rrd"
    # with s.png in place. The rename and the record are one step for signals now.
    import os
    import signal
    import time

    from masonrycli.outputs.files import OutputFile

    out = tmp_path / "s.csv"
    commit = OutputFile.commit

    def ctrl_c_right_after_the_rename(self):
        where = commit(self)
        if where.suffix == ".png":
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.2)  # the handler runs here (it raised: the plot was not recorded as written)
        return where

    monkeypatch.setattr(OutputFile, "commit", ctrl_c_right_after_the_rename)
    result = invoke("sweep", block, "-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", out)
    said = words(result.output)
    assert result.exit_code == 130, result.output
    assert f"interrupted: every row is in {out}, but not written: {tmp_path / 's.rrd'}; " in said
    assert "run the same command with --force (no run is made again)" in said
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "s.csv", "s.png"]


def test_a_signal_held_while_the_plot_s_rename_fails_reports_the_error(block, tmp_path, monkeypatch):
    # A Ctrl-C held around the plot's rename, and the rename then fails: the error is what the user needs
    # (the plot is missing because of it), in one line with its exit code, as without the signal — not an
    # "interrupted" line, and no traceback.
    import errno
    import os
    import signal
    import time

    from masonrycli.outputs.files import OutputFile

    out = tmp_path / "s.csv"
    commit = OutputFile.commit

    def ctrl_c_then_a_failed_rename(self):
        if self.path.suffix != ".png":
            return commit(self)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.2)  # the handler runs here and holds the signal
        raise OSError(errno.EACCES, "Permission denied", str(self.path))

    monkeypatch.setattr(OutputFile, "commit", ctrl_c_then_a_failed_rename)
    result = invoke("sweep", block, "-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", out)
    said = words(result.output)
    assert result.exit_code == 4, result.output  # an output failed (0c388ba: exit 4 and the output named)
    assert f"error: cannot write --out's plot {tmp_path / 's.png'}: Permission denied" in said
    assert "interrupted" not in said and "Traceback" not in said
    assert len(read_rows(out)) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "s.csv"]  # no .s.png.<pid>.part


def test_a_ctrl_c_that_code_turns_into_an_error_still_stops_the_study(block, tmp_path, monkeypatch):
    # numpy's structured comparison (np.unique(..., axis=0) in a block's polygon check) replaced the handler's
    # KeyboardInterrupt with "TypeError: Cannot compare structured arrays": a traceback, exit 1 (0.7 s in).
    import os
    import signal
    import time

    from masonrycli.study import study

    def ctrl_c_replaced_by_an_error(*args):
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5)  # the handler raises here
        except KeyboardInterrupt:
            raise TypeError("Cannot compare structured arrays unless they have a common dtype.") from None
        raise AssertionError("not stopped")

    monkeypatch.setattr(study, "prepare", ctrl_c_replaced_by_an_error)
    out = tmp_path / "s.csv"
    result = invoke("sweep", block, "-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", out)
    assert result.exit_code == 130, result.output
    assert words(result.output).endswith("interrupted: stopped before any row was finished; nothing was written")
    assert "Traceback" not in result.output and "TypeError" not in result.output


def test_an_error_without_a_signal_is_not_taken_for_one(block, tmp_path, monkeypatch):
    from masonrycli.study import study

    def broken(*args):
        raise TypeError("a bug")

    monkeypatch.setattr(study, "prepare", broken)
    result = invoke("sweep", block, "-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", tmp_path / "s.csv")
    assert result.exit_code != 130 and isinstance(result.exception, TypeError), result.output


def test_ctrl_c_before_the_first_row_leaves_no_table_and_the_same_command_runs(block, tmp_path, monkeypatch):
    # Ctrl-C in the first run (a 248-block wall's sweep, 12 s in: the LocalCluster still starting) wrote a
    # header-only s.csv and said "run the same command again to resume"; the same command then said
    # "--out s.csv: the file exists (add --force to replace it)", exit 2: there was no row of this study in it.
    from masonrycli.study import runner

    def interrupted(*args):
        raise KeyboardInterrupt

    out = tmp_path / "s.csv"
    args = ["sweep", block, "-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "-o", out]
    monkeypatch.setattr(runner, "run_task", interrupted)
    result = invoke(*args)
    assert result.exit_code == 130, result.output
    assert words(result.output).endswith("interrupted: stopped before any row was finished; nothing was written")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml"]
    monkeypatch.undo()
    result = invoke(*args)
    assert result.exit_code == 0 and "(2 runs now, 0 rows already there" in words(result.output), result.output


def test_ctrl_c_before_the_first_row_keeps_the_table_that_force_would_replace(block, tmp_path, monkeypatch):
    # Helper-123: with --force over another study's table, a Ctrl-C before any row was finished replaced that
    # table by an empty one (0 rows: the other study lost for nothing) and said "every finished row is in
    # s.csv; run the same command again to resume".
    from masonrycli.study import runner

    def interrupted(*args):
        raise KeyboardInterrupt

    out = tmp_path / "s.csv"
    assert invoke("sweep", block, "-p", "amp=0.05", "--duration", 0.02, "--workers", 0, "-o", out).exit_code == 0
    before = out.read_bytes()
    monkeypatch.setattr(runner, "run_task", interrupted)
    args = ["sweep", block, "-p", "amp=0.1,0.2", "--duration", 0.02, "--workers", 0, "-o", out, "--force"]
    result = invoke(*args, "--no-recording")
    assert result.exit_code == 130, result.output
    said = f"interrupted: stopped before any row was finished; nothing was written ({out} is as it was)"
    assert words(result.output).endswith(said), result.output
    assert out.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "s.csv", "s.png", "s.rrd"]
