"""The recorder: writes one run's ``.rrd`` from its frames.

One ``.rrd`` per run from an explicit ``rr.RecordingStream``, with an embedded default blueprint.
Constants are logged static; frames are buffered and sent with ``send_columns`` every ``batch_frames``
frames, one array per entity kind. Timelines ``step`` (sequence) and ``sim_time`` (duration). Entity
paths: ``layout.ENTITY_PATHS``.

The drawing plane and everything logged once: ``static_content``.

Scales (written in the run document) are fixed once per run, at the first flushed batch where the data
is not all zero, from the 98th percentile of |value| rounded up (``nice_ceil``): the colour range of each
field ([−M, M] if signed, else [0, M]; ``field_ranges`` overrides it), the force scale (that force is one
median block height long; arrows are capped at two) and the principal-axis scales.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import shutil
import time
import uuid
import warnings
from typing import Final

import numpy as np
import pyarrow as pa
import rerun as rr

from masonrycli.colormap import (
    COOLWARM,
    NAN_RGBA,
    VIRIDIS,
    map_scalars,
    nice_ceil,
    robust_max_abs,
)
from masonrycli.frame import CONTACT_OPEN, CONTACT_SLIP, CONTACT_STICK, Frame
from masonrycli.recording.arrays import FrameBatch, Polygons, partition_lengths, uniform_strips, z0
from masonrycli.recording.document import run_document, viewer_safe_text
from masonrycli.recording.layout import (
    ARROW_CAP,
    AXES,
    BLOCKS,
    COMPRESSION_RGBA,
    FIELD_BY_KEY,
    FIELDS,
    FORCES,
    GLYPH_HALF_LENGTH,
    HINGES,
    HOVER_VALUES,
    METADATA,
    OPEN_RGBA,
    ROBUST_PERCENTILE,
    SCALARS,
    SERIES,
    SLIP_RGBA,
    STICK_RGBA,
    SUPPORT_FILL,
    SUPPORT_OUTLINES,
    TENSION_RGBA,
    TENSOR_KEYS,
    TRIANGULATION,
    XY,
    build_blueprint,
)
from masonrycli.recording.readback import check_complete
from masonrycli.recording.static_content import RecordingStatic, log_legend, log_plane, log_static
from masonrycli.sinks import COMPLETED, FAILED, INTERRUPTED, RUNNING

APPLICATION_ID: Final = "masonry"
_RECORDING_NAMESPACE: Final = uuid.UUID("6f1c4f5e-9b0e-4c51-a0a6-3f0d6c1e2a77")
FLUSH_SECONDS: Final = 1.0  # s of wall-clock time between writes to the file, once the scales are fixed


@contextlib.contextmanager
def _io_errors(path: str):
    """Rerun reports a failed write (disk full) as ``RuntimeError('… (os error 28)')``: make it the
    ``OSError`` it is, so the run stops as an output failure rather than an engine error."""
    try:
        yield
    except RuntimeError as exc:  # only rerun's writes run in these blocks
        code = re.search(r"\(os error (\d+)\)", str(exc))
        if code is not None:
            raise OSError(int(code.group(1)), os.strerror(int(code.group(1)))) from None
        folder = os.path.dirname(os.path.abspath(path))
        if shutil.disk_usage(folder).free < 1 << 20:  # the cause rerun's message lost
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC)) from None
        raise OSError(errno.EIO, f"rerun could not write the recording ({str(exc).splitlines()[0]})") from None


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
        if main_field not in FIELD_BY_KEY:
            raise ValueError(f"main_field must be one of {sorted(FIELD_BY_KEY)}, not {main_field!r}")
        self.path, self.static, self.metadata = os.fspath(path), static, dict(metadata)
        self.batch_frames = max(1, int(batch_frames))
        self._t0, self._closed = time.perf_counter(), False
        self._flushed = self._t0
        self._blocks = Polygons(static.block_vert_start, static.block_vert_local)
        self._supports = Polygons(static.support_vert_start, static.support_vert_local)
        self._triangles = np.asarray(static.triangles, dtype=np.intp).reshape(-1, 3)
        self._n = n = self._blocks.count
        first = np.asarray(static.block_vert_start[:-1], dtype=np.intp)
        loc = self._blocks.local
        size = (np.maximum.reduceat(loc, first) - np.minimum.reduceat(loc, first)) if n else np.ones((1, 2))
        self.block_height = float(np.median(size[:, 1]))  # m, median block height: the force-arrow unit
        self._glyph_length = GLYPH_HALF_LENGTH * float(np.median(size.min(axis=1)))
        # Scales, once fixed: field key -> colour range (lo, hi); m per N; glyph set -> |λ| at full length.
        self.field_ranges: dict[str, tuple[float, float]] = dict(field_ranges or {})
        self.force_scale: float | None = None
        self.axis_scale: dict[str, float] = {}
        self._legends: set[str] = set()
        self._legend_box = (0.0, 0.0, 0.0, 0.0)
        self._frames, self._last = 0, None  # frames logged; (step, time) of the last one
        self._ref: tuple[np.ndarray, np.ndarray, float] | None = None  # first block_q, support_q, E_pot
        self._batch = FrameBatch()
        meta_json = json.dumps(self.metadata, sort_keys=True, default=str)
        self.recording_id = str(uuid.uuid5(_RECORDING_NAMESPACE, meta_json))
        self.rec = rr.RecordingStream(application_id, recording_id=self.recording_id)
        os.makedirs(os.path.dirname(os.path.abspath(self.path)), exist_ok=True)
        with _io_errors(self.path):
            self.rec.save(self.path, default_blueprint=build_blueprint(main_field))
            log_static(self.rec, static, self._blocks, self._supports)
            self._log_metadata(RUNNING, "")

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None or issubclass(exc_type, KeyboardInterrupt):
            self.close(COMPLETED if exc_type is None else INTERRUPTED)
        else:
            self.close(FAILED, f"{exc_type.__name__}: {exc}")

    def on_frame(self, frame: Frame) -> None:
        """Buffer one frame (the :class:`~masonrycli.sinks.FrameSink` method); sends the buffer when it holds
        ``batch_frames`` frames, or when ``FLUSH_SECONDS`` have passed and every scale is fixed (the scales
        come from whole batches, so the recording's content does not depend on the machine's speed)."""
        if self._closed:
            raise RuntimeError("Recorder is closed")
        f64 = np.float64
        if self._ref is None:
            self._ref = (
                np.array(frame.block_q, f64),
                np.array(frame.support_q, f64).reshape(-1, 3),
                float(frame.energy_potential),
            )
            self._legend_box = log_plane(self.rec, self._blocks, self._supports, *self._ref[:2])
        b = self._batch
        b.add("step", int(frame.step))
        b.add("time", float(frame.time))
        b.add("scalars", [float(getattr(frame, name)) for name in SCALARS])
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
        for key in TENSOR_KEYS:
            b.add(key, _tensor(frame.tensors, key, self._n))
        self._last = (int(frame.step), float(frame.time))
        self._frames += 1
        due = time.perf_counter() - self._flushed >= FLUSH_SECONDS and self._scales_fixed()
        if len(b["step"]) >= self.batch_frames or due:
            with _io_errors(self.path):
                self.flush()
                self.rec.flush()  # to the file: a killed run loses at most about FLUSH_SECONDS of frames
            self._flushed = time.perf_counter()

    log_frame = on_frame

    def _scales_fixed(self) -> bool:
        return (
            len(self.field_ranges) == len(FIELDS) and self.force_scale is not None and len(self.axis_scale) == len(AXES)
        )

    def flush(self) -> None:
        """Send the buffered frames now."""
        batch, self._batch = self._batch, FrameBatch()  # an interrupted send loses a batch, never duplicates
        if batch:
            self._send_batch(batch)

    def close(self, status: str = COMPLETED, note: str = "") -> None:
        """Flush, write the final run document and disconnect (which writes the file's footer), then read
        the file's footer back: rerun's writer thread reports no I/O error, so a full disk shows only as a
        file without one — raised as ``OSError``.

        ``status``: one of :data:`masonrycli.sinks.STATUSES`; ``note``: one line, e.g.
        "interrupted at t = 0.412 s (step 412)" (without a note, the last frame's time is given).
        """
        if self._closed:
            return
        self._closed = True
        error: Exception | None = None
        with _io_errors(self.path):
            try:
                try:
                    self.flush()
                except OSError:
                    raise
                except Exception as err:  # keep going: the file must be complete
                    error = err
                    note = f"{note} (recording flush failed: {err!r})".strip()
                self._log_metadata(status, note)
            finally:
                self.rec.disconnect()
        check_complete(self.path)
        if error is not None:
            if status == COMPLETED:
                raise error
            warnings.warn(f"recording flush failed while closing: {error!r}", RuntimeWarning, stacklevel=2)

    # ---- per-batch content
    def _send_batch(self, b: FrameBatch) -> None:
        idx = [
            rr.TimeColumn("step", sequence=np.asarray(b["step"], dtype=np.int64)),
            rr.TimeColumn("sim_time", duration=np.asarray(b["time"], dtype=np.float64)),
        ]
        q = b.stack("block_q")  # (F, N, 3)
        tensors = {key: b.stack(key) for key in TENSOR_KEYS}
        if self._fix_scales(tensors, b):
            self._log_metadata(RUNNING, "")
        verts = self._blocks.world(q)  # (F, V, 2)
        self._send_blocks(idx, verts, tensors)
        self._send_supports(idx, b.stack("support_q"))
        self._send_triangulation(idx, q)
        self._send_axes(idx, q, tensors)
        self._send_contacts(idx, b)
        self._send_series(idx, b, q)

    def _fix_scales(self, tensors: dict[str, np.ndarray], b: FrameBatch) -> bool:
        """Fix the scales not fixed yet from this batch if it has non-zero data; True if any was fixed."""
        fixed = False
        for f in FIELDS:
            if f.key not in self.field_ranges:
                m = nice_ceil(robust_max_abs(tensors[f.key], ROBUST_PERCENTILE))
                if m > 0.0:  # all zero or NaN so far: any range draws it the same, decide later
                    self.field_ranges[f.key] = (-m, m) if f.signed else (0.0, m)
            if f.key in self.field_ranges and f.key not in self._legends:
                log_legend(self.rec, f, self.field_ranges[f.key], self._legend_box)
                self._legends.add(f.key)
                fixed = True
        if self.force_scale is None:
            forces, _ = b.concat("contact_force", (0, 2))
            m = nice_ceil(robust_max_abs(np.hypot(forces[:, 0], forces[:, 1]), ROBUST_PERCENTILE))
            if m > 0.0:
                self.force_scale, fixed = self.block_height / m, True
        for name, (values_key, _) in AXES.items():
            m = nice_ceil(robust_max_abs(tensors[values_key], ROBUST_PERCENTILE))
            if name not in self.axis_scale and m > 0.0:
                self.axis_scale[name], fixed = m, True
        return fixed

    def _send_blocks(self, idx: list, verts: np.ndarray, tensors: dict[str, np.ndarray]) -> None:
        """One fill per field (same vertices, colours from the field), the outlines and hover values."""
        n_frames, n_vert = verts.shape[:2]
        pos = z0(verts)
        for f in FIELDS:
            lo, hi = self.field_ranges.get(f.key, (-1.0, 1.0))
            colors = map_scalars(tensors[f.key], lo, hi, COOLWARM if f.signed else VIRIDIS, NAN_RGBA)
            self.rec.send_columns(
                f.fill,
                indexes=idx,
                columns=rr.Mesh3D.columns(
                    vertex_positions=pos,
                    vertex_colors=colors[:, self._blocks.owner].reshape(-1),
                ).partition(partition_lengths(n_frames, n_vert)),
            )
        # pyarrow arrays: AnyValues.columns turns 1-D numpy arrays into Python lists of lists (slow).
        values = {name: pa.array(tensors[key].reshape(-1)) for name, key in HOVER_VALUES.items()}
        per_frame = partition_lengths(n_frames, self._n)
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
                columns=rr.Mesh3D.columns(vertex_positions=z0(verts)).partition(
                    partition_lengths(n_frames, verts.shape[1])
                ),
            )
            self.rec.send_columns(
                SUPPORT_OUTLINES,
                indexes=idx,
                columns=rr.LineStrips2D.columns(strips=poly.outlines(verts)).partition(
                    partition_lengths(n_frames, poly.count)
                ),
            )

    def _send_triangulation(self, idx: list, q: np.ndarray) -> None:
        if len(self._triangles):
            closed = q[:, self._triangles[:, [0, 1, 2, 0]], :2]  # (F, T, 4, 2)
            strips = uniform_strips(closed.reshape(-1, 4, 2))
            self.rec.send_columns(
                TRIANGULATION,
                indexes=idx,
                columns=rr.LineStrips2D.columns(strips=strips).partition(
                    partition_lengths(len(q), len(self._triangles))
                ),
            )

    def _send_axes(self, idx: list, q: np.ndarray, tensors: dict[str, np.ndarray]) -> None:
        """Two segments per cell along the principal directions, half-length ∝ |λ|, coloured by sign."""
        for name, (values_key, angle_key) in AXES.items():
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
                    strips=uniform_strips(ends.reshape(-1, 2, 2)),
                    colors=colors,
                ).partition(partition_lengths(len(q), 2 * self._n)),
            )

    def _send_contacts(self, idx: list, b: FrameBatch) -> None:
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
        cap = ARROW_CAP * self.block_height
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

    def _send_series(self, idx: list, b: FrameBatch, q: np.ndarray) -> None:
        n_frames = len(q)
        ref_q, ref_sq, ref_pot = self._ref
        sc = np.array(b["scalars"])  # (F, 7) in SCALARS order
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
                        partition_lengths(n_frames, values.shape[1])
                    ),
                )

    # ---- run document
    def _log_metadata(self, status: str, note: str) -> None:
        text = run_document(
            self.metadata,
            status,
            note,
            last=self._last,
            wall_time=time.perf_counter() - self._t0,
            frames=self._frames,
            dt=self.static.dt,
            friction=self.static.friction,
            blocks=self._n,
            supports=self._supports.count,
            force_scale=self.force_scale,
            block_height=self.block_height,
            glyph_length=self._glyph_length,
            axis_scale=self.axis_scale,
            field_ranges=self.field_ranges,
        )
        self.rec.log(METADATA, rr.TextDocument(viewer_safe_text(text), media_type="text/markdown"), static=True)


def _tensor(tensors: dict, key: str, n: int) -> np.ndarray:
    """A float64 copy of tensors[key]; NaN of the expected shape when the field is missing."""
    shape = (n, 2) if key in ("cell_principal_stress", "cell_principal_strain_rate") else (n,)
    value = tensors.get(key) if tensors else None
    return np.full(shape, np.nan) if value is None else np.array(value, dtype=np.float64).reshape(shape)
