"""One resultant per joint: what an engineer reads as a force chain or a line of thrust (the sums over
each joint's contacts are a kernel of :mod:`masonrycli.engine.joints`).

A *joint* here is a pair of bodies in contact in the current frame (two blocks, or a block and a
support). Its contact points carry forces F_c (on body b of the pair (a, b), normal n_c from a to b);
the joint passes their sum

    R = Σ_c F_c

through its **point of application** (centre of pressure): the normal-force-weighted mean of the
contact points,

    x_R = Σ_c f_c p_c / Σ_c f_c,    f_c = F_c · n_c ≥ 0 (compression),

which lies on the joint face between its loaded ends — at the face's middle under a centred load, at an
end when the joint has opened into a hinge — so the eccentricity and the line of thrust show. The
moment of R about x_R equals that of the contact forces about x_R up to the friction components' lever
arm along the face, which is zero for a straight face. Joints without compression (Σ f_c ≤ 0) have no
resultant.

**State** of a joint (colour of its resultant): ``JOINT_SLIP`` if one of its closed contacts slides,
else ``JOINT_OPEN`` if one of its contact points is open (the joint has opened at that end and turns
about the other), else ``JOINT_STICK``.
"""

from __future__ import annotations

from typing import Final, NamedTuple

import numpy as np

from masonrycli.engine import joints as _kernels

JOINT_STICK: Final = 0
JOINT_SLIP: Final = 1
JOINT_OPEN: Final = 2


class JointResultants(NamedTuple):
    body: np.ndarray
    """(J, 2) int64 bodies (a, b), a < b (indices ≥ N are supports)."""
    point: np.ndarray
    """(J, 2) m: point of application (centre of pressure)."""
    force: np.ndarray
    """(J, 2) N: resultant force on body b (body a gets −force)."""
    state: np.ndarray
    """(J,) int8: JOINT_STICK, JOINT_SLIP or JOINT_OPEN."""
    frame: np.ndarray | None = None
    """(J,) int64: the frame of each joint, when the contacts of several frames were passed at once."""


def joint_resultants(
    contact_body, contact_point, contact_normal, contact_force, contact_status, contact_frame=None
) -> JointResultants:
    """Resultant of each joint at its point of application (module docstring); rows sorted by (a, b).

    Args:
        contact_body: (C, 2) int bodies (a, b) of each contact; contact_point (C, 2) m; contact_normal
            (C, 2) unit, from a to b; contact_force (C, 2) N on body b; contact_status (C,) int
            (``masonrycli.outputs.frame`` CONTACT_*).
        contact_frame: (C,) int ≥ 0, optional: the frame of each contact, for the contacts of several
            frames at once (a recording's batch). The joints are then those of (frame, a, b), rows sorted
            by (frame, a, b), ``frame`` says which; each frame's rows are what it alone would give.
    """
    body = np.asarray(contact_body).reshape(-1, 2)
    if body.dtype.kind not in "iu":
        body = body.astype(np.int64)
    point = np.asarray(contact_point, dtype=np.float64).reshape(-1, 2)
    normal = np.asarray(contact_normal, dtype=np.float64).reshape(-1, 2)
    force = np.asarray(contact_force, dtype=np.float64).reshape(-1, 2)
    status = np.asarray(contact_status).reshape(-1)
    frame = np.zeros(len(status), np.int64) if contact_frame is None else np.asarray(contact_frame, np.int64)
    keep = body[:, 0] != body[:, 1]  # a body against itself is no joint
    if not keep.all():
        body, point, normal, force, status = body[keep], point[keep], normal[keep], force[keep], status[keep]
        frame = frame[keep]
    # Each contact oriented as (low, high) body (the force on the higher index flips with the order) and
    # keyed (frame, low, high): the engine's contacts come sorted by pair and a batch's frames in order, so
    # a joint's contacts are one run and a kernel sums each run in one pass, in contact order. Otherwise
    # they are put in key order first, stably: each joint's contacts keep their order, hence the same sums.
    rows = _kernels.resultants(body, frame, force, normal, point, status)
    if rows is None:
        keys, _, _ = _kernels.joint_keys(body, frame)
        order = np.argsort(keys, kind="stable")
        rows = _kernels.resultants(body[order], frame[order], force[order], normal[order], point[order], status[order])
    pairs, centre, resultant, state, joint_frame = rows
    return JointResultants(
        body=pairs, point=centre, force=resultant, state=state, frame=None if contact_frame is None else joint_frame
    )


def magnification(displacement: np.ndarray, structure_size: float, share: float = 0.05) -> float:
    """Default displacement magnification: the largest |displacement| drawn as ``share`` of the structure.

    Rounded down to 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k so the factor reads well; never below 1 (a
    structure that moved more than ``share`` of its size is drawn as it is). ``displacement`` (..., 2) m.
    """
    d = np.asarray(displacement, dtype=np.float64).reshape(-1, 2)
    largest = float(np.sqrt((d**2).sum(axis=1)).max()) if d.size else 0.0
    if not largest > 0.0:
        return 1.0
    target = share * structure_size / largest
    if target <= 1.0:
        return 1.0
    e = 10.0 ** np.floor(np.log10(target))
    return float(max(m * e for m in (1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0) if m * e <= target * (1 + 1e-12)))
