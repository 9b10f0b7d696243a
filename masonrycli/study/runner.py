"""Running a study's tasks on Dask distributed.

By default a ``LocalCluster`` with one single-threaded worker *process* per core (the engine is
serial numba code holding the GIL, so threads would not help); ``--scheduler tcp://host:8786`` uses an
existing cluster instead, whose workers need only ``pip install masonry`` — the same masonry as the
command's, checked on every worker before anything is written (:mod:`masonrycli.study.versions`). The
base scenario is one task whose result the other tasks share, so each task ships only its parameters
and returns one row.

Tasks are submitted a few per worker thread at a time (:func:`in_flight_limit`), the next as each
comes back: submitted all at once, a 100 000-point grid spent its first 40 s submitting and wrote no row
meanwhile (and the scheduler held 100 000 tasks). The order in which points start does not change a
row: each is a run of its own parameters.

Rows come back in completion order; the driver (:mod:`masonrycli.study.drivers`) decides what runs
next. A task that fails inside the run returns an error row (:func:`~masonrycli.study.task.run_task`);
a task lost with its worker is retried elsewhere by the scheduler, and if it keeps killing workers
(``KilledWorker``) or the cluster fails it otherwise, its row says so. Each result carries the masonry
of the worker that made it; one from another masonry (a worker that joined after the check, or whose
source changed on disk) stops the study (:class:`~masonrycli.study.versions.WorkerMismatch`). A
scheduler that goes away mid-study stops it too (:class:`SchedulerLost`): its pending tasks are not
failed runs.
"""

from __future__ import annotations

import logging
import os
import signal
import threading
from collections import deque
from collections.abc import Callable
from multiprocessing import resource_tracker

from masonrycli.errors import InputError
from masonrycli.outputs.verdict import counted
from masonrycli.study.scheduler import connect
from masonrycli.study.task import empty_result, run_task


def open_cluster(scheduler: str | None, workers: int | None, runs: int | None = None):
    """``(client, cluster)``: a client of ``scheduler``, or of a new LocalCluster (then also returned,
    to be closed by the caller) with ``workers`` processes (default: one per core), at most ``runs`` (the
    runs that can go at once): "-p amp=0.1,0.2 --workers 4" started 4 processes of ~200 MB, 2 of them idle."""
    import_distributed()
    from distributed import Client, LocalCluster

    if scheduler:
        from masonrycli.study.versions import check_workers

        client = connect(Client, scheduler)
        try:
            check_workers(client, scheduler)  # its workers run this masonry, or nothing is written
        except BaseException:
            client.close()
            raise
        return client, None
    n = workers or os.cpu_count() or 1
    if runs is not None:
        n = max(1, min(n, runs))
    # ":0": the scheduler's HTTP endpoints (it serves them even without a dashboard) on a free port, so
    # two studies at once do not fight over 8787
    # Ctrl-C reaches the terminal's whole process group: a worker process that took it printed a
    # KeyboardInterrupt traceback each. The workers ignore SIGINT themselves (dask_setup below, run in each
    # at its start) and start with it blocked (_WhileWorkersStart), so this process keeps its own handler:
    # it closes the cluster on a Ctrl-C, one of the start too.
    held = _WhileWorkersStart()
    cluster = client = None
    try:  # the start inside: a signal on the way out of `with held` raises with the cluster known, and closed
        with held:
            cluster = LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",
                silence_logs=logging.ERROR,
                preload=[__name__],
            )
        held.deliver()  # a Ctrl-C or SIGTERM of the start stops the command now, the cluster closed below
        client = Client(cluster)
        # A worker process's logs are teardown noise under the one-line "interrupted" message: one whose
        # heartbeat met the closing scheduler printed "Failed to communicate with scheduler during heartbeat"
        # and a StreamClosedError traceback (CI, 2026-11-27). A run's own errors come back in its row.
        # (silence_logs above does not reach the worker processes.)
        client.run(quiet_worker_logs)
    except BaseException:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
        raise
    return client, cluster


