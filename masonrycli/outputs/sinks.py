"""What a run hands its frames to, and the words that say how a run ended.

A sink is anything with ``on_frame(frame)`` and ``close(status, note)``: the history file and the Rerun
recorder are the two the command line uses. ``status`` is one of :data:`STATUSES` — the same words in
the history's ``status`` array, the recording's run document and the summary table.
"""

from __future__ import annotations

from typing import Final, Protocol, runtime_checkable

from masonrycli.outputs.frame import Frame

RUNNING: Final = "running"
COMPLETED: Final = "completed"
INTERRUPTED: Final = "interrupted"
DIVERGED: Final = "diverged"
FAILED: Final = "failed"
STATUSES: Final = (RUNNING, COMPLETED, INTERRUPTED, DIVERGED, FAILED)
"""running: not closed yet · completed: reached the end · interrupted: stopped by Ctrl-C, SIGTERM or SIGHUP ·
diverged: stopped on a non-physical state · failed: an engine error or an output that could not be written."""


@runtime_checkable
class FrameSink(Protocol):
    """Receives every recorded frame, then one ``close``."""

    def on_frame(self, frame: Frame) -> None:
        """Take one frame. Its arrays are its own (``Simulation.frame`` copies the engine's buffers, which the
        engine reuses) and nobody modifies them afterwards: a sink keeps what it needs without copying."""

    def close(self, status: str, note: str = "") -> None:
        """Finish the output; ``status`` is one of :data:`STATUSES`, ``note`` one line (may be empty)."""
