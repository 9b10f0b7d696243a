"""Whether a study's cluster still has a worker: :class:`WorkerWatch`, a thread beside the study's loop
(:func:`masonrycli.study.runner.run_on_cluster`) that says when every worker has gone and when one joins."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

NO_WORKER_WAIT = 10.0
"""s with runs pending and no worker on the scheduler before the study says it waits for one."""
WATCH_EVERY = 1.0
"""s between two looks at the scheduler's workers (:class:`WorkerWatch`)."""


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
        self.thread.join(WATCH_EVERY + 1.0)  # a look held by a dying scheduler is left to end with the process

    def _watch(self) -> None:
        since, said = None, False
        while not self.stop.wait(WATCH_EVERY):
            try:
                workers = len(self.client.nthreads())
            except Exception:  # noqa: BLE001 - a scheduler gone is the study's to report (SchedulerLost)
                continue
            if self.stop.is_set():
                return
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
