"""Output files: nothing overwritten without --force, default names that never collide, paths checked
before step 1, temporary files renamed into place, and the findings of issue 11 about them."""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from masonrycli.cli.app import app
from masonrycli.outputs.files import (
    OutputFile,
    being_written,
    default_recording_path,
    free_name,
    open_part,
    part_path,
    part_writer,
    safe_name,
)

from cli_helpers import words

DATA = Path(__file__).parent / "data"
COLUMN = DATA / "validation" / "column5.toml"


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob("*") if ".part" in p.name)


@pytest.mark.parametrize(
    "name, stem",
    [
        ("../../x", "x"),
        ("a b/c", "a-b-c"),
        ("..", "run"),
        ("wall", "wall"),
        ("/etc/passwd", "etc-passwd"),
        # a letter is a letter: "voûte-arles" was written recordings/vo-te-arles-….rrd, "mur-é" mur-….rrd
        ("voûte-arles", "voûte-arles"),
        ("mur-é", "mur-é"),
        ("🧱", "run"),
    ],
)
def test_safe_name_stays_in_its_folder(name, stem):
    assert safe_name(name) == stem
    assert Path("recordings", safe_name(name)).resolve().parent == Path("recordings").resolve()


def test_safe_name_is_at_most_80_bytes_of_whole_characters():
    # 80 characters of a CJK name were 240 bytes: recordings/<name>-<stamp>.rrd and its temporary name passed
    # the file system's 255
    assert safe_name("墙" * 100) == "墙" * 26  # 78 bytes: a 27th (81) would pass 80
    assert safe_name("a" * 100) == "a" * 80


@pytest.mark.parametrize("size", [248, 260])
def test_a_name_too_long_for_its_temporary_name_is_bad_input(size, tmp_path):
    # walk-through 2026-11-28: --out a{248}.rrd is a valid name, but its .NAME.<pid>.part is not: "internal error:
    # OSError: [Errno 36] File name too long" (exit 1), removing the temporary file never made raising again;
    # a{260}.rrd said "a….rrd: File name too long" without the option
    for option in ("--out", "--history"):
        path = tmp_path / ("a" * size + (".rrd" if option == "--out" else ".npz"))
        extra = () if option == "--out" else ("--no-recording",)
        result = invoke("run", COLUMN, "--duration", 0.01, option, path, *extra)
        assert result.exit_code == 2, result.output
        assert words(result.output) == (
            f"error: {option} {path}: the file name is {size + 4} bytes long, at most 236 here (it is written "
            "under a temporary name .NAME.<pid>.part first; the file system allows 255)"
        )
        assert list(tmp_path.iterdir()) == []


def test_discarding_a_temporary_file_never_made_raises_nothing(tmp_path):
    out = OutputFile(tmp_path / ("a" * 250 + ".npz"), "--history")
    out.discard()  # ENAMETOOLONG from unlink, as FileNotFoundError: nothing to remove


def test_scenario_name_cannot_leave_recordings(tmp_path, monkeypatch):
    """Finding 2: name = "../../x" wrote outside recordings/."""
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    (work / "s.toml").write_text('name = "../../x"\n' + COLUMN.read_text())
    result = invoke("run", "s.toml", "--duration", 0.01)
    assert result.exit_code == 0, result.output
    written = [p for p in tmp_path.rglob("*.rrd")]
    assert len(written) == 1 and written[0].parent == work / "recordings", written
    assert written[0].name.startswith("x-")


def test_default_names_of_the_same_second_differ(tmp_path):
    """Finding 2: two runs started in the same second took the same default name; one recording was lost."""
    first = OutputFile(default_recording_path("wall", tmp_path), "--out", default_name=True)
    open_part(first)  # the first run is writing
    second = OutputFile(default_recording_path("wall", tmp_path), "--out", default_name=True)
    assert second.path != first.path and second.path.name.endswith("-2.rrd")
    # Even if two runs took the same name, the second rename does not replace the first file.
    for text in (b"one", b"two"):
        out = OutputFile(first.path, "--out", default_name=True)
        out.part.write_bytes(text)
        out.commit()
    assert first.path.read_bytes() == b"one"
    assert first.path.with_name(first.path.stem + "-2.rrd").read_bytes() == b"two"


