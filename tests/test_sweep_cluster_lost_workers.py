"""Studies whose cluster is left without a worker, on real clusters: the LocalCluster a study owns gives the
runs it cannot make up as error rows once it has had no worker for NO_WORKER_LIMIT s (the finished rows kept,
and made by the same command again); a --scheduler without a worker says how to start one and waits for it.
(A point that kills its worker, Dask dropping the worker: test_sweep_cluster.)"""

from __future__ import annotations

import json
import re
import sys

import pyarrow.parquet as pq
import pytest
from rich.console import Console
from test_sweep_cluster import BIN, _kill, _read_csv, _spawn, _tails, _wait, _within

from masonrycli.scenario.motion import Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder
from masonrycli.study.axes import StudyBase, parse_axis
from masonrycli.study.study import StudyRequest, run_study

from cli_helpers import words

pytestmark = pytest.mark.slow


def test_a_local_cluster_left_without_a_worker_gives_the_runs_left_up_as_error_rows(tmp_path, monkeypatch):
    # Its nanny closed (as Dask closes one whose worker fails to start again) and no worker able to start, the
    # study's LocalCluster had no worker and none came: the study waited forever. The runs not made are error rows
    # saying why (the watch tries new workers meanwhile), the finished ones kept; the same command makes the error
    # rows again, and only them.
    from masonrycli.study import runner, store, watch

    monkeypatch.setattr(watch, "NO_WORKER_WAIT", 1.0)
    monkeypatch.setattr(watch, "NO_WORKER_LIMIT", 4.0, raising=False)  # (code without it: the test fails, hung)
    clusters, append = [], store.Journal.append
    opened = runner.open_cluster

    def open_cluster(*args):
        client, cluster = opened(*args)
        clusters.append(cluster)
        return client, cluster

    def close_the_nanny_after_the_first_row(journal, row):
        append(journal, row)
        if len(clusters) == 1 and not getattr(journal, "closed_one", False):
            journal.closed_one = True
            cluster = clusters[0]
            # no worker can start from now on (its start fails, as out of memory or its environment broken)
            cluster.new_spec["options"]["preload"] = [str(cannot_start)]
            for nanny in list(cluster.workers.values()):
                cluster.sync(nanny.close)  # as Dask closes a nanny whose worker failed to start again

    cannot_start = tmp_path / "cannot_start.py"
    cannot_start.write_text("import os\n\n\ndef dask_setup(worker):\n    os._exit(1)\n")  # dies as it starts
    monkeypatch.setattr(runner, "open_cluster", open_cluster)
    monkeypatch.setattr(store.Journal, "append", close_the_nanny_after_the_first_row)
    # six runs of 3 s of a 12-block wall (~0.3 s of CPU each): the nanny closes long before the last ends
    scenario = scenario_from_builder(
        "wall", {"blocks": 12}, RunConfig(duration=3.0), Material(), {"ground": Sine(amplitude=0.1, frequency=2.0)}
    )
    out = tmp_path / "study.parquet"
    said: list[str] = []
    request = StudyRequest(axes=[parse_axis("amp=0.1:0.35:6")], out=out, workers=1, warn=said.append)

    def run():
        return run_study(StudyBase(scenario), request, Console(quiet=True))

    result = _within(300, run, on_hang=lambda: [c.close() for c in clusters])
    rows = pq.read_table(out).to_pylist()
    done = [r for r in rows if r["status"] == "completed"]
    lost = [r for r in rows if r["status"] != "completed"]
    assert len(rows) == 6 and result.failed == len(lost) >= 1 and len(done) >= 1, rows
    for r in lost:
        assert r["status"] == "error" and re.fullmatch(
            r"no worker left: the local cluster had none for 4 s after its workers died (once|\d+ times); not run",
            r["error"],
        ), r
    assert said[-1].startswith("the local cluster: no worker for 1 s, "), said
    assert re.search(
        r" runs? waiting: if none starts within 4 s, they are given up \(error rows, which the same command runs again\)$",
        said[-1],
    ), said
    # the same study again: the error rows are made, the finished ones kept as they were
    monkeypatch.setattr(store.Journal, "append", append)
    again = StudyRequest(axes=request.axes, out=out, workers=1)
    result = _within(300, lambda: run_study(StudyBase(scenario), again, Console(quiet=True)))
    rows = pq.read_table(out).to_pylist()
    assert result.ran == len(lost) and result.failed == 0
    assert [r["status"] for r in rows] == ["completed"] * 6
    kept = {r["amp"]: r["wall_time"] for r in done}
    assert {r["amp"]: r["wall_time"] for r in rows if r["amp"] in kept} == kept


