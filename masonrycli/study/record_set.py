"""The records of ``masonry sweep --records``: files and folders of them read into one motion per file name.

A folder gives its .AT2, .ASC, K-NET and .csv files (not its subfolders, named when they hold records; nor the
study's own table kept there, nor the files of other kinds, named); every file is read as ``--record`` reads it,
and a file that cannot be read refuses the study in one line naming it — with the others that cannot be read
counted and named, so that a set of several damaged files is mended in one go.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from masonrycli.errors import NOT_A_FILE, InputError
from masonrycli.records.read import vertical_at2


def read_record_set(entries: list[Path], out: Path, record_dt: float | None, baseline: str) -> tuple[dict, list[str]]:
    """``(record motions by file name, warnings)``, from files and the .AT2 / .ASC / .csv files of folders (but the
    study's table ``out``: kept in its records' folder, it was read as a record by the same command run again,
    "recs/ida.csv:2: not a number", so the study could not be resumed). ``record_dt`` (--record-dt, s):
    the spacing of the samples of the CSVs of one value per line; refused when no file is one. A folder's
    subfolders are not read: those holding records are named (a set kept by station, recs/ELC/*.AT2 beside
    recs/*.AT2, ran the top-level files only, without a word)."""
    files, unread = [], []
    for entry in entries:
        if entry.is_dir():
            found = sorted(p for p in entry.iterdir() if _is_record_file(p) and not same_file(p, out))
            below = sorted(d for d in entry.iterdir() if d.is_dir() and any(map(_is_record_file, d.rglob("*"))))
            if below:
                names = ", ".join(str(d) for d in below[:3]) + (" …" if len(below) > 3 else "")
                verb = "holds" if len(below) == 1 else "hold"
                said = f"--records {entry}: its subfolders are not read; {names} {verb} records (give them too)"
                if not found:
                    raise InputError(said)
                unread.append(said)
            if not found:  # an ESM download's VEL files or KiK-net's borehole ones alone: said why, not "no .ASC"
                left = [w.removeprefix(f"--records {entry}: ") for w in _esm_others(entry) + _boreholes(entry)]
                said = "".join(f"; {w}" for w in left)
                raise InputError(f"--records {entry}: no .AT2, .ASC, K-NET or .csv record in it{said}")
            unread += _not_read(entry) + _esm_others(entry) + _boreholes(entry)
            files += found
        elif entry.is_file():
            files.append(entry)
        else:
            raise InputError(f"--records {entry}: {NOT_A_FILE if entry.exists() else 'no such file or folder'}")
    names = [p.name for p in files]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise InputError(f"--records: two records named {twice[0]} (rows are keyed by the file name)")
    motions, unreadable = {}, []
    for p in files:  # every file read before one is refused: the first damaged one alone sent the user back per file
        try:
            motions[p.name] = _record(p, record_dt, baseline)
        except InputError as exc:
            unreadable.append((p, str(exc)))
    if unreadable:
        first, said = unreadable[0]
        more = [str(p) for p, _ in unreadable[1:]]
        if more:
            names = ", ".join(more[:3]) + (" …" if len(more) > 3 else "")
            said += f" (and {len(more)} more file{'s' if len(more) > 1 else ''} of --records cannot be read: {names})"
        raise InputError(said)
    upright = [p.name for p in files if vertical_at2(p)]
    if upright:  # an unzipped NGA-West2 search holds each recording's H1, H2 and UP files, all .AT2
        names = ", ".join(upright[:3]) + (" …" if len(upright) > 3 else "")
        unread.append(
            f"--records: {names} {'are vertical components' if len(upright) > 1 else 'is a vertical component'} "
            "(PEER's UP / DWN, ESM's Z, K-NET's UD), run along x as the others: leave them out of the set (a scenario file's "
            "vertical = … applies one with its horizontal)"
        )
    if record_dt is not None and all(m.time_step is None for m in motions.values()):
        # as simulate refuses --record-dt with a file that has times: a time step no file takes is a mistake
        raise InputError(
            f"--record-dt {record_dt:g}: no file of --records is one value per line (the .AT2 files and the CSVs "
            "with a time column keep their own times): leave it out"
        )
    return motions, unread


_NOT_RECORDS = {
    ".parquet",
    ".png",
    ".rrd",
    ".npz",
    ".jsonl",
    ".vt2",
    ".dt2",
    ".toml",
    ".geojson",
    ".json",
    ".wkt",
    ".md",
    ".pdf",
}
"""Suffixes a --records folder may hold beside its records without a word: masonry's own files (a study's
table, picture, recording, journal; scenarios, geometry; notes) and PEER's velocity and displacement companions."""


def _not_read(folder: Path) -> list[str]:
    """The warning naming the files of a ``--records`` folder that are not read (no hidden file, none of
    ``_NOT_RECORDS``): a folder of ESM's .ASC files beside its CSVs ran the CSVs alone, without a word, and a
    K-NET .NS / .EW file or a .txt accelerogram would be left out alike."""
    other = sorted(
        p.name
        for p in folder.iterdir()
        if p.is_file()
        and not p.name.startswith(".")
        and not _is_record_file(p)
        and p.suffix.lower() not in _NOT_RECORDS
        and not _esm_other(p)
        and not _kik_borehole(p)
    )
    if not other:
        return []
    names = ", ".join(other[:3]) + (" …" if len(other) > 3 else "")
    count = f"{len(other)} file{'s' if len(other) > 1 else ''}"
    return [
        f"--records {folder}: {count} not read as records ({names}): a set reads PEER .AT2, ESM .ASC, K-NET (.NS, .EW, .UD) and .csv "
        "files (convert the others to a CSV of time and acceleration)"
    ]


def _esm_others(folder: Path) -> list[str]:
    """The warning naming a folder's ESM files of another series than acceleration, left out: an ESM download
    holds each component's ….ACC.ASC, ….VEL.ASC, ….DIS.ASC and spectra, and read all it ran each record twice
    (its acceleration and its velocity, two rows of one shaking) or stopped at the first displacement file."""
    other, names = _left_out(folder, _esm_other)
    if not other:
        return []
    return [
        f"--records {folder}: {len(other)} ESM file{'s' if len(other) > 1 else ''} of another series than "
        f"acceleration left out ({names}): a set folder takes each component's acceleration (….ACC.ASC); give a "
        "velocity file by its name to run it"
    ]


def _left_out(folder: Path, left: Callable[[Path], bool]) -> tuple[list[str], str]:
    """The names of a folder's files that ``left`` leaves out of a set, sorted, and the first three of them for a
    warning ("a, b, c …")."""
    other = sorted(p.name for p in folder.iterdir() if p.is_file() and left(p))
    return other, ", ".join(other[:3]) + (" …" if len(other) > 3 else "")


def _esm_other(path: Path) -> bool:
    """An ESM .ASC file whose header says it is no acceleration series (VELOCITY, DISPLACEMENT, a spectrum)."""
    from masonrycli.records.esm import esm_series

    return path.suffix.lower() == ".asc" and esm_series(path) not in ("", "ACCELERATION")


def _boreholes(folder: Path) -> list[str]:
    """The warning naming a folder's KiK-net borehole files, left out: a KiK-net download holds each station's
    surface (….NS2, .EW2, .UD2) and borehole (….NS1, .EW1, .UD1: the motion at the sensor's depth, tens to
    hundreds of metres down, not the ground a structure stands on) files; read all, each shaking ran twice,
    once as its borehole record."""
    other, names = _left_out(folder, _kik_borehole)
    if not other:
        return []
    return [
        f"--records {folder}: {len(other)} KiK-net borehole file{'s' if len(other) > 1 else ''} left out ({names}): "
        "the motion at the sensor's depth, not at the ground surface; a set folder takes the surface ones (….NS2, "
        ".EW2); give a borehole file by its name to run it"
    ]


def _kik_borehole(path: Path) -> bool:
    """A KiK-net file of the borehole sensor (``.NS1``, ``.EW1``, ``.UD1``)."""
    return path.suffix.lower() in (".ns1", ".ew1", ".ud1")


def _is_record_file(path: Path) -> bool:
    """A file a --records folder reads: .AT2, .csv, K-NET, KiK-net's surface files and ESM .ASC files of
    acceleration."""
    from masonrycli.records.knet import KNET_SUFFIXES

    suffix = path.suffix.lower()
    if suffix not in (".at2", ".asc", ".csv", *KNET_SUFFIXES) or not path.is_file():
        return False
    return not _esm_other(path) and not _kik_borehole(path)


def _record(path: Path, record_dt: float | None, baseline: str = "quadratic"):
    """The motion of one file of a record set: a CSV of one value per line with its samples ``record_dt``
    apart, any other file with its own times (a mixed set: the time step is for its one-column files).
    The file's first sample says which: read without a time step, a one-column file is refused there,
    before the rest of it is parsed, and read again with the time step. A CSV whose header gives its unit
    (g, gal, cm/s², cm/s, …) is read in it, converted to SI, as ``--record`` reads it (the axis's scale then
    multiplies the record as recorded, and a row replays with ``run --record FILE --scale`` the row's scale)."""
    from masonrycli.records.read import record_motion
    from masonrycli.records.text import NoTimeStep

    try:
        return record_motion(path, display=str(path), baseline=baseline)
    except NoTimeStep as exc:
        if record_dt is None:
            raise exc.give("--record-dt SECONDS") from None
        return record_motion(path, display=str(path), time_step=record_dt, baseline=baseline)


def same_file(a, b) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet)
        return False