def import_distributed() -> None:
    """Import distributed, a Ctrl-C or SIGTERM of the import raised once it is done.

    distributed's first import defines its dataclasses by exec(): a KeyboardInterrupt raised inside one,
    even caught, made `python -m masonrycli` exit -2 after the stop line (CPython 3.11 flags it as unhandled;
    2 in 24 Ctrl-Cs 0.45-0.6 s in). Held over the import, the signal is raised after it."""
    importing = _WhileWorkersStart(spawning=False)
    with importing:
        import distributed  # noqa: F401
    importing.deliver()


class _WhileWorkersStart:
    """Around a LocalCluster's start: SIGINT and SIGTERM noted, and :meth:`deliver` raises the first again
    once the cluster is up, where closing it works (a signal raised inside the half-started cluster made
    its exit hook print a traceback, AssertionError: Status.init, under the "interrupted" line). SIGINT is
    also blocked in this thread, and so in the threads the start creates, which spawn the worker processes:
    a process starts with its parent thread's mask (kept across exec), so a Ctrl-C of a worker's first second,
    before its :func:`dask_setup` ignores SIGINT, stays pending there instead of a KeyboardInterrupt
    traceback. This process still takes the signal: a thread from before the start takes it for the handler
    (Python runs it in the main thread), or it waits until the main thread unblocks it on the way out.

    Before, SIGINT was ignored here instead, for the workers to inherit; but a disposition is the whole
    process's, and a Ctrl-C of those 0.6 s was lost: the study ran to exit 0 (walk-through 2026-11-28).
    Outside the main thread (no signal handlers there) it does nothing."""

    def __init__(self, spawning: bool = True) -> None:
        self.main = threading.current_thread() is threading.main_thread()
        self.spawning = spawning  # False: the signals noted only (no process is started in the block)
        self.signum: int | None = None

    def __enter__(self):
        if self.main:
            if self.spawning:
                # multiprocessing's resource tracker, started by the first worker's queues, unblocks SIGINT
                # in the thread that starts it (the cluster's IO loop, whose threads spawn the workers):
                # started here first, it is only reused there
                resource_tracker.ensure_running()
            self._previous = {sig: signal.signal(sig, self._note) for sig in (signal.SIGINT, signal.SIGTERM)}
            self._mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT} if self.spawning else set())
        return self

    def _note(self, signum, _frame) -> None:
        if self.signum is None:
            self.signum = signum

    def __exit__(self, *exc) -> None:
        if self.main:
            # a pending Ctrl-C runs _note inside this call (pthread_sigmask runs the handlers it unblocked)
            signal.pthread_sigmask(signal.SIG_SETMASK, self._mask)
            for sig, handler in self._previous.items():
                signal.signal(sig, handler)
            if exc[0] is not None:  # the start failed: its error goes on, a noted signal after it
                self.deliver()

    def deliver(self) -> None:
        """Raise a noted signal again: the command's own handler takes it now."""
        if self.signum is not None:
            signum, self.signum = self.signum, None
            signal.raise_signal(signum)


def dask_setup(worker) -> None:
    """Run by each worker process of a study's LocalCluster as it starts (a Dask preload): SIGINT ignored,
    so a Ctrl-C in the terminal is left to the command, which closes the cluster (:func:`open_cluster`).
    Setting SIG_IGN also drops a Ctrl-C that waited, blocked, for this moment. Its logs go quiet here too: a
    worker started again after a death (Dask's nanny, or the study's watch) missed :func:`open_cluster`'s call."""
    quiet_worker_logs()
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        if hasattr(signal, "SIGHUP"):  # the terminal closing is the command's to handle too (its rows written)
            signal.signal(signal.SIGHUP, signal.SIG_IGN)


def quiet_worker_logs() -> None:
    """Run on each worker of a study's LocalCluster: its ``distributed`` logger to CRITICAL (see
    :func:`open_cluster`)."""
    logging.getLogger("distributed").setLevel(logging.CRITICAL)


IN_FLIGHT_PER_THREAD = 4
"""Tasks submitted and not yet back, per worker thread (at least :data:`MIN_IN_FLIGHT` in all)."""
MIN_IN_FLIGHT = 64
"""Short tasks wait on the round trip: 20 000 no-op tasks on 2 workers took 133 s with 8 in flight,
87 s with 64 (104 s all submitted at once)."""


