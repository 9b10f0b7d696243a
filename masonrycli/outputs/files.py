"""Output files: checked before step 1, written under a temporary name, renamed into place when complete.

The policy (README, "Outputs and overwriting"):

- An explicit path (``--out``, ``--history``, ``build --out``) that already exists is refused, exit 2,
  unless ``--force`` is given. Two outputs naming the same file are refused. Its missing folders are made,
  as the default recording's ``recordings/`` is (``--out runs/w.rrd`` was refused for want of ``runs/``);
  a typed folder name shows in the summary's path.
- Default recording names ``recordings/<name>-<YYYYmmdd-HHMMSS>.rrd`` never collide: a name already on
  disk, or being written by another run, takes ``-2``, ``-3``… Scenario names are reduced to
  letters, digits and ``._-`` so they cannot leave ``recordings/``.
- Every file is written as a hidden ``.<name>.<pid>.part`` beside its target and renamed onto it when
  complete, so the path holds either the previous file or a complete new one, whatever happens to the
  process. Without ``--force`` the rename cannot replace a file that appeared during the run either (a hard
  link fails if the target exists): the new file then takes the next free ``-k`` name.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from masonrycli.errors import InputError

RECORDINGS_DIR = Path("recordings")

_UNSAFE = re.compile(r"[^\w.-]+")  # \w: letters and digits of any script ("voûte" lost its û), and _


def safe_name(name: str) -> str:
    """A scenario name as a file-name stem that stays in its folder: ``../../x`` → ``x``, ``a b`` → ``a-b``;
    at most 80 bytes of whole characters (80 characters of a CJK name were 240 bytes: with the time stamp
    and the temporary name's additions, more than a file system's 255)."""
    stem = _UNSAFE.sub("-", str(name)).strip(".-")
    stem = re.sub(r"\.{2,}", ".", stem)
    return os.fsencode(stem)[:80].decode(errors="ignore").strip(".-") or "run"


def part_path(path: Path) -> Path:
    """The temporary name ``path`` is written under by this process."""
    return path.with_name(f".{path.name}.{os.getpid()}.part")


def _being_written(path: Path) -> bool:
    return any(path.parent.glob(f".{glob_escape(path.name)}.*.part")) if path.parent.is_dir() else False


def part_writer(part: Path) -> int | None:
    """The process id in a temporary name ``.NAME.<pid>.part`` when that process is running, else None."""
    match = re.fullmatch(r"\..+\.(\d+)\.part", Path(part).name)
    if match is None:
        return None
    pid = int(match.group(1))
    try:
        os.kill(pid, 0)
    except PermissionError:  # another user's process: running
        return pid
    except (ProcessLookupError, OverflowError):  # ended (killed: its file was left), or no such number
        return None
    return pid


def being_written(path: Path) -> tuple[Path, int] | None:
    """The temporary file a running process writes ``path`` under (and its pid), if any: a run still going
    (``masonry inspect`` said "no such recording" of it)."""
    if not path.parent.is_dir():
        return None
    for part in sorted(path.parent.glob(f".{glob_escape(path.name)}.*.part")):
        pid = part_writer(part)
        if pid is not None:
            return part, pid
    return None


def glob_escape(text: str) -> str:
    return re.sub(r"([*?\[])", r"[\1]", text)


def _numbered(path: Path, k: int) -> Path:
    return path if k == 1 else path.with_name(f"{path.stem}-{k}{path.suffix}")


def _to_disk(path: Path, folder: bool = False) -> None:
    """fsync ``path``: a file's data, or a folder's entries (a rename in it). A folder's fsync some file
    systems refuse (EINVAL) or cannot open is skipped: the rename is made, only its durability unsure."""
    try:
        fd = os.open(path, os.O_RDONLY | (getattr(os, "O_DIRECTORY", 0) if folder else 0))
    except OSError:
        if folder:
            return
        raise
    try:
        os.fsync(fd)
    except OSError:
        if not folder:
            raise
    finally:
        os.close(fd)


def free_name(path: Path) -> Path:
    """``path``, or the first ``stem-k.suffix`` (k = 2, 3…) that neither exists nor is being written."""
    k = 1
    while os.path.lexists(_numbered(path, k)) or _being_written(_numbered(path, k)):
        k += 1
    return _numbered(path, k)


def default_recording_path(name: str, folder: Path = RECORDINGS_DIR) -> Path:
    """``recordings/<safe name>-<timestamp>.rrd``, numbered if a run of the same second has it."""
    stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
    return free_name(folder / f"{safe_name(name)}-{stamp}.rrd")


@dataclass(eq=False)
class OutputFile:
    """One output: its final ``path``, the ``part`` file being written and whether it may replace a file."""

    path: Path
    option: str
    """The option that named it ("--out", "--history"), for messages."""
    force: bool = False
    default_name: bool = False

    @property
    def part(self) -> Path:
        return part_path(self.path)

    def commit(self) -> Path:
        """Rename the complete ``part`` file onto ``path`` (see the module docstring); returns where it went.
        The part's bytes reach the disk before the name points at them, and the rename after it: a rename
        may be written before the data it names (XFS, btrfs, ext4 without auto_da_alloc), and a power cut then
        left an empty or partial file where the previous one was. A disk full that only the flush reports
        (NFS, quotas, delayed allocation) is an OSError here, before the rename: the previous file stays."""
        _to_disk(self.part)
        target = self._rename()
        _to_disk(target.parent, folder=True)
        return target

    def _rename(self) -> Path:
        if self.force:
            os.replace(self.part, self.path)
            return self.path
        target = self.path
        while True:
            try:
                os.link(self.part, target)
            except FileExistsError:
                target = free_name(target)
                continue
            except OSError:  # no hard links on this file system: check, then rename
                if target.exists():
                    target = free_name(target)
                    continue
                os.replace(self.part, target)
                break
            os.unlink(self.part)
            break
        self.path = target
        return target

    def discard(self) -> None:
        """Remove the temporary file (and a history's temporary folder), if any."""
        # never made (its folder is a file, its name too long: the error that says so must not be replaced)
        with contextlib.suppress(OSError):
            os.unlink(self.part)
        shutil.rmtree(self.part.with_name(self.part.name + ".rows"), ignore_errors=True)  # a history's rows


def check_output(
    path: Path,
    option: str,
    suffix: str | tuple[str, ...],
    force: bool,
    *,
    default_name: bool = False,
) -> OutputFile:
    """Check ``path`` before anything is computed: suffix (one, or a tuple of accepted ones), not a folder,
    not existing (unless ``force``), its folder existing or creatable (:func:`check_folder`; made when the
    file is opened, :func:`open_part`) and writable. Raises :class:`InputError` naming the option and the
    path."""
    where = f"{option} {path}"
    suffixes = (suffix,) if isinstance(suffix, str) else suffix
    _check_name_length(path, where)  # first: a name too long made path.is_dir() raise
    if path.is_dir():  # first: "--out recordings/" said "the file name must end in .rrd"
        raise InputError(f"{where}: is a folder (name a file in it: {path / ('NAME' + suffixes[0])})")
    if path.suffix.lower() not in suffixes:
        raise InputError(f"{where}: the file name must end in {' or '.join(suffixes)}")
    if os.path.lexists(path) and not force:  # a link to a missing file too: the run wrote "x-2.rrd" instead
        broken = "" if path.exists() else f", a link to the missing {os.readlink(path)}"
        raise InputError(f"{where}: the file exists{broken} (add --force to replace it)")
    if path.exists() and not os.access(path, os.W_OK):
        raise InputError(f"{where}: the file exists and is read-only")
    check_folder(path, where)
    return OutputFile(path, option, force=force, default_name=default_name)


_PART_ADDS = len(".") + len(".4194304.part.rows")
"""Bytes the longest temporary name adds to a file's: a history's rows folder, the largest Linux pid."""


def _check_name_length(path: Path, where: str) -> None:
    """Raise :class:`InputError` if the temporary names of ``path`` are too long for its file system: a name
    of 252 bytes is a valid file, but its ``.NAME.<pid>.part`` was refused when opened (internal error,
    exit 1: removing the temporary file that was never made raised again)."""
    folder = next((p for p in (path.parent, *path.parent.parents) if p.is_dir()), Path("."))
    try:
        limit = os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        limit = 255
    size = len(os.fsencode(path.name))
    if size + _PART_ADDS > limit:
        raise InputError(
            f"{where}: the file name is {size} bytes long, at most {limit - _PART_ADDS} here (it is written "
            f"under a temporary name .NAME.<pid>.part first; the file system allows {limit})"
        )


def check_folder(path: Path, where: str) -> None:
    """Raise :class:`InputError` (``where: problem``) unless ``path``'s folder exists or can be made (its
    nearest existing folder is one, and writable) on a disk. Nothing is made here: ``check`` writes nothing."""
    folder = path.parent
    existing = next((p for p in (folder, *folder.parents) if p.exists()), Path("."))
    if not existing.is_dir():
        raise InputError(f"{where}: {existing} is not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise InputError(f"{where}: cannot write in {existing} ({_why_not_writable(existing)})")
    if shutil.disk_usage(existing).total == 0:  # /proc, /sys: writable to root, yet no file can be made there
        raise InputError(f"{where}: cannot write in {existing} (a system folder, not a disk)")


def _why_not_writable(folder: Path) -> str:
    """A folder on a read-only mount (a dataset, a container's root) said "permission denied", which its
    permissions did not explain."""
    try:
        if os.statvfs(folder).f_flag & os.ST_RDONLY:
            return "a read-only file system"
    except (OSError, AttributeError):
        pass
    return "permission denied"


def check_distinct(*outputs: OutputFile | None) -> None:
    """Two outputs naming the same file is an error (one would replace the other)."""
    seen: dict[str, OutputFile] = {}
    for out in outputs:
        if out is None:
            continue
        key = os.path.realpath(out.path)
        if key in seen:
            raise InputError(f"{seen[key].option} and {out.option} name the same file {out.path}")
        seen[key] = out


def open_part(out: OutputFile) -> None:
    """Create the output's folder and its empty ``part`` file (O_EXCL): proves the folder is writable
    before step 1. Raises :class:`InputError` naming the option, the path and the cause."""
    try:
        out.path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(out.part, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
        os.close(fd)
    except OSError as exc:
        raise InputError(f"{out.option} {out.path}: cannot write: {exc.strerror or exc}") from None


@contextlib.contextmanager
def written_whole(out: OutputFile, around_commit=None):
    """For a writer that makes the whole file at once: yields the ``part`` path to write, renames it into
    place when the block ends (``out.path`` is then where it went) and removes it on any error, Ctrl-C
    included, before re-raising — so ``out.path`` never holds half a file. ``around_commit``: a context
    manager entered around the rename (a caller holding signals there and recording the file as written)."""
    open_part(out)
    try:
        yield out.part
        with around_commit if around_commit is not None else contextlib.nullcontext():
            out.commit()
    except BaseException as exc:  # the rename too: a failed one left the hidden part file beside the path
        out.discard()
        if isinstance(exc, OSError) and not hasattr(exc, "output"):
            # a disk full while it was written said only "error: No space left on device", exit 2 (bad input):
            # the command line names the output (cli.messages.user_errors, exit 4 as simulate's)
            exc.output = f"{out.option} {out.path}"
        raise


def check_space(outputs: list[tuple[OutputFile, int]]) -> None:
    """Refuse a run whose outputs (estimated bytes each) would not fit in the free space of their disk."""
    need: dict[int, tuple[int, list[str], str]] = {}
    for out, size in outputs:
        folder = next(p for p in (out.path.parent, *out.path.parent.parents) if p.exists())
        dev = os.stat(folder).st_dev
        total, names, _ = need.get(dev, (0, [], str(folder)))
        need[dev] = (total + size, [*names, f"{out.option} {out.path}"], str(folder))
    for total, names, folder in need.values():
        free = shutil.disk_usage(folder).free
        if total > free:
            raise InputError(
                f"{' and '.join(names)}: the run would write about {human_bytes(total)} but {folder} has "
                f"{human_bytes(free)} free (shorten --duration or raise --record-every)"
            )


def human_bytes(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if abs(n) < 1000 or unit == "TB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1000
    return f"{n:.1f} TB"  # pragma: no cover
