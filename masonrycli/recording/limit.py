"""Recording of a limit analysis: the collapse mechanism, magnified, beside the undeformed structure.

Two copies of the assembly share one drawing plane (the pinhole of ``static_content``): on the left the
structure as built with the line of thrust (the centre of pressure of every loaded joint) and the
hinges; on the right, shifted by 1.15 × its width, the same blocks moved along the mechanism, filled by
their speed in it (still blocks grey; a colour bar beside it, in fractions of the fastest block's speed),
with the hinges (yellow) and sliding joints (orange) carried
along. The timeline ``step`` runs the mechanism's amplitude from 0 to its full magnification, so the
viewer can play the collapse; the last step shows it fully.

The magnification puts the fastest block point ``MAGNIFIED_SHARE`` × the structure's size away from
where it started (the mechanism is a velocity field: only its shape is meaningful, not its size).
"""

from __future__ import annotations

import os
import uuid
from dataclasses import dataclass
from typing import Final

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from masonrycli.recording.arrays import Polygons, z0
from masonrycli.recording.batching import io_errors
from masonrycli.recording.carried_fill import CARRIED_FILL, CarriedFill, ColumnArrays, no_columns
from masonrycli.recording.colormap import VIRIDIS, colorbar_mesh, map_scalars
from masonrycli.recording.document import parameters_markdown, viewer_safe_text
from masonrycli.recording.layout import (
    HINGE_RGBA,
    LEGEND_TEXT_RGBA,
    OUTLINE_RGBA,
    PLANE,
    SLIP_RGBA,
    SUPPORT_FILL_RGBA,
    XY,
)
from masonrycli.recording.readback import check_complete, wait_written
from masonrycli.recording.recorder import APPLICATION_ID
from masonrycli.recording.static_content import TICKS, legend_positions, log_plane

MAGNIFIED_SHARE: Final = 0.12
STEPS: Final = 20
"""Frames of the amplitude animation (step 0 = undeformed, step STEPS = full magnification)."""
MARKER_RADIUS: Final = (-4.0, -2.0)  # ui points: hinge and sliding dots, few / many (> MANY_MARKERS)
MANY_MARKERS: Final = 60
STILL_RGBA: Final = 0xC8C3B9FF  # blocks that do not move in the mechanism, and the undeformed copy
THRUST_RGBA: Final = 0xD7263DFF  # centres of pressure (line of thrust)

FILL: Final = "structure/limit/blocks"
SUPPORTS: Final = "structure/limit/supports"
OUTLINES: Final = f"{XY}/limit/outlines"
HINGES: Final = f"{XY}/limit/hinges"
SLIDING: Final = f"{XY}/limit/sliding"
THRUST: Final = f"{XY}/limit/thrust"
LOAD: Final = f"{XY}/limit/load"
LOAD_RGBA: Final = 0x3C8CFFFF  # the live load's arrow (blue: no other mark is)
LOAD_LENGTH: Final = 0.15  # × the structure's size: the arrow shows where and which way, the document how much
SPEED_BAR: Final = "structure/limit/speed_bar"
SPEED_LABELS: Final = f"{XY}/limit/speed_bar"
SPEED_TITLE: Final = "Speed / fastest"
DOCUMENT: Final = "limit/document"
LIMIT_PATHS: Final = (
    *(PLANE, XY, FILL, SUPPORTS, OUTLINES, HINGES, SLIDING, THRUST, LOAD, SPEED_BAR, SPEED_LABELS, DOCUMENT),
)
_NAMESPACE: Final = uuid.UUID("2b8f0c57-64f1-4f0e-9a51-1f3c7d0e6a21")


