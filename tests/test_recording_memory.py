"""The recorder's memory does not grow with the run: the magnified view's poses wait in an anonymous file,
the steps' solver health is sent every ``STEP_BATCH`` steps; the magnified rows are those of every frame
kept in memory (restated here), also for an interrupted run."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import masonrycli.recording.batching as batching
from masonrycli.analysis.joint_forces import magnification
from masonrycli.recording import Recorder
from masonrycli.recording.readback import recording_rows

import recording_fixtures as fx
from recording_fixtures import strict_rerun, temporal_rows  # noqa: F401 (strict_rerun: autouse)

MAGNIFIED = "/structure/plane/xy/magnified"


class _Stats:
    iterations, residual, contact_count = 3, 1e-6, 7


@pytest.fixture(scope="module")
def wall():
    return fx.wall()


_MEASURE = """
import dataclasses, gc, json, os, sys, tracemalloc
sys.path[:0] = {paths!r}
import recording_fixtures as fx
import masonrycli.recording.batching as batching
import masonrycli.recording.recorder as recorder

class Stats:
    iterations, residual, contact_count = 3, 1e-6, 7

def traced_after(start, count):
    for i in range(start, start + count):
        rec.log_frame(dataclasses.replace(frames[i % len(frames)], step=10 * i, time=1e-2 * i))
    gc.collect()
    return tracemalloc.get_traced_memory()[0]

static, q0 = fx.wall()
frames = fx.frames(static, q0, 20)
# batches of 50 throughout, by count only (no send by time on a loaded machine): the buffer is empty at both
# readings (1 + 8 x 50 and 1 + 32 x 50 frames); what a batch holds while buffered is not what this measures
batching.FLUSH_SECONDS = 1e9
rec = recorder.Recorder({path!r}, static, fx.METADATA, batch_frames=50, long_batch_frames=50)
first = traced_after(0, 401)  # past the first batches (scales fixed)
later = traced_after(401, 1200)
for i in range(batching.STEP_BATCH):
    rec.log_step(i, 1e-3 * i, Stats)
steps_first = tracemalloc.get_traced_memory()[0]
for i in range(batching.STEP_BATCH, 5 * batching.STEP_BATCH):
    rec.log_step(i, 1e-3 * i, Stats)
steps_later = tracemalloc.get_traced_memory()[0]
rec.close()
print(json.dumps({{"frame": (later - first) / 1200, "step": (steps_later - steps_first) / (4 * batching.STEP_BATCH)}}))
sys.stdout.flush()
os._exit(0)  # tracemalloc is never stopped: stopping it while rerun's threads run can crash CPython 3.11
"""


def test_memory_held_per_frame_and_per_step_does_not_grow(tmp_path):
    """Python memory held by the recorder, N frames then 4N: was ~600 bytes a frame (each frame's poses kept
    for the magnified view, 15 blocks) and ~190 bytes a step (solver health buffered until the next frame).
    Measured in a fresh process traced from its start (``PYTHONTRACEMALLOC``)."""
    here = os.path.dirname(os.path.abspath(__file__))
    script = _MEASURE.format(paths=[here, os.path.dirname(here)], path=str(tmp_path / "x.rrd"))
    env = {**os.environ, "RERUN_ANALYTICS": "0", "PYTHONTRACEMALLOC": "1"}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 0, done.stderr
    held = json.loads(done.stdout.splitlines()[-1])
    assert held["frame"] < 60, f"{held['frame']:.0f} bytes a frame"
    assert held["step"] < 10, f"{held['step']:.0f} bytes a step"
    assert os.listdir(tmp_path) == ["x.rrd"]


@pytest.mark.parametrize("interrupted", [False, True])
def test_magnified_rows_are_every_frame_kept_in_memory(wall, tmp_path, monkeypatch, interrupted):
    """The initial frame, every other computed frame and the last, magnified by the factor of their largest
    displacement, as the recorder drew them when it held every pose (float32) in a list; no file but the
    recording in the output's folder, during the run (the spool has no name) and after it."""
    static, q0 = wall
    monkeypatch.setattr(batching, "STEP_BATCH", 7)  # steps sent on their own too: the same rows
    frames = fx.frames(static, q0, 26)
    path = tmp_path / "m.rrd"
    with pytest.raises(KeyboardInterrupt) if interrupted else _no_error():
        with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
            for f in frames:
                rec.log_frame(f)
                rec.log_step(f.step, f.time, _Stats)
            assert os.listdir(tmp_path) == ["m.rrd"]
            if interrupted:
                raise KeyboardInterrupt
    assert os.listdir(tmp_path) == ["m.rrd"]
    kept = [frames[0], *frames[1:-1][::2], frames[-1]]
    ref = frames[0].block_q
    q = [np.asarray(f.block_q, np.float32).astype(np.float64) for f in kept]
    # the fixture's one ground moves: the displacement relative to it is magnified (magnified.py)
    g = [np.append(np.asarray(f.support_q, np.float32)[0, :2] - frames[0].support_q[0, :2], 0.0) for f in kept]
    m = magnification(
        np.stack(q)[..., :2] - ref[None, :, :2] - np.stack(g)[:, None, :2], rec._size
    )  # the structure's size, as the recorder took it
    assert rec.magnify == m
    rows = temporal_rows(path, MAGNIFIED, "LineStrips2D:strips")
    assert sorted(rows) == [f.step for f in kept]
    for f, qf, gf in zip(kept, q, g):
        drawn = ref + gf + m * (qf - ref - gf)
        for b in (0, len(static.block_name) - 1):
            s, e = static.block_vert_start[b], static.block_vert_start[b + 1]
            c, sn = np.cos(drawn[b, 2]), np.sin(drawn[b, 2])
            outline = drawn[b, :2] + static.block_vert_local[s:e] @ np.array([[c, -sn], [sn, c]]).T
            np.testing.assert_allclose(np.array(rows[f.step][b])[:-1], outline, rtol=0, atol=1e-6)
    residual = temporal_rows(path, "/series/solver/log10_residual", "Scalars:scalars")
    assert sorted(residual) == [f.step for f in frames]


