"""Reading recordings back: a summary of an ``.rrd`` (``inspect``), its views and per-frame field values and
colour ranges (for tests and docs). Screenshots from a headless viewer are in screenshot.py (re-exported here)."""

from __future__ import annotations

import contextlib
import errno
import os
import re
import shlex
import shutil
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pyarrow as pa
import rerun as rr

from masonrycli.errors import BINARY_FILE, NOT_A_FILE, binary_under_text_suffix
from masonrycli.outputs.files import being_written
from masonrycli.recording.layout import (
    BLOCKS,
    CHAIN_KEY,
    COLOURED,
    FILL,
    HOVER_VALUES,
    METADATA,
    PER_STEP_SERIES,
    SERIES,
)
from masonrycli.recording.screenshot import _viewer_executable, screenshot_recording  # noqa: F401 (re-exported)

_PER_STEP = frozenset(f"/{SERIES[k]}" for k in PER_STEP_SERIES)
_RUN_FRAMES = frozenset(f"/{p}" for p in (FILL, BLOCKS, *SERIES.values(), *(f.labels for f in COLOURED)))
"""Entities only a run's recording logs (a limit or a study recording has none): a file with one is a run's,
whose frames are those of its blocks."""

_TRUNCATED = re.compile(r"Message payload \(start (\d+), length \d+\) exceeds file size")
_MESSAGE_HEADER_BYTES = 16  # an RRD message: kind (u64) and length (u64), then the payload


