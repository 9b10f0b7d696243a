"""The history file: one row per recorded frame, an uncompressed ``.npz``.

Arrays (T frames, N blocks, S supports), block order = scenario order:

    time (T,) s · step (T,) · block_q (T,N,3) [x, y m, rotation from the initial orientation rad CCW]
    block_v (T,N,3) [m/s, m/s, rad/s] · support_q (T,S,3) · support_v (T,S,2) · support_force (T,S,2) N
    contact_count (T,) · nlgs_iterations (T,) sweeps · nlgs_residual (T,) m/s (of the step ending at the frame)
    nlgs_unconverged (T,) steps since t = 0 that ended unconverged (residual > tolerance or at the cap)
    energy_kinetic (T,) J · energy_potential (T,) J · energy_dissipated (T,) J (cumulated)
    support_work (T,) J (cumulated) · every per-block tensor field of masonrycli.analysis.tensors.TENSOR_FIELDS
    joint_body (J,2) body indices, blocks then supports (N + s: support s) · joint_hinged (T,J) bool ·
    hinge_count (T,)  (see masonrycli.analysis.mechanism)
    block_mass (N,) kg · block_inertia (N,) kg m² · block_extent (N,4) m (bounding box as built; written by
    the command line, :func:`block_constants`)
    block_name (N,) · support_name (S,) · status () str (masonrycli.outputs.sinks.STATUSES) · note () str
    intensity_pga, intensity_pgv, intensity_arias, intensity_d5_95, intensity_sa () — the ground motion as
    applied (masonrycli.records.intensity), when a support shakes
    result_state () str, result_collapse_time, result_collapse_reason () str, result_peak_drift,
    result_residual_drift, result_max_opening, result_max_displacement, result_hinges, result_height () — the
    run's verdict as its summary gives it (masonrycli.run.run_outcome, measured every step, not every frame)

:class:`HistoryFile` (the command line's sink) streams every row to disk as it comes, so memory stays
flat however long the run; :class:`History` keeps the rows in memory for tests and scripts.

A history file describes itself, for whoever opens it with plain numpy and no documentation: ``units``
(K, 2) str, one row per array of the file — its name and its unit / meaning (:data:`UNITS`), so
``dict(np.load(f)["units"])`` — and ``run`` () str, the JSON of the run's parameters (scenario, dt, solver,
tolerance, the commit and source digest of the masonry that ran it; the recording's run document).
"""

from __future__ import annotations

import json
import os
import shutil
import zipfile
from pathlib import Path

import numpy as np

from masonrycli.analysis.mechanism import JOINT_FIELDS
from masonrycli.analysis.tensors import TENSOR_FIELDS
from masonrycli.outputs.frame import Frame
from masonrycli.outputs.sinks import COMPLETED
from masonrycli.outputs.verdict import RESULT_KEYS

