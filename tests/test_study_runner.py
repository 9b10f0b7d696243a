"""``run_on_cluster`` on an in-process LocalCluster: points are submitted a few per worker thread at a
time, not all at once (a 100 000-point grid wrote no row in its first 40 s), and every point still
gives its row once, with the points a driver hands out on the way. Connecting to a --scheduler address:
test_study_runner_scheduler.py."""

from __future__ import annotations

import time

import pytest

from masonrycli.study import runner, watch


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0")
    client = Client(cluster)
    yield client
    client.close()
    cluster.close()


class Driver:
    """``n`` points; each of the first ``follow`` rows hands out one more point."""

    def __init__(self, n: int, follow: int = 0):
        self.n, self.follow, self.fed = n, follow, 0

    def start(self) -> list[dict]:
        return [{"amp": float(i)} for i in range(self.n)]

    def feed(self, params: dict, row: dict) -> list[dict]:
        self.fed += 1
        return [{"amp": 1000.0 + params["amp"]}] if self.fed <= self.follow else []


def test_points_are_submitted_a_few_at_a_time_and_every_one_gives_its_row(client, monkeypatch):
    def task(base, params, stop_at_collapse, history_dir, force):
        return params | {"base": base, "twice": 2.0 * params["amp"]}

    monkeypatch.setattr(runner, "run_task", task)
    held, rows = [], []

    def on_row(params, row):
        held.append(len(client.futures))  # the base and the tasks submitted and not yet back
        rows.append(row)

    runner.run_on_cluster(client, "scenario", Driver(300, follow=20), on_row, False, None, False)
    # all 300 were held at the first row before; now the base and 64 (2 workers: the floor)
    assert held[0] <= 65 and max(held) <= 65
    assert runner.in_flight_limit(client) == 64
    expected = [float(i) for i in range(300)] + [1000.0 + a for a in sorted(r["amp"] for r in rows[:20])]
    assert sorted(r["amp"] for r in rows) == sorted(expected)
    assert all(r == {"amp": r["amp"], "base": "scenario", "twice": 2.0 * r["amp"]} for r in rows)


def test_an_explicit_limit_is_kept(client, monkeypatch):
    monkeypatch.setattr(runner, "run_task", lambda base, params, *args: dict(params))
    held = []
    runner.run_on_cluster(
        client, "s", Driver(40), lambda p, r: held.append(len(client.futures)), False, None, False, limit=3
    )
    assert len(held) == 40 and max(held) <= 4


def test_a_cluster_without_workers_says_the_study_waits_and_again_when_one_joins(monkeypatch):
    # every worker of a --scheduler killed: the study waited, silent, its bar still (walk-through
    # 2026-11-29, 180 s without a word); it waits still (a worker may join), and says so
    from distributed import Client, LocalCluster

    def task(base, params, *args):  # long enough for the watch to see the worker that joined
        time.sleep(0.3)
        return dict(params)

    monkeypatch.setattr(runner, "run_task", task)
    monkeypatch.setattr(watch, "NO_WORKER_WAIT", 0.5)
    monkeypatch.setattr(watch, "WATCH_EVERY", 0.1)
    cluster = LocalCluster(n_workers=0, threads_per_worker=1, processes=False, dashboard_address=":0")
    client = Client(cluster)
    said, rows = [], []

    def warn(line):
        said.append(line)
        if len(said) == 1:  # the study waits for a worker: one joins
            cluster.scale(1)

    try:
        runner.run_on_cluster(
            client, "s", Driver(3), lambda p, r: rows.append(r), False, None, False, warn=warn, where="X"
        )
    finally:
        client.close()
        cluster.close()
    assert said == [
        "X: no worker for 0.5 s, 3 runs waiting: the study goes on when a worker joins (Ctrl-C stops it, every "
        "finished row written)",
        "X: a worker joined: the study goes on",
    ]
    assert sorted(r["amp"] for r in rows) == [0.0, 1.0, 2.0]