class SchedulerLost(InputError):
    """The client lost its scheduler mid-study: every task still pending was cancelled, none of them ran."""


def _scheduler_lost(client, exc: Exception) -> bool:
    """True when ``exc`` (a task's) is the client's lost connection to its scheduler, not the task's own
    failure: a scheduler killed mid-study made every pending run an error row ('FutureCancelledError: …
    cancelled for reason: scheduler-connection-lost …', five times over), a plot of grey cells and exit 5."""
    from concurrent.futures import CancelledError

    lost = isinstance(exc, CancelledError) and "scheduler-connection-lost" in str(exc)
    return lost or client.status not in ("running", "newly-created")


def in_flight_limit(client) -> int:
    """How many tasks :func:`run_on_cluster` keeps submitted: a few per worker thread, so every worker
    has its next task queued while a result travels back, and no more (module doc)."""
    threads = sum(client.nthreads().values())
    return max(MIN_IN_FLIGHT, IN_FLIGHT_PER_THREAD * threads)


def run_on_cluster(
    client,
    base,
    driver,
    on_row: Callable[[dict, dict], None],
    *task_args,
    limit=None,
    warn=None,
    where="",
    cluster=None,
) -> None:
    """Run ``driver``'s points on ``client`` until it hands out no more; ``on_row(params, row)`` for each.
    ``task_args``: :func:`run_task`'s arguments after the point (stop_at_collapse, history_dir, force,
    study).
    At most ``limit`` tasks (default :func:`in_flight_limit`) are submitted at a time, the next one as
    each comes back. ``warn`` (if given) is told when the cluster has no worker for a while (:class:`~masonrycli.study.watch.WorkerWatch`;
    ``where`` names the cluster). ``cluster``: the LocalCluster the study owns, whose workers the watch starts
    again; left without any for ``NO_WORKER_LIMIT`` s, the runs not made are error rows saying why."""
    from concurrent.futures import CancelledError

    import cloudpickle
    from distributed import KilledWorker, as_completed

    from masonrycli.study import watch as watching
    from masonrycli.study.versions import check_result, make_task, this_version

    limit = limit or in_flight_limit(client)
    ours = this_version()
    keep, run = make_task()  # sent by value: a worker with another masonry, or none, answers (versions.py)
    # The base is a task, not scattered data: the scheduler keeps its spec and recomputes it on another
    # worker if the worker holding it dies (scattered data would be lost with its worker, and every task
    # depending on it cancelled). It travels pickled with the function that runs a point, opened on the
    # worker once its masonry is known to be this one.
    base_future = client.submit(keep, cloudpickle.dumps((run_task, base)), pure=False)
    waiting = deque(driver.start())
    pending = {}  # key -> (params, future)
    completed = as_completed()
    # Points whose workers died under them (KilledWorker), run again one at a time once nothing else runs. A
    # point that ends its worker process (out of memory, a crash) takes with it the tasks running beside it in
    # that process (a worker of several threads, `dask worker`'s default) and those whose results the worker had
    # not yet sent (it batches them every 2 ms); each such death counts against them as against it, and a good
    # point that died with it four times was an error row too (every time with 2 threads, 1 run in 4 with one).
    # Alone, a good point runs; the point that kills its workers does so again, and its row says so.
    killed: deque = deque()
    alone: set = set()  # keys of the tasks so run
    suspects: list = []  # the points whose workers died under them, for the reason below
    lock = threading.Lock()  # pending and gave_up, shared with the watch's give_up
    gave_up: list = []  # why the runs not made are error rows: the cluster was left without a worker

    def submit(points=waiting, most=limit):
        with lock:
            while points and len(pending) < most and not gave_up:
                params = points.popleft()
                future = client.submit(run, ours, base_future, params, *task_args, pure=False)
                pending[future.key] = params, future
                completed.add(future)
                if points is killed:
                    alone.add(future.key)

    def not_made() -> int:  # the runs submitted, waiting, or to run again alone
        return len(pending) + len(waiting) + len(killed)

    def give_up(deaths: int) -> None:  # from the watch's thread: the tasks in flight cancelled, the rest unsent
        named = "; ".join(", ".join(f"{k}={v}" for k, v in p.items()) for p in suspects[:3])
        named = f" (those running when they died: {named}{'; …' if len(suspects) > 3 else ''})" if suspects else ""
        times = "once" if deaths == 1 else f"{deaths} times"
        died = f" after its workers died {times}{named}" if deaths else ""
        why = f"no worker left: the local cluster had none for {watching.NO_WORKER_LIMIT:g} s{died}; not run"
        with lock:
            gave_up.append(why)
            cancel = [future for _, future in pending.values()]
        client.cancel(cancel, reason="no worker left")

    submit()
    with watching.WorkerWatch(client, warn, where, not_made, cluster, give_up if cluster is not None else None):
        while True:
            for future in completed:
                params = pending[future.key][0]
                # pending until fetched: a result lost with its worker is made again inside result() ("Couldn't
                # gather keys"), and with no worker left the study waited there, past give_up (CLI, 2026-11-29)
                try:
                    answer, worker, row = future.result()
                except Exception as exc:  # the task never returned (KilledWorker, a cluster failure)
                    if gave_up and isinstance(exc, CancelledError):
                        row = params | empty_result(gave_up[0], 0.0)
                    elif _scheduler_lost(client, exc):
                        raise SchedulerLost(
                            f"lost the connection to the scheduler with {counted(not_made(), 'run')} pending"
                        ) from None
                    elif isinstance(exc, KilledWorker) and future.key not in alone and not gave_up:
                        with lock:
                            del pending[future.key]
                        killed.append(params)  # run again alone (above)
                        suspects.append(params)
                        future.release()
                        submit()
                        continue
                    else:
                        row = params | empty_result(task_error(exc), 0.0)
                else:
                    check_result(answer, worker, params, ours)  # another masonry's row is not kept
                    if params in suspects:  # it ran alone: not the point that killed them
                        suspects.remove(params)
                with lock:
                    del pending[future.key]
                future.release()
                waiting.extendleft(reversed(driver.feed(params, row)))  # a search's next step first: its row sooner
                on_row(params, row)
                submit()
            if gave_up:  # every run not made says why, each fed to the driver (a search ends at an error)
                while killed or waiting:
                    params = (killed or waiting).popleft()
                    row = params | empty_result(gave_up[0], 0.0)
                    waiting.extendleft(reversed(driver.feed(params, row)))
                    on_row(params, row)
                return
            if not killed:
                return
            submit(killed, 1)  # nothing else in flight: the next one alone


