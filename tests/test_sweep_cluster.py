"""Studies on real Dask clusters: a LocalCluster of 2 worker processes gives the rows of the same runs
made one by one; a scheduler and a worker started as separate processes lose no finished row when the
worker is killed mid-study, and the same command run again completes the study. Each of these tables equals
the same study run with --workers 0, every column but the timings, bit for bit."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest
from rich.console import Console

from masonrycli.run import simulate
from masonrycli.scenario.motion import Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder
from masonrycli.study.axes import StudyBase, apply_point, parse_axis
from masonrycli.study.study import StudyRequest, run_study
from masonrycli.study.task import RESULT_COLUMNS

from cli_helpers import words

pytestmark = pytest.mark.slow
BIN = Path(sys.executable).parent
ROOT = Path(__file__).resolve().parent.parent  # the checkout under test
# Commands and workers import the checkout under test (a worker imported the venv's editable install
# while `python -m masonrycli` took the working directory's: other code, which the command now refuses)
ENV = os.environ | {"RERUN_ANALYTICS": "0", "PYTHONUNBUFFERED": "1", "PYTHONPATH": str(ROOT)}


def test_local_cluster_rows_equal_the_runs_made_one_by_one(tmp_path):
    scenario = scenario_from_builder(
        "wall", {"blocks": 12}, RunConfig(duration=0.15), Material(), {"ground": Sine(amplitude=1.0, frequency=2.0)}
    )
    base = StudyBase(scenario)
    axes = [parse_axis("amp=0.4,1.2"), parse_axis("freq=1.5,3")]
    request = StudyRequest(axes=axes, out=tmp_path / "study.parquet", workers=2)
    result = run_study(base, request, Console(quiet=True))
    rows = pq.read_table(tmp_path / "study.parquet").to_pylist()
    assert len(rows) == 4 and result.ran == 4
    serial = StudyRequest(axes=axes, out=tmp_path / "serial.parquet", workers=0)  # --workers 0: in this process
    run_study(base, serial, Console(quiet=True))
    _assert_same_rows(rows, pq.read_table(tmp_path / "serial.parquet").to_pylist())  # every column, bit for bit
    for row in rows:
        alone = simulate(apply_point(base, {"amp": row["amp"], "freq": row["freq"]}), stop_at_collapse=True)
        assert row["status"] == alone.status == "completed"
        assert row["energy_dissipated"] == alone.energy_dissipated  # bit for bit, across processes
        assert row["steps"] == alone.steps and row["max_penetration"] == alone.max_penetration
        assert row["state"] == alone.outcome["state"] and row["residual_drift"] == alone.outcome["residual_drift"]
        assert row["max_opening"] == alone.outcome["max_opening"] and row["hinges"] == alone.outcome["hinges"]
        assert row["pga"] == alone.intensity["pga"] and row["sa"] == alone.intensity["sa"]
        assert row["sweeps_mean"] == alone.tally.sweeps_mean
    assert {r["state"] for r in rows} >= {"damaged"} and set(rows[0]) == {
        "amp",
        "freq",
        *RESULT_COLUMNS,
        "study",
        "source",
        "command",
    }


TIMINGS = {"wall_time", "cpu_time"}


def _assert_same_rows(rows: list[dict], reference: list[dict]) -> None:
    """Every column but the timings equal, bit for bit (NaN to NaN): runs are deterministic whatever made them."""
    assert len(rows) == len(reference)
    for row, ref in zip(rows, reference):
        assert row.keys() == ref.keys()
        # each row names the line that made it (37c056a; '' from run_study in process): two studies' lines differ
        # by design (--workers, --out), their results must not
        for key in row.keys() - TIMINGS - {"command"}:
            a, b = row[key], ref[key]
            assert a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b)), (
                key,
                row,
                ref,
            )


def _serially(sweep: list, out: Path, log: Path) -> list[dict]:
    """The rows of ``sweep`` run again in the command's own process (--workers 0) into ``out``."""
    cut = [i for i, a in enumerate(sweep) if str(a) in ("--workers", "--scheduler")]  # with their values
    args = [str(a) for i, a in enumerate(sweep) if i not in cut and i - 1 not in cut]
    args[args.index("--out") + 1] = str(out)
    done = subprocess.run([*args, "--workers", "0"], stdout=open(log, "w"), stderr=subprocess.STDOUT, env=ENV)
    assert done.returncode == 0, log.read_text()
    return _read_csv(out)


