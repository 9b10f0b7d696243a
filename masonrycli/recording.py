"""Rerun recording of a run: the only module that imports rerun.

One ``.rrd`` per run from an explicit ``rr.RecordingStream``, with an embedded default blueprint.
Constants are logged static; frames are buffered and sent with ``send_columns`` every ``batch_frames``
frames, one array per entity kind. Timelines ``step`` (sequence) and ``sim_time`` (duration). Entity
paths: ``ENTITY_PATHS``.

Drawing plane. Rerun has no filled 2-D polygon, so fills are ``Mesh3D`` at z = 0 in the 3-D space
``structure``, seen in the 2-D views through the pinhole ``structure/plane``: a camera looking down from
``_CAMERA_HEIGHT`` with focal length equal to that height (1 image unit = 1 m, image v = world −y: y up
on screen). Lines, arrows and points live under ``structure/plane/xy``, mapped to image (x − x0, y0 − y).
The pinhole's resolution is the blocks' bounding box at the first frame (plus margins and the legend), so
the views open fitted. The camera must be far: 2-D content is drawn at a fixed depth that a closer mesh
would hide.

Scales (written in the run document) are fixed once per run, at the first flushed batch where the data
is not all zero, from the 98th percentile of |value| rounded up (``nice_ceil``): the colour range of each
field ([−M, M] if signed, else [0, M]; ``field_ranges`` overrides it), the force scale (that force is one
median block height long; arrows are capped at two) and the principal-axis scales.
"""

from __future__ import annotations

import contextlib
import importlib.metadata
import json
import os
import platform
import shutil
import signal
import socket
import sys
import time
import uuid
import warnings
from dataclasses import dataclass
from typing import Final, NamedTuple

import numpy as np
import pyarrow as pa
import rerun as rr
import rerun.blueprint as rrb

from masonrycli import __version__ as MASONRY_VERSION
from masonrycli.colormap import (
    COOLWARM,
    NAN_RGBA,
    VIRIDIS,
    colorbar_mesh,
    map_scalars,
    nice_ceil,
    robust_max_abs,
    tick_label,
)
from masonrycli.frame import CONTACT_OPEN, CONTACT_SLIP, CONTACT_STICK, Frame

APPLICATION_ID: Final = "masonry"
_RECORDING_NAMESPACE: Final = uuid.UUID("6f1c4f5e-9b0e-4c51-a0a6-3f0d6c1e2a77")
_CAMERA_HEIGHT: Final = 1.0e4  # m, drawing-plane camera above z = 0
_ROBUST_PERCENTILE: Final = 98.0  # scales and colour ranges come from this percentile of |value|
_ARROW_CAP: Final = 2.0  # longest force arrow, in median block heights (hover an arrow for its force)
_GLYPH_HALF_LENGTH: Final = 0.45  # longest principal-axis half-length / median block's smaller side
_SUPPORT_MARGIN: Final = 0.15  # initial view: supports up to this × the structure's size beyond blocks


class FieldSpec(NamedTuple):
    key: str  # name in Frame.tensors
    title: str
    unit: str
    signed: bool  # diverging colour map on [−M, M] if True, sequential on [0, M] otherwise
    fill: str  # entity paths: the blocks filled with the field's colours, the colour bar, its labels
    bar: str
    labels: str


def _field(key: str, title: str, unit: str, signed: bool) -> FieldSpec:
    short = key.removeprefix("cell_")
    return FieldSpec(
        key,
        title,
        unit,
        signed,
        f"structure/fields/{short}",
        f"structure/legend/{short}",
        f"structure/plane/xy/legend/{short}",
    )


FIELDS: Final = (
    _field("cell_volumetric_strain_rate", "Volumetric strain rate", "1/s", True),
    _field("cell_deviatoric_strain", "Deviatoric cumulated strain", "", False),
    _field("cell_spherical_stress", "Spherical stress p", "Pa", True),
    _field("cell_deviatoric_stress", "Deviatoric stress q", "Pa", False),
)
_FIELD_BY_KEY: Final = {f.key: f for f in FIELDS}
_HOVER_VALUES: Final = {  # per-block value shown when hovering a block outline -> Frame.tensors key
    "p": "cell_spherical_stress",
    "q": "cell_deviatoric_stress",
    "volumetric_strain_rate": "cell_volumetric_strain_rate",
    "deviatoric_strain": "cell_deviatoric_strain",
    "sliding_ratio": "block_sliding_ratio",
    "max_opening": "block_max_opening",
}
_AXES: Final = {  # glyph set -> (principal values (N, 2) key, angle of the major one (N,) key)
    "stress_axes": ("cell_principal_stress", "cell_principal_angle"),
    "strain_rate_axes": ("cell_principal_strain_rate", "cell_principal_strain_rate_angle"),
}
_TENSOR_KEYS: Final = tuple(
    dict.fromkeys([*(f.key for f in FIELDS), *(k for pair in _AXES.values() for k in pair), *_HOVER_VALUES.values()])
)
_SCALARS: Final = (
    "energy_kinetic",
    "energy_potential",
    "energy_dissipated",
    "support_work",
    "nlgs_iterations",
    "nlgs_residual",
    "contact_count",
)

PLANE: Final = "structure/plane"
XY: Final = "structure/plane/xy"
BLOCKS: Final = f"{XY}/blocks"
SUPPORT_OUTLINES: Final = f"{XY}/supports"
TRIANGULATION: Final = f"{XY}/triangulation"
FORCES: Final = f"{XY}/forces"
HINGES: Final = f"{XY}/hinges"
STRESS_AXES: Final = f"{XY}/stress_axes"
STRAIN_RATE_AXES: Final = f"{XY}/strain_rate_axes"
SUPPORT_FILL: Final = "structure/supports"
METADATA: Final = "run/metadata"
SERIES: Final = {
    "energy": "series/energy",
    "max_displacement": "series/blocks/max_displacement",
    "support_velocity": "series/supports/velocity",
    "support_displacement": "series/supports/displacement",
    "iterations": "series/solver/iterations",
    "residual": "series/solver/residual",
    "contacts": "series/contacts/count",
}


