"""masonrycli.outputs.sinks: the status words, and the one sink contract that the history and the recorder meet."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from masonrycli.outputs.history import History, HistoryFile
from masonrycli.outputs.sinks import COMPLETED, DIVERGED, FAILED, INTERRUPTED, RUNNING, STATUSES, FrameSink

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


def test_a_frames_arrays_are_its_own():
    """FrameSink: sinks keep a frame's arrays without copying, so no two frames share memory (the engine
    reuses its buffers) and a frame is unchanged by the steps after it."""
    from masonrycli.run import Simulation
    from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

    sim = Simulation(scenario_from_builder("wall", {"blocks": 51}, RunConfig(duration=0.02), Material(), {}))
    for _ in range(3):
        sim.step()
    first = sim.frame()

    def arrays(frame):
        fields = {k: v for k, v in vars(frame).items() if isinstance(v, np.ndarray) and k != "joint_body"}
        return fields | {f"tensors.{k}": v for k, v in frame.tensors.items()}

    kept = {k: v.copy() for k, v in arrays(first).items()}
    for _ in range(5):
        sim.step()
    later = arrays(sim.frame())
    for name, value in arrays(first).items():
        assert np.array_equal(value, kept[name], equal_nan=value.dtype.kind == "f"), name
        assert not any(np.shares_memory(value, other) for other in later.values()), name
    assert not np.array_equal(first.block_q, later["block_q"])