def _lose_the_scheduler(client, monkeypatch, points: int, limit: int) -> tuple[list, str]:
    """A study of ``points`` points, ``limit`` at a time, whose point amp = 1 finds the scheduler gone: (the rows
    made, the SchedulerLost message)."""

    def task(base, params, *args):
        if params["amp"] == 1.0:
            raise OSError("the connection to the scheduler went with it")  # taken for the scheduler's loss below
        return dict(params)

    monkeypatch.setattr(runner, "run_task", task)
    monkeypatch.setattr(runner, "_scheduler_lost", lambda client, exc: True)
    rows = []
    with pytest.raises(runner.SchedulerLost) as lost:
        runner.run_on_cluster(client, "s", Driver(points), lambda p, r: rows.append(r), False, None, False, limit=limit)
    return rows, str(lost.value)


def test_a_lost_scheduler_counts_every_run_not_made(client, monkeypatch):
    # "with 2 runs pending" of a study with 5 runs to go: the points not yet submitted (at most a few per worker
    # thread are) were left out, 64 pending of a 10 000-point grid
    rows, said = _lose_the_scheduler(client, monkeypatch, 6, 2)
    assert said == f"lost the connection to the scheduler with {6 - len(rows)} runs pending"


def test_a_lost_scheduler_with_one_run_left_says_one_run(client, monkeypatch):
    # "with 1 runs pending" when the last point's run found the scheduler gone (9a2001f's fix): one point at a
    # time (limit=1), the first gives its row, the second is the one run left
    rows, said = _lose_the_scheduler(client, monkeypatch, 2, 1)
    assert len(rows) == 1 and said == "lost the connection to the scheduler with 1 run pending"


def _distributed_log_level() -> int:
    import logging

    return logging.getLogger("distributed.worker").getEffectiveLevel()


def test_local_cluster_workers_log_nothing_below_critical():
    # A worker's heartbeat that met the scheduler closing on SIGTERM printed an ERROR line and a
    # StreamClosedError traceback under the "interrupted" line (CI at ace4a71). Its logs say nothing a user
    # needs: a run's errors come back in its row.
    import logging

    from masonrycli.study import runner

    client, cluster = runner.open_cluster(None, 1)
    try:
        levels = client.run(_distributed_log_level)
        # a worker started again (its process died under a point) was not: it logged at INFO (its preload now
        # quiets it, as it starts)
        client.restart()
        again = client.run(_distributed_log_level)
    finally:
        client.close()
        cluster.close()
    assert levels and all(level >= logging.CRITICAL for level in levels.values()), levels
    assert again and all(level >= logging.CRITICAL for level in again.values()), again


def test_local_cluster_has_no_more_workers_than_runs():
    # "-p amp=0.1,0.2 --workers 4" started 4 worker processes (~200 MB each) for 2 runs
    from masonrycli.study import runner

    client, cluster = runner.open_cluster(None, 4, runs=2)
    try:
        assert len(client.scheduler_info()["workers"]) == 2
    finally:
        client.close()
        cluster.close()