@dataclass(frozen=True, eq=False)
class MechanismDrawing:
    """What the recording draws (N blocks, S supports; CSR polygons as in ``RecordingStatic``)."""

    block_vert_start: np.ndarray
    """(N+1,) int64."""
    block_vert_local: np.ndarray
    """(V, 2) m, relative to each block's centroid."""
    block_q0: np.ndarray
    """(N, 3) centroid x, y (m), θ = 0."""
    block_velocity: np.ndarray
    """(N, 3) the mechanism vx, vy, ω (any scale)."""
    block_moving: np.ndarray
    """(N,) bool."""
    support_vert_start: np.ndarray
    """(S+1,) int64."""
    support_vert_local: np.ndarray
    """(Vs, 2) m."""
    support_q0: np.ndarray
    """(S, 3) centroid x, y (m), θ = 0."""
    hinge_point: np.ndarray
    """(H, 2) m: the hinges."""
    hinge_block: np.ndarray
    """(H,) int: the block that carries each hinge into the mechanism copy."""
    sliding_point: np.ndarray
    """(K, 2) m: the middle of each sliding joint."""
    sliding_block: np.ndarray
    """(K,) int: the block that carries each sliding point into the mechanism copy."""
    thrust_point: np.ndarray
    """(P, 2) m: centres of pressure of the loaded joints."""
    document: str
    """Markdown shown beside the view (λ, load, hinges…)."""
    load: tuple[np.ndarray, np.ndarray] | None = None
    """(point, unit direction), m: where the live load acts and which way (drawn on the structure as built)."""
    fill: ColumnArrays | None = None
    """The columns of fill the blocks carry (``carried_fill``), drawn on both copies; None: no fill."""
    parameters: dict | None = None
    """The run's parameters, as a simulate recording's Parameters table has them (``execute.run_metadata``:
    the structure's options, the fill, how a surveyed file was read and settled, friction, versions); None:
    no scenario (a limit analysis made in Python)."""


def _block_speed(polys: Polygons, velocity: np.ndarray) -> np.ndarray:
    """(N,) fastest vertex of each block under block velocities (N, 3)."""
    v = velocity[polys.owner]
    speed = np.hypot(v[:, 0] - v[:, 2] * polys.local[:, 1], v[:, 1] + v[:, 2] * polys.local[:, 0])
    out = np.zeros(polys.count)
    np.maximum.at(out, polys.owner, speed)
    return out


def mechanism_poses(q0: np.ndarray, velocity: np.ndarray, amplitude: np.ndarray) -> np.ndarray:
    """(F, N, 3) poses after moving each block rigidly along its velocity (vx, vy, ω) by ``amplitude`` (F,).

    Each block turns by s·ω about its instantaneous centre p = c + (−vy, vx)/ω (translates if ω = 0), so
    a block hinged on a fixed point stays on it however large the magnification.
    """
    s = np.asarray(amplitude, dtype=np.float64)[:, None]
    vx, vy, w = velocity[:, 0], velocity[:, 1], velocity[:, 2]
    turning = np.abs(w) > 1e-12
    safe = np.where(turning, w, 1.0)
    # Rotation by θ = sω about p moves the centroid by (R(θ) − I)(c − p), c − p = (vy, −vx)/ω.
    theta = s * w
    rx, ry = vy / safe, -vx / safe
    c, sn = np.cos(theta), np.sin(theta)
    dx = np.where(turning, (c - 1.0) * rx - sn * ry, s * vx)
    dy = np.where(turning, sn * rx + (c - 1.0) * ry, s * vy)
    return q0[None] + np.stack([dx, dy, theta], axis=-1)


def _carry(points: np.ndarray, block: np.ndarray, q0: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Points attached to blocks ``block`` moved from poses q0 to poses q (rigidly)."""
    rel = points - q0[block, :2]
    th = q[block, 2]
    c, s = np.cos(th), np.sin(th)
    return q[block, :2] + np.stack([c * rel[:, 0] - s * rel[:, 1], s * rel[:, 0] + c * rel[:, 1]], axis=1)


def _doubled(start: np.ndarray, local: np.ndarray) -> Polygons:
    """The polygon set twice over (the undeformed copy, then the mechanism copy)."""
    start = np.asarray(start, dtype=np.int64)
    return Polygons(np.r_[start, start[1:] + start[-1]], np.concatenate([local, local]))


def magnification(start: np.ndarray, local: np.ndarray, q0: np.ndarray, velocity: np.ndarray) -> tuple[float, float]:
    """(amplitude, size): the factor the mechanism's velocities (N, 3) are drawn times at the last step, and the
    structure's size, m (the larger side of the blocks' box as built). The fastest block point moves
    ``MAGNIFIED_SHARE`` × size; amplitude 0 when no block moves."""
    blocks = Polygons(start, local)
    verts = blocks.world(q0[None])[0]
    size = float(max(verts.max(axis=0) - verts.min(axis=0))) or 1.0
    speed = _block_speed(blocks, velocity)
    fastest = float(speed.max(initial=0.0))
    return (MAGNIFIED_SHARE * size / fastest if fastest > 0 else 0.0), size


def magnified_words(size: float) -> str:
    """What the mechanism copy's magnification is, said where it is drawn: the recording said "magnified" and
    not by how much ('masonry limit arch --out l.rrd'). A mechanism is a velocity field, its size arbitrary:
    the drawing moves its fastest block point ``MAGNIFIED_SHARE`` × the structure's size."""
    return (
        f"magnified so that its fastest block point travels {MAGNIFIED_SHARE * size:.3g} m "
        f"({MAGNIFIED_SHARE:.0%} of the structure's {size:.3g} m) at the last step"
    )


