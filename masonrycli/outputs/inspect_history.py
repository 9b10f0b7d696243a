"""``masonry inspect H.npz``: what a run history holds, read from the file alone.

A history (:mod:`masonrycli.outputs.history`) describes itself: ``run`` (the JSON of the run's parameters),
``units`` (each array's unit / meaning), ``status`` and ``note``. Histories written before those existed
are summarised too, their missing parts said "not recorded". Only the arrays' headers are read (shape and
dtype), and the few small arrays the summary shows (``time``, ``step``, ``run``, ``units``, ``status``,
``note``, the 0-d intensities): a history of gigabytes is summarised in the time of a small one.
"""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path

import numpy as np

from masonrycli.errors import NOT_A_FILE, InputError, file_kind, one_line
from masonrycli.outputs.files import being_written
from masonrycli.outputs.verdict import counted

NOT_RECORDED = "not recorded"
_ZIP_MAGIC = b"PK\x03\x04"
_SMALL = ("run", "units", "status", "note")  # read whole, besides time, step and the 0-d numbers


def is_history(path: str | os.PathLike) -> bool:
    """True for a path ``inspect`` reads as a history: a ``.npz`` (a damaged or missing one too: the history
    reader says what is wrong with it), or a zip of ``.npy`` arrays holding ``time`` under another name."""
    if os.fspath(path).lower().endswith(".npz"):
        return True
    if not os.path.isfile(path):
        return False
    try:
        with open(path, "rb") as f:
            if f.read(len(_ZIP_MAGIC)) != _ZIP_MAGIC:
                return False
        with zipfile.ZipFile(path) as zf:
            return "time.npy" in zf.namelist()
    except (OSError, zipfile.BadZipFile, ValueError):
        return False


def _header(zf: zipfile.ZipFile, member: str) -> tuple[tuple[int, ...], np.dtype]:
    """Shape and dtype of one ``.npy`` member, from its header (the data is not read)."""
    with zf.open(member) as f:
        version = np.lib.format.read_magic(f)
        if version == (1, 0):
            shape, _, dtype = np.lib.format.read_array_header_1_0(f)
        elif version == (2, 0):
            shape, _, dtype = np.lib.format.read_array_header_2_0(f)
        else:  # format 3.0 (utf-8 field names): no public header reader; such members are small
            f.seek(0)
            array = np.lib.format.read_array(f, allow_pickle=False)
            shape, dtype = array.shape, array.dtype
    return tuple(int(n) for n in shape), dtype


def _unreadable(path, exc: Exception) -> InputError:
    return InputError(one_line(f"{os.fspath(path)}: not a readable history (.npz): {type(exc).__name__}: {exc}"))


def inspect_history(path: str | os.PathLike) -> dict:
    """Summary of the history at ``path``; :class:`InputError` (one line) for a damaged file or a ``.npz``
    that is no history.

    Keys: ``run`` (dict, or None: not recorded), ``status`` and ``note`` (str or None), ``frames``, ``steps``
    (first, last recorded step) and ``time_span`` (s) or None, ``blocks``, ``supports``, ``joints`` (or
    None), ``units_recorded`` and ``arrays``: (name, shape, dtype, unit / meaning or None, value of a 0-d
    number or None), in the file's order.
    """
    shown = os.fspath(path)
    if not os.path.isfile(path):
        if os.path.isdir(path):
            raise InputError(f"{shown}: a folder, not a history")
        if os.path.exists(path):
            raise InputError(f"{shown}: {NOT_A_FILE}")
        live = being_written(Path(path))
        if live is not None:  # streamed as raw rows, made an .npz at the end: nothing to read before it
            raise InputError(f"{shown}: not there yet: a run still going (pid {live[1]}) writes it, whole at its end")
        raise InputError(f"{shown}: no such history")
    other = file_kind(path, "a history (.npz)", skip=(".npz",))
    if other is not None:  # export or read_history given a recording said "not a readable history: BadZipFile"
        raise other
    try:
        with zipfile.ZipFile(path) as zf:
            # every array's checksum first: a file damaged inside an array inspect does not load was summarised
            # as sound (exit 0), and np.load of that array failed later (CRC of 57 MB: 0.02 s of CPU)
            damaged = zf.testzip()
            members = [m for m in zf.namelist() if m.endswith(".npy")]
            headers = {} if damaged else {m[: -len(".npy")]: _header(zf, m) for m in members}
    except (OSError, zipfile.BadZipFile, ValueError, EOFError, KeyError) as exc:
        raise _unreadable(path, exc) from None
    if damaged is not None:
        raise InputError(f"{shown}: a damaged history: the array {damaged.removesuffix('.npy')} fails its checksum")
    if "time" not in headers:
        held = ", ".join(list(headers)[:4]) + (" …" if len(headers) > 4 else "") if headers else "no arrays"
        raise InputError(
            f"{shown}: a NumPy archive (.npz) but not a run history (no time array; it holds {held}); "
            "inspect reads recordings (.rrd) and histories (--history H.npz)"
        )
    try:
        with np.load(path, allow_pickle=False) as npz:
            small = {
                name: npz[name]
                for name, (shape, dtype) in headers.items()
                if name in ("time", "step", *_SMALL) or (shape == () and dtype.kind in "biufU")
            }
    except (OSError, zipfile.BadZipFile, ValueError, EOFError) as exc:
        raise _unreadable(path, exc) from None
    try:
        run = json.loads(str(small["run"])) if "run" in small else None
    except ValueError:  # not JSON: shown as not recorded rather than refusing the whole file
        run = None
    table = small.get("units")
    units = {str(k): str(v) for k, v in table} if table is not None and table.ndim == 2 and table.shape[1] == 2 else {}
    time, step = small["time"], small.get("step")
    frames = int(time.shape[0]) if time.ndim else 0
    arrays = []
    for name, (shape, dtype) in headers.items():
        value = small.get(name) if shape == () and dtype.kind in "biufU" else None
        arrays.append((name, shape, _dtype_name(dtype), units.get(name), None if value is None else value.item()))

    def text(name):
        return str(small[name]) if name in small else None

    def count(name):
        return headers[name][0][0] if name in headers and headers[name][0] else None

    return {
        "run": run if isinstance(run, dict) else None,
        "status": text("status"),
        "note": text("note"),
        "frames": frames,
        "steps": (int(step[0]), int(step[-1])) if step is not None and step.ndim == 1 and step.size else None,
        "time_span": (float(time[0]), float(time[-1])) if frames and time.ndim == 1 else None,
        "blocks": count("block_name"),
        "supports": count("support_name"),
        "joints": count("joint_body"),
        "units_recorded": bool(units),
        "arrays": arrays,
    }