def task_error(exc: Exception) -> str:
    """What a row's error column says of a task that never returned. Dask's KilledWorker text (the task's key,
    "Inspecting worker logs is often a good next step…", a URL) was cut at 300 characters before it said what
    had happened to the point: the worker processes running it died, one after the other."""
    from distributed import KilledWorker

    if isinstance(exc, KilledWorker):
        last = getattr(exc.last_worker, "address", exc.last_worker)
        return (
            f"KilledWorker: the worker process running this point died, on each of the {exc.allowed_failures + 1} "
            f"workers that tried it (the last {last}): out of memory, or a crash (the workers' logs say which)"
        )
    return f"{type(exc).__name__}: {exc}"


def run_serially(base, driver, on_row: Callable[[dict, dict], None], *task_args) -> None:
    """The same as :func:`run_on_cluster` in this process, one task after the other (``--workers 0``)."""
    from masonrycli.interrupt import raise_dropped

    queue = list(driver.start())
    while queue:
        params = queue.pop(0)
        row = run_task(base, params, *task_args)
        if row["status"] == "error":
            raise_dropped()  # a Ctrl-C inside numba's compiler (interrupt.py) failed the run: a stop, no row
        more = driver.feed(params, row)
        on_row(params, row)
        queue += more
        raise_dropped()  # one dropped there while the run went on: the row is kept, then the stop