_SCALARS = (
    "time",
    "step",
    "contact_count",
    "nlgs_iterations",
    "nlgs_residual",
    "nlgs_unconverged",
    "energy_kinetic",
    "energy_potential",
    "energy_dissipated",
    "support_work",
)
_ARRAYS = ("block_q", "block_v", "support_q", "support_v", "support_force")
UNITS: dict[str, str] = {
    "time": "s, time of the frame",
    "step": "step index (time / dt)",
    "contact_count": "contacts of the step ending at the frame",
    "nlgs_iterations": "NLGS sweeps of the step ending at the frame (at rest: with the continuation's)",
    "nlgs_residual": "m/s, RMS contact-law violation of the last sweep (compared with the tolerance)",
    "nlgs_unconverged": "steps since t = 0 that ended unconverged (residual > tolerance or at the cap)",
    "energy_kinetic": "J",
    "energy_potential": "J, -sum m g.x",
    "energy_dissipated": "J, dissipated at contacts since t = 0",
    "support_work": "J, work of the supports on the blocks since t = 0",
    "block_q": "(T,N,3) centroid x, y (m); rotation from the initial orientation (rad, counter-clockwise)",
    "block_v": "(T,N,3) vx, vy (m/s), angular velocity (rad/s)",
    "support_q": "(T,S,3) support centroid x, y (m), rotation (rad)",
    "support_v": "(T,S,2) imposed velocity vx, vy (m/s)",
    "support_force": "(T,S,2) N per block thickness, total contact force of the blocks on the support",
    **{name: f"{unit}, {text}" for name, (_, unit, text) in (TENSOR_FIELDS | JOINT_FIELDS).items()},
    "joint_hinged": "(T,J) bool, joint hinged (one end carries all the normal force, the other is open)",
    "hinge_count": "hinged joints at the frame",
    "block_mass": "(N,) kg, block mass (density x area x thickness)",
    "block_inertia": "(N,) kg m2, polar moment of inertia about the centroid",
    "block_extent": "(N,4) m, bounding box as built at t = 0: xmin, ymin, xmax, ymax",
    "block_name": "(N,) block names, the order of every block axis",
    "support_name": "(S,) support names",
    "joint_body": "(J,2) the two bodies of each joint: index into block_name, or N + s for support s",
    "status": "completed, interrupted, diverged or failed",
    "note": "where and why the run stopped",
    "intensity_pga": "m/s2, peak ground acceleration as applied",
    "intensity_pgv": "m/s, peak ground velocity as applied",
    "intensity_arias": "m/s, Arias intensity",
    "intensity_d5_95": "s, significant duration D5-95",
    "intensity_sa": "m/s2, spectral acceleration at 0.5 s, 5 % damping",
    "result_state": "intact, damaged or collapsed, as the run's summary (masonry docs collapse)",
    "result_collapse_time": "s, time of collapse (NaN: none)",
    "result_collapse_reason": "why the structure collapsed (empty: it did not)",
    "result_peak_drift": "x height, the top's largest drift relative to the ground, over every step",
    "result_residual_drift": "x height, the top's drift relative to the ground at the end",
    "result_max_opening": "m, the largest joint opening at the end",
    "result_max_displacement": "m, the largest block displacement relative to the ground at the end",
    "result_hinges": "hinged joints at the end",
    "result_height": "m, the structure's height the drifts are ratios of (the blocks' vertical extent)",
    "units": "(K,2) this table: array name, unit / meaning",
    "run": "JSON of the run's parameters (scenario, dt, solver, commit, ...)",
}
"""Unit and meaning of every history array (written into the file as ``units``); T frames, N blocks, S
supports, J joints."""

_ROW_BUFFER = 1 << 16  # bytes of write buffer per array file (37 files: 2.4 MB at most)


def _row_arrays(frame: Frame):
    """(name, array) of one history row, views of the frame's arrays where they allow (no copy)."""
    for name in _SCALARS:
        yield name, np.asarray(getattr(frame, name))
    for name in _ARRAYS:
        yield name, np.asarray(getattr(frame, name))
    for name, value in frame.tensors.items():
        yield name, np.asarray(value)
    hinged = np.asarray(frame.joint_hinged, dtype=bool)
    yield "joint_hinged", hinged
    yield "hinge_count", np.asarray(int(hinged.sum()))


def block_constants(model) -> dict[str, np.ndarray]:
    """The blocks' mass, inertia and bounding box as built (``block_mass``, ``block_inertia``,
    ``block_extent``): what ``masonry export`` needs besides the rows (the course of a block, the structure's
    height for the drift ratio, the inertia forces for the overturning moment). Constant arrays of the run,
    given to a history's ``run_values``."""
    n = model.block_count
    start = model.body_vert_start
    extent = np.empty((n, 4))
    for b in range(n):  # once per run, not in the time loop
        xy = model.vert_local[start[b] : start[b + 1]] + model.body_q0[b, :2]
        extent[b] = (*xy.min(axis=0), *xy.max(axis=0))
    return {
        "block_mass": np.array(model.body_mass[:n], dtype=float),
        "block_inertia": np.array(model.body_inertia[:n], dtype=float),
        "block_extent": extent,
    }


