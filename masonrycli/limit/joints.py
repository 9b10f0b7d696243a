"""Joints of an assembly for limit analysis: the engine's contacts, grouped per pair of bodies.

The contact points come from :func:`masonrycli.engine.collision.detect_contacts` — the very detection the
time loop runs — in the initial configuration, within the model's alert distance but at most
:data:`~masonrycli.analysis.mechanism.JOINT_GAP` (1 mm, the default alert distance). So every assembly the engine
can run can also be analysed, and a joint here is a joint there. The cap: with ``[run] alert_distance =
0.5`` the 51-block wall had "joints" between blocks 0.2 m apart (and with 1e9 between its two ends),
which carried the LP's forces across the gaps: λ 0.544 / 0.569 instead of 0.464, with hinges such as
``c01-b01|c01-b08``.

A *joint* is one pair of bodies (a < b; supports come after the blocks) with its contact points: two
for a face-to-face joint (the ends of the shared segment), one for a corner touching a face. All the
points of a joint share one normal n (from a to b) and tangent t = (n_y, −n_x) (the engine's convention,
docs/architecture.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from masonrycli.analysis.mechanism import JOINT_GAP
from masonrycli.engine.collision import ContactBuffers, detect_contacts, world_vertices
from masonrycli.limit.corners import rounded_corner_normal
from masonrycli.model import Model


@dataclass(frozen=True, eq=False)
class Joints:
    """Contacts of the initial configuration, sorted by pair (C contacts, J joints)."""

    contact_body: np.ndarray
    """(C, 2) int64: bodies a < b (blocks 0..N-1, then supports)."""
    contact_point: np.ndarray
    """(C, 2) m: contact point, world coordinates."""
    contact_normal: np.ndarray
    """(C, 2): unit normal from a to b."""
    contact_joint: np.ndarray
    """(C,) int64: joint of each contact."""
    joint_body: np.ndarray
    """(J, 2) int64: the two bodies of each joint."""
    joint_start: np.ndarray
    """(J+1,) int64: contacts of joint j are rows joint_start[j]:joint_start[j+1]."""
    contact_grip: np.ndarray | None = None
    """(C,) share of μ each contact carries: 0 at a corner on a corner, rising to 1 over the rounding radius
    along a face from its rounded end (:mod:`masonrycli.limit.corners`); None: 1 everywhere."""

    def contact_friction(self, mu: float) -> np.ndarray:
        """(C,) Coulomb coefficient of each contact: ``mu`` × its grip."""
        if self.contact_grip is None:
            return np.full(self.contact_count, float(mu))
        return float(mu) * self.contact_grip

    @property
    def contact_count(self) -> int:
        return int(self.contact_body.shape[0])

    @property
    def joint_count(self) -> int:
        return int(self.joint_body.shape[0])

    @property
    def contact_tangent(self) -> np.ndarray:
        """(C, 2): t = (n_y, −n_x), so that (t, n) is right-handed as in the engine."""
        n = self.contact_normal
        return np.stack([n[:, 1], -n[:, 0]], axis=1)

    @property
    def joint_points(self) -> np.ndarray:
        """(J,) int64: number of contact points of each joint (2 for faces, 1 for corners)."""
        return np.diff(self.joint_start)


def find_joints(model: Model) -> Joints:
    """The joints of ``model`` in its initial configuration (engine contact detection within the model's
    alert distance, at most JOINT_GAP: module doc)."""
    buffers = ContactBuffers(model.body_vert_start)
    reach = min(model.alert_distance, JOINT_GAP)
    count = detect_contacts(model.body_q0, model.body_vert_start, model.vert_local, model.body_dynamic, reach, buffers)
    c = buffers.view()
    body = np.asarray(c.contact_body[:count], dtype=np.int64)
    # detect_contacts sorts by pair already; a stable sort keeps that promise explicit and cheap.
    key = body[:, 0] * model.body_count + body[:, 1]
    order = np.argsort(key, kind="stable")
    key, body = key[order], body[order]
    first = np.ones(key.size, dtype=bool)
    first[1:] = key[1:] != key[:-1]
    starts = np.flatnonzero(first)
    normal = np.array(c.contact_normal[:count][order], dtype=np.float64)
    single = starts[np.diff(np.append(starts, key.size)) == 1]
    grip = _round_corners(model, body, normal, single)
    return Joints(
        contact_body=body,
        contact_point=np.array(c.contact_point[:count][order], dtype=np.float64),
        contact_normal=normal,
        contact_joint=np.cumsum(first) - 1,
        joint_body=body[starts].copy(),
        joint_start=np.append(starts, key.size).astype(np.int64),
        contact_grip=grip,
    )


def _round_corners(model: Model, body: np.ndarray, normal: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """(C,) grip of every contact (the share of μ it carries); the single-point contacts ``rows`` that touch
    within the rounding of a corner (:mod:`masonrycli.limit.corners`) take the normal of the rounded corners (in
    place) and grip < 1: a corner on a corner's detected normal turned by up to 90° with a survey's last digit.
    A corner on a face away from its ends keeps its detected normal bit for bit, and grip 1; one on a sliver of
    a face (3.5 mm long on the aqueduct, whose direction a millimetre's rounding turns by 18°) takes the normal of
    the face the rounding leaves."""
    grip = np.ones(normal.shape[0])
    if rows.size == 0:
        return grip
    verts = world_vertices(model.body_q0, model.body_vert_start, model.vert_local)
    start = model.body_vert_start
    for r in rows:
        a, b = int(body[r, 0]), int(body[r, 1])
        found = rounded_corner_normal(verts[start[a] : start[a + 1]], verts[start[b] : start[b + 1]])
        # a normal within ~1e-6 rad of the detected one is that face's: kept bit for bit
        if found is not None and (found[1] < 1.0 or float(found[0] @ normal[r]) < 1.0 - 1e-12):
            normal[r], grip[r] = found
    return grip


def joint_names(model: Model, joints: Joints) -> list[str]:
    """``"a|b"`` for each joint, the two body names as the dynamic run's hinge report spells them."""
    return model.joint_names(joints.joint_body)
