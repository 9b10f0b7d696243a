"""A disk that fills while a command writes its output: one line naming the output, exit 4 (an output failed,
as simulate's), the previous file kept with --force, no temporary file left. export, report and build said
only "error: No space left on device" (or named the hidden .part file), exit 2 as bad input; limit --out
ended in rerun's RuntimeError, a traceback, exit 1. The disk is made full where the bytes are written."""

from __future__ import annotations

import errno
import os
from pathlib import Path

import pytest
from typer.testing import CliRunner

from masonrycli.cli.app import app

PREVIOUS = b"the previous file"


@pytest.fixture(scope="module")
def history(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("run") / "h.npz"
    result = CliRunner().invoke(
        app, ["simulate", "wall", "--duration", "0.02", "--no-recording", "--history", str(path)]
    )
    assert result.exit_code == 0, result.output
    return path


def one_line(result) -> str:
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in result.output, result.output
    return lines[0]


def kept(folder: Path, *names: str) -> None:
    for name in names:
        assert (folder / name).read_bytes() == PREVIOUS
    assert [p.name for p in folder.iterdir() if ".part" in p.name] == []


def previous(folder: Path, *names: str) -> None:
    for name in names:
        (folder / name).write_bytes(PREVIOUS)


def full_disk(*args, **kwargs):
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_export_on_a_full_disk(history, tmp_path, monkeypatch):
    import masonrycli.outputs.export as export

    monkeypatch.setattr(export, "write_csv", full_disk)
    previous(tmp_path, "h.csv")
    result = CliRunner().invoke(app, ["export", str(history), "--out", str(tmp_path / "h.csv"), "--force"])
    assert result.exit_code == 4
    assert one_line(result) == f"error: cannot write --out {tmp_path / 'h.csv'}: No space left on device"
    kept(tmp_path, "h.csv")


def test_report_on_a_full_disk(history, tmp_path, monkeypatch):
    monkeypatch.setattr(Path, "write_text", full_disk)  # the page, after its figure
    previous(tmp_path, "r.md", "r.png")
    result = CliRunner().invoke(app, ["report", str(history), "--out", str(tmp_path / "r.md"), "--force"])
    assert result.exit_code == 4
    assert one_line(result) == f"error: cannot write --out {tmp_path / 'r.md'}: No space left on device"
    assert (tmp_path / "r.md").read_bytes() == PREVIOUS


def test_build_on_a_full_disk(tmp_path, monkeypatch):
    monkeypatch.setattr(Path, "write_text", full_disk)
    previous(tmp_path, "w.geojson")
    result = CliRunner().invoke(app, ["build", "wall", "--out", str(tmp_path / "w.geojson"), "--force"])
    assert result.exit_code == 4
    assert one_line(result) == f"error: cannot write --out {tmp_path / 'w.geojson'}: No space left on device"
    kept(tmp_path, "w.geojson")


def test_limit_recording_on_a_full_disk(tmp_path, monkeypatch):
    import rerun as rr

    def save(*args, **kwargs):  # what rerun 0.2x raises when its file cannot be written
        raise RuntimeError("Failed to encode LogMsg: Failed to write: No space left on device (os error 28)")

    monkeypatch.setattr(rr.RecordingStream, "save", save)
    previous(tmp_path, "l.rrd")
    result = CliRunner().invoke(app, ["limit", "wall", "--out", str(tmp_path / "l.rrd"), "--force"])
    assert result.exit_code == 4
    assert one_line(result) == f"error: cannot write --out {tmp_path / 'l.rrd'}: No space left on device"
    kept(tmp_path, "l.rrd")