def test_two_runs_in_the_same_second_keep_both_recordings(tmp_path, monkeypatch):
    import masonrycli.outputs.files as outputs

    class Frozen:
        @staticmethod
        def now():
            from datetime import datetime

            return datetime(2026, 1, 2, 3, 4, 5)

    monkeypatch.setattr(outputs, "datetime", Frozen)
    monkeypatch.chdir(tmp_path)
    for _ in range(2):
        assert invoke("run", COLUMN, "--duration", 0.01).exit_code == 0
    names = sorted(p.name for p in (tmp_path / "recordings").iterdir())
    assert names == ["column5-20260102-030405-2.rrd", "column5-20260102-030405.rrd"], names


def test_existing_outputs_are_kept_unless_force(tmp_path):
    """Finding 2: an existing --out, --history or build --out file was overwritten without a word."""
    rrd, npz, geo = tmp_path / "r.rrd", tmp_path / "h.npz", tmp_path / "w.geojson"
    for path in (rrd, npz, geo):
        path.write_bytes(b"previous")
    assert invoke("run", COLUMN, "--duration", 0.01, "--out", rrd).exit_code == 2
    assert invoke("run", COLUMN, "--duration", 0.01, "--no-recording", "--history", npz).exit_code == 2
    assert invoke("build", "wall", "--out", geo).exit_code == 2
    assert all(p.read_bytes() == b"previous" for p in (rrd, npz, geo))
    result = invoke("run", COLUMN, "--duration", 0.01, "--out", rrd, "--history", npz, "--force")
    assert result.exit_code == 0, result.output
    assert np.load(npz)["block_q"].shape[0] == 2 and rrd.read_bytes()[:4] != b"prev"
    assert invoke("build", "wall", "--out", geo, "--force").exit_code == 0
    assert len(json.loads(geo.read_text())["features"]) == 52
    assert leftovers(tmp_path) == []


def test_a_link_to_a_missing_file_is_an_existing_output(tmp_path):
    """--out x.rrd where x.rrd is a link to a missing file ran and wrote x-2.rrd, a name nobody asked for."""
    link = tmp_path / "x.rrd"
    os.symlink(tmp_path / "gone" / "x.rrd", link)
    result = invoke("run", COLUMN, "--duration", 0.01, "--out", link)
    assert result.exit_code == 2, result.output
    said = words(result.output)
    assert f"--out {link}: the file exists, a link to the missing {tmp_path / 'gone' / 'x.rrd'}" in said
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.rrd"] and link.is_symlink()
    result = invoke("run", COLUMN, "--duration", 0.01, "--out", link, "--force")  # replaces the link itself
    assert result.exit_code == 0, result.output
    assert not link.is_symlink() and link.read_bytes()[:4] == b"RRF2" and not (tmp_path / "gone").exists()
    os.symlink(tmp_path / "gone", tmp_path / "y-2.rrd")
    (tmp_path / "y.rrd").write_bytes(b"")
    assert free_name(tmp_path / "y.rrd") == tmp_path / "y-3.rrd"  # a default name skips a broken link too


def test_out_and_history_naming_one_file_is_refused(tmp_path):
    """Finding 2: --out X.rrd --history X.rrd replaced the recording with the history and exited 0."""
    x = tmp_path / "x.rrd"
    result = invoke("run", COLUMN, "--duration", 0.01, "--out", x, "--history", x)
    assert result.exit_code == 2 and not x.exists()


def test_unwritable_history_is_found_before_any_computing(tmp_path, monkeypatch):
    """Finding 4: an unwritable --history was found only after the whole run (exit 1, frames lost)."""
    import masonrycli.run as run_module

    def no_run(*args, **kwargs):
        raise AssertionError("the run started")

    monkeypatch.setattr(run_module.Simulation, "__init__", no_run)
    blocker = tmp_path / "file"
    blocker.write_text("")
    for args in (("--no-recording", "--history", blocker / "h.npz"), ("--out", blocker / "r.rrd")):
        result = invoke("run", COLUMN, "--duration", 0.01, *args)
        assert result.exit_code == 2, result.output
        assert "is not a folder" in result.output and len(result.output.strip().splitlines()) == 1


