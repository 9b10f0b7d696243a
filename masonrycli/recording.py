"""Rerun recording of a run: the only module that imports rerun.

One ``.rrd`` per run, written through an explicit ``rr.RecordingStream`` with an embedded default
blueprint. Everything constant is logged static; per-frame data is buffered and sent with
``send_columns`` every ``batch_frames`` frames, as one array per entity kind (never one entity per
block). Timelines: ``step`` (sequence) and ``sim_time`` (duration, s).

Drawing plane. Rerun has no filled 2-D polygon, so fills are ``Mesh3D`` at z = 0 in the 3-D space
``structure``, seen in the 2-D views through the pinhole ``structure/plane``: a camera looking straight
down from ``_CAMERA_HEIGHT`` m with focal length equal to that height, so one image unit is one metre
and the image's v axis is world −y (y up on screen). 2-D things (outlines, arrows, axes) live under
``structure/plane/xy``, whose static transform maps world (x, y) to image (x − x0, y0 − y). The
pinhole's resolution is the structure's bounding box at the first frame (plus a margin and room for the
colour legend), so the 2-D views open fitted to the structure. The camera must be far: 2-D content is
drawn at a fixed depth and a closer 3-D mesh would hide it.

Colour ranges (documented in the run document): each field's range is fixed once for the whole run, at
the first flushed batch in which the field is not identically zero: ``nice_ceil`` of the 98th percentile
of |value| over that batch, symmetric for signed fields and [0, M] for >= 0 fields; values beyond are
clipped to the end colours. The same rule fixes the force-arrow scale (a force of that robust maximum is
drawn one median block height long; arrows are capped at two) and the principal-axis glyph scales.
A ``field_ranges`` argument overrides the colour ranges.

Entity paths: ``ENTITY_PATHS`` below.
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
from masonrycli.colormap import COOLWARM, NAN_RGBA, VIRIDIS, map_scalars, nice_ceil, pack_rgba, robust_max_abs
from masonrycli.frame import CONTACT_OPEN, CONTACT_SLIP, CONTACT_STICK, Frame

# ---------------------------------------------------------------------------------------------- constants
APPLICATION_ID: Final = "masonry"
_RECORDING_NAMESPACE: Final = uuid.UUID("6f1c4f5e-9b0e-4c51-a0a6-3f0d6c1e2a77")
_CAMERA_HEIGHT: Final = 1.0e4
"""m. Distance of the drawing-plane camera (see the module docstring)."""
_ROBUST_PERCENTILE: Final = 98.0
"""Colour ranges, force and glyph scales come from this percentile of |value| (see the module docstring)."""
_ARROW_CAP: Final = 2.0
"""Longest force arrow, in median block heights (hover an arrow for its force)."""
_SUPPORT_MARGIN: Final = 0.15
"""The initial view shows supports up to this fraction of the structure's size beyond the blocks."""
_GLYPH_HALF_LENGTH: Final = 0.45
"""Largest principal-axis half-length, as a fraction of the median block's smaller side."""


class FieldSpec(NamedTuple):
    key: str
    """Name in ``Frame.tensors``."""
    short: str
    """Entity-path segment and per-block value name."""
    title: str
    unit: str
    signed: bool
    """Diverging colour map on [−M, M] if True, sequential on [0, M] otherwise."""


FIELDS: Final = (
    FieldSpec("cell_volumetric_strain_rate", "volumetric_strain_rate", "Volumetric strain rate", "1/s", True),
    FieldSpec("cell_deviatoric_strain", "deviatoric_strain", "Deviatoric cumulated strain", "", False),
    FieldSpec("cell_spherical_stress", "spherical_stress", "Spherical stress p", "Pa", True),
    FieldSpec("cell_deviatoric_stress", "deviatoric_stress", "Deviatoric stress q", "Pa", False),
)
_FIELD_BY_KEY: Final = {f.key: f for f in FIELDS}
_HOVER_VALUES: Final = (("p", "cell_spherical_stress"), ("q", "cell_deviatoric_stress"),
                        ("volumetric_strain_rate", "cell_volumetric_strain_rate"),
                        ("deviatoric_strain", "cell_deviatoric_strain"),
                        ("sliding_ratio", "block_sliding_ratio"), ("max_opening", "block_max_opening"))
"""Per-block values shown when hovering a block outline: name -> Frame.tensors key."""
_AXES: Final = {  # glyph set -> (principal values key, principal angle key)
    "stress_axes": ("cell_principal_stress", "cell_principal_angle"),
    "strain_rate_axes": ("cell_principal_strain_rate", "cell_principal_strain_rate_angle"),
}

# Entity paths.
PLANE: Final = "structure/plane"
XY: Final = "structure/plane/xy"
BLOCKS: Final = f"{XY}/blocks"
SUPPORT_OUTLINES: Final = f"{XY}/supports"
TRIANGULATION: Final = f"{XY}/triangulation"
FORCES: Final = f"{XY}/forces"
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


def field_fill_path(f: FieldSpec) -> str:
    return f"structure/fields/{f.short}"


def legend_bar_path(f: FieldSpec) -> str:
    return f"structure/legend/{f.short}"


def legend_label_path(f: FieldSpec) -> str:
    return f"{XY}/legend/{f.short}"


ENTITY_PATHS: Final = (
    PLANE, XY, BLOCKS, SUPPORT_OUTLINES, TRIANGULATION, FORCES, STRESS_AXES, STRAIN_RATE_AXES, SUPPORT_FILL,
    *(field_fill_path(f) for f in FIELDS), *(legend_bar_path(f) for f in FIELDS),
    *(legend_label_path(f) for f in FIELDS), *SERIES.values(), METADATA,
)
"""Every entity a recording holds (without the leading "/")."""