def test_a_worker_whose_nanny_closed_is_replaced_and_the_study_completes(monkeypatch):
    # Dask closes a nanny whose worker fails to start again ("Failed to restart worker after its process
    # exited"), and nothing replaces it: the study's LocalCluster of one worker had none, and waited forever
    import time

    from distributed import Client, LocalCluster

    from masonrycli.study import runner

    class Driver:
        def start(self):
            return [{"amp": a} for a in (0.1, 0.2, 0.3, 0.4)]

        def feed(self, params, row):
            return []

    def task(base, params, *args):
        time.sleep(0.5)
        return dict(params, status="completed", error="")

    monkeypatch.setattr(runner, "run_task", task)
    cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0")
    client = Client(cluster)
    rows = []

    def on_row(params, row):
        rows.append(row)
        if len(rows) == 1:
            for nanny in list(cluster.workers.values()):
                cluster.sync(nanny.close)

    try:
        _within(300, lambda: runner.run_on_cluster(client, "s", Driver(), on_row, False, None, False, cluster=cluster))
        assert sorted((r["amp"], r["status"]) for r in rows) == [(a, "completed") for a in (0.1, 0.2, 0.3, 0.4)]
        assert len(cluster.workers) == 1 and len(client.nthreads()) == 1  # one in its place, not more
    finally:
        client.close()
        cluster.close()


def test_a_scheduler_without_a_worker_says_how_to_start_one_and_waits_for_it(tmp_path):
    # a --scheduler with no worker (none started yet, or every one killed): the study waits, as Dask keeps its
    # tasks for the next worker (a batch queue may take an hour to start one), and says so with the command
    # that starts one; a worker started then makes the runs
    sched_file = tmp_path / "scheduler.json"
    out = tmp_path / "study.csv"
    scheduler = _spawn(
        [BIN / "dask", "scheduler", "--port", "0", "--no-dashboard", "--scheduler-file", sched_file], tmp_path / "s.log"
    )
    procs, logs = [scheduler], {scheduler: tmp_path / "s.log"}
    try:
        _wait(sched_file.exists, 60, "the scheduler file", logs)
        address = json.loads(sched_file.read_text())["address"]
        sweep = [sys.executable, "-m", "masonrycli", "sweep", "wall", "--param", "blocks=12", "--duration", "0.2"]
        sweep += ["--param", "amp=0.1,0.2", "--scheduler", address, "--out", out]
        procs.append(_spawn(sweep, tmp_path / "sweep.log"))
        logs[procs[-1]] = tmp_path / "sweep.log"
        _wait(lambda: "no worker for" in (tmp_path / "sweep.log").read_text(), 120, "the line", logs)
        worker = [BIN / "dask", "worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard"]
        procs.append(_spawn(worker, tmp_path / "w.log"))
        assert procs[1].wait(timeout=300) == 0, _tails(logs)
        said = words((tmp_path / "sweep.log").read_text())
        assert (
            f"warning: --scheduler {address}: no worker for 10 s, 2 runs waiting: the study goes on when a worker "
            f"joins (`dask worker {address}` starts one; Ctrl-C stops it, every finished row written)"
        ) in said, said
        assert f"warning: --scheduler {address}: a worker joined: the study goes on" in said, said
        assert [r["status"] for r in _read_csv(out)] == ["completed", "completed"]
    finally:
        for proc in procs:
            _kill(proc)
