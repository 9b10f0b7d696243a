"""What is drawn over the block fills per frame: principal-stress glyphs, joint resultants, hinges."""

from __future__ import annotations

from typing import Final

import numpy as np
import pyarrow as pa
import rerun as rr

from masonrycli.analysis.joint_forces import JOINT_OPEN, JOINT_SLIP, JOINT_STICK, joint_resultants
from masonrycli.recording.arrays import FrameBatch, partition_lengths, uniform_strips
from masonrycli.recording.layout import (
    COMPRESSION_RGBA,
    FORCES,
    HINGES,
    OPEN_RGBA,
    SLIP_RGBA,
    STICK_RGBA,
    TENSION_RGBA,
)

_STATE_RGBA: Final = {JOINT_STICK: STICK_RGBA, JOINT_SLIP: SLIP_RGBA, JOINT_OPEN: OPEN_RGBA}


def send_axes(
    rec: rr.RecordingStream,
    path: str,
    idx: list,
    q: np.ndarray,
    values: np.ndarray,
    angle: np.ndarray,
    scale: float | None,
    full_length: np.ndarray,
) -> None:
    """Two segments per cell along the principal directions, half-length min(|λ| / ``scale``, 1) ×
    ``full_length`` (N,) m, black for a negative value, magenta for a positive one.

    ``q`` (F, N, 3) poses; ``values`` (F, N, 2) major, minor; ``angle`` (F, N) of the major one.
    """
    lam = np.nan_to_num(values, nan=0.0)
    ang = np.nan_to_num(angle, nan=0.0)
    half = np.minimum(np.abs(lam) / scale, 1.0) * full_length[None, :, None] if scale else 0.0 * lam
    c, s = np.cos(ang), np.sin(ang)
    axes = np.stack([np.stack([c, s], -1), np.stack([-s, c], -1)], axis=2)  # (F, N, 2, 2)
    d, centre = axes * half[..., None], q[:, :, None, :2]
    ends = np.stack([centre - d, centre + d], axis=3)  # (F, N, axis, end, xy)
    colors = np.where(lam < 0.0, np.uint32(COMPRESSION_RGBA), np.uint32(TENSION_RGBA)).reshape(-1)
    rec.send_columns(
        path,
        indexes=idx,
        columns=rr.LineStrips2D.columns(strips=uniform_strips(ends.reshape(-1, 2, 2)), colors=colors).partition(
            partition_lengths(len(q), 2 * q.shape[1])
        ),
    )


def send_joints(
    rec: rr.RecordingStream, idx: list, b: FrameBatch, force_scale: float | None, max_length: float = np.inf
) -> np.ndarray:
    """One arrow per loaded joint (the batch's "joint_point", "joint_force", "joint_state"), centred on its
    point of application, ``force_scale`` m per N but at most ``max_length`` m long, coloured by state; the
    hinges ("hinge_point"). Returns the arrows' extent (xmin, ymin, xmax, ymax), m (inf, inf, -inf, -inf:
    none), for the view to hold them (``static_content.log_plane``)."""
    points, lengths = b.concat("joint_point", (0, 2))
    forces, _ = b.concat("joint_force", (0, 2))
    state, _ = b.concat("joint_state", (0,))
    colors = np.full(len(state), np.uint32(STICK_RGBA))
    for value, rgba in _STATE_RGBA.items():
        colors[state == value] = rgba
    vectors = forces * (force_scale or 0.0)
    # an impact's one-frame spike (a 64-course wall's toe: 12 m at 1.6 MN, the wall 12.8 m high) would set
    # the view of every frame: drawn at the cap, its force on hover
    length = np.hypot(vectors[:, 0], vectors[:, 1])
    over = length > max_length
    vectors[over] *= (max_length / length[over])[:, None]
    magnitude = 1e-3 * np.hypot(forces[:, 0], forces[:, 1]).astype(np.float32)
    origins = points - 0.5 * vectors
    ends = np.concatenate([origins, origins + vectors]) if len(points) else np.zeros((0, 2))
    extent = np.r_[ends.min(axis=0), ends.max(axis=0)] if len(ends) else np.array([np.inf, np.inf, -np.inf, -np.inf])
    rec.send_columns(
        FORCES,
        indexes=idx,
        columns=[
            *rr.Arrows2D.columns(
                origins=origins.astype(np.float32), colors=colors, vectors=vectors.astype(np.float32)
            ).partition(lengths),
            *rr.AnyValues.columns(force_kN=pa.array(magnitude, type=pa.float32())).partition(lengths),
        ],
    )
    hinges, per_frame = b.concat("hinge_point", (0, 2))
    rec.send_columns(
        HINGES, indexes=idx, columns=rr.Points2D.columns(positions=hinges.astype(np.float32)).partition(per_frame)
    )
    return extent


def frame_joint_resultants(frame, block_q: np.ndarray, support_q: np.ndarray):
    """One frame's joint resultants (point, force, state per joint), each force drawn on the body above its
    joint (up the structure, whatever the index order). Made when the frame comes, while its contacts are
    still in the cache: the same rows as the frame's share of a batch's (``joint_resultants``)."""
    j = joint_resultants(
        frame.contact_body, frame.contact_point, frame.contact_normal, frame.contact_force, frame.contact_status
    )
    body_y = np.concatenate([block_q[:, 1], support_q[:, 1]])
    sign = np.where(body_y[j.body[:, 1]] >= body_y[j.body[:, 0]], 1.0, -1.0)[:, None]
    return j.point, j.force * sign, j.state