def _spawn(args, log: Path, terminal: bool = False):
    """Start ``args`` in a session of its own, output to ``log``; ``terminal``: with SIGINT at its default
    as in a terminal, whoever runs pytest (a Ctrl-C is then sent to the group by ``os.killpg``)."""
    preexec = (lambda: signal.signal(signal.SIGINT, signal.SIG_DFL)) if terminal else None
    return subprocess.Popen(
        args, stdout=open(log, "w"), stderr=subprocess.STDOUT, env=ENV, start_new_session=True, preexec_fn=preexec
    )


def _kill(proc, sig=signal.SIGKILL):
    if proc.poll() is None:
        os.killpg(proc.pid, sig)
    proc.wait(timeout=60)


def _wait(predicate, timeout: float, what: str, logs: dict):
    """Poll ``predicate``; fail at once, with every log, if a process in ``logs`` (proc -> log) exits."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return
        for proc, log in logs.items():
            if proc.poll() is not None:
                raise AssertionError(f"{log.name} exited ({proc.returncode}) while waiting for {what}\n" + _tails(logs))
        time.sleep(0.2)
    raise AssertionError(f"timed out waiting for {what}\n" + _tails(logs))


def _tails(logs: dict) -> str:
    return "\n".join(f"--- {log.name}\n" + "\n".join(log.read_text().splitlines()[-15:]) for log in logs.values())


def _journal_rows(out: Path) -> list[dict]:
    journal = out.with_name(out.name + ".journal.jsonl")
    if not journal.exists():
        return []
    return [json.loads(line) for line in journal.read_text().splitlines() if line.endswith("}")]


def test_scheduler_and_worker_processes_kill_the_worker_and_resume(tmp_path):
    sched_file = tmp_path / "scheduler.json"
    out = tmp_path / "study.csv"
    scheduler = _spawn(
        [BIN / "dask", "scheduler", "--port", "0", "--no-dashboard", "--scheduler-file", sched_file], tmp_path / "s.log"
    )
    workers, sweeps = [], []
    logs = {scheduler: tmp_path / "s.log"}
    try:
        _wait(sched_file.exists, 60, "the scheduler file", logs)
        address = json.loads(sched_file.read_text())["address"]
        worker_args = [BIN / "dask", "worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard"]
        workers.append(_spawn(worker_args, tmp_path / "w1.log"))
        # Four runs of 5 s that stay intact (~0.5 s of CPU each). Once two rows are in, the two runs left
        # take a second of the worker's CPU: far more than the test needs to see the rows and kill it, however
        # loaded the machine (six runs of 0.3 s took 20-130 ms each: the study could end, and its journal go,
        # between two looks, and the wait for two rows then timed out).
        sweep = [sys.executable, "-m", "masonrycli", "sweep", "wall", "--param", "blocks=12", "--duration", "5"]
        sweep += ["--param", "amp=0.1:0.25:4", "--scheduler", address, "--out", out]
        sweeps.append(_spawn(sweep, tmp_path / "sweep1.log"))
        logs |= {workers[0]: tmp_path / "w1.log", sweeps[0]: tmp_path / "sweep1.log"}
        _wait(lambda: len(_journal_rows(out)) >= 2, 240, "two finished rows", logs)
        _kill(workers[0])  # mid-study: the remaining tasks have no worker now
        finished = _journal_rows(out)
        time.sleep(1.0)
        _kill(sweeps[0], signal.SIGINT)  # the user gives up waiting: the finished rows are written
        rows = _read_csv(out)
        assert len(rows) >= len(finished) >= 2 and len(rows) < 4, _tails(logs)
        assert all(r["status"] == "completed" for r in rows)
        kept = {r["amp"]: r["wall_time"] for r in rows}
        workers.append(_spawn(worker_args, tmp_path / "w2.log"))
        sweeps.append(_spawn(sweep, tmp_path / "sweep2.log"))
        logs = {scheduler: tmp_path / "s.log", workers[1]: tmp_path / "w2.log", sweeps[1]: tmp_path / "sweep2.log"}
        assert sweeps[1].wait(timeout=300) == 0, _tails(logs)
        rows = _read_csv(out)
        assert [r["amp"] for r in rows] == pytest.approx([0.1, 0.15, 0.2, 0.25])
        assert all(r["status"] == "completed" and r["time"] == pytest.approx(5.0) for r in rows)  # none cut short
        for r in rows:  # rows finished before the kill were not run again
            if r["amp"] in kept:
                assert r["wall_time"] == kept[r["amp"]]
        assert f"{len(kept)} rows already there" in words((tmp_path / "sweep2.log").read_text())
        # the rows of the two workers, one killed, are those of the same runs made in one process
        _assert_same_rows(rows, _serially(sweep, tmp_path / "serial.csv", tmp_path / "serial.log"))
    finally:
        for proc in sweeps + workers + [scheduler]:
            _kill(proc)


def test_a_scheduler_killed_mid_study_is_one_line_and_the_finished_rows_kept(tmp_path):
    # 'kill <scheduler>' mid-study made every pending run an error row, "FutureCancelledError: run-… cancelled
    # for reason: scheduler-connection-lost …" five times, a plot of grey cells and exit 5 ("5 of 6 rows failed")
    sched_file = tmp_path / "scheduler.json"
    out = tmp_path / "study.csv"
    scheduler = _spawn(
        [BIN / "dask", "scheduler", "--port", "0", "--no-dashboard", "--scheduler-file", sched_file], tmp_path / "s.log"
    )
    procs = [scheduler]
    logs = {scheduler: tmp_path / "s.log"}
    try:
        _wait(sched_file.exists, 60, "the scheduler file", logs)
        address = json.loads(sched_file.read_text())["address"]
        worker = [BIN / "dask", "worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard"]
        procs.append(_spawn(worker, tmp_path / "w.log"))
        # four runs of 30 s of the 51-block wall (2-4 s of CPU each): after the first row the others take
        # seconds, long enough to kill the scheduler under them (runs of 5 s on 12 blocks all ended first)
        sweep = [sys.executable, "-m", "masonrycli", "sweep", "wall", "--duration", "30"]
        sweep += ["--param", "amp=0.2:0.35:4", "--scheduler", address, "--out", out]
        procs.append(_spawn(sweep, tmp_path / "sweep.log"))
        logs |= {procs[1]: tmp_path / "w.log", procs[2]: tmp_path / "sweep.log"}
        _wait(lambda: len(_journal_rows(out)) >= 1, 240, "a finished row", logs)
        _kill(scheduler)
        assert procs[2].wait(timeout=120) == 2, _tails(logs)
        lines = (tmp_path / "sweep.log").read_text().splitlines()
        said = words("\n".join(ln for ln in lines if not ln.startswith("sweep: ")))  # not the progress lines
        assert said.startswith(f"error: --scheduler {address}: lost the connection to the scheduler with"), said
        assert f"every finished row is in {out}" in said and "Traceback" not in said and "Cancelled" not in said
        rows = _read_csv(out)
        assert 1 <= len(rows) < 4 and all(r["status"] == "completed" for r in rows)  # no error row for the rest
    finally:
        for proc in procs:
            _kill(proc)


def _worker_without_masonry(tmp_path: Path) -> list:
    """A Python environment with Dask but no masonry: a venv of the same interpreter that sees this
    venv's site-packages through a path file, which does not process their .pth files (so not the
    editable install's finder either)."""
    import sysconfig

    venv = tmp_path / "no-masonry"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", venv], check=True)
    python = venv / "bin" / "python"
    site = subprocess.run(
        [python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], capture_output=True, text=True
    ).stdout.strip()
    Path(site, "project.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    return [python, "-m", "distributed.cli.dask_worker"]


def test_workers_with_another_masonry_or_none_are_refused_before_any_file(tmp_path):
    # A worker with another masonry ran the study's tasks without a word (rows of other code in the
    # table); one without masonry failed every run, an error row each. The command now asks every
    # worker (the probe runs there) and refuses with one line, exit 2, before writing anything.
    sched_file = tmp_path / "scheduler.json"
    scheduler = _spawn(
        [BIN / "dask", "scheduler", "--port", "0", "--no-dashboard", "--scheduler-file", sched_file], tmp_path / "s.log"
    )
    logs = {scheduler: tmp_path / "s.log"}
    other = tmp_path / "other"  # a masonry of another release, first on the worker's path
    for package, text in (("masonrycli", '__version__ = "0.0.9"\n'), ("geometry_library", "")):
        (other / package).mkdir(parents=True)
        (other / package / "__init__.py").write_text(text)
    work = tmp_path / "work"
    work.mkdir()
    try:
        _wait(sched_file.exists, 60, "the scheduler file", logs)
        address = json.loads(sched_file.read_text())["address"]
        args = [address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard"]
        sweep = [sys.executable, "-m", "masonrycli", "sweep", "wall", "--param", "blocks=12", "--duration", "0.05"]
        sweep += ["--param", "amp=0.1,0.2", "--scheduler", address, "--out", "study.csv"]
        ours = subprocess.run(
            [sys.executable, "-c", "from masonrycli.study.versions import *; print(describe(this_version()))"],
            capture_output=True, text=True, env=ENV, cwd=work,
        ).stdout.strip()  # fmt: skip
        assert ours.startswith("masonry 0.1.0 (source ")
        cases = [
            ([BIN / "dask", "worker"], {"PYTHONPATH": str(other)}, "runs masonry 0.0.9 (source "),
            (
                _worker_without_masonry(tmp_path),
                {"PYTHONPATH": ""},
                "runs no masonry (ModuleNotFoundError: No module named 'masonrycli')",
            ),
            ([BIN / "dask", "worker"], {"PYTHONPATH": str(ROOT)}, None),  # the same masonry: the study runs
        ]
        for command, extra, said in cases:
            log = tmp_path / f"w{len(logs)}.log"
            worker = subprocess.Popen(
                [*command, *args], stdout=open(log, "w"), stderr=subprocess.STDOUT, env=ENV | extra,
                cwd=tmp_path, start_new_session=True,
            )  # fmt: skip
            logs[worker] = log
            try:
                _wait(lambda log=log: "Registered to" in log.read_text(), 120, "the worker", logs)
                done = subprocess.run(sweep, capture_output=True, text=True, env=ENV, cwd=work, timeout=300)
            finally:
                _kill(worker)
                del logs[worker]
            if said is None:
                assert done.returncode == 0, done.stdout + done.stderr
                assert len(_read_csv(work / "study.csv")) == 2
                continue
            lines = [ln for ln in (done.stdout + done.stderr).splitlines() if ln.strip()]
            assert done.returncode == 2 and len(lines) == 1, lines
            assert lines[0].startswith(f"error: --scheduler {address}: worker tcp://"), lines
            assert said in lines[0] and f"this command runs {ours}" in lines[0], lines
            assert list(work.iterdir()) == []  # no table, journal, plot or recording
    finally:
        _kill(scheduler)


def _read_csv(path: Path) -> list[dict]:
    from masonrycli.study.store import read_rows

    return read_rows(path)


def _other_masonry(tmp_path: Path) -> Path:
    """A folder holding a masonry of another release (version 0.0.9, no code), for a worker's path."""
    other = tmp_path / "other"
    for package, text in (("masonrycli", '__version__ = "0.0.9"\n'), ("geometry_library", "")):
        (other / package).mkdir(parents=True)
        (other / package / "__init__.py").write_text(text)
    return other


def test_a_worker_with_another_masonry_joining_mid_study_is_refused_and_the_rows_kept(tmp_path, monkeypatch):
    # The check before the study asks the workers present then; one that joined later ran its tasks with its
    # own masonry (here: error rows, 'No module named masonrycli.study'; rows of other code in general).
    # Each result now says which masonry made it. A real LocalCluster (one worker process, this masonry)
    # passes the check; once the first row is in, a `dask worker` of masonry 0.0.9 joins and the first
    # worker leaves (one task in flight, so the next one can only go to the newcomer): its result stops the
    # study with one line, and the row before it is in the table.
    from distributed import Client, LocalCluster

    from masonrycli.errors import InputError
    from masonrycli.study import runner, store
    from masonrycli.study.versions import describe, this_version

    other = _other_masonry(tmp_path)
    out = tmp_path / "study.csv"
    cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0")
    client = Client(cluster)
    monkeypatch.setattr(runner, "MIN_IN_FLIGHT", 1)
    monkeypatch.setattr(runner, "IN_FLIGHT_PER_THREAD", 1)
    late, append = [], store.Journal.append

    def replace_the_worker_after_the_first_row(journal, row):
        append(journal, row)
        if late:
            return
        (first,) = client.scheduler_info()["workers"]
        late.append(
            subprocess.Popen(
                [BIN / "dask", "worker", cluster.scheduler_address, "--nthreads", "1", "--no-dashboard"],
                stdout=open(tmp_path / "late.log", "w"),
                stderr=subprocess.STDOUT,
                env=ENV | {"PYTHONPATH": str(other)},
                cwd=tmp_path,
                start_new_session=True,
            )  # fmt: skip
        )
        client.wait_for_workers(2, timeout=120)
        client.retire_workers([first], close_workers=True)

    monkeypatch.setattr(store.Journal, "append", replace_the_worker_after_the_first_row)
    scenario = scenario_from_builder(
        "wall", {"blocks": 12}, RunConfig(duration=0.2), Material(), {"ground": Sine(amplitude=0.1, frequency=2.0)}
    )
    request = StudyRequest(axes=[parse_axis("amp=0.1:0.2:6")], out=out, scheduler=cluster.scheduler_address)
    try:
        with pytest.raises(InputError) as err:
            run_study(StudyBase(scenario), request, Console(quiet=True))
    finally:
        for proc in late:
            _kill(proc)
        client.close()
        cluster.close()
    said = str(err.value)
    assert "\n" not in said and said.startswith(f"--scheduler {cluster.scheduler_address}: worker tcp://"), said
    assert "runs masonry 0.0.9 (source " in said and f"this command runs {describe(this_version())}" in said
    assert said.endswith(
        f"is not kept and the study stops; every finished row is in {out} (the same command resumes the study "
        "once every worker runs this masonry)"
    ), said
    rows = _read_csv(out)
    assert [r["amp"] for r in rows] == [0.1] and rows[0]["status"] == "completed"
    assert not out.with_name(out.name + ".journal.jsonl").exists()  # the table holds every finished row


def test_the_masonry_check_waits_60_s_at_most(tmp_path, monkeypatch):
    # A worker that does not answer (stopped here; busy inside a long numba call in life) kept the check,
    # and the command, waiting without a word.
    from distributed import Client, LocalCluster

    from masonrycli.errors import InputError
    from masonrycli.study import versions

    monkeypatch.setattr(versions, "PROBE_TIMEOUT", 2.0)
    cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0")
    client = Client(cluster)
    (pid,) = client.run(os.getpid).values()
    try:
        versions.check_workers(client, cluster.scheduler_address)  # answers: passes
        os.kill(pid, signal.SIGSTOP)
        start = time.monotonic()
        with pytest.raises(InputError, match=r"the workers \(1\) did not all answer the masonry check within 2 s"):
            versions.check_workers(client, cluster.scheduler_address)
        assert time.monotonic() - start < 30
    finally:
        os.kill(pid, signal.SIGCONT)
        client.close()
        cluster.close()


def _within(seconds: float, call, on_hang=lambda: None):
    """``call()``'s result, made in a thread of its own; a failed test (``on_hang`` called first, to free the
    thread) if it has not returned within ``seconds``: a study that hangs fails its test, it does not hang it."""
    import threading

    box: dict = {}

    def target():
        try:
            box["value"] = call()
        except BaseException as exc:  # noqa: BLE001 - raised again in the test's thread
            box["error"] = exc

    thread = threading.Thread(target=target, name="study-under-test", daemon=True)
    thread.start()
    thread.join(seconds)
    if thread.is_alive():
        on_hang()
        pytest.fail(f"the study hung: no end within {seconds:g} s")
    if "error" in box:
        raise box["error"]
    return box.get("value")


def test_a_point_that_kills_its_worker_is_an_error_row_saying_so_and_only_it(monkeypatch):
    # the row said "KilledWorker: Attempted to run task 'run-21434d39-…' on 4 different workers, but all those
    # workers died while running it. The last worker … Inspecting worker logs is often a good next step to diagnose
    # what went wrong. Fo" (cut at 300 characters); and a point running beside it in the same worker process (a
    # worker of 2 threads, as `dask worker` makes by default; or one whose result was not yet sent) died with it,
    # four times over: an error row too, for a good point
    import dask
    from distributed import Client, LocalCluster

    from masonrycli.study import runner

    class Driver:
        def start(self):
            return [{"amp": 0.1}, {"amp": 0.2}]

        def feed(self, params, row):
            return []

    def task(base, params, *args):  # the point 0.2 ends its worker process, as an out-of-memory kill would
        time.sleep(0.2 if params["amp"] == 0.2 else 1.0)
        if params["amp"] == 0.2:
            os._exit(1)
        return dict(params, status="completed", error="")

    monkeypatch.setattr(runner, "run_task", task)  # sent to the workers by value (runner.make_task)
    # Dask drops a worker not back 15 s after a loss (distributed.deploy.lost-worker-timeout), timed from that
    # loss, and none replaces it (runner's WorkerWatch): on a loaded machine a worker restarting then was lost,
    # and the study waited forever (3 runs in 4 beside three busy loops). At 0.1 s each death drops it.
    monkeypatch.setitem(dask.config.config["distributed"]["deploy"], "lost-worker-timeout", "0.1s")
    cluster = LocalCluster(n_workers=1, threads_per_worker=2, processes=True, dashboard_address=":0")
    client = Client(cluster)
    rows = []
    try:
        _within(
            300,
            lambda: runner.run_on_cluster(
                client, "s", Driver(), lambda p, r: rows.append(r), False, None, False, cluster=cluster
            ),
        )
    finally:
        client.close()
        cluster.close()
    rows.sort(key=lambda r: r["amp"])
    assert [(r["amp"], r["status"]) for r in rows] == [(0.1, "completed"), (0.2, "error")], [r["error"] for r in rows]
    said = rows[1]["error"]
    assert said.startswith("KilledWorker: the worker process running this point died, on each of the 4 workers ")
    assert said.endswith(": out of memory, or a crash (the workers' logs say which)"), said