def check_complete(path: str | os.PathLike) -> None:
    """Raise ``OSError`` unless ``path`` is a whole recording with its footer (cheap: the footer says
    where everything is). Rerun writes from its own thread and reports no error, so this is how a full
    disk is noticed."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reader = rr.chunk.RrdReader(os.fspath(path))
            reader.store(store=reader.recordings()[0])
    except Exception as exc:
        folder = os.path.dirname(os.path.abspath(path))
        cause = "the disk is full" if shutil.disk_usage(folder).free < 1 << 20 else str(exc).splitlines()[0]
        raise OSError(errno.EIO, f"the recording is incomplete on disk ({cause})") from None


WRITE_STALL_SECONDS = 5.0
"""s the file may stop growing while rerun's writer still has messages for it before the writer is taken
for stopped (wait_written)."""


def wait_written(rec, path: str | os.PathLike) -> None:
    """Wait until rerun's file writer has written everything ``rec`` was sent; ``OSError`` if it cannot.

    rerun 0.41's file sink stops at its first failed write (a full disk, a file-size limit: "Failed to
    write log stream ... File too large") and then never answers: ``disconnect`` and ``flush()`` waited for
    it forever, the command hung at the end of its run with nothing said. Here ``flush`` is asked with a
    short timeout, again while the file still grows (a slow disk writing a large batch), and the writer is
    given up when rerun says it has shut down or the file has not grown for WRITE_STALL_SECONDS; the stream
    is then abandoned (:func:`_abandon`) and must not be disconnected."""
    size, since = -1, time.monotonic()
    while True:
        try:
            rec.flush(timeout_sec=1.0)
            return
        except RuntimeError as exc:
            why = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            if "timed out" in why:
                try:
                    now = os.path.getsize(path)
                except OSError:
                    now = -1
                if now != size:
                    size, since = now, time.monotonic()
                    continue
                if time.monotonic() - since < WRITE_STALL_SECONDS:
                    continue
                why = f"nothing written for {WRITE_STALL_SECONDS:g} s"
            _abandon(rec)
            folder = os.path.dirname(os.path.abspath(path))
            if shutil.disk_usage(folder).free < 1 << 20:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)) from None
            raise OSError(errno.EIO, f"rerun's writer stopped, the recording is incomplete ({why})") from None


def _abandon(rec) -> None:
    """Never release ``rec``, whose writer stopped: its ``__del__`` disconnects it (and rerun's exit handler
    flushes every stream), which waited forever for that writer, after the command had said its error. One
    reference leaked on purpose (the stream is never freed), and rerun's exit handler unregistered: every
    other stream masonry opens is disconnected explicitly before the process ends."""
    import ctypes

    ctypes.pythonapi.Py_IncRef(ctypes.py_object(rec))
    rr.unregister_shutdown()


_FOLDER_NAMES = 3  # recordings named in the message about a folder; the rest are counted

_RRD_MAGIC = b"RRF"  # a recording's first bytes ("RRF2" now; the digit is the format version)
_OTHER_FILES = {  # suffix: what masonry writes or reads under it, for a file that is not a recording
    ".toml": "a scenario file (TOML; run it with masonry run)",
    ".geojson": "a geometry file (GeoJSON; run it with masonry run)",
    ".json": "a geometry file (GeoJSON; run it with masonry run)",
    ".wkt": "a geometry file (WKT; run it with masonry run)",
    ".parquet": "a sweep table (.parquet)",
    ".csv": "a table (.csv)",
    ".png": "an image (.png)",
    ".at2": "a ground-motion record (PEER .AT2; simulate and run take it with --record)",
    ".asc": "a ground-motion record (ESM .ASC; simulate and run take it with --record)",
    **{  # K-NET / KiK-net's (records.knet.KNET_SUFFIXES): 'Not an RRD file: expected FourCC header "RRF2", got "Orig"'
        f".{c}{n}": f"a ground-motion record (K-NET .{c.upper()}{n}; simulate and run take it with --record)"
        for c in ("ns", "ew", "ud")
        for n in ("", "1", "2")
    },
}


def _foreign_file(path: str | os.PathLike) -> str | None:
    """What a file that is not a recording is, from its suffix, when its first bytes are not a recording's
    (rerun's own error spoke of a "FourCC header"); None for a recording, and for a ``.rrd`` or an unknown
    suffix (its content is then reported as not readable)."""
    kind = _OTHER_FILES.get(os.path.splitext(os.fspath(path))[1].lower())
    if kind is None:
        return None
    try:
        with open(path, "rb") as f:
            if f.read(len(_RRD_MAGIC)) == _RRD_MAGIC:
                return None
    except OSError:  # unreadable: the reader says why
        return None
    record = ""
    if binary_under_text_suffix(path):  # a binary file under a text suffix is none of those kinds
        kind = BINARY_FILE
    elif kind.startswith("a ground-motion record"):  # what one inspecting it wants: its PGA, its length
        record = f" (its PGA, PGV, Arias and length as a run applies it: masonry check wall --record {os.fspath(path)})"
    return f"{os.fspath(path)}: {kind}, not a recording; inspect reads the .rrd recordings that --out writes{record}"


def recording_path_problem(path: str | os.PathLike) -> str | None:
    """What stops ``path`` from being read as a recording, in one line (None when it is a file that may be
    one): it is another of masonry's files (a history, a scenario), it does not exist, or it is a folder — then the ``.rrd`` files directly in it are named (the first few by name)
    and the newest is suggested, as ``masonry inspect recordings`` usually means the last run."""
    shown = os.fspath(path)
    if os.path.isfile(path):
        return _foreign_file(path)
    if not os.path.isdir(path):
        if os.path.exists(path):
            return f"{shown}: {NOT_A_FILE}"
        live = being_written(Path(path))
        if live is None:
            return f"{shown}: no such recording"
        part, pid = live
        return (
            f"{shown}: not there yet: a run still going (pid {pid}) writes it as {part.name}, renamed to it when "
            f"the run ends; masonry inspect {shlex.quote(os.fspath(part))} shows it so far"
        )
    try:
        with os.scandir(path) as entries:
            found = sorted((e for e in entries if e.name.endswith(".rrd") and e.is_file()), key=lambda e: e.name)
    except OSError:  # a folder we may not list: say what it is, no more
        found = []
    if not found:
        return f"{shown}: a folder, not a recording (it holds no .rrd file)"
    names = ", ".join(e.name for e in found[:_FOLDER_NAMES])
    more = f" and {len(found) - _FOLDER_NAMES} more" if len(found) > _FOLDER_NAMES else ""
    newest = max(found, key=lambda e: (e.stat().st_mtime_ns, e.name))
    count = f"{len(found)} recording" + ("s" if len(found) > 1 else "")
    return (
        f"{shown}: a folder, not a recording; it holds {count} ({names}{more}): "
        f"give one, e.g. masonry inspect {shlex.quote(os.path.join(shown, newest.name))}"  # a command to paste
        + (" (the newest)" if len(found) > 1 else "")
    )


def _open_reader(path: str, scratch: str) -> tuple[rr.chunk.RrdReader, bool]:
    """A reader of ``path``; a file cut in the middle of a message (a killed writer, a full disk) is read
    up to its last complete message, from a shortened copy in ``scratch``. Returns (reader, truncated)."""
    source, truncated = path, False
    for _ in range(8):
        try:
            with warnings.catch_warnings():  # a file without footer is reported as complete=False
                warnings.simplefilter("ignore")
                reader = rr.chunk.RrdReader(source)
                reader.recordings()  # reads the file: a cut message raises here
                return reader, truncated
        except RuntimeError as exc:
            cut = _TRUNCATED.search(str(exc))
            if cut is None:
                raise
            end = max(0, int(cut.group(1)) - _MESSAGE_HEADER_BYTES)
            shorter = os.path.join(scratch, f"prefix-{end}.rrd")
            with open(source, "rb") as src, open(shorter, "wb") as dst:
                dst.write(src.read(end))
            source, truncated = shorter, True
    raise ValueError("no complete message in it (cut short, or damaged)")


@contextlib.contextmanager
def _reading(path: str | os.PathLike):
    """A reader of ``path`` as :func:`_open_reader` makes it (a file cut by a killed writer read up to its last
    complete message): ``field_frames`` and the others raised "Message payload … exceeds file size" on the
    recording ``masonry inspect`` summarised, a ``kill -9``'s ``.NAME.<pid>.part``."""
    with tempfile.TemporaryDirectory(prefix="masonry-read-") as scratch, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "RRD file has no footer/manifest": what truncated means
        yield _open_reader(os.fspath(path), scratch)[0]


def inspect_recording(path: str | os.PathLike) -> dict:
    """Summary of a recording file; works without a footer too (a killed writer's file) and on a file cut
    in the middle of a message (read up to its last complete message).

    Keys: application_id, recording_id, frames (distinct `step` values of the recorded frames whose
    blocks are in the file; solver health is logged for every step besides), steps (first, last frame) or
    None, time_span (first, last frame's sim_time, s) or None, entity_paths (sorted, with the leading "/"), has_blueprint, complete
    (footer present), truncated (the writer did not finish: no footer, or cut in a message; what
    ``masonry inspect`` warns about), metadata (the run document's Markdown, or None).
    """
    with tempfile.TemporaryDirectory(prefix="masonry-inspect-") as scratch:
        return _summarise(*_open_reader(os.fspath(path), scratch), path)


def _summarise(reader: rr.chunk.RrdReader, truncated: bool, path) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        recordings = reader.recordings()
    if not recordings:
        raise ValueError(f"no complete recording in its {os.path.getsize(path):,} bytes (cut short, or damaged)")
    entry = recordings[0]
    paths: set[str] = set()
    # steps and sim_time span of every timed entity ("all") and of the blocks' ("blocks"): a run's frame is
    # shown once its blocks are in the file. A batch sends the colour bars' labels, then the fill, then the
    # blocks, so a file cut in between (an interrupted run's, written at close) held the labels of every frame
    # and was said to hold them all ("83 frames up to its last complete chunk": a tenth of the file, no block
    # drawn past step 0). A limit or study recording has no blocks: its frames are any entity's.
    seen = {key: (set(), [np.inf, -np.inf]) for key in ("all", "blocks")}
    metadata: str | None = None
    for chunk in reader.stream(store=entry):
        paths.add(chunk.entity_path)
        batch = chunk.to_record_batch()
        names = batch.schema.names
        if chunk.is_static:
            if chunk.entity_path == f"/{METADATA}" and "TextDocument:text" in names:
                texts = [t for t in batch.column("TextDocument:text").to_pylist() if t]
                metadata = texts[-1][0] if texts else metadata  # the last one logged wins
            continue
        if chunk.entity_path in _PER_STEP:  # solver health, logged at every step: not frames
            continue
        for key in ("all", "blocks") if chunk.entity_path == f"/{BLOCKS}" else ("all",):
            steps, span = seen[key]
            if "step" in names:
                steps.update(batch.column("step").to_numpy().tolist())
            if "sim_time" in names and batch.num_rows:
                t = batch.column("sim_time").cast(pa.int64()).to_numpy() * 1e-9
                span[:] = min(span[0], t.min()), max(span[1], t.max())
    steps, (t_lo, t_hi) = seen["blocks" if paths & _RUN_FRAMES else "all"]
    try:
        reader.store(store=entry)
        complete = True
    except Exception:  # no footer / manifest: the writer did not finish
        complete = False
    return {
        "application_id": entry.application_id,
        "recording_id": entry.recording_id,
        "frames": len(steps),
        "steps": (min(steps), max(steps)) if steps else None,
        "time_span": (round(float(t_lo), 9), round(float(t_hi), 9)) if np.isfinite(t_lo) else None,
        "entity_paths": sorted(paths),
        "has_blueprint": bool(reader.blueprints()),
        "complete": complete,
        # a killed writer leaves no footer but whole messages: truncated too (it was "False" under the
        # inspect warning saying "truncated")
        "truncated": truncated or not complete,
        "metadata": metadata,
    }


def _last_blueprint(reader: rr.chunk.RrdReader):
    """The blueprint sent last (the viewer opens on the last default): ``blueprints()`` is in no particular
    order, so the one whose chunks were logged last (``log_time``)."""

    def logged(entry) -> int:
        times = [
            chunk.to_record_batch().column("log_time").cast(pa.int64()).to_numpy().max(initial=0)
            for chunk in reader.stream(store=entry)
            if "log_time" in chunk.to_record_batch().schema.names
        ]
        return int(max(times, default=0))

    return max(reader.blueprints(), key=logged)


def blueprint_views(path: str | os.PathLike) -> dict[str, dict]:
    """The views of the recording's last default blueprint (the one the viewer opens on; a run that ended
    before the paper's instant sends a second one without the pinned tabs): name -> {"kind", "origin",
    "pinned", "legend"}; ``pinned`` is (timeline, start s, end s) for a view whose visible time range is
    fixed, else None; ``legend``: False for a plot whose legend is hidden, else None (the viewer's default); ``y_range``: a plot's fixed y range or None; ``bounds``: a 2-D view's
    fixed framing ((x0, x1), (y0, y1)) or None (the viewer's fit)."""
    with _reading(path) as reader:
        chunks = list(reader.stream(store=_last_blueprint(reader)))
    by_id: dict[str, dict] = {}
    for chunk in chunks:
        batch = chunk.to_record_batch()
        parts = chunk.entity_path.strip("/").split("/")
        if parts[0] != "view" or len(parts) < 2:
            continue
        view = by_id.setdefault(parts[1], {"pinned": None, "legend": None, "y_range": None, "bounds": None})
        names = batch.schema.names
        if "ViewBlueprint:display_name" in names:
            view["name"] = batch.column("ViewBlueprint:display_name").to_pylist()[-1][0]
            view["kind"] = batch.column("ViewBlueprint:class_identifier").to_pylist()[-1][0]
            view["origin"] = batch.column("ViewBlueprint:space_origin").to_pylist()[-1][0]
        if "ScalarAxis:range" in names:
            view["y_range"] = tuple(batch.column("ScalarAxis:range").to_pylist()[-1][0])
        if "VisualBounds2D:range" in names:  # a 2-D view's framing: (x range, y range) in its origin's units
            (r,) = batch.column("VisualBounds2D:range").to_pylist()[-1]
            view["bounds"] = (tuple(r["x_range"]), tuple(r["y_range"]))
        if "PlotLegend:visible" in names:
            view["legend"] = batch.column("PlotLegend:visible").to_pylist()[-1][0]
        if "VisibleTimeRanges:ranges" in names:
            (r,) = batch.column("VisibleTimeRanges:ranges").to_pylist()[-1]
            view["pinned"] = (r["timeline"], 1e-9 * r["range"]["start"], 1e-9 * r["range"]["end"])
    return {v["name"]: v for v in by_id.values() if "name" in v}


def blueprint_tabs(path: str | os.PathLike) -> list[tuple[list[str], str]]:
    """Every tab container of the recording's last default blueprint: (its views' names in order, the one
    shown at open: its active tab, else the first)."""
    with _reading(path) as reader:
        chunks = list(reader.stream(store=_last_blueprint(reader)))
    names: dict[str, str] = {}
    tabs: list[tuple[list[str], str | None]] = []
    for chunk in chunks:
        batch = chunk.to_record_batch()
        cols = batch.schema.names
        if "ViewBlueprint:display_name" in cols:
            names[chunk.entity_path.strip("/")] = batch.column("ViewBlueprint:display_name").to_pylist()[-1][0]
        if "ContainerBlueprint:container_kind" in cols and batch.column(
            "ContainerBlueprint:container_kind"
        ).to_pylist()[-1] == [1]:  # rerun.blueprint.components.ContainerKind.Tabs
            active = (
                batch.column("ContainerBlueprint:active_tab").to_pylist()[-1]
                if "ContainerBlueprint:active_tab" in cols
                else None
            )
            tabs.append((batch.column("ContainerBlueprint:contents").to_pylist()[-1], active[0] if active else None))
    return [([names[c] for c in contents], names[active or contents[0]]) for contents, active in tabs]


def blueprint_row_shares(path: str | os.PathLike) -> list[list[float]]:
    """The row shares of every vertical container of the recording's last default blueprint (those set)."""
    with _reading(path) as reader:
        chunks = list(reader.stream(store=_last_blueprint(reader)))
    out = []
    for chunk in chunks:
        batch = chunk.to_record_batch()
        if "ContainerBlueprint:row_shares" in batch.schema.names:
            shares = batch.column("ContainerBlueprint:row_shares").to_pylist()[-1]
            if shares:
                out.append([float(x) for x in shares])
    return out


def blueprint_time_panel(path: str | os.PathLike) -> dict:
    """The embedded blueprint's time panel: {"timeline": name or None, "play_state": "paused", "playing",
    "following" or None} (None: not set, the viewer's default)."""
    out: dict = {"timeline": None, "play_state": None}
    names = {1: "paused", 2: "playing", 3: "following"}  # rerun.blueprint.components.PlayState
    with _reading(path) as reader:
        chunks = list(reader.stream(store=_last_blueprint(reader)))
    for chunk in chunks:
        if chunk.entity_path != "/time_panel":
            continue
        batch = chunk.to_record_batch()
        if "TimePanelBlueprint:timeline" in batch.schema.names:
            out["timeline"] = batch.column("TimePanelBlueprint:timeline").to_pylist()[-1][0]
        if "TimePanelBlueprint:play_state" in batch.schema.names:
            out["play_state"] = names[batch.column("TimePanelBlueprint:play_state").to_pylist()[-1][0]]
    return out


def field_frames(path: str | os.PathLike) -> dict[int, dict]:
    """Per recorded step: {"time": s, "values": hover values by field key (N,), "ranges": field key ->
    the colour range logged for that frame; a square-root view's under ``FieldSpec.name``, "key@sqrt"}. The
    volumetric strain rate is the one the fill shows (the chain strain rate where the cell has none)."""
    out: dict[int, dict] = {}
    hover = {name: key for name, key in HOVER_VALUES.items()}
    labels = {f"/{f.labels}": f.name for f in COLOURED}
    with _reading(path) as reader:
        chunks = list(reader.stream())
    for chunk in chunks:
        if chunk.is_static:
            continue
        batch = chunk.to_record_batch()
        names = batch.schema.names
        if "step" not in names:
            continue
        steps = batch.column("step").to_pylist()
        if chunk.entity_path == f"/{BLOCKS}":
            times = batch.column("sim_time").cast(pa.int64()).to_numpy() * 1e-9
            for name, key in hover.items():
                if name in names:
                    for step, t, v in zip(steps, times, batch.column(name).to_pylist()):
                        row = out.setdefault(step, {"values": {}, "ranges": {}})
                        row["time"] = float(t)
                        row["values"][key] = np.array(v, dtype=np.float64)
        elif chunk.entity_path in labels and "range_lo" in names:
            key = labels[chunk.entity_path]
            for step, lo, hi in zip(steps, batch.column("range_lo").to_pylist(), batch.column("range_hi").to_pylist()):
                out.setdefault(step, {"values": {}, "ranges": {}})["ranges"][key] = (lo[0], hi[0])
    for row in out.values():
        v = row["values"]
        if "cell_volumetric_strain_rate" in v and CHAIN_KEY in v:
            cell = v["cell_volumetric_strain_rate"]
            v["cell_volumetric_strain_rate"] = np.where(np.isnan(cell), v[CHAIN_KEY], cell)
    return out


_RUN_CLOCK = re.compile(r"(\*\*Run time:\*\* )[0-9.]+( s)|(\| (?:started|commit|source_digest) \| )[^|]*")
"""What differs between two runs of one command: the clock, and the code (two revisions compared)."""
_RUN_CODE = re.compile(r"(, commit )[^,]*(, source )[0-9a-z ]+")
"""The code in the run document's heading (``**masonry** 0.1.0, commit f935f83, source 4583eaac5ced``)."""


def recording_rows(path: str | os.PathLike) -> dict[str, list[str]]:
    """Every entity's rows, comparable between two runs of the same command: ``{entity: sorted rows}``, a row
    the ``repr`` of its time columns and component values (no row ids, so chunking does not matter); static
    entities as ``"static <entity>"`` with the values in force, each component's of its latest row id (what
    the viewer shows: a static entity may be logged again with some components, e.g. the centroid dots'
    radii once the view is sized, and the chunks are not stored in the order logged), the run document's wall
    time, start time, commit and source digest masked, the recording's own start time (``/__properties``) left out."""
    temporal: dict[str, list[str]] = {}
    latest: dict[str, dict[str, tuple[bytes, object]]] = {}
    with _reading(path) as reader:
        chunks = list(reader.stream())
    for chunk in chunks:
        if chunk.entity_path == "/__properties":
            continue
        batch = chunk.to_record_batch()
        names = sorted(n for n in batch.schema.names if n != "rerun.controls.RowId")
        columns = [(n, _plain(batch.column(n)).to_pylist()) for n in names]
        if chunk.is_static:
            in_force = latest.setdefault(chunk.entity_path, {})
            row_ids = batch.column("rerun.controls.RowId").to_pylist()
            for n, values in columns:
                for row_id, value in zip(row_ids, values):  # row ids: big-endian, time first
                    if value is not None and (n not in in_force or row_id > in_force[n][0]):
                        in_force[n] = (row_id, value)
        else:
            rows = [repr([(n, values[i]) for n, values in columns]) for i in range(batch.num_rows)]
            temporal.setdefault(chunk.entity_path, []).extend(rows)
    static = {}
    for entity, in_force in latest.items():
        row = repr([(n, in_force[n][1]) for n in sorted(in_force)])
        static[f"static {entity}"] = [_RUN_CODE.sub(r"\1\2", _RUN_CLOCK.sub(r"\1\2\3", row))]
    return {entity: sorted(rows) for entity, rows in temporal.items()} | static


def _plain(column: pa.Array) -> pa.Array:
    """Durations, timestamps as int64 ns: to_pylist's timedelta raises on 1.024999999 s without pandas."""
    time_like = pa.types.is_duration(column.type) or pa.types.is_timestamp(column.type)
    return column.cast(pa.int64()) if time_like else column
