"""The recorder: writes one run's ``.rrd`` from its frames (and its steps' solver health).

One ``.rrd`` per run from an explicit ``rr.RecordingStream``, with an embedded default blueprint.
Constants are logged static; frames are buffered and sent with ``send_columns`` in batches (below), one
array per entity kind. Timelines ``step`` (sequence) and ``sim_time`` (duration). Entity
paths: ``layout.ENTITY_PATHS``. The initial frame (step 0, t = 0: the structure as built, at rest, before
the first step) sets the references (drawing plane, as-built shape) and is logged like any other, so the
recording starts at t = 0 as the history does: no contacts and no forces yet (the first step's solve makes
them), so no joint arrows and no glyphs; the stresses and strain rates are undefined there (NaN: grey), the
cumulated strain, sliding ratio and openings 0. It takes the colour ranges of the first computed frame and
does not count towards a batch's ``batch_frames`` nor fix a scale, so every later frame reads as before.

What is logged per frame, once each: the block fill mesh's vertex positions (float32, inset so the
joints show) with one colour component per field and view (each view maps its own, ``layout.COLOURED``:
the fields, and p again on a square-root scale); a hover point per block with its values (float32); the principal-axis glyphs; one resultant arrow per joint
(``masonrycli.analysis.joint_forces``); hinges; each field's colour range and legend labels; the time series
(energies, displacements, support motion: ``series``). Solver health (sweeps, residual, contacts) is
logged for every step (``log_step``), sent with the frames or every ``batching.STEP_BATCH`` steps. The
magnified deformed shape is logged when the recorder closes, when the largest displacement of the run is
known; its poses wait in an anonymous temporary file until then (``magnified.PoseSpool``). Memory held does
not grow with the run but for rerun's own index of the chunks written (the file's footer, ~22 chunks a batch
sent).

Batches: ``batch_frames`` (100) frames until the scales are fixed, then ``long_batch_frames``; also every
``FLUSH_SECONDS`` once the scales are fixed (the rules and their reasons: ``batching``).

Scales: colour ranges follow the data (``masonrycli.recording.colour_range.RangeTracker``, checked every frame);
the joint-resultant scale (``RESULTANT_LENGTH`` block heights for the 95th percentile resultant of the
first loaded frame) and the glyph scales (98th percentile of the first batch) are fixed once per run so
lengths compare across time.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import time
import uuid
import warnings
from typing import Final

import numpy as np
import rerun as rr

from masonrycli.outputs.frame import Frame
from masonrycli.outputs.sinks import COMPLETED, FAILED, INTERRUPTED, RUNNING
from masonrycli.recording.arrays import FrameBatch, Polygons, own_centroids, posed_points, time_indexes
from masonrycli.recording.batching import Batching, initial_frames, io_errors, steps_due
from masonrycli.recording.carried_fill import CarriedFill, ColumnArrays
from masonrycli.recording.field_colours import FieldColours
from masonrycli.recording.fills import send_blocks, send_supports
from masonrycli.recording.layout import (
    AXES,
    CHAIN_KEY,
    COLOURED,
    FIELD_BY_KEY,
    FIELDS,
    GLYPH_HALF_LENGTH,
    INSET,
    INSET_BLOCK_CAP,
    LEGEND_BARS,
    LEGEND_LABELS,
    RESULTANT_CAP,
    SCALARS,
    TENSOR_KEYS,
    XY,
    build_blueprint,
    paper_figures,
)
from masonrycli.recording.magnified import PoseSpool, send_magnified
from masonrycli.recording.overlays import frame_joint_resultants, send_axes, send_joints
from masonrycli.recording.plot_range import plot_range
from masonrycli.recording.reach import Reach
from masonrycli.recording.readback import check_complete, wait_written
from masonrycli.recording.residual_range import ResidualRange
from masonrycli.recording.run_panels import PanelFacts, log_run_panels
from masonrycli.recording.scales import fix_scales
from masonrycli.recording.series import RANGED, send_series, send_steps
from masonrycli.recording.static_content import (
    RecordingStatic,
    inset_local,
    legend_move,
    legend_positions,
    log_initial_shape,
    log_legend,
    log_plane,
    log_static,
)

APPLICATION_ID: Final = "masonry"
_RECORDING_NAMESPACE: Final = uuid.UUID("6f1c4f5e-9b0e-4c51-a0a6-3f0d6c1e2a77")


class Recorder:
    """Writes one run's ``.rrd``. A context manager; ``close`` is idempotent.

    >>> with Recorder(path, static, {"scenario": "wall"}) as rec:   # doctest: +SKIP
    ...     for frame in frames:
    ...         rec.log_frame(frame)

    Leaving the ``with`` block by an exception closes the recording with status "failed"
    (KeyboardInterrupt: "interrupted") and the time of the last frame; the file is complete either way.
    ``batch_frames``: frames a batch until the scales are fixed; ``long_batch_frames`` after (None:
    ``batching.LONG_BATCH_BLOCK_FRAMES`` over the block count; at least ``batch_frames``). ``magnify``: the
    magnified view's factor (None: the largest displacement of the run drawn as 5 % of the structure's size,
    ``masonrycli.analysis.joint_forces.magnification``). The paper-figure tabs are added for the scenarios of
    ``layout.PAPER_FIGURES`` under the paper's loading whose ``duration_s`` reaches the paper's instant
    (``paper_figures``).
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
        magnify: float | None = None,
        long_batch_frames: int | None = None,
    ) -> None:
        if main_field not in FIELD_BY_KEY:
            raise ValueError(f"main_field must be one of {sorted(FIELD_BY_KEY)}, not {main_field!r}")
        self.path, self.static, self.metadata = os.fspath(path), static, dict(metadata)
        self._t0, self._closed, self._stopped = time.perf_counter(), False, False
        self._blocks = Polygons(static.block_vert_start, static.block_vert_local)
        self._own = own_centroids(static.block_vert_start, static.block_vert_local)  # (N, 2): posed_points
        self._supports = Polygons(static.support_vert_start, static.support_vert_local)
        self._carried = CarriedFill(ColumnArrays(static.fill_block, static.fill_vert_start, static.fill_vert_local))
        self._fill: Polygons | None = None  # inset blocks, once the structure's size is known
        self._n = n = self._blocks.count
        self.batching = Batching(batch_frames, n, long_batch_frames)
        first = np.asarray(static.block_vert_start[:-1], dtype=np.intp)
        loc = self._blocks.local
        size = (np.maximum.reduceat(loc, first) - np.minimum.reduceat(loc, first)) if n else np.ones((1, 2))
        self.block_height = float(np.median(size[:, 1]))  # m, median block height: the force-arrow unit
        self._block_side = float(np.median(size.min(axis=1)))  # m: the glyphs' unit; caps the fills' inset
        # what the run drew, from each block's farthest vertex from its centroid: the view widens to hold it
        # (_clear_the_legend)
        self._reach = Reach(np.maximum.reduceat(np.hypot(*loc.T), first) if n else np.zeros(0))
        self._glyph_length = GLYPH_HALF_LENGTH * self._block_side
        # (N,) m: a glyph never reaches out of its own block (thin cut spandrel blocks of the aqueduct)
        self._glyph_cap = np.minimum(self._glyph_length, GLYPH_HALF_LENGTH * size.min(axis=1))[: self._n]
        self._colours = FieldColours(FIELDS)
        self.field_ranges = self._colours.field_ranges
        """The range each field has at the last frame sent."""
        self.force_scale: float | None = None
        """m per N of the joint resultants, fixed at the first batch with a loaded joint."""
        self.axis_scale: dict[str, float] = {}
        self.magnify = magnify
        self._legend_box = (0.0, 0.0, 0.0, 0.0)
        self._structure_view = None  # the Magnified tab's part of the view (log_plane)
        self._legend_lines = 7  # the Legend's lines at 1920 x 1080 (_log_metadata)
        self._spans = dict.fromkeys(RANGED, (0.0, 0.0))  # each ranged plot's lowest and highest value, 0 in
        self._most_sweeps = 0.0  # the most sweeps a step took: the Sweeps plot's range, from 0
        self._label_anchors = np.zeros((0, 2), np.float32)
        self._size = 1.0
        self._frames, self._last = 0, None  # frames logged; (step, time) of the last one
        self._ref: tuple[np.ndarray, np.ndarray, float] | None = None  # first block_q, support_q, E_pot
        self._batch, self._steps = FrameBatch(), FrameBatch()
        self._poses: PoseSpool | None = None  # for the magnified view: on disk, not in RAM (its module doc)
        self.paper = paper_figures(self.metadata)
        meta_json = json.dumps(self.metadata, sort_keys=True, default=str)
        self.recording_id = str(uuid.uuid5(_RECORDING_NAMESPACE, meta_json))
        self.rec = rr.RecordingStream(application_id, recording_id=self.recording_id)
        os.makedirs(os.path.dirname(os.path.abspath(self.path)), exist_ok=True)
        with io_errors(self.path):
            self._main_field = main_field
            self.rec.save(self.path, default_blueprint=build_blueprint(main_field, self.paper))
            log_static(self.rec, static, self._blocks, self._supports)
            self._carried.log_static(self.rec)
            self._residuals = ResidualRange(self.metadata.get("nlgs_tolerance"))  # the residual plot's range
            self._log10_tolerance = self._residuals.log10_tolerance
            self._log_metadata(RUNNING, "")

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None or issubclass(exc_type, KeyboardInterrupt):
            self.close(COMPLETED if exc_type is None else INTERRUPTED)
        else:
            self.close(FAILED, f"{exc_type.__name__}: {exc}")

    def log_step(self, step: int, time_s: float, stats) -> None:
        """Solver health of one step (``stats``: iterations, residual, contact_count), logged every step."""
        if self._closed:
            raise RuntimeError("Recorder is closed")
        s = self._steps
        s.add("step", int(step))
        s.add("time", float(time_s))
        s.add("values", (float(stats.iterations), float(stats.residual), float(stats.contact_count)))
        self._residuals.add(stats.residual)
        self._most_sweeps = max(self._most_sweeps, float(stats.iterations))
        if steps_due(s):
            self._steps = FrameBatch()
            with io_errors(self.path):
                send_steps(self.rec, s, self._log10_tolerance)

    def on_frame(self, frame: Frame) -> None:
        """Buffer one frame (the :class:`~masonrycli.outputs.sinks.FrameSink` method); sends the buffer when it is
        due (``batching.Batching.frames_due``)."""
        if self._closed:
            raise RuntimeError("Recorder is closed")
        f64 = np.float64
        q = np.asarray(frame.block_q, f64)
        sq = np.asarray(frame.support_q, f64).reshape(-1, 3)
        if self._ref is None:
            self._ref = (q, sq, float(frame.energy_potential))
            self._legend_box, self._size, _ = log_plane(
                self.rec, self._blocks, self._supports, q, sq, block_side=self._block_side
            )
            self._fill = Polygons(
                self.static.block_vert_start,
                inset_local(self.static.block_vert_start, self.static.block_vert_local, self.fill_inset()),
            )
            own = posed_points(q[None], self._own)[0]  # the cells' points (analysis.tensors), not the fill's pull
            log_initial_shape(self.rec, self._blocks, self.static.triangles, q, sq, self._supports, own)
            for f in COLOURED:
                log_legend(self.rec, f, self._legend_box)
            self._label_anchors = legend_positions(self._legend_box).astype(np.float32)
            folder = os.path.dirname(os.path.abspath(self.path))
            with io_errors(self.path):
                self._poses = PoseSpool(folder, self._n, self._supports.count)
        b = self._batch
        b.add("step", int(frame.step))
        b.add("time", float(frame.time))
        b.add("scalars", [float(getattr(frame, name)) for name in SCALARS])
        b.add("block_q", q)
        b.add("support_q", sq)
        b.add("support_v", np.asarray(frame.support_v, f64).reshape(-1, 2))
        for name, value in zip(("joint_point", "joint_force", "joint_state"), frame_joint_resultants(frame, q, sq)):
            b.add(name, value)
        b.add("hinge_point", np.asarray(getattr(frame, "hinge_point", np.zeros((0, 2))), f64).reshape(-1, 2))
        for key in TENSOR_KEYS:
            b.add(key, _tensor(frame.tensors, key, self._n))
        q0, sq0, _ = self._ref  # displacements in float64, then float32 on disk: step 0's exactly 0 (magnified doc)
        self._poses.append(int(frame.step), float(frame.time), q - q0, sq - sq0)
        self._last = (int(frame.step), float(frame.time))
        self._frames += 1
        if self.batching.frames_due(b, self._scales_fixed()):
            with io_errors(self.path):
                self.flush()
                self._wait_written()  # to the file: a killed run loses at most about FLUSH_SECONDS of frames
            self.batching.sent()

    log_frame = on_frame

    @property
    def batch_frames(self) -> int:
        return self.batching.batch_frames

    @property
    def long_batch_frames(self) -> int:
        return self.batching.long_batch_frames

    def _batch_size(self) -> int:
        """Frames a batch: ``batch_frames`` until the scales are fixed, then ``long_batch_frames``."""
        return self.batching.size(self._scales_fixed())

    def _scales_fixed(self) -> bool:
        """The force and glyph scales come from the first batch with data; the colour ranges follow each frame."""
        return self.force_scale is not None and len(self.axis_scale) == len(AXES)

    def _wait_written(self) -> None:
        """readback.wait_written; after its OSError ``_stopped``: close neither sends nor disconnects."""
        try:
            wait_written(self.rec, self.path)
        except OSError:
            self._stopped = True
            raise

    def flush(self) -> None:
        """Send the buffered frames and steps now."""
        batch, self._batch = self._batch, FrameBatch()  # an interrupted send loses a batch, never duplicates
        steps, self._steps = self._steps, FrameBatch()
        if batch:
            self._send_batch(batch)
        if steps:
            send_steps(self.rec, steps, self._log10_tolerance)

    def close(self, status: str = COMPLETED, note: str = "") -> None:
        """Flush, log the magnified shape, write the final run document, wait for rerun's writer
        (readback.wait_written: stopped by a full disk, ``OSError``, no disconnect) and disconnect (which
        writes the footer), then read the footer back (a full disk may show only there: ``OSError``).

        ``status``: one of :data:`masonrycli.outputs.sinks.STATUSES`; ``note``: one line, e.g.
        "interrupted at t = 0.412 s (step 412)" (without a note, the last frame's time is given).
        """
        if self._closed:
            return
        self._closed = True
        if self._stopped:  # the run already stopped on the writer's OSError: the file stays incomplete
            if self._poses is not None:
                with contextlib.suppress(OSError):
                    self._poses.close()
            if status == COMPLETED:
                raise OSError(errno.EIO, "the recording is incomplete (rerun's writer stopped during the run)")
            return
        error: Exception | None = None
        with io_errors(self.path):
            try:
                try:
                    self.flush()
                    self._send_magnified()
                except OSError:
                    raise
                except Exception as err:  # keep going: the file must be complete
                    error = err
                    note = f"{note} (recording flush failed: {err!r})".strip()
                self._log_metadata(status, note)
                self._clear_the_legend()
                self._send_final_layout()
            finally:
                try:
                    self._wait_written()  # its OSError (the writer stopped) skips the disconnect
                    self.rec.disconnect()
                finally:
                    if self._poses is not None:  # after the footer: a full disk here must not cost the file
                        with contextlib.suppress(OSError):
                            self._poses.close()
        check_complete(self.path)
        if error is not None:
            if status == COMPLETED:
                raise error
            warnings.warn(f"recording flush failed while closing: {error!r}", RuntimeWarning, stacklevel=2)

    def _clear_the_legend(self) -> None:
        """The colour bars and their labels moved right of the farthest x a block or arrow reached, the view
        widened to hold them and every frame's arrows: they stood right of the structure as built, and a wall
        shaken 0.32 m to the right and collapsing ('masonry simulate wall --amp 2 --freq 1') covered the bar
        and its title (log_plane)."""
        if self._ref is None:
            return
        q, sq, _ = self._ref
        box, _, self._structure_view = log_plane(
            self.rec,
            self._blocks,
            self._supports,
            q,
            sq,
            content=self._reach.content(),
            block_side=self._block_side,
            shape=self._reach.extent,
        )
        shift = legend_move(self._legend_box, box)  # the bar sized to the view at close (log_plane)
        for path in (LEGEND_BARS, LEGEND_LABELS):
            self.rec.log(path, shift, static=True)

    def fill_inset(self) -> float:
        """How far (m) the block fills are inset: INSET × the structure's size, at most INSET_BLOCK_CAP × a
        median block's smaller side."""
        return min(INSET * self._size, INSET_BLOCK_CAP * self._block_side)

    def residual_range(self) -> tuple[float, float] | None:
        """The residual plot's y range, log10 of m/s, or None (``residual_range.ResidualRange``)."""
        return self._residuals.range()

    def _send_final_layout(self) -> None:
        """The layout again, the last default wins: with the magnified view's factor in its tab's name (the
        default factor is known now; the tab did not say it), and without the tabs pinned to the paper's
        instant when the run ended before it (Ctrl-C, --stop-at-collapse, a failure): they had no frame
        there, were empty (the colour bar and the triangulation) and the recording opened on the first."""
        if self.paper is not None:
            reached = self._last is not None and self._last[1] >= self.paper[0] - 0.5 * self.static.dt
            if not reached:
                self.paper = None
        rows = {"energy_large": 3, "support_velocity": 2 * self._supports.count}
        rows["support_displacement"] = rows["support_velocity"]
        ranges = {key: plot_range(*self._spans[key], rows[key]) for key in RANGED}  # None: all 0
        # from 0: fitted to its data, the plot of a run whose steps took 2 to 22 sweeps had one tick, "10"
        ranges["iterations"] = plot_range(0.0, self._most_sweeps, 0)
        moved = ranges["support_velocity"] is not None  # a support that moved: its plot shows at open
        args = (self._main_field, self.paper, self.residual_range(), self._structure_view, moved)
        layout = build_blueprint(*args, plot_ranges=ranges, legend_lines=self._legend_lines)
        self.rec.send_blueprint(layout, make_active=True, make_default=True)

    # ---- per-batch content
    def _send_batch(self, b: FrameBatch) -> None:
        idx = time_indexes(b)
        q = b.stack("block_q")  # (F, N, 3)
        floor = self._supports.world(b.stack("support_q"))[..., 1].min(axis=1) if self._supports.count else None
        self._reach.add_blocks(q, floor)
        tensors = {key: b.stack(key) for key in TENSOR_KEYS}
        # A voussoir of a bare ring has no cell strain rate; its strain rate along the ring stands in.
        vsr = tensors["cell_volumetric_strain_rate"]
        tensors["cell_volumetric_strain_rate"] = np.where(np.isnan(vsr), tensors[CHAIN_KEY], vsr)
        initial = initial_frames(b)  # the state as built: no scale from it (module doc)
        if self._fix_scales({k: v[initial:] for k, v in tensors.items()}, b):
            self._log_metadata(RUNNING, "")
        # dots and glyphs on each block's own centroid: a carried fill pulls the body's centre up into it
        own = posed_points(q, self._own)
        args = (self._fill, self._blocks.owner, self._colours, self._label_anchors, q, tensors, initial)
        send_blocks(self.rec, idx, *args, at=own, times=b["time"])
        send_supports(self.rec, idx, self._supports, b.stack("support_q"))
        self._carried.send(self.rec, idx, q)
        self._send_axes(idx, np.concatenate([own, q[..., 2:]], axis=-1), tensors)
        self._send_joints(idx, b)
        spans = send_series(self.rec, idx, b, q, self._ref, self._n)
        for key, (low, high) in spans.items():
            self._spans[key] = (min(self._spans[key][0], low), max(self._spans[key][1], high))

    def _fix_scales(self, tensors: dict[str, np.ndarray], b: FrameBatch) -> bool:
        """Fix the force and glyph scales not fixed yet from this batch if it has data; True if any was."""
        self.force_scale, fixed = fix_scales(self.force_scale, self.axis_scale, tensors, b, self.block_height)
        return fixed

    def _send_axes(self, idx: list, q: np.ndarray, tensors: dict[str, np.ndarray]) -> None:
        for name, (lam, angle) in AXES.items():
            args = (q, tensors[lam], tensors[angle], self.axis_scale.get(name), self._glyph_cap)
            send_axes(self.rec, f"{XY}/{name}", idx, *args)

    def _send_joints(self, idx: list, b: FrameBatch) -> None:
        arrows = send_joints(self.rec, idx, b, self.force_scale, RESULTANT_CAP * self._size)
        self._reach.add_arrows(arrows)

    def _send_magnified(self) -> None:
        if self._poses is not None and self._poses.count and self._ref is not None:
            args = (self._poses, self._ref[:2], self.magnify, self._size, self.long_batch_frames)
            self.magnify, drawn = send_magnified(self.rec, self._blocks, self._supports, *args, self._carried)
            self._reach.add_drawn(drawn)

    # ---- run document
    def _log_metadata(self, status: str, note: str) -> None:
        facts = PanelFacts(
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
            range_changes=self._colours.range_changes(),
            magnify=self.magnify,
            main_field=self._main_field,
            paper_t=None if self.paper is None else self.paper[0],
            resultant_cap=RESULTANT_CAP * self._size,
            fill_load_n=self.static.fill_load_n,
            fill_drawn=self._carried.count > 0,
        )
        self._legend_lines = log_run_panels(self.rec, self.metadata, status, note, facts)


def _tensor(tensors: dict, key: str, n: int) -> np.ndarray:
    """tensors[key] as float64 of the expected shape (no copy: a frame's arrays are its own, sinks.FrameSink);
    NaN of that shape when the field is missing."""
    shape = (n, 2) if key in ("cell_principal_stress", "cell_principal_strain_rate") else (n,)
    value = tensors.get(key) if tensors else None
    return np.full(shape, np.nan) if value is None else np.asarray(value, dtype=np.float64).reshape(shape)
