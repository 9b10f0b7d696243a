"""Whether a study's cluster still has a worker and a scheduler that answers: :class:`WorkerWatch`, a thread
beside the study's loop (:func:`masonrycli.study.runner.run_on_cluster`) that says when every worker has gone or
the scheduler has stopped answering, and when that ends. On the LocalCluster the study owns it also starts again
a worker Dask dropped, and gives the runs up when no worker comes back: the study ends, it never hangs."""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable

from masonrycli.outputs.verdict import counted

NO_WORKER_WAIT = 10.0
"""s with runs pending and no worker on the scheduler before the study says it waits for one."""
WATCH_EVERY = 1.0
"""s between two looks at the scheduler's workers (:class:`WorkerWatch`)."""
ASK_TIMEOUT = 5.0
"""s a look waits for the scheduler's answer."""
NO_ANSWER_WAIT = 30.0
"""s without an answer from the scheduler before the study says so."""
STARTING_WAIT = 15.0
"""s a worker this watch started again counts as still starting: twice the slowest start measured (7.1 s beside
three busy loops, :data:`NO_WORKER_LIMIT`). One Dask drops again before any look sees it is then replaced at the
first look after it (it would otherwise stay "starting" for ever, and the study give up at the limit)."""
NO_WORKER_LIMIT = 60.0
"""s the study's own LocalCluster may have no worker, runs waiting, before the study gives them up (error rows
that the same command runs again). A worker process started again in 1.3 s on a quiet machine and in up to 7.1 s
beside three busy loops on 2 cores (tests/test_sweep_cluster_lost_workers.py's scenario, 2026-11-29): 60 s is
eight times that, and a minute is as long as a user should wait without an answer. A ``--scheduler``'s workers
are someone else's to start (a batch queue may take an hour): there the study waits, and says so."""