def write_limit_recording(path: str | os.PathLike, drawing: MechanismDrawing) -> None:
    """Write the mechanism recording ``path`` (.rrd, complete with its footer and default blueprint)."""
    d = drawing
    n = len(d.block_vert_start) - 1
    blocks = Polygons(d.block_vert_start, d.block_vert_local)
    both, sup_both = (
        _doubled(d.block_vert_start, d.block_vert_local),
        _doubled(d.support_vert_start, d.support_vert_local),
    )
    verts0 = blocks.world(d.block_q0[None])[0]
    lo, hi = verts0.min(axis=0), verts0.max(axis=0)
    amplitude, size = magnification(d.block_vert_start, d.block_vert_local, d.block_q0, d.block_velocity)
    shift = np.array([1.15 * (hi[0] - lo[0]) + 0.05 * size, 0.0, 0.0])
    speed = _block_speed(blocks, d.block_velocity)
    colours = np.where(
        d.block_moving, map_scalars(speed, 0.0, float(speed.max(initial=0.0)) or 1.0, VIRIDIS), STILL_RGBA
    )
    fill_colour = np.r_[np.full(n, STILL_RGBA), colours].astype(np.uint32)[both.owner]
    sup_q = np.concatenate([d.support_q0, d.support_q0 + shift])
    # Poses of both copies at every step of the amplitude animation: (F, 2N, 3).
    ramp = np.arange(STEPS + 1) / STEPS
    moved = mechanism_poses(d.block_q0, d.block_velocity, ramp * amplitude) + shift
    poses = np.concatenate([np.broadcast_to(d.block_q0, moved.shape), moved], axis=1)
    verts = both.world(poses)
    frames = len(ramp)
    hinges = [np.concatenate([d.hinge_point, _carry(d.hinge_point, d.hinge_block, d.block_q0, q)]) for q in moved]
    sliding = [
        np.concatenate([d.sliding_point, _carry(d.sliding_point, d.sliding_block, d.block_q0, q)]) for q in moved
    ]

    rec = rr.RecordingStream(APPLICATION_ID, recording_id=str(uuid.uuid5(_NAMESPACE, os.fspath(path))))
    view = rrb.Spatial2DView(
        origin=f"/{PLANE}",
        contents=[
            f"+ /{p}"
            for p in (SUPPORTS, FILL, *CARRIED_FILL, OUTLINES, THRUST, LOAD, HINGES, SLIDING, SPEED_BAR, SPEED_LABELS)
        ],
        # its magnification in its name, as the document says it (the Legend of this recording)
        name=f"Collapse mechanism (right, fastest point moved {MAGNIFIED_SHARE * size:.3g} m) and line of thrust",
    )
    blueprint = rrb.Blueprint(
        rrb.Horizontal(view, rrb.TextDocumentView(origin=f"/{DOCUMENT}", name="Limit analysis"), column_shares=[3, 1]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed"),
    )
    with io_errors(os.fspath(path)):  # a full disk here was rerun's RuntimeError: a traceback, exit 1
        rec.save(os.fspath(path), default_blueprint=blueprint)
    try:
        legend_box, _, _ = log_plane(rec, both, sup_both, poses[-1], sup_q)
        _log_speed_bar(rec, legend_box)
        rec.log(
            DOCUMENT, rr.TextDocument(viewer_safe_text(_document(d)), media_type=rr.MediaType.MARKDOWN), static=True
        )
        rec.log(
            SUPPORTS,
            rr.Mesh3D(
                vertex_positions=z0(sup_both.world(sup_q[None])[0]),
                triangle_indices=sup_both.fan,
                albedo_factor=SUPPORT_FILL_RGBA,
            ),
            static=True,
        )
        rec.log(FILL, rr.Mesh3D.from_fields(triangle_indices=both.fan), static=True)
        rec.log(OUTLINES, rr.LineStrips2D.from_fields(colors=OUTLINE_RGBA, radii=-0.75, draw_order=30.0), static=True)
        # smaller dots when there are many: the aqueduct's 315 hinges and 380 sliding joints covered its upper
        # wall in yellow and orange, the blocks' speed colours hidden under them
        for path_, colour, count in (
            (HINGES, HINGE_RGBA, len(d.hinge_point)),
            (SLIDING, SLIP_RGBA, len(d.sliding_point)),
        ):
            radius = MARKER_RADIUS[count > MANY_MARKERS]
            rec.log(path_, rr.Points2D.from_fields(radii=radius, colors=colour, draw_order=60.0), static=True)
        rec.log(THRUST, rr.Points2D(d.thrust_point, radii=-2.5, colors=THRUST_RGBA, draw_order=55.0), static=True)
        if d.load is not None:  # the point load was nowhere on screen: the document alone named its block
            _log_load(rec, d.load, LOAD_LENGTH * size)
        idx = [rr.TimeColumn("step", sequence=np.arange(frames))]
        carried = CarriedFill(no_columns() if d.fill is None else d.fill, copies=2, blocks=n)
        carried.log_static(rec, magnified=False)
        carried.send(rec, idx, poses)  # each column on its block in both copies: carried along the mechanism
        rec.send_columns(
            FILL,
            indexes=idx,
            columns=rr.Mesh3D.columns(vertex_positions=z0(verts), vertex_colors=np.tile(fill_colour, frames)).partition(
                np.full(frames, verts.shape[1])
            ),
        )
        rec.send_columns(
            OUTLINES,
            indexes=idx,
            columns=rr.LineStrips2D.columns(strips=both.outlines(verts)).partition(np.full(frames, both.count)),
        )
        for path_, points in ((HINGES, hinges), (SLIDING, sliding)):
            rec.send_columns(
                path_,
                indexes=idx,
                columns=rr.Points2D.columns(positions=np.concatenate(points).astype(np.float32)).partition(
                    [len(p) for p in points]
                ),
            )
    finally:  # a writer stopped by a full disk: OSError, no disconnect (it hung); a file without its footer too
        wait_written(rec, path)
        rec.disconnect()
    check_complete(path)


def _document(d: MechanismDrawing) -> str:
    """The side panel: the analysis's document, then the run's Parameters table as simulate's recording has it
    (the bridge's said neither its span nor its fill cover; e7f9366 gave it the 'reading' rows alone)."""
    if not d.parameters:
        return d.document
    return "\n".join([d.document, "", *parameters_markdown(d.parameters)])


def _log_load(rec: rr.RecordingStream, load: tuple[np.ndarray, np.ndarray], length: float) -> None:
    """The live load: an arrow ``length`` m long whose tip is on its point, along its direction. No label:
    the viewer draws it on a grey box at the tip, which hid the loaded block (the document says blue arrow)."""
    point, direction = (np.asarray(a, dtype=np.float64) for a in load)
    vector = length * direction
    rec.log(
        LOAD,
        rr.Arrows2D(
            origins=[point - vector],
            vectors=[vector],
            colors=LOAD_RGBA,
            radii=-2.5,
            draw_order=70.0,
        ),
        static=True,
    )


def _log_speed_bar(rec: rr.RecordingStream, legend_box: tuple[float, float, float, float]) -> None:
    """The key of the mechanism copy's colours, in the room ``log_plane`` leaves right of the structure:
    the blocks were filled by speed with no scale beside them. The mechanism is a velocity field of no
    particular size, so the bar reads in fractions of the fastest block's speed (0 to 1)."""
    verts, tri, colors = colorbar_mesh(legend_box, VIRIDIS)
    rec.log(SPEED_BAR, rr.Mesh3D(vertex_positions=z0(verts), triangle_indices=tri, vertex_colors=colors), static=True)
    anchors = legend_positions(legend_box)[: TICKS + 1]  # the ticks (bottom up) and the title
    labels = [f"{v:g}" for v in np.linspace(0.0, 1.0, TICKS)] + [SPEED_TITLE]
    rec.log(
        SPEED_LABELS,
        rr.Points2D(anchors, labels=labels, radii=0.0, colors=LEGEND_TEXT_RGBA, show_labels=True, draw_order=60.0),
        static=True,
    )
