"""``masonry sweep`` as a user drives it (in process, --workers 0): its options checked into one-line errors,
the counts line and the terminal table, what it sweeps (a scenario, a geometry file),
and its exit codes (3: some runs diverged, 5: some failed). Over records: test_cli_sweep_records.py; inspect of
its table: test_cli_inspect_file.py. The recording and pictures are in test_recording_study.py, the files it
writes in test_sweep_outputs.py, signals in test_sweep_interrupt.py."""

from __future__ import annotations

from pathlib import Path

import pytest

from masonrycli.study.store import read_rows

from cli_helpers import assert_one_line_error, words
from sweep_helpers import invoke, write_block


@pytest.fixture
def block(tmp_path) -> Path:
    return write_block(tmp_path)


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["-p", "bogus=1"], "--param bogus: unknown parameter"),
        # an engineer's names for them: "mu" said "unknown parameter" and no more
        (["-p", "mu=0.5,0.7"], '--param mu: unknown parameter (did you mean "friction"?)'),
        (["-p", "amplitude=1"], '--param amplitude: unknown parameter (did you mean "amp"?)'),
        (
            ["-p", "pga=1"],
            '--param pga: unknown parameter (records are scaled to a PGA in g by "pga_g": --param pga_g=',
        ),
        (["-p", "amp=1:2"], "--param amp=1:2: a range is LO:HI:N"),
        # a repeated value ran twice, into two rows of one key
        (["-p", "amp=0.1,0.2,0.1"], "--param amp: the value 0.1 is given twice (each point runs once)"),
        (["-p", "amp=0.1:0.1:3"], "--param amp: the value 0.1 is given twice"),
        ([], "nothing to sweep"),
        (["-p", "amp=0.1,0.2", "--find", "freq"], "--find freq: give its range too"),
        (["-p", "amp=0.1,0.2", "--outcome", "fall"], "--outcome fall: expected collapse, sliding"),
        (["-p", "amp=0.1,0.2", "--out", "x.txt"], "a study is written as .parquet or .csv"),
        # 100 worker processes of ~200 MB on a 2-core machine (10 meant): each run uses one core
        (["-p", "amp=0.1", "--workers", "100000"], "--workers 100000: more than 4 per core ("),
        (["-p", "scale=1,2"], "has no record motion"),
        # the point at 0 Hz ran with the ground at rest, where simulate --freq 0 is refused
        (["-p", "freq=0:2:3"], "--param freq=0: support 'ground': the velocity 0.1 m/s · sin(2π·0·t) is 0"),
        (["-p", "amp=0.1", "--records", "nowhere"], "--records nowhere: no such file or folder"),
        (["-p", "amp=0.1", "--workers", "2", "--scheduler", "tcp://x:1"], "--workers with --scheduler"),
        (["-p", "amp=0.1", "--recording", "x.png"], "--recording x.png: the file name must end in .rrd"),
        (["-p", "amp=0.1", "--plot", "x.jpg"], "--plot x.jpg: the file name must end in .png"),
        (["-p", "amp=0.1", "--recording", "x.rrd", "--no-recording"], "--recording x.rrd with --no-recording"),
        # these four ended in a Dask traceback (exit 1); the empty one started a LocalCluster instead
        (["-p", "amp=0.1", "--scheduler", "foo"], "--scheduler 'foo': not an address with a port from 1 to 65535"),
        (["-p", "amp=0.1", "--scheduler", "http://h:8786"], "--scheduler http://h:8786: http:// is not supported"),
        (["-p", "amp=0.1", "--scheduler", "tls://h:8786"], "tls:// is not supported (expected tcp://HOST:PORT"),
        (["-p", "amp=0.1", "--scheduler", "tcp://h:99999"], "a port from 1 to 65535"),  # waited 20 s
        (["-p", "amp=0.1", "--scheduler", ""], "--scheduler '': not an address"),
        # a bad --dt given with --duration was blamed on --duration ("--duration: dt = 0.0: must be > 0")
        (["-p", "amp=0.1", "--duration", "0.02", "--dt", "0"], "--dt: dt = 0: must be > 0"),  # said 0.0: as typed
        (["-p", "amp=0.1", "--duration", "0.02", "--dt", "nan"], "--dt: dt = nan: must be a finite number"),
        (["-p", "amp=0.1", "--duration", "-1", "--dt", "0.01"], "--duration: duration = -1: must be > 0"),
        (["-p", "amp=0.1:1:4", "--find", "amp", "--rtol", "0"], "--rtol 0: must be in (0, 1)"),  # said 0.0
        (["-p", "amp=0.1:1:4", "--find", "amp", "--rtol", "1e0"], "--rtol 1e0: must be in (0, 1)"),
        # a bracket with no float64 middle: the same point ran for ever
        (["-p", "amp=0.1:1:4", "--find", "amp", "--rtol", "1e-300"], "--rtol 1e-300: must be >= 1e-09 (each halving"),
        (["-p", "amp=0.1", "--rtol", "0.010"], "--rtol 0.010: goes with --find"),
        (["-p", "amp=0.1,1e30"], "--param amp=1e+30: "),  # it ran, exit 0
        (["-p", "amp=0.1", "--histories", "h.npz"], "--histories h.npz: names the folder for one history per run"),
        (["-p", "phase=0,1e300"], "--param phase: phase = 1e+300: must be within ±10000 rad"),  # it ran
        # both rows ran at 0.5 m/s, under the names amp=0.1 and amp=0.2
        (["-p", "amp=0.1,0.2", "-p", "ground.amp=0.5"], "--param ground.amp: sets the amplitude of support 'ground'"),
        # without --find these were ignored: a grid ran and reported states, not the outcome asked for
        (["-p", "amp=0.1,0.2", "--outcome", "sliding"], "--outcome sliding: goes with --find"),
        (["-p", "amp=0.1,0.2", "--outcome", "collapse"], "--outcome collapse: goes with --find"),
        (["-p", "amp=0.1,0.2", "--rtol", "0.1"], "--rtol 0.1: goes with --find"),
        # a bad value inside an axis (only its ends were checked) ran into an error row, and the study said
        # "3 rows ... 1 failed"
        (["-p", "friction=0.5,-1,0.6"], "--param friction=-1: friction = -1.0: must be >= 0"),
        (["-p", "dt=0.002:0.004:3"], "--param dt=0.003: duration = 1.0 is not a whole number of steps of dt = 0.003"),
        (["-p", "amp=0.1,1e30,0.2", "-p", "freq=1,2"], "--param amp=1e+30 freq=1: "),
        # a bad combination of values each good with the first point (30 Hz at dt = 0.02 s, aliased) ran into an
        # error row: "1 of 4 rows failed …; run the same command again to retry them", refused again each time
        (["-p", "freq=30,1", "-p", "dt=0.002,0.02"], 'block.toml: support "ground": frequency = 30 Hz is above'),
    ],
)
def test_sweep_errors_are_one_line(block, args, fragment, tmp_path, monkeypatch):
    # in a folder of its own: a row that ran (before its refusal existed) wrote study-block.parquet and .png
    # into the working directory, and every later row then said "--out's plot study-block.png: the file exists"
    monkeypatch.chdir(tmp_path)
    result = invoke("sweep", block, *args)
    assert result.exit_code == 2, result.output
    lines = [ln for ln in result.output.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and fragment in lines[0], result.output


@pytest.mark.parametrize("option", ["--out", "--plot", "--recording", "--histories", "--records"])
def test_an_empty_path_is_said_to_be_empty(option):
    # Path("") is ".": sweep took --out "" as the folder "."
    from cli_helpers import invoke

    assert_one_line_error(invoke("sweep", "wall", "--param", "amp=0.1", option, ""), option, "the path is empty")


def test_the_counts_line_says_one_row(block, tmp_path):
    # it said "1 rows in s.csv (1 runs now, 0 rows already there, 0 failed)"
    args = ["-p", "amp=0.1", "--duration", 0.02, "--workers", 0, "-o", tmp_path / "s.csv", "--no-recording"]
    result = invoke("sweep", block, *args)
    assert result.exit_code == 0, result.output
    assert f"1 row in {tmp_path / 's.csv'} (1 run now, 0 rows already there, 0 failed)" in words(result.output)
    again = words(invoke("sweep", block, *args, "--force").output)
    assert "(0 runs now, 1 row already there, 0 failed)" in again


def test_the_table_fits_80_columns_in_a_real_terminal_width(block, tmp_path):
    import os
    import subprocess
    import sys

    out = tmp_path / "s.csv"
    args = ["-p", "amp=0.05,0.6", "-p", "freq=1,2.5", "--duration", 0.02, "--workers", 0, "-o", out, "--no-recording"]
    env = os.environ | {"COLUMNS": "80", "RERUN_ANALYTICS": "0"}
    cmd = [sys.executable, "-m", "masonrycli", "sweep", str(block), *map(str, args)]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    # the table and its legend; a line naming a file is whole however long its path (the terminal folds it; a
    # newline inside a path or a command broke copying it: test_sweep_outputs)
    assert max(len(line) for line in lines if str(tmp_path) not in line) <= 80, done.stdout
    body = [line for line in lines if line.startswith("│")]
    assert len(body) == 4 and all(line.split("│")[3].strip() in ("intact", "damaged", "collapsed") for line in body), (
        done.stdout
    )
    assert "collapse: time of collapse, s" in done.stdout and "every column in" in done.stdout


def test_a_geometry_file_is_swept_as_run_runs_it(tmp_path):
    # `sweep wall.geojson` said "wall.geojson: TOML syntax error: Invalid statement (at line 1, column 1)";
    # run, check and limit take a GeoJSON / WKT file as it is (supports fixed).
    geo = tmp_path / "wall.geojson"
    assert invoke("build", "wall", "--blocks", 7, "--out", geo).exit_code == 0
    out = tmp_path / "g.csv"
    args = ("-p", "friction=0.5,0.6", "--duration", 0.01, "--workers", 0, "--no-recording", "--out", out)
    result = invoke("sweep", geo, *args)
    assert result.exit_code == 0, result.output
    assert [r["friction"] for r in read_rows(out)] == [0.5, 0.6]


def test_rows_name_the_masonry_that_made_them_and_a_resume_says_when_it_differs(block, tmp_path):
    # the study's fingerprint is of its inputs, not of the code: resumed after an upgrade, a table mixed the
    # rows of two solvers without a word, and no row said which masonry had made it
    from masonrycli.study.versions import this_version

    ours = this_version()[1]
    out = tmp_path / "s.csv"
    args = ["sweep", block, "--workers", 0, "--no-recording", "--duration", 0.05, "--out", out, "--force"]
    assert invoke(*args, "-p", "amp=0.1,0.2").exit_code == 0
    assert [r["source"] for r in read_rows(out)] == [ours, ours]
    text = out.read_text()
    out.write_text(text.replace(ours, "0123456789ab", 1))  # the first row made by another masonry
    result = invoke(*args, "-p", "amp=0.1,0.2,0.3")
    assert result.exit_code == 0, result.output
    assert (
        f"warning: 1 row of {out} was made by another masonry (source 0123456789ab; this one is {ours}): kept, "
        "not run again" in words(result.output)
    ), result.output
    assert [r["source"] for r in read_rows(out)] == ["0123456789ab", ours, ours]


def test_failed_rows_give_exit_5_after_the_whole_table(block, tmp_path, monkeypatch):
    # Two of three runs failed (histories on a full disk): the study said "2 failed" and exited 0, so a
    # script took it for a complete study.
    from masonrycli import run

    real = run.simulate

    def full_disk(scenario, sinks, **kw):
        if scenario.motions[0].amplitude > 0.15:
            raise OSError(28, "No space left on device")
        return real(scenario, sinks, **kw)

    monkeypatch.setattr(run, "simulate", full_disk)
    out = tmp_path / "s.csv"
    args = ["-p", "amp=0.1,0.2,0.3", "--duration", 0.02, "--workers", 0, "-o", out, "--no-recording"]
    result = invoke("sweep", block, *args)
    assert result.exit_code == 5, result.output
    assert len(read_rows(out)) == 3 and (tmp_path / "s.png").exists()  # the table and the plot are whole
    said = words(result.output)
    assert f"error: 2 of 3 rows failed (the reason is in their error column in {out}); run the same" in said, said
    # it said "run the same command again to retry them", which was refused: "--out's plot s.png: the file exists"
    assert said.endswith("run the same command again with --force to retry them (it reuses the finished rows, and "
                         "replaces the plot and the recording)"), said  # fmt: skip
    assert "the file exists" in invoke("sweep", block, *args).output
    monkeypatch.setattr(run, "simulate", real)
    again = invoke("sweep", block, *args, "--force")  # --force: the plot exists
    # words, not lines: the console wraps the line with the table's path, where depends on the path's length
    said = words(again.output)
    assert again.exit_code == 0 and "(2 runs now, 1 row already there, 0 failed)" in said, again.output


def test_diverged_rows_give_exit_3_as_simulate_does(block, tmp_path, monkeypatch):
    # A diverged run (exit 3 from `masonry simulate`) left a row with status diverged and exit 0.
    import dataclasses

    from masonrycli import run

    real = run.simulate

    def diverging(scenario, sinks, **kw):
        result = real(scenario, sinks, **kw)
        if scenario.motions[0].amplitude > 0.15:
            return dataclasses.replace(result, status="diverged", message="diverged at t = 0.0100 s")
        return result

    monkeypatch.setattr(run, "simulate", diverging)
    out = tmp_path / "s.csv"
    result = invoke(
        "sweep", block, "-p", "amp=0.1,0.2", "--duration", 0.02, "--workers", 0, "-o", out, "--no-recording"
    )
    assert result.exit_code == 3, result.output
    assert [r["status"] for r in read_rows(out)] == ["completed", "diverged"]
    said = words(result.output)
    assert f"error: 1 of 2 rows diverged (their error column in {out} says when); a smaller" in said
    assert [r["error"] for r in read_rows(out)] == ["", "diverged at t = 0.0100 s"]


def test_a_point_refused_in_a_grid_too_large_to_check_is_a_row_the_closing_line_says_is_refused_again(
    block, tmp_path, monkeypatch
):
    # a grid of more than MAX_CHECKED_POINTS is checked only along its axes: a bad combination there is refused
    # by its run. It said "1 of 4 rows failed …; run the same command again to retry them", which refused it again.
    monkeypatch.setattr("masonrycli.study.study.MAX_CHECKED_POINTS", 3)
    out = tmp_path / "s.csv"
    args = ["-p", "freq=30,1", "-p", "dt=0.002,0.02", "--duration", 0.02, "--workers", 0, "-o", out, "--no-recording"]
    for again in ([], ["--force"]):  # --force: the plot exists
        result = invoke("sweep", block, *args, *again)
        assert result.exit_code == 5, result.output
        rows = read_rows(out)
        assert [r["status"] for r in rows] == ["completed", "error", "completed", "completed"]
        why = f'--param freq=30 dt=0.02: {block}: support "ground": frequency = 30 Hz is above 1/(2 dt) = 25 Hz'
        assert rows[1]["error"].startswith(f"refused: {why}")
        said = words(result.output)
        assert "retry" not in said, said
        assert said.endswith(
            f"error: 1 of 4 rows refused their parameters ({why}: steps of dt = 0.02 s sample it at aliased phases "
            "(dt = 0.00167 s gives 20 steps a period)): the same command refuses it again; a grid without it, with "
            f"--force, reuses the finished rows (every reason is in the error column in {out})"
        ), said
        assert ("1 run now, 3 rows already there" in said) == bool(again)


def test_a_misspelt_parameter_is_said_before_the_outputs_that_exist(block, tmp_path, monkeypatch):
    # with the last study's plot in place, "-p Amp=0.1" said "--out's plot study-block.png: the file exists (add
    # --force …)"; with --force, then, "unknown parameter"
    monkeypatch.chdir(tmp_path)
    (tmp_path / "study-block.png").write_bytes(b"last study's plot")
    result = invoke("sweep", block, "-p", "Amp=0.1", "--workers", 0)
    assert result.exit_code == 2
    assert (
        result.output.strip()
        == 'error: --param Amp: unknown parameter (did you mean "amp"?) (see masonry sweep --help)'
    )


def test_a_builder_option_on_a_structure_read_from_a_file_says_why(tmp_path):
    # "--param voussoirs: unknown parameter" for an arch read from GeoJSON: an option of the arch builder
    geo = tmp_path / "arch.geojson"
    assert invoke("build", "arch", "--out", geo).exit_code == 0
    result = invoke("sweep", geo, "-p", "voussoirs=10,20", "--workers", 0, "--out", tmp_path / "s.csv")
    assert result.exit_code == 2
    assert result.output.strip() == (
        "error: --param voussoirs: unknown parameter (an option of the arch, aqueduct builders: this structure is "
        "read, not built) (see masonry sweep --help)"
    )


def test_a_reader_of_stdout_that_goes_away_leaves_the_plot_and_the_recording(tmp_path):
    # walk-through 2026-11-28: `masonry sweep … | head -2` wrote the table only: the pipe broke at the first
    # line printed after the table, before the plot and the recording were written (exit 1, nothing said)
    import os
    import subprocess
    import sys

    block, out = write_block(tmp_path), tmp_path / "s.csv"
    argv = ["sweep", str(block), "-p", "amp=0.05,0.1", "--duration", "0.02", "--workers", "0", "-o", str(out)]
    proc = subprocess.Popen(
        [sys.executable, "-m", "masonrycli", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        env=dict(os.environ, RERUN_ANALYTICS="0"),
    )
    proc.stdout.readline()  # `head -1`: the first line, then the reader is gone
    proc.stdout.close()
    proc.wait(timeout=300)
    assert {p.name for p in tmp_path.iterdir()} >= {"s.csv", "s.png", "s.rrd"}
    assert len(read_rows(out)) == 2


def test_a_scheduler_lost_before_the_first_row_says_nothing_was_written(block, tmp_path, monkeypatch):
    # a scheduler killed before any row came back said "every finished row is in s.csv", and there was no s.csv
    from masonrycli.study import runner

    class Client:
        def close(self):
            pass

    def lost(*args, **kwargs):
        raise runner.SchedulerLost("lost the connection to the scheduler with 2 runs pending")

    monkeypatch.setattr(runner, "open_cluster", lambda *args: (Client(), None))
    monkeypatch.setattr(runner, "run_on_cluster", lost)
    result = invoke("sweep", block, "-p", "amp=0.1,0.2", "--scheduler", "tcp://127.0.0.1:1", "-o", tmp_path / "s.csv")
    assert result.exit_code == 2, result.output
    assert words(result.output) == (
        "error: --scheduler tcp://127.0.0.1:1: lost the connection to the scheduler with 2 runs pending; no row was "
        "finished, nothing was written (the same command runs the study once the scheduler is back)"
    )
    assert [p.name for p in tmp_path.iterdir()] == ["block.toml"]


def test_a_rows_run_replays_with_simulate_and_stop_at_collapse(tmp_path):
    # docs/sweep.md "One run of a study, in the viewer": the row's point given to simulate, --stop-at-collapse
    import numpy as np

    out, folder = tmp_path / "s.csv", tmp_path / "h"
    args = ["--param", "amp=1.25", "--param", "freq=2", "--duration", 2, "--histories", folder, "--out", out]
    result = invoke("sweep", "wall", *args, "--workers", 0, "--no-recording")
    assert result.exit_code == 0, result.output
    (row,) = read_rows(out)
    again = tmp_path / "r.npz"
    result = invoke(
        "simulate", "wall", "--amp", 1.25, "--freq", 2, "--duration", 2, "--stop-at-collapse", "--history", again,
        "--no-recording",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    study, replay = np.load(folder / "amp=1.25_freq=2.npz"), np.load(again)
    assert row["state"] == "collapsed" and replay["time"][-1] == pytest.approx(row["collapse_time"])
    for name in ("time", "block_q", "block_v", "energy_dissipated"):
        assert np.array_equal(study[name], replay[name]), name


def test_the_study_recording_line_says_how_to_open_it(block, tmp_path):
    # 'recording: s.rrd' left a first user to find out what opens a .rrd; masonry run says "Open the recording: rerun …"
    import shlex

    folder = tmp_path / "my runs"
    folder.mkdir()
    out = folder / "s.csv"
    result = invoke("sweep", block, "-p", "amp=0.05,0.1", "--duration", 0.02, "--workers", 0, "--out", out)
    assert result.exit_code == 0, result.output
    last = words(result.output).split("recording: ")[-1]
    assert last.startswith(f"{folder / 's.rrd'} (open it: ") and last.endswith(")"), last
    command = shlex.split(last.split("(open it: ")[1].removesuffix(")"))  # quoted for the shell: one path
    assert command[0].endswith("rerun") and command[1:] == [str(folder / "s.rrd")]
