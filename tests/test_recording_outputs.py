"""The recording as an output: a failed write stops the run (exit 4, never "completed"), a file without its
footer is noticed at close, and ``inspect`` reads a truncated file up to its last complete chunk."""

from __future__ import annotations

import errno
import os
import shutil

import numpy as np
import pytest
from typer.testing import CliRunner

import masonrycli.recording.batching as batching
from masonrycli.cli.app import app
from masonrycli.recording.readback import check_complete, inspect_recording

from cli_helpers import words


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    rrd = tmp_path_factory.mktemp("rec") / "w.rrd"
    with pytest.MonkeyPatch.context() as mp:  # a send every 100 frames: a file cut at a third holds some
        mp.setattr(batching, "LONG_BATCH_BLOCK_FRAMES", 0)  # batches of batch_frames (100) throughout
        result = invoke("simulate", "wall", "--duration", 0.3, "--record-every", 1, "--out", rrd)
    assert result.exit_code == 0, result.output
    return rrd


def test_full_disk_at_the_recorder_stops_the_run(tmp_path, monkeypatch):
    """Finding 3: disk full while recording exited 0 with "completed" and an unreadable .rrd. Rerun's writer
    reports ENOSPC as a RuntimeError from its flush: injected there, the run stops with exit 4, one line
    naming the file and the cause, the history kept (status "failed"), no temporary file."""
    from masonrycli.recording.recorder import Recorder

    original = Recorder.flush

    def full_disk(self):
        if self._frames > 150:
            raise RuntimeError("Failed to encode LogMsg: Failed to write: No space left on device (os error 28)")
        original(self)

    monkeypatch.setattr(Recorder, "flush", full_disk)
    monkeypatch.setattr(batching, "LONG_BATCH_BLOCK_FRAMES", 0)  # a send at frame 201: the disk fills mid-run
    rrd, npz = tmp_path / "w.rrd", tmp_path / "h.npz"
    result = invoke("simulate", "wall", "--duration", 0.3, "--record-every", 1, "--out", rrd, "--history", npz)
    assert result.exit_code == 4, result.output
    assert "completed" not in result.output
    line = next(ln for ln in result.output.splitlines() if ln.startswith("error:"))
    assert line.startswith(f"error: cannot write --out {rrd}: ") and line.endswith("No space left on device"), line
    assert not rrd.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["h.npz"]
    h = np.load(npz)
    assert str(h["status"]) == "failed" and 150 <= h["step"][-1] <= 300


