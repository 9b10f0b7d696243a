"""The frame benchmark's check that two revisions wrote the same outputs (benchmarks/bench_frames.py,
masonrycli.recording.readback.recording_rows): the same command twice gives the same rows and arrays, a
different one does not."""

from __future__ import annotations

import os

from benchmarks import bench_frames
from masonrycli.cli.app import app

os.environ.setdefault("RERUN_ANALYTICS", "0")


def _run(stem, duration: str) -> None:
    files = ["--out", f"{stem}.rrd", "--history", f"{stem}.npz", "--force"]
    app(["simulate", "wall", "--duration", duration, "--record-every", "5", *files], standalone_mode=False)


def test_same_outputs_tells_equal_runs_from_different_ones(tmp_path):
    a, b, c = (str(tmp_path / name) for name in "abc")
    _run(a, "0.03")
    _run(b, "0.03")  # another start time and wall time: masked
    _run(c, "0.04")
    assert bench_frames.same_outputs(a, b) == {"history": True, "recording": True, "differ": []}
    other = bench_frames.same_outputs(a, c)
    assert not other["history"] and not other["recording"]
    assert "/structure/fill" in other["differ"] and "static /run/metadata" in other["differ"]


def test_same_outputs_leaves_out_the_code_that_wrote_them(tmp_path, monkeypatch):
    # two revisions compared write two commits and source digests (run document, history "run"): not a difference
    import masonrycli.execute as execute

    a, b = (str(tmp_path / name) for name in "ab")
    monkeypatch.setattr(execute, "source_commit", lambda: "1111111")
    _run(a, "0.01")
    monkeypatch.setattr(execute, "source_commit", lambda: "2222222+changes")
    monkeypatch.setattr(execute, "SOURCE_DIGEST", "0123456789ab")
    _run(b, "0.01")
    assert bench_frames.same_outputs(a, b) == {"history": True, "recording": True, "differ": []}