class WorkerWatch:
    """A thread that says when the cluster has had no worker for :data:`NO_WORKER_WAIT` s while runs wait,
    and when one joins again. Every worker of a ``--scheduler`` killed (``kill`` of the ``dask worker``
    command, a preempted machine) left the study waiting, silent, its bar still, until a worker joined:
    Dask keeps the tasks for the next worker, which is right (workers come back), but the user saw a hang
    (walk-through 2026-11-29: 180 s without a word, then killed). ``warn`` takes the lines (None: unsaid).

    ``cluster``: the LocalCluster the study owns. Dask's own SpecCluster drops a worker for good when it is
    not back ``distributed.deploy.lost-worker-timeout`` (15 s) after *a* loss, timed from that loss: a worker
    that died again meanwhile and was restarting then is closed, its nanny with it, and none replaces it. On a
    loaded machine (three busy loops on 2 cores) a point that killed its worker left the cluster without any,
    after its 3rd or 4th death, 22-40 s in, in 3 runs of 3, and the study waited forever. The watch starts such
    a worker again, or one whose nanny closed, at its next look (:meth:`_restore`); and if the cluster still has no worker
    :data:`NO_WORKER_LIMIT` s on, it calls ``give_up(deaths)`` once (the workers the scheduler said left) and
    stops."""

    def __init__(self, client, warn, where: str, waiting: Callable[[], int], cluster=None, give_up=None) -> None:
        self.client, self.where, self.waiting = client, where, waiting
        self.warn = warn or (lambda line: None)
        self.cluster, self.give_up = cluster, give_up
        self.size = len(cluster.worker_spec) if cluster is not None else 0  # the workers the study asked for
        self.asked: dict = {}  # name -> time.monotonic() this watch started it again, until Dask lists it
        self.restarts = 0
        self.joined = self.left = 0  # workers the scheduler said joined, left (:meth:`_event`)
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._watch, name="masonry-worker-watch", daemon=True)

    def __enter__(self):
        if self.give_up is not None:
            # A worker that registers and dies between two looks is never seen by them: beside three busy loops a
            # point that killed its workers had each live about a second, and the looks alone could see none for
            # 60 s while one came every few seconds (a run of the kill-its-worker test ended at 64 s, its good
            # point an error row). The scheduler tells each worker that comes or goes.
            self.client.subscribe_topic("all", self._event)
        self.thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self.stop.set()
        if self.give_up is not None:
            with contextlib.suppress(Exception):  # a scheduler gone (SchedulerLost) has no topic left
                self.client.unsubscribe_topic("all")
        self.thread.join(WATCH_EVERY + 1.0)  # a look held by a silent scheduler is left to end with the process

    def _event(self, event) -> None:
        """Counts the workers that joined and left, told by the scheduler (in the client's loop)."""
        action = event[1].get("action") if isinstance(event[1], dict) else None
        if action == "add-worker":
            self.joined += 1
        elif action == "remove-worker":
            self.left += 1

    def _watch(self) -> None:
        since = silent = None
        said = quiet = False
        joined = 0
        while not self.stop.wait(WATCH_EVERY):
            try:
                workers = set(self.client.nthreads(callback_timeout=ASK_TIMEOUT))
            except TimeoutError:
                # a scheduler stopped (SIGSTOP, a suspended laptop) or cut off without a word (a firewall, a
                # cable): its connection stays open, nothing comes, and the study waited silent for as long
                # (walk-through 2026-11-29: 60 s without a line, then it went on when the scheduler did)
                silent = silent or time.monotonic() - ASK_TIMEOUT
                if not quiet and time.monotonic() - silent >= NO_ANSWER_WAIT and not self.stop.is_set():
                    quiet = True
                    self.warn(
                        f"{self.where}: the scheduler has not answered for {NO_ANSWER_WAIT:g} s (stopped, its "
                        f"machine overloaded or cut off?), {counted(self.waiting(), 'run')} waiting: the study goes on when it "
                        "answers (Ctrl-C stops it, every finished row written)"
                    )
                continue
            except Exception:  # noqa: BLE001 - a scheduler gone is the study's to report (SchedulerLost)
                continue
            if self.stop.is_set():
                return
            came, joined = self.joined != joined, self.joined  # one came since the last look, if gone again
            if self.cluster is not None:
                self._restore()
            if quiet:
                self.warn(f"{self.where}: the scheduler answers again: the study goes on")
            silent, quiet = None, False
            if workers or came:
                if said:
                    self.warn(f"{self.where}: a worker joined: the study goes on")
                since, said = None, False
                continue
            since = since or time.monotonic()
            if not said and time.monotonic() - since >= NO_WORKER_WAIT:
                said = True
                self.warn(
                    f"{self.where}: no worker for {NO_WORKER_WAIT:g} s, {counted(self.waiting(), 'run')} waiting: "
                    + self._plan()
                )
            if self.give_up is not None and time.monotonic() - since >= NO_WORKER_LIMIT and self.waiting():
                self.give_up(self.left)
                return

    def _plan(self) -> str:
        if self.cluster is None:  # someone else's workers: one may join at any time
            start = ""
            if self.where.startswith("--scheduler "):
                start = f"`dask worker {self.where.removeprefix('--scheduler ')}` starts one; "
            return f"the study goes on when a worker joins ({start}Ctrl-C stops it, every finished row written)"
        return (
            f"if none starts within {NO_WORKER_LIMIT:g} s, they are given up (error rows, which the same command "
            "runs again)"
        )

    def _restore(self) -> None:
        """Replace each worker of the study's LocalCluster that is gone for good: one Dask dropped (in its
        ``worker_spec``, not in its ``workers``, and not one this watch asked for, still starting) or whose
        nanny closed (it failed to start its worker again). Each comes under a name never used: under its old
        one, Dask's loop neither closed the old nanny nor started a new one (both are named by the spec), and
        the study waited for its limit (a closed nanny, 2026-11-29: 60 s, then every run left an error row)."""
        from distributed.core import Status

        cluster = self.cluster
        workers = dict(cluster.workers)
        now = time.monotonic()
        self.asked = {n: t for n, t in self.asked.items() if n not in workers and now - t < STARTING_WAIT}
        gone = [
            name
            for name in list(cluster.worker_spec)
            if (name not in workers and name not in self.asked)
            or (name in workers and workers[name].status in (Status.closed, Status.failed))
        ]
        if not gone or self.stop.is_set():
            return
        for name in gone:
            self.restarts += 1
            cluster.worker_spec.pop(name, None)
            cluster.worker_spec[f"again-{self.restarts}"] = cluster.new_spec  # as SpecCluster.new_worker_spec
            self.asked[f"again-{self.restarts}"] = now
        # Dask's loop closes the nannies no longer asked for and starts the new ones (``scale`` to the spec's own
        # size adds and removes nothing: it is the public way to ask for that correction; distributed's private
        # ``_correct_state`` is free to change in any release); one that fails to start is closed, and replaced
        # at a later look.
        cluster.scale(len(cluster.worker_spec))