# Colours (packed 0xRRGGBBAA).
_OUTLINE_RGBA: Final = 0x282828FF
_SUPPORT_FILL_RGBA: Final = 0x8C8273FF
_SUPPORT_LINE_RGBA: Final = 0x4A443CFF
_TRIANGULATION_RGBA: Final = 0x5A5A5AFF
STICK_RGBA: Final = 0x00963CFF
"""Force arrow of a sticking contact (green)."""
SLIP_RGBA: Final = 0xFF8C00FF
"""Force arrow of a sliding contact (orange)."""
OPEN_RGBA: Final = 0x9A9A9AFF
COMPRESSION_RGBA: Final = 0x141414FF
"""Principal axis with a negative value: compression / contraction (near black)."""
TENSION_RGBA: Final = 0xDC00DCFF
"""Principal axis with a positive value: tension / extension (magenta)."""
_LEGEND_TEXT_RGBA: Final = 0xDCDCDCFF
_ENERGY_NAMES: Final = ("kinetic", "potential change", "dissipated", "support work")

_STRIP_TYPE: Final = rr.components.LineStrip2DBatch._ARROW_DATATYPE
_VEC2_TYPE: Final = _STRIP_TYPE.value_type


# ------------------------------------------------------------------------------------------ static data
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
    """(Vs, 2) m, relative to the support's initial centroid (= its reference point in Frame.support_q)."""
    triangles: np.ndarray
    """(T, 3) int64 block indices of the centroid triangulation."""
    friction: float
    dt: float
    """s."""


class _Polygons:
    """Derived index arrays for a CSR polygon set: owner of each vertex, fan triangles, closed outlines."""

    def __init__(self, start: np.ndarray, local: np.ndarray) -> None:
        start = np.asarray(start, dtype=np.int64)
        self.local = np.asarray(local, dtype=np.float64).reshape(-1, 2)
        self.count = len(start) - 1
        n_vert = np.diff(start)
        self.owner = np.repeat(np.arange(self.count), n_vert)
        # Fan triangulation of each convex polygon: (s, s+k, s+k+1), k = 1 .. n-2.
        tri = [np.stack([np.full(n - 2, s), s + np.arange(1, n - 1), s + np.arange(2, n)], axis=1)
               for s, n in zip(start[:-1], n_vert)]
        self.fan = (np.concatenate(tri) if tri else np.zeros((0, 3))).astype(np.uint32)
        # Closed outline: the polygon's vertices then its first vertex again.
        self.outline_index = np.concatenate(
            [np.r_[np.arange(s, s + n), s] for s, n in zip(start[:-1], n_vert)] or [np.zeros(0)]
        ).astype(np.intp)
        self.outline_offsets = np.r_[0, np.cumsum(n_vert + 1)].astype(np.int32)

    def world(self, q: np.ndarray) -> np.ndarray:
        """(F, P, 3) poses -> (F, V, 2) world vertices x_b + R(θ_b) local."""
        q = q[:, self.owner]
        c, s = np.cos(q[..., 2]), np.sin(q[..., 2])
        lx, ly = self.local[:, 0], self.local[:, 1]
        return np.stack([q[..., 0] + c * lx - s * ly, q[..., 1] + s * lx + c * ly], axis=-1)


def _strips(points: np.ndarray, offsets: np.ndarray) -> pa.Array:
    """Ragged line strips as one Arrow array: points (P, 2), offsets (n+1,) int32."""
    flat = pa.array(np.ascontiguousarray(points, dtype=np.float32).reshape(-1))
    values = pa.FixedSizeListArray.from_arrays(flat, type=_VEC2_TYPE)
    return pa.ListArray.from_arrays(pa.array(offsets, type=pa.int32()), values, type=_STRIP_TYPE)


def _uniform_strips(points: np.ndarray) -> pa.Array:
    """(M, k, 2) strips of k points each."""
    m, k = points.shape[0], points.shape[1]
    return _strips(points.reshape(-1, 2), np.arange(m + 1, dtype=np.int32) * k)


def _frame_offsets(per_frame: np.ndarray, n_frames: int, total: int) -> np.ndarray:
    """Offsets of n_frames copies of a per-frame offset array whose frames hold `total` points each."""
    shift = (np.arange(n_frames, dtype=np.int64) * total)[:, None]
    return np.r_[(per_frame[:-1][None, :] + shift).ravel(), n_frames * total].astype(np.int32)


# -------------------------------------------------------------------------------------------- buffering
class _Batch:
    """Copies of the per-frame arrays since the last flush (the engine may reuse its buffers)."""

    def __init__(self) -> None:
        self.step: list[int] = []
        self.time: list[float] = []
        self.block_q: list[np.ndarray] = []
        self.support_q: list[np.ndarray] = []
        self.support_v: list[np.ndarray] = []
        self.scalars: list[tuple[float, ...]] = []
        self.contact_point: list[np.ndarray] = []
        self.contact_force: list[np.ndarray] = []
        self.contact_status: list[np.ndarray] = []
        self.contact_mobilised: list[np.ndarray] = []
        self.tensors: dict[str, list[np.ndarray]] = {}

    def __len__(self) -> int:
        return len(self.step)


_SCALAR_ORDER: Final = ("energy_kinetic", "energy_potential", "energy_dissipated", "support_work",
                        "nlgs_iterations", "nlgs_residual", "contact_count")