def result_values(outcome: dict, height: float) -> dict[str, np.ndarray]:
    """The run's verdict as history arrays (``result_*``, 0-d), from its outcome and the structure's height:
    ``masonry report`` reads them back (it said 'the history does not store the state or peak drift')."""
    values = {f"result_{key}": np.asarray(outcome[key]) for key in RESULT_KEYS if key in outcome}
    return values | {"result_height": np.asarray(float(height))}


def frame_rows(frame: Frame) -> dict[str, np.ndarray]:
    """One history row per array name (copies: the engine reuses its buffers)."""
    return {name: np.array(value, copy=True) for name, value in _row_arrays(frame)}


class History:
    """Collects frames in memory (tests, scripts); :meth:`arrays` gives the history's arrays."""

    def __init__(self, block_name, support_name):
        self.block_name = np.asarray(block_name, dtype=str)
        self.support_name = np.asarray(support_name, dtype=str)
        self._rows: dict[str, list] = {}
        self.joint_body = np.zeros((0, 2), dtype=np.int64)
        self.run_values: dict[str, float | np.ndarray] = {}
        """One value per run (e.g. ``intensity_pga``, written as 0-d arrays) or constant array of the run
        (:func:`block_constants`)."""
        self.run_info: dict = {}
        """The run's parameters, as :class:`HistoryFile`'s (``run``, once closed)."""
        self._closing: dict[str, np.ndarray] = {}

    def __len__(self) -> int:
        return len(self._rows.get("time", ()))

    def on_frame(self, frame: Frame) -> None:
        for name, value in frame_rows(frame).items():
            self._rows.setdefault(name, []).append(value)
        self.joint_body = frame.joint_body

    append = on_frame

    def close(self, status: str = COMPLETED, note: str = "") -> None:
        """The rows stay in memory; from now on :meth:`arrays` also holds what a closed :class:`HistoryFile`
        adds: ``status``, ``note``, ``run`` and ``units`` (the Python API's run has every array of the file)."""
        self._closing = {"status": np.asarray(status), "note": np.asarray(note)}
        self._closing["run"] = np.asarray(json.dumps(self.run_info, default=str, ensure_ascii=False))

    def arrays(self) -> dict[str, np.ndarray]:
        out = {name: np.asarray(values) for name, values in self._rows.items()}
        out["block_name"] = self.block_name
        out["support_name"] = self.support_name
        if self._rows or self._closing:
            out["joint_body"] = np.asarray(self.joint_body)
        # closed: in the order HistoryFile.close writes them, so that ``units`` lists them alike
        closing = dict(self._closing)
        out |= {name: closing.pop(name) for name in ("status", "note") if name in closing}
        out |= {name: np.asarray(value) for name, value in self.run_values.items()}
        if closing:
            out |= closing
            out["units"] = units_table([*out, "units"])
        return out


def units_table(names) -> np.ndarray:
    """(K, 2) str: each array name and its unit / meaning (:data:`UNITS`), the history's ``units``."""
    return np.array([[n, UNITS.get(n, "")] for n in names], dtype=str)