def test_unwritable_folder_found_when_the_temporary_file_is_created(tmp_path, monkeypatch):
    """Permissions are checked by creating the temporary file (root passes os.access checks)."""
    import masonrycli.outputs.files as outputs

    def denied(*args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(outputs.os, "open", denied)
    result = invoke("run", COLUMN, "--duration", 0.01, "--no-recording", "--history", tmp_path / "h.npz")
    assert result.exit_code == 2, result.output
    assert f"--history {tmp_path / 'h.npz'}: cannot write: Permission denied" in result.output
    assert leftovers(tmp_path) == []


def test_commit_replaces_only_with_force(tmp_path):
    target = tmp_path / "a.npz"
    target.write_bytes(b"old")
    out = OutputFile(target, "--history", force=True)
    open_part(out)
    out.part.write_bytes(b"new")
    assert out.commit() == target and target.read_bytes() == b"new"
    assert not part_path(target).exists()
    assert free_name(target) == tmp_path / "a-2.npz"


def _spy_on_the_disk(monkeypatch, fail_on: str | None = None) -> list:
    """Log the fsyncs (of what), renames and links in order; an fsync of a path ending in ``fail_on`` says the
    disk is full, as NFS, quotas and delayed allocation do only when the data is flushed."""
    log, real_fsync, real_replace, real_link = [], os.fsync, os.replace, os.link

    def fsync(fd):
        path = os.readlink(f"/proc/self/fd/{fd}")
        log.append(("fsync", path))
        if fail_on and path.endswith(fail_on):
            raise OSError(errno.ENOSPC, "No space left on device")
        real_fsync(fd)

    def replace(src, dst, *args, **kwargs):
        log.append(("rename", str(src), str(dst)))
        real_replace(src, dst, *args, **kwargs)

    def link(src, dst, *args, **kwargs):
        log.append(("rename", str(src), str(dst)))
        real_link(src, dst, *args, **kwargs)

    monkeypatch.setattr(os, "fsync", fsync)
    monkeypatch.setattr(os, "replace", replace)
    monkeypatch.setattr(os, "link", link)
    return log


@pytest.mark.parametrize("force", [True, False])
def test_a_file_is_on_the_disk_before_its_name_points_at_it(force, tmp_path, monkeypatch):
    """Renamed unflushed, a file could reach the disk after its new name (XFS, btrfs, ext4 without
    auto_da_alloc): a power cut then left an empty file where the previous one was. The part is flushed
    first, the folder's rename after."""
    target = tmp_path / "a.npz"
    out = OutputFile(target, "--history", force=force)
    open_part(out)
    out.part.write_bytes(b"new")
    log = _spy_on_the_disk(monkeypatch)
    assert out.commit() == target and target.read_bytes() == b"new"
    assert log == [("fsync", str(part_path(target))), ("rename", str(out.part), str(target)), ("fsync", str(tmp_path))]


def test_a_disk_full_only_the_flush_reports_keeps_the_previous_file(tmp_path, monkeypatch):
    """A history whose flush failed (ENOSPC at fsync) was renamed onto the previous one all the same."""
    npz = tmp_path / "h.npz"
    npz.write_bytes(b"the previous history")
    _spy_on_the_disk(monkeypatch, fail_on=".part")
    result = invoke("simulate", "wall", "--duration", 0.01, "--no-recording", "--history", npz, "--force")
    assert result.exit_code == 4, result.output
    assert "No space left on device" in result.output and "completed" not in result.output
    assert npz.read_bytes() == b"the previous history"
    assert leftovers(tmp_path) == []


def test_courses_and_length_choose_the_wall(tmp_path):
    """Finding 8: --courses/--length without --blocks always failed ("51 blocks cannot be laid…")."""
    npz = tmp_path / "h.npz"
    result = invoke(
        "simulate", "wall", "--courses", 8, "--length", 3, "--duration", 0.01, "--no-recording", "--history", npz
    )
    assert result.exit_code == 0, result.output
    assert np.load(npz)["block_q"].shape[1] == 8 * 10 + 4  # 8 courses of 10 blocks, half blocks on 4 of them
    geo = tmp_path / "w.geojson"
    assert invoke("build", "wall", "--courses", 4, "--length", 1.2, "--out", geo).exit_code == 0
    roles = [f["properties"]["role"] for f in json.loads(geo.read_text())["features"]]
    assert roles.count("block") == 4 * 4 + 2


def test_check_reads_geometry_files_like_run(tmp_path, monkeypatch):
    """Finding 7: `masonry check a.geojson` answered "TOML syntax error"."""
    monkeypatch.chdir(tmp_path)
    assert invoke("build", "wall", "--out", "a.geojson").exit_code == 0
    result = invoke("check", "a.geojson", "--duration", 0.5, "--history", "h.npz")
    assert result.exit_code == 0, result.output
    assert "51" in result.output and "500 steps" in result.output and "h.npz" in result.output
    assert not (tmp_path / "h.npz").exists()


def test_wkt_nan_prints_no_warning(tmp_path):
    """Finding 10: WKT with a NaN printed shapely's RuntimeWarning and a source line before the error."""
    import warnings

    from geometry_library.blocks import GeometryError
    from geometry_library.wkt import read_wkt

    path = tmp_path / "n.wkt"
    path.write_text("POLYGON ((0 0, nan 0, 1 1, 0 1, 0 0))\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(GeometryError, match="NaN"):
            read_wkt(path)
    assert [str(w.message) for w in caught] == []


def test_dt_not_dividing_the_duration_is_reported():
    """Finding 11: --dt 0.3 --duration 1 silently ran 3 steps and stopped at t = 0.9 s."""
    result = invoke("run", COLUMN, "--duration", 1, "--dt", 0.3, "--no-recording")
    assert result.exit_code == 2
    assert (
        "duration = 1 is not a whole number of steps of dt = 0.3 (" in result.output
        and "0.333333 (3 steps)" in result.output
    )
    assert invoke("run", COLUMN, "--duration", 0.9, "--dt", 0.3, "--no-recording").exit_code == 0


def test_outputs_that_would_not_fit_are_refused(tmp_path, monkeypatch):
    """Finding 6: a run whose outputs cannot fit on the disk is refused before it starts, with the estimate."""
    import shutil

    import masonrycli.outputs.files as outputs

    monkeypatch.setattr(outputs.shutil, "disk_usage", lambda p: shutil._ntuple_diskusage(10**9, 10**9 - 10**6, 10**6))
    result = invoke("simulate", "wall", "--duration", 20, "--record-every", 1, "--history", tmp_path / "h.npz")
    assert result.exit_code == 2, result.output
    assert "the run would write about" in result.output and "1.0 MB free" in result.output
    assert leftovers(tmp_path) == [] and not (tmp_path / "recordings").exists()


def test_history_write_failure_stops_the_run(tmp_path, monkeypatch):
    """Finding 3 (history side): disk full on the history exited 1 and left h.npz.tmp.npz behind. Now: exit
    4, one line naming the file and the cause, never "completed", no temporary file, the recording kept."""
    from masonrycli.outputs.history import HistoryFile

    original = HistoryFile.on_frame

    def full_disk(self, frame):
        if self.frames == 3:
            raise OSError(errno.ENOSPC, "No space left on device")
        original(self, frame)

    monkeypatch.setattr(HistoryFile, "on_frame", full_disk)
    rrd, npz = tmp_path / "r.rrd", tmp_path / "h.npz"
    result = invoke("simulate", "wall", "--duration", 0.1, "--out", rrd, "--history", npz)
    assert result.exit_code == 4, result.output
    assert "completed" not in result.output
    assert f"cannot write --history {npz}: stopped at t = 0.0300 s (step 30): No space left on device" in result.output
    assert not npz.exists() and leftovers(tmp_path) == []
    assert rrd.exists()  # what was computed is kept where possible
    assert os.listdir(tmp_path) == ["r.rrd"]


def test_an_output_may_accept_several_suffixes(tmp_path):
    # build --out w.json was refused although `run` reads .json as GeoJSON
    from masonrycli.errors import InputError
    from masonrycli.outputs.files import check_output

    for name in ("w.geojson", "w.JSON"):
        assert check_output(tmp_path / name, "--out", (".geojson", ".json"), False).path == tmp_path / name
    with pytest.raises(InputError, match=r"--out .*w\.txt: the file name must end in \.geojson or \.json$"):
        check_output(tmp_path / "w.txt", "--out", (".geojson", ".json"), False)


def test_a_folder_given_as_the_output_says_so_first(tmp_path):
    # --out recordings/ said "the file name must end in .rrd", as if a name were wrong, not a folder given
    from masonrycli.errors import InputError
    from masonrycli.outputs.files import check_output

    with pytest.raises(InputError) as info:
        check_output(tmp_path, "--out", ".rrd", False)
    assert str(info.value) == f"--out {tmp_path}: is a folder (name a file in it: {tmp_path / 'NAME.rrd'})"


def test_a_temporary_file_is_being_written_only_while_its_process_runs(tmp_path):
    import subprocess
    import sys

    target = tmp_path / "r.rrd"
    assert being_written(target) is None
    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    (tmp_path / f".r.rrd.{ended.stdout.strip()}.part").write_bytes(b"")  # left by a process that is gone
    assert being_written(target) is None
    live = tmp_path / f".r.rrd.{os.getpid()}.part"
    live.write_bytes(b"")
    assert being_written(target) == (live, os.getpid()) and part_writer(live) == os.getpid()
    assert part_writer(target) is None


def test_a_read_only_file_system_is_named(tmp_path, monkeypatch):
    # A folder on a read-only mount (mount -o ro: 'masonry simulate wall' there) said "cannot write in .
    # (permission denied)", which the folder's permissions did not explain.
    from types import SimpleNamespace

    folder = tmp_path / "ro"
    folder.mkdir()
    access, statvfs = os.access, os.statvfs
    monkeypatch.setattr(os, "access", lambda p, mode, **kw: False if Path(p) == folder else access(p, mode, **kw))
    monkeypatch.setattr(
        os, "statvfs", lambda p: SimpleNamespace(f_flag=os.ST_RDONLY) if Path(p) == folder else statvfs(p)
    )
    result = invoke("run", COLUMN, "--duration", 0.01, "--out", folder / "r.rrd")
    said = f"error: --out {folder / 'r.rrd'}: cannot write in {folder} (a read-only file system)"
    assert result.exit_code == 2 and result.output.strip() == said, result.output


def test_an_output_in_a_missing_folder_is_written_there(tmp_path, monkeypatch):
    # '--out recordings/x.rrd' was refused ("there is no folder recordings (make it first)") where the default
    # recording's recordings/ is made; --history, build --out, export --out and sweep's outputs alike. Made
    # when the file is opened, after every check: check makes nothing, and a refused run leaves no folder.
    monkeypatch.chdir(tmp_path)
    assert invoke("check", COLUMN, "--out", "new/w.rrd", "--history", "new/h.npz").exit_code == 0
    refused = invoke("run", COLUMN, "--duration", -1, "--out", "new/w.rrd")
    assert refused.exit_code == 2 and list(tmp_path.iterdir()) == [], refused.output
    result = invoke("run", COLUMN, "--duration", 0.01, "--out", "recordings/x.rrd", "--history", "a/b/h.npz")
    assert result.exit_code == 0, result.output
    assert invoke("build", "wall", "--out", "x/w.geojson").exit_code == 0
    assert invoke("export", "a/b/h.npz", "--out", "e/f/h.csv").exit_code == 0
    sweep = ("sweep", COLUMN, "-p", "friction=0.5", "--duration", 0.01, "--workers", 0, "--out", "s/t.csv")
    outputs = ("--plot", "p/t.png", "--recording", "r/t.rrd", "--histories", "hh/runs")
    result = invoke(*sweep, *outputs)
    assert result.exit_code == 0, result.output
    made = ["a/b/h.npz", "e/f/h.csv", "hh/runs/friction=0.5.npz", "p/t.png", "r/t.rrd", "recordings/x.rrd"]
    made += ["s/t.csv", "x/w.geojson"]
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*") if p.is_file()) == made
    assert leftovers(tmp_path) == []
    # a file where a folder is named is still refused, whole
    result = invoke("run", COLUMN, "--duration", 0.01, "--out", "x/w.geojson/y.rrd")
    assert result.exit_code == 2 and "x/w.geojson is not a folder" in result.output, result.output