_TENSOR_KEYS: Final = tuple(dict.fromkeys([*(f.key for f in FIELDS), *(k for pair in _AXES.values() for k in pair),
                                           *(key for _, key in _HOVER_VALUES)]))


# ---------------------------------------------------------------------------------------------- recorder
class Recorder:
    """Writes one run's ``.rrd``. Use as a context manager; ``close`` is idempotent.

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
        self.path = os.fspath(path)
        self.static = static
        self.metadata = dict(metadata)
        self.batch_frames = max(1, int(batch_frames))
        self.main_field = _FIELD_BY_KEY[main_field]
        self._t0 = time.perf_counter()
        self._closed = False
        self._blocks = _Polygons(static.block_vert_start, static.block_vert_local)
        self._supports = _Polygons(static.support_vert_start, static.support_vert_local)
        self._triangles = np.asarray(static.triangles, dtype=np.intp).reshape(-1, 3)
        self._n = self._blocks.count
        ext = np.array([np.ptp(self._blocks.local[self._blocks.owner == b], axis=0) for b in range(self._n)])
        self.block_height = float(np.median(ext[:, 1])) if self._n else 1.0
        self._glyph_length = _GLYPH_HALF_LENGTH * (float(np.median(ext.min(axis=1))) if self._n else 1.0)
        # Scales fixed at the first flush with non-zero data (see the module docstring).
        self.field_ranges: dict[str, tuple[float, float]] = dict(field_ranges or {})
        self.force_scale: float | None = None
        """m per N: arrow length of a contact force."""
        self.axis_scale: dict[str, float] = {}
        """Glyph set -> |principal value| drawn at the full half-length."""
        self._legends_logged: set[str] = set()
        self._fixed_now = False
        self._legend_box = (0.0, 0.0, 0.0, 0.0)
        self._frames = 0
        self._last: tuple[int, float] | None = None
        self._ref: tuple[np.ndarray, np.ndarray, float] | None = None  # first block_q, support_q, E_pot
        self._batch = _Batch()

        self.recording_id = str(uuid.uuid5(_RECORDING_NAMESPACE, json.dumps(self.metadata, sort_keys=True,
                                                                             default=str)))
        self.rec = rr.RecordingStream(application_id, recording_id=self.recording_id)
        os.makedirs(os.path.dirname(os.path.abspath(self.path)), exist_ok=True)
        self.rec.save(self.path, default_blueprint=build_blueprint(self.main_field.key))
        self._log_static()
        self._log_metadata("running", "")

    # ---- context manager
    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        elif issubclass(exc_type, KeyboardInterrupt):
            self.close("interrupted")
        else:
            self.close("failed", f"{exc_type.__name__}: {exc}")

    # ---- public API
    def log_frame(self, frame: Frame) -> None:
        """Buffer one frame; sends the buffer when it holds ``batch_frames`` frames."""
        if self._closed:
            raise RuntimeError("Recorder is closed")
        if self._ref is None:
            self._ref = (np.array(frame.block_q, dtype=np.float64), np.array(frame.support_q, dtype=np.float64),
                         float(frame.energy_potential))
            self._log_plane(self._ref[0], self._ref[1])
        b = self._batch
        b.step.append(int(frame.step))
        b.time.append(float(frame.time))
        b.block_q.append(np.array(frame.block_q, dtype=np.float64))
        b.support_q.append(np.array(frame.support_q, dtype=np.float64).reshape(-1, 3))
        b.support_v.append(np.array(frame.support_v, dtype=np.float64).reshape(-1, 2))
        b.scalars.append(tuple(float(getattr(frame, name)) for name in _SCALAR_ORDER))
        force = np.asarray(frame.contact_force, dtype=np.float64).reshape(-1, 2)
        status = np.asarray(frame.contact_status).reshape(-1)
        shown = (status != CONTACT_OPEN) | np.any(force != 0.0, axis=1)  # open contacts carry no force
        b.contact_point.append(np.array(np.asarray(frame.contact_point).reshape(-1, 2)[shown], dtype=np.float64))
        b.contact_force.append(force[shown])
        b.contact_status.append(np.array(status[shown]))
        b.contact_mobilised.append(np.array(np.asarray(frame.contact_mobilised, dtype=np.float64).reshape(-1)[shown]))
        for key in _TENSOR_KEYS:
            b.tensors.setdefault(key, []).append(_tensor(frame.tensors, key, self._n))
        self._last = (int(frame.step), float(frame.time))
        self._frames += 1
        if len(b) >= self.batch_frames:
            self.flush()

    def flush(self) -> None:
        """Send the buffered frames now."""
        batch, self._batch = self._batch, _Batch()  # an interrupted send loses a batch, never duplicates
        if len(batch):
            self._send_batch(batch)

    def close(self, status: str = "completed", note: str = "") -> None:
        """Flush, write the final run document, and disconnect (writes the file's footer). Idempotent."""
        if self._closed:
            return
        self._closed = True
        error: BaseException | None = None
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
        tri = self._blocks.fan
        for f in FIELDS:
            rec.log(field_fill_path(f), rr.Mesh3D.from_fields(triangle_indices=tri), static=True)
        rec.log(SUPPORT_FILL, rr.Mesh3D.from_fields(triangle_indices=self._supports.fan,
                                                   albedo_factor=_SUPPORT_FILL_RGBA), static=True)
        rec.log(BLOCKS, rr.LineStrips2D.from_fields(colors=_OUTLINE_RGBA, radii=-0.75, draw_order=30.0),
                rr.AnyValues(name=[viewer_safe_text(str(n)) for n in st.block_name]), static=True)
        rec.log(SUPPORT_OUTLINES, rr.LineStrips2D.from_fields(colors=_SUPPORT_LINE_RGBA, radii=-0.75),
                rr.AnyValues(name=[viewer_safe_text(str(n)) for n in st.support_name]), static=True)
        rec.log(TRIANGULATION, rr.LineStrips2D.from_fields(colors=_TRIANGULATION_RGBA, radii=-0.5,
                                                          draw_order=31.0), static=True)
        for path in (STRESS_AXES, STRAIN_RATE_AXES):
            rec.log(path, rr.LineStrips2D.from_fields(radii=-1.25, draw_order=40.0), static=True)
        rec.log(FORCES, rr.Arrows2D.from_fields(radii=-1.25, draw_order=50.0), static=True)
        names = [viewer_safe_text(str(n)) for n in st.support_name]
        rec.log(SERIES["energy"], rr.SeriesLines(names=list(_ENERGY_NAMES)), static=True)
        rec.log(SERIES["max_displacement"], rr.SeriesLines(names="max block displacement"), static=True)
        rec.log(SERIES["support_velocity"], rr.SeriesLines(names=[f"{n} v{c}" for n in names for c in "xy"]),
                static=True)
        rec.log(SERIES["support_displacement"],
                rr.SeriesLines(names=[f"{n} u{c}" for n in names for c in "xy"]), static=True)
        rec.log(SERIES["iterations"], rr.SeriesLines(names="NLGS iterations"), static=True)
        rec.log(SERIES["residual"], rr.SeriesLines(names="NLGS residual"), static=True)
        rec.log(SERIES["contacts"], rr.SeriesLines(names="contacts"), static=True)

    def _log_plane(self, block_q: np.ndarray, support_q: np.ndarray) -> None:
        """Pinhole and y-up transform, sized to the structure at the first frame; remembers the legend box."""
        sup = self._supports.world(support_q[None])[0]
        blk = self._blocks.world(block_q[None])[0] if self._n else sup
        lo, hi = blk.min(axis=0), blk.max(axis=0)
        size = float(max(hi - lo)) or 1.0
        if len(sup):  # show the supports, but a wide ground only a little beyond the blocks
            lo = np.minimum(lo, np.maximum(sup.min(axis=0), lo - _SUPPORT_MARGIN * size))
            hi = np.maximum(hi, np.minimum(sup.max(axis=0), hi + _SUPPORT_MARGIN * size))
        pad = 0.05 * size
        bar_w = 0.025 * size
        ya, yb = blk[:, 1].min(), blk[:, 1].max()
        shrink = 0.08 * (yb - ya)  # room for the labels above and below the bar
        self._legend_box = (hi[0] + 2 * pad, ya + shrink, hi[0] + 2 * pad + bar_w, yb - shrink)
        x0, y0 = lo[0] - pad, hi[1] + pad
        width = (hi[0] + pad - x0) + 2 * pad + bar_w + 0.12 * size
        height = y0 - (lo[1] - pad)
        self.rec.log(PLANE, rr.Pinhole(focal_length=_CAMERA_HEIGHT, principal_point=[0.0, 0.0],
                                       resolution=[width, height]),
                     rr.Transform3D(translation=[x0, y0, _CAMERA_HEIGHT], mat3x3=np.diag([1.0, -1.0, -1.0])),
                     static=True)
        self.rec.log(XY, rr.Transform3D(translation=[-x0, y0, 0.0], scale=[1.0, -1.0, 1.0]), static=True)

    def _log_legend(self, f: FieldSpec) -> None:
        """Colour bar (a Mesh3D gradient beside the structure) and its labels, for a fixed range."""
        lo, hi = self.field_ranges[f.key]
        lut = COOLWARM if f.signed else VIRIDIS
        xa, ya, xb, yb = self._legend_box
        k = 32
        y = np.linspace(ya, yb, k + 1)
        verts = np.zeros((2 * (k + 1), 3), dtype=np.float32)
        verts[0::2, 0], verts[1::2, 0] = xa, xb
        verts[0::2, 1] = verts[1::2, 1] = y
        cols = np.repeat(lut[np.rint(np.linspace(0, len(lut) - 1, k + 1)).astype(int)], 2)
        j = 2 * np.arange(k)
        tri = np.concatenate([np.stack([j, j + 1, j + 3], 1), np.stack([j, j + 3, j + 2], 1)]).astype(np.uint32)
        self.rec.log(legend_bar_path(f), rr.Mesh3D(vertex_positions=verts, triangle_indices=tri,
                                                   vertex_colors=cols), static=True)
        labels = [_fmt_quantity(v, f.unit, max(abs(lo), abs(hi)), f.signed) for v in (lo, 0.5 * (lo + hi), hi)]
        labels[-1] = f"{f.title}\n{labels[-1]}"
        xm, gap = 0.5 * (xa + xb), 0.5 * (yb - ya) * 0.08
        pos = np.array([[xm, ya - gap], [xb + (xb - xa), 0.5 * (ya + yb)], [xm, yb + 2 * gap]])
        self.rec.log(legend_label_path(f), rr.Points2D(pos, labels=labels, radii=-0.5, colors=_LEGEND_TEXT_RGBA,
                                                       show_labels=True), static=True)

    # ---- per-batch content
    def _send_batch(self, b: _Batch) -> None:
        n_frames = len(b)
        idx = [rr.TimeColumn("step", sequence=np.asarray(b.step, dtype=np.int64)),
               rr.TimeColumn("sim_time", duration=np.asarray(b.time, dtype=np.float64))]
        q = np.stack(b.block_q)  # (F, N, 3)
        tensors = {k: np.stack(v) for k, v in b.tensors.items()}
        self._fix_scales(tensors, b)
        verts = self._blocks.world(q)  # (F, V, 2)
        self._send_fields(idx, verts, tensors)
        self._send_outlines(idx, verts, q, tensors)
        self._send_supports(idx, np.stack(b.support_q))
        self._send_triangulation(idx, q)
        self._send_axes(idx, q, tensors)
        self._send_forces(idx, b)
        self._send_series(idx, b, q)
        if self._fixed_now:
            self._log_metadata("running", "")

    def _fix_scales(self, tensors: dict[str, np.ndarray], b: _Batch) -> None:
        self._fixed_now = False
        for f in FIELDS:
            if f.key in self.field_ranges and f.key in self._legends_logged:
                continue
            if f.key not in self.field_ranges:
                m = nice_ceil(robust_max_abs(tensors[f.key], _ROBUST_PERCENTILE))
                if m == 0.0:
                    continue  # all zero or NaN so far: any range draws it the same; decide later
                self.field_ranges[f.key] = (-m, m) if f.signed else (0.0, m)
            self._log_legend(f)
            self._legends_logged.add(f.key)
            self._fixed_now = True
        if self.force_scale is None:
            forces = np.concatenate(b.contact_force) if b.contact_force else np.zeros((0, 2))
            m = robust_max_abs(np.hypot(forces[:, 0], forces[:, 1]), _ROBUST_PERCENTILE)
            if m > 0.0:
                self.force_scale = self.block_height / nice_ceil(m)
                self._fixed_now = True
        for name, (values_key, _) in _AXES.items():
            if name not in self.axis_scale:
                m = nice_ceil(robust_max_abs(tensors[values_key], _ROBUST_PERCENTILE))
                if m > 0.0:
                    self.axis_scale[name] = m
                    self._fixed_now = True

    def _send_fields(self, idx: list, verts: np.ndarray, tensors: dict[str, np.ndarray]) -> None:
        n_frames, n_vert = verts.shape[:2]
        pos = np.zeros((n_frames, n_vert, 3), dtype=np.float32)
        pos[..., :2] = verts
        pos = pos.reshape(-1, 3)
        lengths = np.full(n_frames, n_vert)
        for f in FIELDS:
            lo, hi = self.field_ranges.get(f.key, (-1.0, 1.0) if f.signed else (0.0, 1.0))
            colors = map_scalars(tensors[f.key], lo, hi, COOLWARM if f.signed else VIRIDIS, NAN_RGBA)
            colors = colors[:, self._blocks.owner].reshape(-1)
            self.rec.send_columns(field_fill_path(f), indexes=idx, columns=rr.Mesh3D.columns(
                vertex_positions=pos, vertex_colors=colors).partition(lengths))

    def _send_outlines(self, idx: list, verts: np.ndarray, q: np.ndarray, tensors: dict[str, np.ndarray]) -> None:
        n_frames, n_vert = verts.shape[:2]
        poly = self._blocks
        pts = verts[:, poly.outline_index].reshape(-1, 2)
        offsets = _frame_offsets(poly.outline_offsets, n_frames, len(poly.outline_index))
        lengths = np.full(n_frames, self._n)
        # pyarrow arrays: AnyValues.columns turns a 1-D numpy array into a Python list of lists (slow).
        values = {name: pa.array(tensors[key].reshape(-1)) for name, key in _HOVER_VALUES}
        self.rec.send_columns(BLOCKS, indexes=idx, columns=[
            *rr.LineStrips2D.columns(strips=_strips(pts, offsets)).partition(lengths),
            *rr.AnyValues.columns(**values).partition(lengths),
        ])

    def _send_supports(self, idx: list, sq: np.ndarray) -> None:
        poly = self._supports
        if poly.count == 0:
            return
        n_frames = len(sq)
        verts = poly.world(sq)
        pos = np.zeros((n_frames, verts.shape[1], 3), dtype=np.float32)
        pos[..., :2] = verts
        self.rec.send_columns(SUPPORT_FILL, indexes=idx, columns=rr.Mesh3D.columns(
            vertex_positions=pos.reshape(-1, 3)).partition(np.full(n_frames, verts.shape[1])))
        offsets = _frame_offsets(poly.outline_offsets, n_frames, len(poly.outline_index))
        pts = verts[:, poly.outline_index].reshape(-1, 2)
        self.rec.send_columns(SUPPORT_OUTLINES, indexes=idx, columns=rr.LineStrips2D.columns(
            strips=_strips(pts, offsets)).partition(np.full(n_frames, poly.count)))

    def _send_triangulation(self, idx: list, q: np.ndarray) -> None:
        n_tri = len(self._triangles)
        if n_tri == 0:
            return
        pts = q[:, self._triangles[:, [0, 1, 2, 0]], :2]  # (F, T, 4, 2)
        self.rec.send_columns(TRIANGULATION, indexes=idx, columns=rr.LineStrips2D.columns(
            strips=_uniform_strips(pts.reshape(-1, 4, 2))).partition(np.full(len(q), n_tri)))

    def _send_axes(self, idx: list, q: np.ndarray, tensors: dict[str, np.ndarray]) -> None:
        """Two segments per cell along the principal directions, half-length proportional to |λ|, coloured by sign."""
        n_frames = len(q)
        for name, (values_key, angle_key) in _AXES.items():
            lam = np.nan_to_num(tensors[values_key], nan=0.0)  # (F, N, 2): major, minor
            ang = np.nan_to_num(tensors[angle_key], nan=0.0)  # (F, N)
            scale = self.axis_scale.get(name)
            half = np.zeros_like(lam) if scale is None else np.minimum(np.abs(lam) / scale, 1.0) * self._glyph_length
            c, s = np.cos(ang), np.sin(ang)
            e = np.stack([np.stack([c, s], -1), np.stack([-s, c], -1)], axis=2)  # (F, N, 2 axes, 2)
            d = e * half[..., None]
            centre = q[:, :, None, :2]
            seg = np.stack([centre - d, centre + d], axis=3)  # (F, N, 2 axes, 2 ends, 2)
            colors = np.where(lam < 0.0, np.uint32(COMPRESSION_RGBA), np.uint32(TENSION_RGBA)).reshape(-1)
            self.rec.send_columns(f"{XY}/{name}", indexes=idx, columns=rr.LineStrips2D.columns(
                strips=_uniform_strips(seg.reshape(-1, 2, 2)), colors=colors).partition(np.full(n_frames, 2 * self._n)))

    def _send_forces(self, idx: list, b: _Batch) -> None:
        lengths = np.array([len(p) for p in b.contact_point])
        points = np.concatenate(b.contact_point) if lengths.sum() else np.zeros((0, 2))
        forces = np.concatenate(b.contact_force) if lengths.sum() else np.zeros((0, 2))
        status = np.concatenate(b.contact_status) if lengths.sum() else np.zeros(0, dtype=np.int8)
        mobilised = np.concatenate(b.contact_mobilised) if lengths.sum() else np.zeros(0)
        colors = np.full(len(status), np.uint32(OPEN_RGBA))
        colors[status == CONTACT_STICK] = STICK_RGBA
        colors[status == CONTACT_SLIP] = SLIP_RGBA
        magnitude = np.hypot(forces[:, 0], forces[:, 1])
        scale = self.force_scale or 0.0
        cap = _ARROW_CAP * self.block_height
        with np.errstate(divide="ignore", invalid="ignore"):
            shrink = np.where(magnitude * scale > cap, cap / (magnitude * scale), 1.0)
        vectors = forces * (scale * shrink)[:, None]
        self.rec.send_columns(FORCES, indexes=idx, columns=[
            *rr.Arrows2D.columns(origins=points.astype(np.float32), vectors=vectors.astype(np.float32),
                                 colors=colors).partition(lengths),
            *rr.AnyValues.columns(force=pa.array(magnitude), mobilised_friction=pa.array(mobilised)
                                  ).partition(lengths),
        ])

    def _send_series(self, idx: list, b: _Batch, q: np.ndarray) -> None:
        n_frames = len(q)
        ref_q, ref_sq, ref_pot = self._ref
        sc = np.array(b.scalars)  # (F, 7) in _SCALAR_ORDER
        energy = np.stack([sc[:, 0], sc[:, 1] - ref_pot, sc[:, 2], sc[:, 3]], axis=1)
        disp = np.hypot(*(q[..., :2] - ref_q[None, :, :2]).transpose(2, 0, 1)).max(axis=1) if self._n \
            else np.zeros(n_frames)
        sq = np.stack(b.support_q)
        sv = np.stack(b.support_v)
        n_sup = sq.shape[1]

        def send(key: str, values: np.ndarray) -> None:
            values = np.asarray(values, dtype=np.float64).reshape(n_frames, -1)
            if values.shape[1]:
                self.rec.send_columns(SERIES[key], indexes=idx, columns=rr.Scalars.columns(
                    scalars=values.reshape(-1)).partition(np.full(n_frames, values.shape[1])))

        send("energy", energy)
        send("max_displacement", disp)
        send("support_velocity", sv.reshape(n_frames, 2 * n_sup))
        send("support_displacement", (sq[..., :2] - ref_sq[None, :, :2]).reshape(n_frames, 2 * n_sup))
        send("iterations", sc[:, 4])
        send("residual", sc[:, 5])
        send("contacts", sc[:, 6])

    # ---- run document
    def _log_metadata(self, status: str, note: str) -> None:
        text = viewer_safe_text(self._metadata_markdown(status, note))
        self.rec.log(METADATA, rr.TextDocument(text, media_type="text/markdown"), static=True)

    def _metadata_markdown(self, status: str, note: str) -> str:
        md = self.metadata
        scenario = md.get("scenario", "run")
        status_line = status
        if self._last is not None:
            at = f"t = {self._last[1]:.3f} s (step {self._last[0]})"
            status_line = f"{status}, last frame {at}" if status in ("completed", "running") else f"{status} at {at}"
        if note:  # the caller's note usually says it all ("interrupted at t = ..."): do not repeat the status
            status_line = note if note.startswith(status) else f"{status_line}: {note}"
        lines = [f"# masonry — {scenario}", "", f"**Status:** {status_line}", "",
                 f"**Wall time:** {time.perf_counter() - self._t0:.2f} s · **frames:** {self._frames} · "
                 f"**dt:** {self.static.dt:g} s · **friction:** {self.static.friction:g} · "
                 f"**blocks:** {self._n} · **supports:** {self._supports.count}", "", "## Parameters", "",
                 "| parameter | value |", "|---|---|"]
        lines += [f"| {k} | {v} |" for k, v in _flatten(md)]
        lines += ["", "## How to read the views", "",
                  "- **Forces**: arrow = contact force on body b at the contact point; green = stick, orange = "
                  f"slip. Scale {_fmt_scale(self.force_scale, 'm per N')}: a force of the first batch's "
                  f"{_ROBUST_PERCENTILE:g}th-percentile magnitude is one median block height "
                  f"({self.block_height:.3g} m) long; arrows are capped at {_ARROW_CAP:g} block heights "
                  "(hover an arrow for its force in N).",
                  "- **Principal axes**: two segments per cell along the eigenvectors, half-length proportional "
                  f"to |λ|, {self._glyph_length:.3g} m at the scale below (longer ones clipped); black = "
                  "compression / contraction, magenta = tension / extension. Stress axes in the main view, "
                  "strain-rate axes (and the centroid triangulation) in the volumetric strain rate view."]
        lines += [f"  - {name.replace('_', ' ')}: full length at |λ| = {_fmt_scale(self.axis_scale.get(name), '')}"
                  for name in _AXES]
        lines += ["- **Fields**: each colour range is fixed for the whole run, at the first batch where the "
                  f"field is not zero ({_ROBUST_PERCENTILE:g}th percentile of |value|, rounded up); values "
                  "beyond take the end colours; grey = undefined (NaN). Hover a block outline for its values.",
                  "", "| field | colour map | range |", "|---|---|---|"]
        for f in FIELDS:
            r = self.field_ranges.get(f.key)
            rng = "not fixed yet (field zero so far)" if r is None else f"{r[0]:.4g} … {r[1]:.4g} {f.unit}"
            lines.append(f"| {f.title} | {'blue–grey–red' if f.signed else 'viridis'} | {rng} |")
        lines += ["", "## Versions", "", "| package | version |", "|---|---|"]
        lines += [f"| {k} | {v} |" for k, v in _versions().items()]
        return "\n".join(lines) + "\n"


def viewer_safe_text(text: str) -> str:
    """``text`` with every character the viewer's only font may lack replaced by "?".

    Rerun 0.41's viewer panics (the whole viewer dies) on a glyph its bundled Inter font lacks, e.g. "∝"
    or CJK, anywhere in a document, label or hover text. Kept: Latin (ASCII, Latin-1, Extended-A),
    Greek, basic Cyrillic and a few punctuation and math signs checked in the headless viewer.
    """
    return "".join(c if _glyph_ok(c) else "?" for c in text)


_SAFE_EXTRA: Final = frozenset("–—‘’“”…·•×−≤≥≈°±²³µ√∞→✓∑ΔΣ")


def _glyph_ok(c: str) -> bool:
    o = ord(c)
    return (c in "\n\t" or 0x20 <= o < 0x7F or 0xA0 <= o < 0x180 or 0x370 <= o < 0x400 or 0x400 <= o < 0x460
            or c in _SAFE_EXTRA)


def _tensor(tensors: dict, key: str, n: int) -> np.ndarray:
    """A copy of tensors[key] as float64; NaN of the expected shape when the field is missing."""
    shape = (n, 2) if key in ("cell_principal_stress", "cell_principal_strain_rate") else (n,)
    value = tensors.get(key) if tensors else None
    if value is None:
        return np.full(shape, np.nan)
    return np.array(value, dtype=np.float64).reshape(shape)


def _flatten(d: dict, prefix: str = "") -> list[tuple[str, str]]:
    out: list[tuple[str, str]] = []
    for k, v in d.items():
        if isinstance(v, dict):
            out += _flatten(v, f"{prefix}{k}.")
        else:
            out.append((f"{prefix}{k}", str(v).replace("|", "\\|").replace("\n", " ")))
    return out


def _fmt_quantity(v: float, unit: str, span: float, signed: bool) -> str:
    """Legend value: Pa with a prefix chosen from the range, 3 significant digits, sign if signed."""
    scale, prefix = 1.0, ""
    if unit == "Pa":
        scale, prefix = next(((s, p) for s, p in ((1e9, "G"), (1e6, "M"), (1e3, "k")) if span >= s), (1.0, ""))
    x = v / scale
    text = f"{x:+.3g}" if signed and x != 0 else f"{x:.3g}"
    return f"{text} {prefix}{unit}".strip()


def _fmt_scale(x: float | None, unit: str) -> str:
    return "not fixed yet (no non-zero value so far)" if x is None else f"{x:.4g} {unit}".strip()


def _versions() -> dict[str, str]:
    def dist(name: str) -> str:
        try:
            return importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            return "not installed"

    return {"masonry": MASONRY_VERSION, "rerun-sdk": rr.__version__, "numpy": np.__version__,
            "numba": dist("numba"), "python": platform.python_version()}


# --------------------------------------------------------------------------------------------- blueprint
def _structure_view(name: str, field: FieldSpec, extra: tuple[str, ...] = ()) -> rrb.Spatial2DView:
    paths = (SUPPORT_FILL, field_fill_path(field), legend_bar_path(field), BLOCKS, SUPPORT_OUTLINES,
             legend_label_path(field), *extra)
    return rrb.Spatial2DView(origin=f"/{PLANE}", contents=[f"+ /{p}" for p in paths], name=name)


def build_blueprint(main_field: str = "cell_spherical_stress") -> rrb.Blueprint:
    """Default layout: structure tabs (left), time series and the run document (right)."""
    main = _FIELD_BY_KEY[main_field]
    structure = rrb.Tabs(
        _structure_view(f"Structure: forces, principal stress, {main.title}", main, (FORCES, STRESS_AXES)),
        *(_structure_view(f.title, f, (TRIANGULATION, STRAIN_RATE_AXES) if f.short == "volumetric_strain_rate"
                          else ()) for f in FIELDS),
        active_tab=0,
    )

    def plot(key: str, name: str) -> rrb.TimeSeriesView:
        return rrb.TimeSeriesView(origin=f"/{SERIES[key]}", name=name)

    right = rrb.Vertical(
        rrb.Tabs(plot("energy", "Energy (J)"), plot("max_displacement", "Max block displacement (m)"),
                 plot("support_velocity", "Support velocity (m/s)"),
                 plot("support_displacement", "Support displacement (m)")),
        rrb.Tabs(plot("iterations", "NLGS iterations"), plot("residual", "NLGS residual"),
                 plot("contacts", "Contacts")),
        rrb.TextDocumentView(origin=f"/{METADATA}", name="Run"),
        row_shares=[2, 2, 3],
    )
    return rrb.Blueprint(rrb.Horizontal(structure, right, column_shares=[3, 2]),
                         rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
                         rrb.TimePanel(state="collapsed"))


# -------------------------------------------------------------------------------------------- read back
def inspect_recording(path: str | os.PathLike) -> dict:
    """Summary of a recording file (works without a footer, i.e. on a killed run's file too).

    Keys: application_id, recording_id, frames (distinct `step` values), steps (first, last) or None,
    time_span (first, last sim_time in s) or None, entity_paths (sorted, with leading "/"),
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
            if chunk.entity_path == f"/{METADATA}":
                col = next((n for n in names if n.endswith(":text")), None)
                if col is not None:
                    texts = batch.column(col).to_pylist()
                    metadata = next((t[0] for t in reversed(texts) if t), metadata)
            continue
        if "step" in names:
            steps.update(batch.column("step").to_numpy().tolist())
        if "sim_time" in names:
            t = batch.column("sim_time").cast(pa.int64()).to_numpy() * 1e-9
            if t.size:
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
        "time_span": (round(float(t_lo), 9), round(float(t_hi), 9)) if steps and np.isfinite(t_lo) else None,
        "entity_paths": sorted(paths),
        "has_blueprint": bool(reader.blueprints()),
        "complete": complete,
        "metadata": metadata,
    }


# ------------------------------------------------------------------------------------- headless viewer
def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _viewer_executable() -> str | None:
    """The `rerun` next to this interpreter (same version as the SDK), else the one on PATH."""
    here = os.path.join(os.path.dirname(sys.executable), "rerun")
    return here if os.access(here, os.X_OK) else shutil.which("rerun")


def screenshot_recording(rrd_path: str | os.PathLike, png_path: str | os.PathLike, time_step: int | None = None,
                         timeout: float = 60, *, tabs_dir: str | os.PathLike | None = None) -> list[str]:
    """Open a recording in a headless viewer, save a PNG of the whole window, return the views' error reports.

    ``time_step``: the `step` to show (None: the last one). The PNG shows the default layout. Hidden tabs
    are not drawn and so cannot report, so every tab of every tab container is then brought to the front
    in turn (saved as ``tabs_dir/tab<i>.png`` if given) and the reports of all views are collected, as
    "view name: severity: summary" strings; an empty list means every view is healthy.
    Needs a Vulkan driver (Debian: mesa-vulkan-drivers libvulkan1).
    """
    from rerun.experimental import ViewerClient

    deadline = time.monotonic() + timeout
    viewer = ViewerClient.spawn(headless=True, port=_free_port(), hide_welcome_screen=True,
                                executable_path=_viewer_executable())
    pid = viewer._pid
    try:
        _retry(viewer.get_state, deadline)
        viewer.open(os.path.abspath(rrd_path))
        while True:  # wait until the file is loaded and its timelines are known
            state = viewer.get_state()
            recs = [r for r in state.recordings if r.timelines]
            if not state.loading and recs and state.views:
                break
            if time.monotonic() > deadline:
                raise TimeoutError(f"viewer did not load {rrd_path} within {timeout} s")
            time.sleep(0.2)
        if time_step is None:
            step_line = next((t for r in recs for t in r.timelines if t.name == "step"), None)
            time_step = step_line.end if step_line is not None and step_line.end is not None else 0
        viewer.set_time("step", sequence=int(time_step), play_state="paused")
        _settle(viewer)
        viewer.save_screenshot(os.path.abspath(png_path))
        reports = {v.view_id: (v.name, v.reports) for v in viewer.get_state().views}
        blueprint = viewer.get_blueprint(of="recording").blueprint
        tabs = [c["ContainerBlueprint"] for c in blueprint.values()
                if c.get("ContainerBlueprint", {}).get("container_kind") == "Tabs"]
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
        return [f"{name}: {r.severity}: {r.summary}" + (f" ({r.details})" if r.details else "")
                for name, rs in reports.values() for r in rs]
    finally:
        with contextlib.suppress(Exception):
            viewer.quit(timeout=5.0)
        if pid is not None:  # the venv's `rerun` is a Python shim: end its whole process group
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(pid, signal.SIGKILL)


def _settle(viewer, paints: int = 2, pause: float = 0.2) -> None:
    """Let the viewer paint a few frames: newly shown views fetch their chunks on demand."""
    for _ in range(paints):
        viewer.take_screenshot(max_size=64)
        time.sleep(pause)


def _retry(fn, deadline: float):
    while True:
        try:
            return fn()
        except Exception:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)
