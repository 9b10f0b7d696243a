"""masonrycli.sinks: the status words, and the one sink contract that the history and the recorder meet."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from masonrycli.history import History, HistoryFile
from masonrycli.sinks import COMPLETED, DIVERGED, FAILED, INTERRUPTED, RUNNING, STATUSES, FrameSink

README = Path(__file__).parent.parent / "README.md"


def test_the_status_words_are_the_documented_ones():
    """The README's history table names the words a closed output holds: all of them but "running"."""
    assert STATUSES == (RUNNING, COMPLETED, INTERRUPTED, DIVERGED, FAILED)
    row = next(ln for ln in README.read_text(encoding="utf-8").splitlines() if ln.startswith("| `block_name`"))
    closed = row.split("names; ", 1)[1].split(" (the words", 1)[0]
    assert re.findall(r"`(\w+)`", closed) == [s for s in STATUSES if s != RUNNING]


def test_a_sink_is_anything_with_on_frame_and_close():
    class Counter:
        def __init__(self):
            self.frames, self.closed = 0, None

        def on_frame(self, frame):
            self.frames += 1

        def close(self, status, note=""):
            self.closed = (status, note)

    class NoClose:
        def on_frame(self, frame):
            pass

    assert isinstance(Counter(), FrameSink) and not isinstance(NoClose(), FrameSink)
    assert not isinstance(object(), FrameSink)


def test_sinks_share_one_contract(tmp_path):
    from masonrycli.recording import Recorder

    hist = HistoryFile(tmp_path / "h.npz", ["a"], [])
    assert isinstance(hist, FrameSink) and isinstance(History(["a"], []), FrameSink)
    hist.close(INTERRUPTED, "stopped")
    h = np.load(tmp_path / "h.npz")
    assert (str(h["status"]), str(h["note"])) == ("interrupted", "stopped")
    assert all(callable(getattr(Recorder, name, None)) for name in ("on_frame", "close"))