ENTITY_PATHS: Final = (
    PLANE,
    XY,
    BLOCKS,
    SUPPORT_OUTLINES,
    TRIANGULATION,
    FORCES,
    HINGES,
    STRESS_AXES,
    STRAIN_RATE_AXES,
    SUPPORT_FILL,
    *(p for f in FIELDS for p in (f.fill, f.bar, f.labels)),
    *SERIES.values(),
    METADATA,
)
"""Every entity of a recording (without the leading "/")."""

# Colours, packed 0xRRGGBBAA.
_OUTLINE_RGBA: Final = 0x282828FF
_SUPPORT_FILL_RGBA: Final = 0x8C8273FF
_SUPPORT_LINE_RGBA: Final = 0x4A443CFF
_TRIANGULATION_RGBA: Final = 0x5A5A5AFF
_LEGEND_TEXT_RGBA: Final = 0xDCDCDCFF
STICK_RGBA: Final = 0x00963CFF  # force arrow of a sticking contact (green)
SLIP_RGBA: Final = 0xFF8C00FF  # force arrow of a sliding contact (orange)
OPEN_RGBA: Final = 0x9A9A9AFF  # an open contact with a force (should not happen)
HINGE_RGBA: Final = 0xFFD700FF
COMPRESSION_RGBA: Final = 0x141414FF  # principal axis with a negative value (near black)
TENSION_RGBA: Final = 0xDC00DCFF  # principal axis with a positive value (magenta)

_STRIP_TYPE: Final = rr.components.LineStrip2DBatch._ARROW_DATATYPE
_VEC2_TYPE: Final = _STRIP_TYPE.value_type


@dataclass(frozen=True)
class RecordingStatic:
    """Geometry and constants the recording needs once (CSR polygons as in docs/architecture.md)."""

    block_name: np.ndarray
    """(N,) str."""
    block_vert_start: np.ndarray
    """(N+1,) int64: block i's vertices are block_vert_local[start[i]:start[i+1]]."""
    block_vert_local: np.ndarray
    """(V, 2) m, counter-clockwise, relative to the block centroid at θ = 0."""
    support_name: np.ndarray
    """(S,) str."""
    support_vert_start: np.ndarray
    """(S+1,) int64."""
    support_vert_local: np.ndarray
    """(Vs, 2) m, relative to the support's initial centroid (its position in Frame.support_q)."""
    triangles: np.ndarray
    """(T, 3) int64 block indices of the centroid triangulation."""
    friction: float
    dt: float
    """s."""


class _Polygons:
    """Index arrays of a CSR polygon set: owner of each vertex, fan triangles, closed outlines."""

    def __init__(self, start: np.ndarray, local: np.ndarray) -> None:
        start = np.asarray(start, dtype=np.int64)
        self.local = np.asarray(local, dtype=np.float64).reshape(-1, 2)
        self.count = len(start) - 1
        n_vert = np.diff(start)
        self.owner = np.repeat(np.arange(self.count), n_vert)
        # Fan of each convex polygon: (s, s+k, s+k+1), k = 1 .. n-2.
        fans = [
            np.stack([np.full(n - 2, s), s + np.arange(1, n - 1), s + np.arange(2, n)], axis=1)
            for s, n in zip(start[:-1], n_vert)
        ]
        self.fan = np.concatenate(fans or [np.zeros((0, 3))]).astype(np.uint32)
        # Closed outline: the polygon's vertices, then its first vertex again.
        self.outline_index = np.concatenate(
            [np.r_[s : s + n, s] for s, n in zip(start[:-1], n_vert)] or [np.zeros(0)]
        ).astype(np.intp)
        self.outline_offsets = np.r_[0, np.cumsum(n_vert + 1)].astype(np.int32)

    def world(self, q: np.ndarray) -> np.ndarray:
        """(F, P, 3) poses -> (F, V, 2) world vertices x_b + R(θ_b) local."""
        q = q[:, self.owner]
        c, s = np.cos(q[..., 2]), np.sin(q[..., 2])
        lx, ly = self.local[:, 0], self.local[:, 1]
        return np.stack([q[..., 0] + c * lx - s * ly, q[..., 1] + s * lx + c * ly], axis=-1)

    def outlines(self, verts: np.ndarray) -> pa.Array:
        """(F, V, 2) world vertices -> F × count closed strips, one Arrow array."""
        n_frames, total = len(verts), len(self.outline_index)
        shift = (np.arange(n_frames, dtype=np.int64) * total)[:, None]
        offsets = np.r_[(self.outline_offsets[:-1][None, :] + shift).ravel(), n_frames * total]
        return _strips(verts[:, self.outline_index].reshape(-1, 2), offsets)


def _strips(points: np.ndarray, offsets: np.ndarray) -> pa.Array:
    """Ragged line strips as one Arrow array (the SDK would loop in Python): points (P, 2), offsets (n+1,)."""
    flat = pa.array(np.ascontiguousarray(points, dtype=np.float32).reshape(-1))
    values = pa.FixedSizeListArray.from_arrays(flat, type=_VEC2_TYPE)
    return pa.ListArray.from_arrays(pa.array(offsets, type=pa.int32()), values, type=_STRIP_TYPE)