class _no_error:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_a_full_disk_under_the_spool_still_leaves_a_complete_recording(wall, tmp_path, monkeypatch):
    """The poses' file is written on the output's disk: a write failing there (ENOSPC when its buffer goes
    out at close) stops the run as an output failure, and the recording still gets its footer."""
    from masonrycli.recording.magnified import PoseSpool
    from masonrycli.recording.readback import inspect_recording

    def full(self, first, stop):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(PoseSpool, "read", full)
    monkeypatch.setattr(PoseSpool, "close", lambda self: full(self, 0, 0))
    static, q0 = wall
    path = tmp_path / "full.rrd"
    with pytest.raises(OSError, match="No space left"):
        with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
            for f in fx.frames(static, q0, 9):
                rec.log_frame(f)
    assert inspect_recording(path)["complete"]


@pytest.mark.parametrize("interrupted", [False, True])
def test_long_batches_once_the_scales_are_fixed(wall, tmp_path, monkeypatch, interrupted):
    """The first batch fixes the scales (``batch_frames``); after it, ``long_batch_frames`` a batch (rerun's
    index of the chunks written, kept for the footer, grows by batch sent), with the same rows as batches of
    ``batch_frames`` throughout, for a finished and for an interrupted run."""
    monkeypatch.setattr(batching, "FLUSH_SECONDS", 1e9)  # by frame count only, however slow the machine
    static, q0 = wall
    frames = fx.frames(static, q0, 31)
    rows, sent = {}, []
    original = Recorder._send_batch

    def send_batch(self, b):
        if self.long_batch_frames == 12:
            sent.append(len(b["step"]))
        original(self, b)

    monkeypatch.setattr(Recorder, "_send_batch", send_batch)
    for long in (4, 12):
        path = tmp_path / f"b{long}.rrd"
        with pytest.raises(KeyboardInterrupt) if interrupted else _no_error():
            with Recorder(path, static, fx.METADATA, batch_frames=4, long_batch_frames=long) as rec:
                for f in frames:
                    assert rec._batch_size() == (long if rec._scales_fixed() else 4)
                    rec.log_frame(f)
                if interrupted:
                    raise KeyboardInterrupt
        rows[long] = recording_rows(path)
    assert sent == [5, 12, 12, 2]  # the initial frame and 4 (scales fixed), then 12 a batch, the rest at close
    assert rows[12] == rows[4]
    with Recorder(tmp_path / "d.rrd", static, fx.METADATA) as rec:
        assert rec.long_batch_frames == batching.LONG_BATCH_BLOCK_FRAMES // len(static.block_name)  # the default


def test_rows_of_a_time_with_a_nanosecond_remainder(wall, tmp_path):
    """recording_rows read sim_time through datetime.timedelta (microseconds): 1.024999999 s raised
    (found comparing the rows of `simulate wall --duration 2`); durations are compared as ns now."""
    import dataclasses

    static, q0 = wall
    frames = fx.frames(static, q0, 3)
    path = tmp_path / "ns.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=2) as rec:
        for i, f in enumerate(frames):
            rec.log_frame(dataclasses.replace(f, time=[0.0, 1.024999999, 1.025][i]))
    rows = [r for rows in recording_rows(path).values() for r in rows]
    assert any("('sim_time', 1024999999)" in row for row in rows), rows[0][:300]


def test_the_ground_is_taken_out_only_when_every_support_moves_with_it(tmp_path):
    """Both foundations shaken alike: one translation, taken out of the magnified displacement; the arch's right
    foundation settling beside the fixed left one: the structure's displacement is magnified as it is."""
    from masonrycli.recording.magnified import PoseSpool, _supports_move_together

    ref_sq = np.array([[-2.0, -0.25, 0.0], [2.0, -0.25, 0.0]])
    for moves, together in (([0.05, 0.05], True), ([0.0, -0.01], False)):
        spool = PoseSpool(str(tmp_path), 1, 2)
        for k in range(5):
            sq = ref_sq.copy()
            sq[:, 0 if together else 1] += np.array(moves) * k
            spool.append(10 * k, 0.01 * k, np.zeros((1, 3)), sq - ref_sq)  # the spool holds displacements
        assert _supports_move_together(spool, ref_sq, 4.0, batch_frames=2) is together
        spool.close()