def reading_text(reading: dict) -> str:
    """One line of how a run's geometry file was read (``run["reading"]``: geometry_library.survey's record, and
    ``settle_s``): the command line's option for each, with what it did."""
    said = []
    if (origin := reading.get("map_origin_m")) is not None:
        said.append(f"moved near the origin: add ({origin[0]:.0f}, {origin[1]:.0f}) m for the map's coordinates")
    if "units" in reading:
        said.append(f"--units {reading['units']} ({reading.get('metres_per_unit', float('nan')):g} m per unit)")
    if reading.get("flip_y"):
        said.append("--flip-y")
    if isinstance(hull := reading.get("convex_hull"), dict):
        said.append(
            f"--convex-hull: {hull.get('stones')} stones read as their hulls (+{hull.get('area_added_m2', 0):.3g} m²)"
        )
    if isinstance(trim := reading.get("trim_overlaps"), dict):
        said.append(f"--trim-overlaps {trim.get('depth_m', 0):g}: {trim.get('pairs')} overlapping pairs trimmed")
    if "settle_s" in reading:
        said.append(f"--settle {reading['settle_s']:g}: settled before the run")
    return "; ".join(said)


def _dtype_name(dtype: np.dtype) -> str:
    return "str" if dtype.kind == "U" else dtype.name