class HistoryFile:
    """A :class:`~masonrycli.outputs.sinks.FrameSink` writing the history ``.npz`` at ``path`` without holding it.

    Each frame's rows are appended to one raw file per array in the scratch folder ``<path>.rows``;
    :meth:`close` writes the ``.npz`` from them (a stored zip of ``.npy`` members, read by ``np.load``)
    and removes the folder. A write error (disk full, folder removed) raises ``OSError`` from
    :meth:`on_frame` or :meth:`close`; the scratch folder is removed either way.
    """

    def __init__(self, path: str | os.PathLike, block_name, support_name):
        self.path = Path(path)
        self.block_name = np.asarray(block_name, dtype=str)
        self.support_name = np.asarray(support_name, dtype=str)
        self.scratch = self.path.with_name(self.path.name + ".rows")
        self.scratch.mkdir()
        self.frames = 0
        self.joint_body = np.zeros((0, 2), dtype=np.int64)
        self.run_values: dict[str, float | np.ndarray] = {}
        """One value per run (e.g. ``intensity_pga``, written as 0-d arrays) or constant array of the run
        (:func:`block_constants`); set before :meth:`close`."""
        self.run_info: dict = {}
        """The run's parameters (:func:`masonrycli.execute.run_metadata`), written as ``run`` (JSON)."""
        self._files: dict[str, tuple] = {}  # name -> (open raw file, dtype, row shape)
        self._closed = False

    def on_frame(self, frame: Frame) -> None:
        # Each row goes to its file as it is (written now, so no copy), through a 64 kB buffer: the wall's
        # (248, 2, 2) tensors are 8 kB a frame, one system call each with the default 8 kB buffer.
        for name, row in _row_arrays(frame):
            row = np.asarray(row, order="C")  # not ascontiguousarray: it makes scalars 1-d
            entry = self._files.get(name)
            if entry is None:
                raw = open(self.scratch / f"{name}.raw", "wb", buffering=_ROW_BUFFER)
                entry = self._files[name] = (raw, row.dtype, row.shape)
            fh, dtype, shape = entry
            if row.dtype != dtype or row.shape != shape:
                raise ValueError(f"history: {name} changed from {dtype}{shape} to {row.dtype}{row.shape}")
            fh.write(row)  # the array's bytes (C order), as row.tobytes() without the copy
        self.joint_body = np.array(frame.joint_body, copy=True)
        self.frames += 1

    def close(self, status: str = COMPLETED, note: str = "") -> None:
        """Write the ``.npz`` (every frame handed over so far) and remove the scratch folder. Idempotent."""
        if self._closed:
            return
        self._closed = True
        try:
            for fh, _, _ in self._files.values():
                fh.close()
            constants = {
                "block_name": self.block_name,
                "support_name": self.support_name,
                "joint_body": self.joint_body,
                "status": np.asarray(status),
                "note": np.asarray(note),
            } | {name: np.asarray(value) for name, value in self.run_values.items()}
            constants["run"] = np.asarray(json.dumps(self.run_info, default=str, ensure_ascii=False))
            names = [*self._files, *constants, "units"]
            constants["units"] = units_table(names)
            with zipfile.ZipFile(self.path, "w", zipfile.ZIP_STORED, allowZip64=True) as zf:
                for name, (_, dtype, shape) in self._files.items():
                    with zf.open(f"{name}.npy", "w", force_zip64=True) as member:
                        header = {"descr": np.lib.format.dtype_to_descr(dtype), "fortran_order": False}
                        np.lib.format.write_array_header_2_0(member, header | {"shape": (self.frames, *shape)})
                        _copy_rows(
                            self.scratch / f"{name}.raw", member, self.frames * dtype.itemsize * int(np.prod(shape))
                        )
                for name, value in constants.items():
                    with zf.open(f"{name}.npy", "w") as member:
                        np.lib.format.write_array(member, value, allow_pickle=False)
        finally:
            for fh, _, _ in self._files.values():
                fh.close()
            shutil.rmtree(self.scratch, ignore_errors=True)


def _copy_rows(raw_path: Path, member, size: int) -> None:
    """Copy the first ``size`` bytes (the whole rows: a failed write may have left part of one after them)."""
    with open(raw_path, "rb") as raw:
        while size > 0:
            chunk = raw.read(min(size, 1 << 20))
            if not chunk:
                raise OSError(f"history: {raw_path.name} is {size} bytes short")
            member.write(chunk)
            size -= len(chunk)
