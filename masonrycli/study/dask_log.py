"""Dask's own log lines during a study go to a file beside the table, not to the terminal.

distributed logs to stderr from the command's process: its scheduler (a LocalCluster's runs in the command),
its nannies and its client. A worker that died under a point gave ``distributed.scheduler - ERROR - Task
run-2c2b… marked as failed because 4 workers died while trying to run it``, one such line a point, among
masonry's own lines (the progress, the warnings, the one-line error), which say the same for a user: the
row's error column names the point and why. Those lines are for whoever debugs the cluster; they are kept,
in ``<out>.dask.log`` (``study.csv.dask.log``, beside the journal), opened only when Dask has something to
say and appended to by a resumed study, and the study ends with one line naming the file and the first error.

The worker processes of the study's LocalCluster log at CRITICAL (:func:`masonrycli.study.runner.quiet_worker_logs`):
what they say is teardown noise, and a run's own errors come back in its row.
"""

from __future__ import annotations

import logging
import threading
from pathlib import Path

LOGGERS = ("distributed", "tornado", "bokeh")
"""The loggers distributed configures with a handler on stderr of their own (``distributed.config``)."""
LEVEL = logging.WARNING
"""Kept in the file from this level (a worker restarted is a warning, and explains the error after it)."""
FORMAT = "%(asctime)s - %(name)s - %(levelname)s - %(message)s"


def log_path(out: Path) -> Path:
    """Where a study writing ``out`` keeps Dask's log: ``study.csv`` → ``study.csv.dask.log``."""
    return out.with_name(out.name + ".dask.log")


class _ToFile(logging.Handler):
    """A handler that opens ``path`` (appending) at its first record, and counts the errors among them.
    Not a ``logging.StreamHandler``: a LocalCluster's ``silence_logs`` resets every StreamHandler's level."""

    def __init__(self, path: Path) -> None:
        super().__init__(LEVEL)
        self.path = path
        self.errors = 0
        self.first_error = ""
        self._file = None
        self._write = threading.Lock()  # records come from the cluster's IO thread and from this one
        self.setFormatter(logging.Formatter(FORMAT))

    def emit(self, record: logging.LogRecord) -> None:
        try:
            text = self.format(record)
            with self._write:
                if self._file is None:
                    self._file = open(self.path, "a", encoding="utf-8")  # noqa: SIM115 (closed in close())
                self._file.write(text + "\n")
                self._file.flush()
                if record.levelno >= logging.ERROR:
                    self.errors += 1
                    self.first_error = self.first_error or record.getMessage().splitlines()[0]
        except Exception:  # a log line that cannot be written (a full disk) is not the study's failure
            self.handleError(record)

    def close(self) -> None:
        with self._write:
            if self._file is not None:
                self._file.close()
                self._file = None
        super().close()


class DaskLog:
    """``with DaskLog(path) as log:`` Dask's loggers write to ``path`` instead of stderr; on the way out their
    handlers are as before. ``log.said()``: the line for the user when errors were logged, else None.

    distributed must be imported before (its import installs its stderr handler): :meth:`__enter__` does it."""

    def __init__(self, path: Path) -> None:
        self.handler = _ToFile(path)
        self._saved: list[tuple[logging.Logger, list, bool]] = []

    def __enter__(self) -> DaskLog:
        from masonrycli.study.runner import import_distributed

        import_distributed()  # its logging set up now, not inside the block over ours (a Ctrl-C raised after)

        for name in LOGGERS:
            logger = logging.getLogger(name)
            self._saved.append((logger, list(logger.handlers), logger.propagate))
            for handler in list(logger.handlers):
                logger.removeHandler(handler)
            logger.addHandler(self.handler)
            logger.propagate = False  # not to the root's handlers either (a host application's, pytest's)
        return self

    def __exit__(self, *exc) -> None:
        for logger, handlers, propagate in self._saved:
            logger.removeHandler(self.handler)
            for handler in handlers:
                logger.addHandler(handler)
            logger.propagate = propagate
        self._saved.clear()
        self.handler.close()

    def said(self) -> str | None:
        """One line naming the file and the first error ("Dask logged 2 errors …"), None without an error."""
        n = self.handler.errors
        if not n:
            return None
        first = self.handler.first_error
        first = first if len(first) <= 120 else first[:119] + "…"
        return (
            f"Dask logged {n} error{'' if n == 1 else 's'} ({first}): in {self.handler.path} (what became of each "
            "run is in its row)"
        )