def run_rows(info: dict) -> list[tuple[str, str]]:
    """The summary's rows (label, value) before the arrays: the run's metadata, what the file spans."""
    run = info["run"]
    rows: list[tuple[str, str]] = []

    def get(key):
        return None if run is None else run.get(key)

    if get("command"):  # the masonry command line, the Python API's call or the sweep that made it
        rows.append(("command", str(get("command"))))

    def given(*values) -> bool:
        return all(v is not None for v in values)

    scenario, source = get("scenario"), get("source")
    rows.append(("scenario", f"{scenario} ({source})" if given(scenario, source) else str(scenario or NOT_RECORDED)))
    structure = get("structure")
    if isinstance(structure, dict) and structure.get("builder"):  # its size: "wall (builder:wall)" said none
        options = [
            f"{k} {v:g}" if isinstance(v, float) else f"{k} {v}"
            for k, v in structure.items()
            if k != "builder" and v is not None
        ]
        rows.append(("structure", f"{structure['builder']}: {', '.join(options) or 'as built by default'}"))
    reading = get("reading")
    if isinstance(reading, dict) and reading:  # how its geometry file was read: the history is of that reading
        rows.append(("reading", reading_text(reading)))
    point = get("study_point")
    if isinstance(point, dict):  # a history of masonry sweep --histories
        rows.append(("study point", ", ".join(f"{k} = {v}" for k, v in point.items())))
    status = info["status"]
    note = info["note"]
    if status and note:  # "interrupted at t = …", "diverged at t = …" name their status already
        status = note if note.startswith(status) else f"{status}: {note}"
    rows.append(("status", status or NOT_RECORDED))
    rows += verdict_rows({name: value for name, _, _, _, value in info.get("arrays", ())})
    solver, tol, cap = get("solver"), get("nlgs_tolerance"), get("nlgs_max_iterations")
    rows.append(("solver", str(solver) if solver is not None else NOT_RECORDED))
    rows.append(("tolerance", f"{tol:g} m/s (at most {cap} sweeps a step)" if given(tol, cap) else _or(tol, " m/s")))
    dt, duration, theta = get("dt_s"), get("duration_s"), get("theta")
    dt_text = _or(dt, " s")
    if given(dt, duration, theta):
        dt_text = f"{dt:g} s (duration {duration:g} s, θ = {theta:g}, a frame every {get('record_every')} steps)"
    rows.append(("dt", dt_text))
    loading = get("supports")
    if isinstance(loading, dict) and loading:
        rows.append(("loading", "\n".join(f"{name}: {motion}" for name, motion in loading.items())))
    mu, rho, thick = get("friction"), get("density_kg_m3"), get("thickness_m")
    if given(mu, rho, thick):
        rows.append(("material", f"friction {mu:g}, density {_value(rho)} kg/m³, thickness {_value(thick)} m"))
    if (fill := get("fill_mass_kg")) is not None:  # a bridge's fill, often heavier than its stones: said by neither
        rows.append(("fill", f"{fill:.6g} kg carried by the blocks under it (dead load only)"))
    version, commit, digest = get("masonry"), get("commit"), get("source_digest")
    rows.append(
        (
            "masonry",
            ", ".join(f"{label}{v}" for label, v in (("", version), ("commit ", commit), ("source ", digest)) if v)
            or NOT_RECORDED,
        )
    )
    if get("started"):
        rows.append(("started", str(get("started"))))
    rows.append(("frames", str(info["frames"])))
    first_last = info["steps"]
    rows.append(("steps", f"{first_last[0]} … {first_last[1]}" if first_last else "—"))
    span = info["time_span"]
    rows.append(("time_span", f"{span[0]:g} … {span[1]:g} s" if span else "—"))
    bodies = [
        counted(n, word)
        for n, word in ((info["blocks"], "block"), (info["supports"], "support"), (info["joints"], "joint"))
        if n is not None
    ]
    rows.append(("bodies", ", ".join(bodies) or NOT_RECORDED))
    if not info["units_recorded"]:
        rows.append(("units", f"{NOT_RECORDED} in this file (masonry docs readme, 'What a run writes', lists them)"))
    return rows


def _value(value) -> str:
    """A material value: one number, or the blocks' [least, greatest] when they differ ("2300–2700 (per block)")."""
    if isinstance(value, (list, tuple)) and len(value) == 2:
        return f"{value[0]:g}–{value[1]:g} (per block)"
    return f"{value:g}"


def verdict_rows(values: dict) -> list[tuple[str, str]]:
    """The run's verdict from its ``result_*`` numbers (``values``: name -> the 0-d array's value), in the
    summary's words: state, peak drift, residual drift; none for a history written before it was kept."""
    from masonrycli.outputs.verdict import RESULT_KEYS, describe_outcome, describe_peak_drift, describe_residual_drift

    out = {key: values.get(f"result_{key}") for key in RESULT_KEYS}
    height = values.get("result_height")
    if height is None or any(v is None for v in out.values()):
        return []
    return [
        ("state", describe_outcome(out)),
        ("peak drift", describe_peak_drift(out["peak_drift"], height)),
        ("residual drift", describe_residual_drift(out["residual_drift"], height)),
    ]


def _or(value, unit: str) -> str:
    return f"{value:g}{unit}" if isinstance(value, (int, float)) else NOT_RECORDED


def array_rows(info: dict) -> list[tuple[str, str, str, str]]:
    """One row per array: name, shape (a 0-d number's value after it), dtype, unit / meaning."""
    rows = []
    for name, shape, dtype, meaning, value in info["arrays"]:
        shape_text = "(" + ", ".join(map(str, shape)) + ("," if len(shape) == 1 else "") + ")"
        if isinstance(value, str):  # a word (a state, a status) quoted, '' shown; the run's JSON is its table
            value = repr(value) if len(value) <= 40 and "\n" not in value else None
        if value is not None:
            shape_text += f" = {value:.4g}" if isinstance(value, float) else f" = {value}"
        rows.append((name, shape_text, dtype, meaning if meaning else NOT_RECORDED))
    return rows