def _uniform_strips(points: np.ndarray) -> pa.Array:
    """(M, k, 2): M strips of k points."""
    return _strips(points.reshape(-1, 2), np.arange(len(points) + 1, dtype=np.int32) * points.shape[1])


def _z0(verts: np.ndarray) -> np.ndarray:
    """(..., 2) -> (n, 3) float32 with z = 0."""
    return np.pad(np.asarray(verts, dtype=np.float32).reshape(-1, 2), ((0, 0), (0, 1)))


_per_frame = np.full  # (n_frames, instances per frame) -> partition lengths


class _Batch(dict):
    """name -> list of per-frame copies since the last flush (the engine may reuse its buffers)."""

    def add(self, name: str, value) -> None:
        self.setdefault(name, []).append(value)

    def stack(self, name: str) -> np.ndarray:
        return np.stack(self[name])

    def concat(self, name: str, empty_shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        """Ragged per-frame arrays -> (all rows, rows per frame)."""
        lengths = np.array([len(p) for p in self[name]], dtype=np.int64)
        return (np.concatenate(self[name]) if lengths.sum() else np.zeros(empty_shape)), lengths


class Recorder:
    """Writes one run's ``.rrd``. A context manager; ``close`` is idempotent.

    >>> with Recorder(path, static, {"scenario": "wall"}) as rec:   # doctest: +SKIP
    ...     for frame in frames:
    ...         rec.log_frame(frame)

    Leaving the ``with`` block by an exception closes the recording with status "failed"
    (KeyboardInterrupt: "interrupted") and the time of the last frame; the file is complete either way.
    """

    def __init__(
        self,
        path: str | os.PathLike,
        static: RecordingStatic,
        metadata: dict,
        application_id: str = APPLICATION_ID,
        batch_frames: int = 100,
        *,
        main_field: str = "cell_spherical_stress",
        field_ranges: dict[str, tuple[float, float]] | None = None,
    ) -> None:
        if main_field not in _FIELD_BY_KEY:
            raise ValueError(f"main_field must be one of {sorted(_FIELD_BY_KEY)}, not {main_field!r}")
        self.path, self.static, self.metadata = os.fspath(path), static, dict(metadata)
        self.batch_frames = max(1, int(batch_frames))
        self._t0, self._closed = time.perf_counter(), False
        self._blocks = _Polygons(static.block_vert_start, static.block_vert_local)
        self._supports = _Polygons(static.support_vert_start, static.support_vert_local)
        self._triangles = np.asarray(static.triangles, dtype=np.intp).reshape(-1, 3)
        self._n = n = self._blocks.count
        first = np.asarray(static.block_vert_start[:-1], dtype=np.intp)
        loc = self._blocks.local
        size = (np.maximum.reduceat(loc, first) - np.minimum.reduceat(loc, first)) if n else np.ones((1, 2))
        self.block_height = float(np.median(size[:, 1]))  # m, median block height: the force-arrow unit
        self._glyph_length = _GLYPH_HALF_LENGTH * float(np.median(size.min(axis=1)))
        # Scales, once fixed: field key -> colour range (lo, hi); m per N; glyph set -> |λ| at full length.
        self.field_ranges: dict[str, tuple[float, float]] = dict(field_ranges or {})
        self.force_scale: float | None = None
        self.axis_scale: dict[str, float] = {}
        self._legends: set[str] = set()
        self._legend_box = (0.0, 0.0, 0.0, 0.0)
        self._frames, self._last = 0, None  # frames logged; (step, time) of the last one
        self._ref: tuple[np.ndarray, np.ndarray, float] | None = None  # first block_q, support_q, E_pot
        self._batch = _Batch()
        meta_json = json.dumps(self.metadata, sort_keys=True, default=str)
        self.recording_id = str(uuid.uuid5(_RECORDING_NAMESPACE, meta_json))
        self.rec = rr.RecordingStream(application_id, recording_id=self.recording_id)
        os.makedirs(os.path.dirname(os.path.abspath(self.path)), exist_ok=True)
        self.rec.save(self.path, default_blueprint=build_blueprint(main_field))
        self._log_static()
        self._log_metadata("running", "")

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None or issubclass(exc_type, KeyboardInterrupt):
            self.close("completed" if exc_type is None else "interrupted")
        else:
            self.close("failed", f"{exc_type.__name__}: {exc}")

    def log_frame(self, frame: Frame) -> None:
        """Buffer one frame; sends the buffer when it holds ``batch_frames`` frames."""
        if self._closed:
            raise RuntimeError("Recorder is closed")
        f64 = np.float64
        if self._ref is None:
            self._ref = (
                np.array(frame.block_q, f64),
                np.array(frame.support_q, f64).reshape(-1, 3),
                float(frame.energy_potential),
            )
            self._log_plane(*self._ref[:2])
        b = self._batch
        b.add("step", int(frame.step))
        b.add("time", float(frame.time))
        b.add("scalars", [float(getattr(frame, name)) for name in _SCALARS])
        b.add("block_q", np.array(frame.block_q, f64))
        b.add("support_q", np.array(frame.support_q, f64).reshape(-1, 3))
        b.add("support_v", np.array(frame.support_v, f64).reshape(-1, 2))
        force = np.asarray(frame.contact_force, f64).reshape(-1, 2)
        status = np.asarray(frame.contact_status).reshape(-1)
        shown = (status != CONTACT_OPEN) | np.any(force != 0.0, axis=1)  # open contacts carry no force
        b.add("contact_point", np.asarray(frame.contact_point, f64).reshape(-1, 2)[shown])
        b.add("contact_force", force[shown])
        b.add("contact_status", status[shown])
        b.add("contact_mobilised", np.asarray(frame.contact_mobilised, f64).reshape(-1)[shown])
        b.add("hinge_point", np.array(getattr(frame, "hinge_point", np.zeros((0, 2))), f64).reshape(-1, 2))
        for key in _TENSOR_KEYS:
            b.add(key, _tensor(frame.tensors, key, self._n))
        self._last = (int(frame.step), float(frame.time))
        self._frames += 1
        if len(b["step"]) >= self.batch_frames:
            self.flush()

    def flush(self) -> None:
        """Send the buffered frames now."""
        batch, self._batch = self._batch, _Batch()  # an interrupted send loses a batch, never duplicates
        if batch:
            self._send_batch(batch)

    def close(self, status: str = "completed", note: str = "") -> None:
        """Flush, write the final run document and disconnect (which writes the file's footer).

        ``status``: "completed", "interrupted", "failed", "diverged"...; ``note``: one line, e.g.
        "interrupted at t = 0.412 s (step 412)" (without a note, the last frame's time is given).
        """
        if self._closed:
            return
        self._closed = True
        error: Exception | None = None
        try:
            try:
                self.flush()
            except Exception as err:  # keep going: the file must be complete
                error = err
                note = f"{note} (recording flush failed: {err!r})".strip()
            self._log_metadata(status, note)
        finally:
            self.rec.disconnect()
        if error is not None:
            if status == "completed":
                raise error
            warnings.warn(f"recording flush failed while closing: {error!r}", RuntimeWarning, stacklevel=2)

    # ---- static content
    def _log_static(self) -> None:
        rec, st = self.rec, self.static
        for f in FIELDS:
            rec.log(f.fill, rr.Mesh3D.from_fields(triangle_indices=self._blocks.fan), static=True)
        rec.log(
            SUPPORT_FILL,
            rr.Mesh3D.from_fields(triangle_indices=self._supports.fan, albedo_factor=_SUPPORT_FILL_RGBA),
            static=True,
        )
        rec.log(
            BLOCKS,
            rr.LineStrips2D.from_fields(colors=_OUTLINE_RGBA, radii=-0.75, draw_order=30.0),
            rr.AnyValues(name=[viewer_safe_text(str(n)) for n in st.block_name]),
            static=True,
        )
        names = [viewer_safe_text(str(n)) for n in st.support_name]
        rec.log(
            SUPPORT_OUTLINES,
            rr.LineStrips2D.from_fields(colors=_SUPPORT_LINE_RGBA, radii=-0.75),
            rr.AnyValues(name=names),
            static=True,
        )
        rec.log(
            TRIANGULATION,
            rr.LineStrips2D.from_fields(colors=_TRIANGULATION_RGBA, radii=-0.5, draw_order=31.0),
            static=True,
        )
        for path in (STRESS_AXES, STRAIN_RATE_AXES):
            rec.log(path, rr.LineStrips2D.from_fields(radii=-1.25, draw_order=40.0), static=True)
        rec.log(FORCES, rr.Arrows2D.from_fields(radii=-1.25, draw_order=50.0), static=True)
        rec.log(HINGES, rr.Points2D.from_fields(radii=-4.0, colors=HINGE_RGBA, draw_order=60.0), static=True)
        series_names = {
            "energy": ["kinetic", "potential change", "dissipated", "support work"],
            "max_displacement": ["max block displacement"],
            "support_velocity": [f"{n} v{c}" for n in names for c in "xy"],
            "support_displacement": [f"{n} u{c}" for n in names for c in "xy"],
            "iterations": ["NLGS iterations"],
            "residual": ["NLGS residual"],
            "contacts": ["contacts"],
        }
        for key, path in SERIES.items():
            rec.log(path, rr.SeriesLines(names=series_names[key]), static=True)

    def _log_plane(self, block_q: np.ndarray, support_q: np.ndarray) -> None:
        """Pinhole and y-up transform sized to the structure at the first frame; places the legend."""
        sup = self._supports.world(support_q[None])[0]
        blk = self._blocks.world(block_q[None])[0] if self._n else sup
        lo, hi = blk.min(axis=0), blk.max(axis=0)
        size = float(max(hi - lo)) or 1.0
        if len(sup):  # show the supports, but a wide ground only a little beyond the blocks
            lo = np.minimum(lo, np.maximum(sup.min(axis=0), lo - _SUPPORT_MARGIN * size))
            hi = np.maximum(hi, np.minimum(sup.max(axis=0), hi + _SUPPORT_MARGIN * size))
        pad, bar = 0.05 * size, 0.025 * size
        ya, yb = blk[:, 1].min(), blk[:, 1].max()
        room = 0.08 * (yb - ya)  # for the labels above and below the bar
        self._legend_box = (hi[0] + 2 * pad, ya + room, hi[0] + 2 * pad + bar, yb - room)
        x0, y0 = lo[0] - pad, hi[1] + pad
        resolution = [hi[0] + 3 * pad + bar + 0.12 * size - x0, y0 - lo[1] + pad]
        self.rec.log(
            PLANE,
            rr.Pinhole(focal_length=_CAMERA_HEIGHT, principal_point=[0.0, 0.0], resolution=resolution),
            rr.Transform3D(translation=[x0, y0, _CAMERA_HEIGHT], mat3x3=np.diag([1.0, -1.0, -1.0])),
            static=True,
        )
        self.rec.log(XY, rr.Transform3D(translation=[-x0, y0, 0.0], scale=[1.0, -1.0, 1.0]), static=True)

    def _log_legend(self, f: FieldSpec) -> None:
        """Colour bar (a Mesh3D gradient beside the structure) and its labels, once the range is fixed."""
        (lo, hi), (xa, ya, xb, yb) = self.field_ranges[f.key], self._legend_box
        verts, tri, colors = colorbar_mesh(self._legend_box, COOLWARM if f.signed else VIRIDIS)
        bar = rr.Mesh3D(vertex_positions=_z0(verts), triangle_indices=tri, vertex_colors=colors)
        self.rec.log(f.bar, bar, static=True)
        labels = [tick_label(v, f.unit, max(-lo, hi), f.signed) for v in (lo, 0.5 * (lo + hi), hi)]
        labels[-1] = f"{f.title}\n{labels[-1]}"
        xm, gap = 0.5 * (xa + xb), 0.04 * (yb - ya)
        pos = [[xm, ya - gap], [2 * xb - xa, 0.5 * (ya + yb)], [xm, yb + 2 * gap]]
        self.rec.log(
            f.labels,
            rr.Points2D(pos, labels=labels, radii=-0.5, show_labels=True, colors=_LEGEND_TEXT_RGBA),
            static=True,
        )

    # ---- per-batch content
    def _send_batch(self, b: _Batch) -> None:
        idx = [
            rr.TimeColumn("step", sequence=np.asarray(b["step"], dtype=np.int64)),
            rr.TimeColumn("sim_time", duration=np.asarray(b["time"], dtype=np.float64)),
        ]
        q = b.stack("block_q")  # (F, N, 3)
        tensors = {key: b.stack(key) for key in _TENSOR_KEYS}
        if self._fix_scales(tensors, b):
            self._log_metadata("running", "")
        verts = self._blocks.world(q)  # (F, V, 2)
        self._send_blocks(idx, verts, tensors)
        self._send_supports(idx, b.stack("support_q"))
        self._send_triangulation(idx, q)
        self._send_axes(idx, q, tensors)
        self._send_contacts(idx, b)
        self._send_series(idx, b, q)

    def _fix_scales(self, tensors: dict[str, np.ndarray], b: _Batch) -> bool:
        """Fix the scales not fixed yet from this batch if it has non-zero data; True if any was fixed."""
        fixed = False
        for f in FIELDS:
            if f.key not in self.field_ranges:
                m = nice_ceil(robust_max_abs(tensors[f.key], _ROBUST_PERCENTILE))
                if m > 0.0:  # all zero or NaN so far: any range draws it the same, decide later
                    self.field_ranges[f.key] = (-m, m) if f.signed else (0.0, m)
            if f.key in self.field_ranges and f.key not in self._legends:
                self._log_legend(f)
                self._legends.add(f.key)
                fixed = True
        if self.force_scale is None:
            forces, _ = b.concat("contact_force", (0, 2))
            m = nice_ceil(robust_max_abs(np.hypot(forces[:, 0], forces[:, 1]), _ROBUST_PERCENTILE))
            if m > 0.0:
                self.force_scale, fixed = self.block_height / m, True
        for name, (values_key, _) in _AXES.items():
            m = nice_ceil(robust_max_abs(tensors[values_key], _ROBUST_PERCENTILE))
            if name not in self.axis_scale and m > 0.0:
                self.axis_scale[name], fixed = m, True
        return fixed

    def _send_blocks(self, idx: list, verts: np.ndarray, tensors: dict[str, np.ndarray]) -> None:
        """One fill per field (same vertices, colours from the field), the outlines and hover values."""
        n_frames, n_vert = verts.shape[:2]
        pos = _z0(verts)
        for f in FIELDS:
            lo, hi = self.field_ranges.get(f.key, (-1.0, 1.0))
            colors = map_scalars(tensors[f.key], lo, hi, COOLWARM if f.signed else VIRIDIS, NAN_RGBA)
            self.rec.send_columns(
                f.fill,
                indexes=idx,
                columns=rr.Mesh3D.columns(
                    vertex_positions=pos,
                    vertex_colors=colors[:, self._blocks.owner].reshape(-1),
                ).partition(_per_frame(n_frames, n_vert)),
            )
        # pyarrow arrays: AnyValues.columns turns 1-D numpy arrays into Python lists of lists (slow).
        values = {name: pa.array(tensors[key].reshape(-1)) for name, key in _HOVER_VALUES.items()}
        per_frame = _per_frame(n_frames, self._n)
        self.rec.send_columns(
            BLOCKS,
            indexes=idx,
            columns=[
                *rr.LineStrips2D.columns(strips=self._blocks.outlines(verts)).partition(per_frame),
                *rr.AnyValues.columns(**values).partition(per_frame),
            ],
        )

    def _send_supports(self, idx: list, support_q: np.ndarray) -> None:
        poly, n_frames = self._supports, len(support_q)
        if poly.count:
            verts = poly.world(support_q)
            self.rec.send_columns(
                SUPPORT_FILL,
                indexes=idx,
                columns=rr.Mesh3D.columns(vertex_positions=_z0(verts)).partition(_per_frame(n_frames, verts.shape[1])),
            )
            self.rec.send_columns(
                SUPPORT_OUTLINES,
                indexes=idx,
                columns=rr.LineStrips2D.columns(strips=poly.outlines(verts)).partition(
                    _per_frame(n_frames, poly.count)
                ),
            )

    def _send_triangulation(self, idx: list, q: np.ndarray) -> None:
        if len(self._triangles):
            closed = q[:, self._triangles[:, [0, 1, 2, 0]], :2]  # (F, T, 4, 2)
            strips = _uniform_strips(closed.reshape(-1, 4, 2))
            self.rec.send_columns(
                TRIANGULATION,
                indexes=idx,
                columns=rr.LineStrips2D.columns(strips=strips).partition(_per_frame(len(q), len(self._triangles))),
            )

    def _send_axes(self, idx: list, q: np.ndarray, tensors: dict[str, np.ndarray]) -> None:
        """Two segments per cell along the principal directions, half-length ∝ |λ|, coloured by sign."""
        for name, (values_key, angle_key) in _AXES.items():
            lam = np.nan_to_num(tensors[values_key], nan=0.0)  # (F, N, 2): major, minor
            ang = np.nan_to_num(tensors[angle_key], nan=0.0)  # (F, N): direction of the major one
            scale = self.axis_scale.get(name)
            half = np.minimum(np.abs(lam) / scale, 1.0) * self._glyph_length if scale else 0.0 * lam
            c, s = np.cos(ang), np.sin(ang)
            axes = np.stack([np.stack([c, s], -1), np.stack([-s, c], -1)], axis=2)  # (F, N, 2, 2)
            d, centre = axes * half[..., None], q[:, :, None, :2]
            ends = np.stack([centre - d, centre + d], axis=3)  # (F, N, axis, end, xy)
            colors = np.where(lam < 0.0, np.uint32(COMPRESSION_RGBA), np.uint32(TENSION_RGBA)).reshape(-1)
            self.rec.send_columns(
                f"{XY}/{name}",
                indexes=idx,
                columns=rr.LineStrips2D.columns(
                    strips=_uniform_strips(ends.reshape(-1, 2, 2)),
                    colors=colors,
                ).partition(_per_frame(len(q), 2 * self._n)),
            )

    def _send_contacts(self, idx: list, b: _Batch) -> None:
        """Force on body b at each closed contact, coloured stick / slip, capped; hinges as points."""
        points, lengths = b.concat("contact_point", (0, 2))
        forces, _ = b.concat("contact_force", (0, 2))
        status, _ = b.concat("contact_status", (0,))
        mobilised, _ = b.concat("contact_mobilised", (0,))
        colors = np.full(len(status), np.uint32(OPEN_RGBA))
        colors[status == CONTACT_STICK] = STICK_RGBA
        colors[status == CONTACT_SLIP] = SLIP_RGBA
        magnitude = np.hypot(forces[:, 0], forces[:, 1])
        length = magnitude * (self.force_scale or 0.0)
        cap = _ARROW_CAP * self.block_height
        factor = (self.force_scale or 0.0) * np.minimum(1.0, cap / np.maximum(length, 1e-300))
        self.rec.send_columns(
            FORCES,
            indexes=idx,
            columns=[
                *rr.Arrows2D.columns(
                    origins=points.astype(np.float32),
                    colors=colors,
                    vectors=(forces * factor[:, None]).astype(np.float32),
                ).partition(lengths),
                *rr.AnyValues.columns(force=pa.array(magnitude), mobilised_friction=pa.array(mobilised)).partition(
                    lengths
                ),
            ],
        )
        hinges, per_frame = b.concat("hinge_point", (0, 2))
        self.rec.send_columns(
            HINGES, indexes=idx, columns=rr.Points2D.columns(positions=hinges.astype(np.float32)).partition(per_frame)
        )

    def _send_series(self, idx: list, b: _Batch, q: np.ndarray) -> None:
        n_frames = len(q)
        ref_q, ref_sq, ref_pot = self._ref
        sc = np.array(b["scalars"])  # (F, 7) in _SCALARS order
        moved = q[..., :2] - ref_q[None, :, :2]
        sq, sv = b.stack("support_q"), b.stack("support_v")
        series = {
            "energy": np.stack([sc[:, 0], sc[:, 1] - ref_pot, sc[:, 2], sc[:, 3]], axis=1),
            "max_displacement": np.sqrt((moved**2).sum(-1)).max(axis=1) if self._n else np.zeros(n_frames),
            "support_velocity": sv,
            "support_displacement": sq[..., :2] - ref_sq[None, :, :2],
            "iterations": sc[:, 4],
            "residual": sc[:, 5],
            "contacts": sc[:, 6],
        }
        for key, values in series.items():
            values = np.asarray(values, dtype=np.float64).reshape(n_frames, -1)
            if values.shape[1]:
                self.rec.send_columns(
                    SERIES[key],
                    indexes=idx,
                    columns=rr.Scalars.columns(scalars=values.reshape(-1)).partition(
                        _per_frame(n_frames, values.shape[1])
                    ),
                )

    # ---- run document
    def _log_metadata(self, status: str, note: str) -> None:
        text = viewer_safe_text(self._metadata_markdown(status, note))
        self.rec.log(METADATA, rr.TextDocument(text, media_type="text/markdown"), static=True)

    def _metadata_markdown(self, status: str, note: str) -> str:
        line = status
        if self._last is not None:
            at = f"t = {self._last[1]:.3f} s (step {self._last[0]})"
            line = f"{status}, last frame {at}" if status in ("completed", "running") else f"{status} at {at}"
        if note:  # the caller's note usually says it all ("interrupted at t = ..."): do not repeat it
            line = note if note.startswith(status) else f"{line}: {note}"
        pct = f"{_ROBUST_PERCENTILE:g}th percentile"
        lines = [
            f"# masonry — {self.metadata.get('scenario', 'run')}",
            "",
            f"**Status:** {line}",
            "",
            f"**Wall time:** {time.perf_counter() - self._t0:.2f} s · **frames:** {self._frames} · "
            f"**dt:** {self.static.dt:g} s · **friction:** {self.static.friction:g} · "
            f"**blocks:** {self._n} · **supports:** {self._supports.count}",
            "",
            "## Parameters",
            "",
            "| parameter | value |",
            "|---|---|",
            *(f"| {k} | {v} |" for k, v in _flatten(self.metadata)),
            "",
            "## How to read the views",
            "",
            "- **Forces**: arrow = contact force on body b at the contact point; green = stick, orange = "
            f"slip. Scale {_fmt_scale(self.force_scale, 'm per N')}: a force of the first batch's {pct} is "
            f"one median block height ({self.block_height:.3g} m) long; arrows are capped at {_ARROW_CAP:g} "
            "block heights (hover an arrow for its force in N). Yellow dots: hinges.",
            "- **Principal axes**: two segments per cell along the eigenvectors, half-length proportional "
            f"to |λ|, {self._glyph_length:.3g} m at the value below (longer ones clipped); black = "
            "compression / contraction, magenta = tension / extension. Stress axes in the main view; "
            "strain-rate axes and the centroid triangulation in the volumetric strain rate view.",
            *(
                f"  - {n.replace('_', ' ')}: full length at |λ| = {_fmt_scale(self.axis_scale.get(n), '')}"
                for n in _AXES
            ),
            "- **Fields**: each colour range is fixed for the whole run, at the first batch where the field "
            f"is not zero ({pct} of |value|, rounded up); values beyond take the end colours; grey = "
            "undefined (NaN). Hover a block outline for its values.",
            "",
            "| field | colour map | range |",
            "|---|---|---|",
        ]
        for f in FIELDS:
            r = self.field_ranges.get(f.key)
            rng = "not fixed yet (zero so far)" if r is None else f"{r[0]:.4g} … {r[1]:.4g} {f.unit}"
            lines.append(f"| {f.title} | {'blue–grey–red' if f.signed else 'viridis'} | {rng} |")
        lines += [
            "",
            "## Versions",
            "",
            "| package | version |",
            "|---|---|",
            *(f"| {k} | {v} |" for k, v in _versions().items()),
        ]
        return "\n".join(lines) + "\n"


_SAFE_EXTRA: Final = frozenset("–—‘’“”…·•×−≤≥≈°±²³µ√∞→✓∑ΔΣ")


def viewer_safe_text(text: str) -> str:
    """``text`` with every character the viewer's font may lack replaced by "?".

    Rerun 0.41's viewer panics (the whole viewer dies) on a glyph its one bundled font (Inter) lacks,
    e.g. "∝" or CJK, in a document, label or hover text. Kept: ASCII, Latin-1, Latin Extended-A, Greek,
    basic Cyrillic and a few punctuation and math signs checked in the headless viewer.
    """

    def ok(c: str) -> bool:
        o = ord(c)
        return c in "\n\t" or 0x20 <= o < 0x7F or 0xA0 <= o < 0x180 or 0x370 <= o < 0x460 or c in _SAFE_EXTRA

    return "".join(c if ok(c) else "?" for c in text)


def _tensor(tensors: dict, key: str, n: int) -> np.ndarray:
    """A float64 copy of tensors[key]; NaN of the expected shape when the field is missing."""
    shape = (n, 2) if key in ("cell_principal_stress", "cell_principal_strain_rate") else (n,)
    value = tensors.get(key) if tensors else None
    return np.full(shape, np.nan) if value is None else np.array(value, dtype=np.float64).reshape(shape)


def _flatten(d: dict, prefix: str = "") -> list[tuple[str, str]]:
    """Nested metadata -> (dotted key, table-safe value) rows."""
    return [
        row
        for k, v in d.items()
        for row in (
            _flatten(v, f"{prefix}{k}.")
            if isinstance(v, dict)
            else [(f"{prefix}{k}", str(v).replace("|", "\\|").replace("\n", " "))]
        )
    ]


def _fmt_scale(x: float | None, unit: str) -> str:
    return "not fixed yet (zero so far)" if x is None else f"{x:.4g} {unit}".strip()


def _versions() -> dict[str, str]:
    def dist(name: str) -> str:
        try:
            return importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            return "not installed"

    return {
        "masonry": MASONRY_VERSION,
        "rerun-sdk": rr.__version__,
        "numpy": np.__version__,
        "numba": dist("numba"),
        "python": platform.python_version(),
    }


# ---------------------------------------------------------------------------------------------- blueprint
def _structure_view(name: str, field: FieldSpec, extra: tuple[str, ...] = ()) -> rrb.Spatial2DView:
    paths = (SUPPORT_FILL, field.fill, field.bar, BLOCKS, SUPPORT_OUTLINES, field.labels, *extra)
    return rrb.Spatial2DView(origin=f"/{PLANE}", contents=[f"+ /{p}" for p in paths], name=name)


def build_blueprint(main_field: str = "cell_spherical_stress") -> rrb.Blueprint:
    """Structure views in tabs (left); time series and the run document (right)."""
    main = _FIELD_BY_KEY[main_field]
    strain_rate_extra = (TRIANGULATION, STRAIN_RATE_AXES)
    structure = rrb.Tabs(
        _structure_view(f"Structure: forces, principal stress, {main.title}", main, (FORCES, STRESS_AXES, HINGES)),
        *(_structure_view(f.title, f, strain_rate_extra if f is FIELDS[0] else ()) for f in FIELDS),
        active_tab=0,
    )

    whole_run = rrb.TimeAxis(
        view_range=rrb.TimeRange(rrb.TimeRangeBoundary.infinite(), rrb.TimeRangeBoundary.infinite())
    )

    def plot(key: str, name: str) -> rrb.TimeSeriesView:
        return rrb.TimeSeriesView(origin=f"/{SERIES[key]}", name=name, axis_x=whole_run)

    right = rrb.Vertical(
        rrb.Tabs(
            plot("energy", "Energy (J)"),
            plot("max_displacement", "Max block displacement (m)"),
            plot("support_velocity", "Support velocity (m/s)"),
            plot("support_displacement", "Support displacement (m)"),
        ),
        rrb.Tabs(
            plot("iterations", "NLGS iterations"), plot("residual", "NLGS residual"), plot("contacts", "Contacts")
        ),
        rrb.TextDocumentView(origin=f"/{METADATA}", name="Run"),
        row_shares=[2, 2, 3],
    )
    return rrb.Blueprint(
        rrb.Horizontal(structure, right, column_shares=[3, 2]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed"),
    )


# ---------------------------------------------------------------------------------------------- read back
def inspect_recording(path: str | os.PathLike) -> dict:
    """Summary of a recording file; works without a footer too (a killed writer's file).

    Keys: application_id, recording_id, frames (distinct `step` values), steps (first, last) or None,
    time_span (first, last sim_time, s) or None, entity_paths (sorted, with the leading "/"),
    has_blueprint, complete (footer present), metadata (the run document's Markdown, or None).
    """
    with warnings.catch_warnings():  # a file without footer is reported as complete=False below
        warnings.simplefilter("ignore")
        reader = rr.chunk.RrdReader(os.fspath(path))
        recordings = reader.recordings()
    if not recordings:
        raise ValueError(f"{path}: no recording in this file")
    entry = recordings[0]
    paths: set[str] = set()
    steps: set[int] = set()
    t_lo, t_hi = np.inf, -np.inf
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
        if "step" in names:
            steps.update(batch.column("step").to_numpy().tolist())
        if "sim_time" in names and batch.num_rows:
            t = batch.column("sim_time").cast(pa.int64()).to_numpy() * 1e-9
            t_lo, t_hi = min(t_lo, t.min()), max(t_hi, t.max())
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
        "metadata": metadata,
    }


# ---------------------------------------------------------------------------------------- headless viewer
def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _viewer_executable() -> str | None:
    """The `rerun` next to this interpreter (same version as the SDK), else the one on PATH."""
    here = os.path.join(os.path.dirname(sys.executable), "rerun")
    return here if os.access(here, os.X_OK) else shutil.which("rerun")


def screenshot_recording(
    rrd_path: str | os.PathLike,
    png_path: str | os.PathLike,
    time_step: int | None = None,
    timeout: float = 60,
    *,
    tabs_dir: str | os.PathLike | None = None,
) -> list[str]:
    """Open a recording in a headless viewer, save a PNG of the window, return the views' error reports.

    ``time_step``: the `step` shown (None: the last one). The PNG shows the default layout. A hidden tab
    is not drawn and cannot report, so every tab is then brought to the front in turn (saved as
    ``tabs_dir/tab<i>.png`` if given). Returns "view: severity: summary" for every report of every view;
    empty means healthy. Needs a Vulkan driver (Debian: mesa-vulkan-drivers libvulkan1).
    """
    from rerun.experimental import ViewerClient

    os.makedirs(os.path.dirname(os.path.abspath(png_path)), exist_ok=True)
    deadline = time.monotonic() + timeout
    viewer = ViewerClient.spawn(
        headless=True, port=_free_port(), hide_welcome_screen=True, executable_path=_viewer_executable()
    )
    pid = viewer._pid
    try:
        while True:  # until the viewer answers
            try:
                viewer.get_state()
                break
            except Exception:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.2)
        viewer.open(os.path.abspath(rrd_path))
        while True:  # until the file is loaded and its timelines are known
            state = viewer.get_state()
            recs = [r for r in state.recordings if r.timelines]
            if not state.loading and recs and state.views:
                break
            if time.monotonic() > deadline:
                raise TimeoutError(f"viewer did not load {rrd_path} within {timeout} s")
            time.sleep(0.2)
        if time_step is None:
            line = next((t for r in recs for t in r.timelines if t.name == "step"), None)
            time_step = line.end if line is not None and line.end is not None else 0
        viewer.set_time("step", sequence=int(time_step), play_state="paused")
        _settle(viewer)
        viewer.save_screenshot(os.path.abspath(png_path))
        reports = {v.view_id: (v.name, v.reports) for v in viewer.get_state().views}
        blueprint = viewer.get_blueprint(of="recording").blueprint
        tabs = [
            c["ContainerBlueprint"]
            for c in blueprint.values()
            if c.get("ContainerBlueprint", {}).get("container_kind") == "Tabs"
        ]
        for i in range(1, max((len(t.get("contents", [])) for t in tabs), default=0)):
            if time.monotonic() > deadline:
                raise TimeoutError(f"viewer did not show every tab of {rrd_path} within {timeout} s")
            for t in tabs:
                t["active_tab"] = t["contents"][min(i, len(t["contents"]) - 1)]
            viewer.set_blueprint(blueprint, of="recording")
            _settle(viewer)
            png = viewer.take_screenshot()
            if tabs_dir is not None:
                os.makedirs(tabs_dir, exist_ok=True)
                with open(os.path.join(tabs_dir, f"tab{i}.png"), "wb") as fh:
                    fh.write(png)
            for v in viewer.get_state().views:
                if v.reports or v.view_id not in reports:
                    reports[v.view_id] = (v.name, v.reports)
        return [
            f"{name}: {r.severity}: {r.summary}" + (f" ({r.details})" if r.details else "")
            for name, rs in reports.values()
            for r in rs
        ]
    finally:
        with contextlib.suppress(Exception):
            viewer.quit(timeout=5.0)
        if viewer._pid is not None and pid is not None:  # quit failed: end the shim's process group
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(pid, signal.SIGKILL)


def _settle(viewer, paints: int = 2, pause: float = 0.2) -> None:
    """Let the viewer paint a few frames: newly shown views fetch their chunks on demand."""
    for _ in range(paints):
        viewer.take_screenshot(max_size=64)
        time.sleep(pause)