def test_a_recording_without_footer_is_noticed(recording, tmp_path):
    check_complete(recording)  # a whole file passes
    cut = tmp_path / "cut.rrd"
    cut.write_bytes(recording.read_bytes()[: recording.stat().st_size * 2 // 3])
    with pytest.raises(OSError) as info:
        check_complete(cut)
    assert info.value.errno == errno.EIO and "incomplete on disk" in str(info.value)


def test_inspect_reads_a_truncated_recording(recording, tmp_path):
    """Finding 9: `masonry inspect` could not read a truncated recording — the file a kill or a full disk leaves."""
    whole = inspect_recording(recording)
    # 301 frames: steps 0 … 300 (the initial state, as built, then every step)
    assert whole["frames"] == 301 and whole["complete"] and not whole["truncated"]
    cut = tmp_path / "cut.rrd"
    with open(recording, "rb") as src, open(cut, "wb") as dst:
        # a third: the last third holds the magnified shape, written when the recorder closes
        dst.write(src.read(recording.stat().st_size // 3))
    info = inspect_recording(cut)
    assert info["truncated"] and not info["complete"] and 0 < info["frames"] < whole["frames"]
    assert info["steps"] == (0, info["frames"] - 1)
    result = invoke("inspect", cut)
    assert result.exit_code == 0, result.output
    assert f"truncated (its writer did not finish: killed, or the disk was full) — {info['frames']} frames" in (
        words(result.output)
    )
    # walk-through 2026-11-28: the temporary file of a run still going was said to be of a killed writer
    live = tmp_path / f".run.rrd.{os.getpid()}.part"
    os.replace(cut, live)
    result = invoke("inspect", live)
    assert result.exit_code == 0, result.output
    assert f"truncated (a run still going (pid {os.getpid()}) writes it) — {info['frames']} frames" in (
        words(result.output)
    )
    # and its target, not there until the run ends, was "no such recording"
    result = invoke("inspect", tmp_path / "run.rrd")
    assert words(result.output) == (
        f"error: {tmp_path / 'run.rrd'}: not there yet: a run still going (pid {os.getpid()}) writes it as "
        f"{live.name}, renamed to it when the run ends; masonry inspect {live} shows it so far"
    )
    assert result.exit_code == 2
    shutil.rmtree(tmp_path)


def test_recorder_writes_to_the_file_every_second(tmp_path, monkeypatch):
    """Finding 5: frames reached the file only every 100 frames (0 frames for the first 1000 steps). Once the
    first batch has fixed the scales, a frame is written as soon as FLUSH_SECONDS have passed."""
    import masonrycli.recording.recorder as recorder

    import recording_fixtures as fx

    static, q0 = fx.wall()
    frames = fx.frames(static, q0, 104)
    path = tmp_path / "r.rrd"
    rec = recorder.Recorder(path, static, fx.METADATA, batch_frames=100)
    for frame in frames[:101]:  # the first batch (the initial frame and 100 more): written, fixes every scale
        rec.on_frame(frame)
    assert rec._scales_fixed()
    size = path.stat().st_size
    rec.on_frame(frames[101])  # less than FLUSH_SECONDS later: buffered
    assert path.stat().st_size == size
    monkeypatch.setattr(batching, "FLUSH_SECONDS", 0.0)
    rec.on_frame(frames[102])  # FLUSH_SECONDS have passed: on disk now, with the frame before
    assert path.stat().st_size > size
    copy = tmp_path / "copy.rrd"  # what a SIGKILL now would leave: no footer, 103 frames
    shutil.copyfile(path, copy)
    assert inspect_recording(copy)["frames"] == 103
    rec.on_frame(frames[103])
    rec.close()
    assert inspect_recording(path)["frames"] == 104


_LIMITED = """
import resource, runpy, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG, as on a full disk
import masonrycli.recording.readback as readback
readback.WRITE_STALL_SECONDS = 1.0  # a stopped writer found sooner (5 s in a real run)
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
sys.argv = ["masonry", *sys.argv[2:]]
runpy.run_module("masonrycli", run_name="__main__")
"""


def test_a_recording_whose_writes_fail_at_the_end_is_an_error_not_a_hang(tmp_path):
    """rerun's file writer stops at its first failed write and never answers again: the recorder's final
    disconnect (and the stream's __del__, and rerun's exit handler) then waited for it forever, the command
    hung after its summary (4 of 9 runs with limits between 560 and 680 kB: a race in rerun, so four limits
    are tried there). Here every file the command writes
    is limited in size (RLIMIT_FSIZE, in a process of its own: the writes fail with EFBIG as on a full
    disk) below the recording's size and above the history's: the command ends with exit 4 and one error
    line naming --out, leaves no .rrd and no temporary file, and its history holds every frame of a run
    without the limit."""
    import subprocess
    import sys

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    args = ["simulate", "wall", "--duration", "0.3", "--out", "w.rrd", "--history", "h.npz"]
    ref = tmp_path / "ref"
    ref.mkdir()
    done = subprocess.run([sys.executable, "-m", "masonrycli", *args], cwd=ref, capture_output=True, text=True,
                          env=dict(os.environ, PYTHONPATH=root), timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    rrd_size, npz_size = (ref / "w.rrd").stat().st_size, (ref / "h.npz").stat().st_size
    assert npz_size < 0.6 * rrd_size  # 581 and 1033 kB at 87f3ff3
    reference = np.load(ref / "h.npz")
    for k, share in enumerate((0.6, 0.62, 0.64, 0.66, 0.9)):  # 0.9: in the last message, found by its footer
        limit = int(share * rrd_size)
        run = tmp_path / f"limit{k}"
        run.mkdir()
        done = subprocess.run([sys.executable, "-c", _LIMITED, str(limit), *args], cwd=run, capture_output=True,
                              text=True, env=dict(os.environ, PYTHONPATH=root), timeout=30)  # fmt: skip
        assert done.returncode == 4, (limit, done.stdout[-2000:], done.stderr[-2000:])
        lines = [ln for ln in done.stderr.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("error: cannot write --out w.rrd: "), done.stderr
        assert "incomplete" in lines[0] and "Traceback" not in done.stdout + done.stderr
        assert sorted(p.name for p in run.iterdir()) == ["h.npz"]
        history = np.load(run / "h.npz")
        assert str(history["status"]) == "failed"  # the run's outputs failed; its frames are all there
        for key in ("step", "time", "block_q", "block_v", "cell_stress"):
            assert np.array_equal(history[key], reference[key], equal_nan=True), key  # the same bits: NaN at t = 0