@pytest.mark.parametrize("failed", [True, False], ids=["the-run-failed", "the-run-went-on"])
def test_a_ctrl_c_dropped_inside_numbas_compiler_stops_a_serial_study(failed, monkeypatch, capfd):
    # walk-through 2026-11-28, `masonry sweep … --workers 0` with an empty numba cache, Ctrl-C 2.4 s in: the
    # KeyboardInterrupt raised in a ctypes callback of the compile was dropped, the run failed ("RuntimeError: no
    # compiled object yet"), the study went on to exit 5, and every later Ctrl-C was taken for a repeat
    import signal

    from masonrycli.interrupt import FirstSignalStops

    from cli_helpers import signal_inside_a_ctypes_callback

    def task(base, params):
        if params["amp"] == 0.0:
            signal_inside_a_ctypes_callback(signal.SIGINT)
        return params | {"status": "error" if failed else "completed"}

    monkeypatch.setattr(runner, "run_task", task)
    rows, before = [], {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        with FirstSignalStops() as signals:
            with pytest.raises(KeyboardInterrupt):
                runner.run_serially("base", Driver(3), lambda params, row: rows.append(row))
            assert signals.stopping() == signal.SIGINT
    finally:  # a stopped context leaves both signals ignored, for the command's way out: not pytest's
        for s, handler in before.items():
            signal.signal(s, handler)
    assert rows == ([] if failed else [{"amp": 0.0, "status": "completed"}])  # a failed row is not kept
    assert "Traceback" not in capfd.readouterr().err


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_signal_while_the_local_cluster_starts_stops_once_it_is_up_and_closes_it(monkeypatch, sig):
    # walk-through 2026-11-28: SIGTERM 0.8-1.2 s into `masonry sweep` raised inside the half-started LocalCluster;
    # "interrupted (SIGTERM): …" was followed by a traceback of distributed's exit hook (AssertionError:
    # Status.init). Now the start finishes, the signal is raised then, and the cluster is closed. A Ctrl-C
    # there was lost (SIGINT ignored by the whole process): now it goes the same way.
    import os
    import signal
    import time

    import distributed

    from masonrycli.interrupt import FirstSignalStops

    seen = {}
    signum = signal.Signals[sig]

    class Cluster:
        def __init__(self, **kwargs):
            seen["sigint"] = signal.getsignal(signal.SIGINT)
            seen["blocked"] = signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, set())  # for the workers
            seen["preload"] = kwargs["preload"]
            os.kill(os.getpid(), signum)
            time.sleep(0.2)  # a handler would run here
            seen["started"] = True

        def close(self):
            seen["closed"] = True

    monkeypatch.setattr(distributed, "LocalCluster", Cluster)
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        with FirstSignalStops() as signals:
            with pytest.raises(KeyboardInterrupt):
                runner.open_cluster(None, 2)
            assert signals.stopping() == signum
            assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, set())  # unblocked again
    finally:
        for s, handler in before.items():
            signal.signal(s, handler)
    assert seen.pop("sigint") not in (signal.SIG_IGN, signal.SIG_DFL, signal.default_int_handler)
    assert seen == {"blocked": True, "preload": ["masonrycli.study.runner"], "started": True, "closed": True}


def test_a_worker_process_ignores_sigint_from_its_start():
    # dask_setup runs in each worker process of a study's LocalCluster (a preload): a terminal's Ctrl-C
    # reaches them too, and is the command's to act on
    import logging
    import signal

    before = signal.getsignal(signal.SIGINT)
    hangup = signal.getsignal(signal.SIGHUP)
    level = logging.getLogger("distributed").level  # dask_setup quiets the worker's logs: this process's here
    try:
        runner.dask_setup(None)
        assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)
        signal.signal(signal.SIGHUP, hangup)
        logging.getLogger("distributed").setLevel(level)


def test_a_run_stays_pending_until_its_result_is_fetched(client, monkeypatch):
    # 361c8d0: a result lost with its worker is made again inside future.result() ("Couldn't gather keys"); the loop
    # had taken the run out of `pending` before fetching it, so while result() waited the watch counted no run
    # waiting, and the give-up (no worker left) did not cancel it: the CLI waited there for good. Here the fetch of
    # the one run finds the watch giving up (as its thread would, 60 s without a worker): the run counts as waiting,
    # is cancelled, and its row says why; before, the fetch returned the row as made, and no run was waiting.
    import distributed

    monkeypatch.setattr(runner, "run_task", lambda base, params, *args: dict(params, status="completed", error=""))
    watched = {}

    class Watch:  # the WorkerWatch's place: keeps what the loop gives it (its count of runs waiting, give_up)
        def __init__(self, client, warn, where, waiting, cluster=None, give_up=None):
            watched.update(waiting=waiting, give_up=give_up)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return None

    fetched, seen = distributed.Future.result, []

    def result(future, *args, **kwargs):  # the fetch: the worker holding the result is gone, none comes back
        seen.append(watched["waiting"]())
        watched["give_up"](2)
        return fetched(future, *args, **kwargs)

    monkeypatch.setattr(watch, "WorkerWatch", Watch)
    monkeypatch.setattr(distributed.Future, "result", result)
    rows = []
    runner.run_on_cluster(client, "s", Driver(1), lambda p, r: rows.append(r), False, None, False, cluster=object())
    assert seen == [1]  # the run being fetched is waiting (0 before)
    assert [(r["amp"], r["status"]) for r in rows] == [(0.0, "error")], rows
    assert rows[0]["error"] == (
        f"no worker left: the local cluster had none for {watch.NO_WORKER_LIMIT:g} s after its workers died 2 times; "
        "not run"
    )
