"""Whether a study's cluster still has a worker and a scheduler that answers: :class:`WorkerWatch`, a thread
beside the study's loop (:func:`masonrycli.study.runner.run_on_cluster`) that says when every worker has gone or
the scheduler has stopped answering, and when that ends."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

NO_WORKER_WAIT = 10.0
"""s with runs pending and no worker on the scheduler before the study says it waits for one."""
WATCH_EVERY = 1.0
"""s between two looks at the scheduler's workers (:class:`WorkerWatch`)."""
ASK_TIMEOUT = 5.0
"""s a look waits for the scheduler's answer."""
NO_ANSWER_WAIT = 30.0
"""s without an answer from the scheduler before the study says so."""


class WorkerWatch:
    """A thread that says when the cluster has had no worker for :data:`NO_WORKER_WAIT` s while runs wait,
    and when one joins again. Every worker of a ``--scheduler`` killed (``kill`` of the ``dask worker``
    command, a preempted machine) left the study waiting, silent, its bar still, until a worker joined:
    Dask keeps the tasks for the next worker, which is right (workers come back), but the user saw a hang
    (walk-through 2026-11-29: 180 s without a word, then killed). ``warn`` takes the lines."""

    def __init__(self, client, warn: Callable[[str], None], where: str, waiting: Callable[[], int]) -> None:
        self.client, self.warn, self.where, self.waiting = client, warn, where, waiting
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._watch, name="masonry-worker-watch", daemon=True)

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self.stop.set()
        self.thread.join(WATCH_EVERY + 1.0)  # a look held by a silent scheduler is left to end with the process

    def _watch(self) -> None:
        since = silent = None
        said = quiet = False
        while not self.stop.wait(WATCH_EVERY):
            try:
                workers = len(self.client.nthreads(callback_timeout=ASK_TIMEOUT))
            except TimeoutError:
                # a scheduler stopped (SIGSTOP, a suspended laptop) or cut off without a word (a firewall, a
                # cable): its connection stays open, nothing comes, and the study waited silent for as long
                # (walk-through 2026-11-29: 60 s without a line, then it went on when the scheduler did)
                silent = silent or time.monotonic() - ASK_TIMEOUT
                if not quiet and time.monotonic() - silent >= NO_ANSWER_WAIT and not self.stop.is_set():
                    quiet = True
                    self.warn(
                        f"{self.where}: the scheduler has not answered for {NO_ANSWER_WAIT:g} s (stopped, its "
                        f"machine overloaded or cut off?), {self.waiting()} runs waiting: the study goes on when it "
                        "answers (Ctrl-C stops it, every finished row written)"
                    )
                continue
            except Exception:  # noqa: BLE001 - a scheduler gone is the study's to report (SchedulerLost)
                continue
            if self.stop.is_set():
                return
            if quiet:
                self.warn(f"{self.where}: the scheduler answers again: the study goes on")
            silent, quiet = None, False
            if workers:
                if said:
                    self.warn(f"{self.where}: a worker joined: the study goes on")
                since, said = None, False
                continue
            since = since or time.monotonic()
            if not said and time.monotonic() - since >= NO_WORKER_WAIT:
                said = True
                self.warn(
                    f"{self.where}: no worker for {NO_WORKER_WAIT:g} s, {self.waiting()} runs waiting: the study "
                    "goes on when a worker joins (Ctrl-C stops it, every finished row written)"
                )
