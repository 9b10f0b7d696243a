"""Contact detection for one configuration: world vertices → boxes → candidate pairs → contacts.

Stages (each a numba kernel): world vertices, bounding boxes and sweep-and-prune
(:mod:`.broadphase`); edge normals and the separating-axis / clipping narrow phase
(:mod:`.narrowphase`).

The stages run as one kernel call (:func:`_detect`); the launcher checks shapes and dtypes as the stage
launchers of :mod:`.broadphase` and :mod:`.narrowphase` do, once per model and buffers, chooses the sweep
axis at the first call and grows the buffers. One :class:`ContactBuffers` per model is reused every step,
so that a step allocates nothing unless a capacity is exceeded (capacities then double).

Typical use in the time loop::

    buffers = ContactBuffers(model.body_vert_start)
    ...
    n = detect_contacts(body_q_m, model.body_vert_start, model.vert_local, model.body_dynamic,
                        alert, buffers)
    c = buffers.view()          # c.contact_body, c.contact_point, ... — views of the first n rows
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ._arrays import check_array, check_vertices
from ._jit import njit
from .broadphase import PairBuffers, _body_aabbs, _sweep_and_prune, _world_vertices, check_pair_inputs, world_vertices
from .contact_key import check_topology, decode_contact_key
from .narrowphase import _edge_normals, _narrowphase

__all__ = ["ContactBuffers", "Contacts", "decode_contact_key", "detect_contacts", "world_vertices"]


class Contacts(NamedTuple):
    """Views of the contacts found by the last :func:`detect_contacts` call (C = contact count)."""

    contact_body: np.ndarray
    """(C, 2) int32: bodies a < b; the normal points from a to b."""
    contact_point: np.ndarray
    """(C, 2) float64: contact point, world coordinates [m]."""
    contact_normal: np.ndarray
    """(C, 2) float64: unit normal from a to b; the tangent is t = (n_y, −n_x) (:mod:`.contact`)."""
    contact_gap: np.ndarray
    """(C,) float64: gap [m] at detection, < 0 = penetration."""
    contact_key: np.ndarray
    """(C,) int64: stable key (pair + vertex/edge features), see :mod:`.narrowphase`."""


class ContactBuffers:
    """Work and output arrays of :func:`detect_contacts`, reused from one step to the next.

    Parameters
    ----------
    body_vert_start : (B+1,) int64
        CSR vertex offsets of the model (3..256 vertices per body, B < 2**23; checked here).
    pair_capacity, contact_capacity : int, optional
        Initial capacities (default 8·B pairs and 2 × pair capacity contacts); both double whenever
        a step needs more.

    Attributes
    ----------
    vert_world : (V, 2) float64
        World vertices [m] of the last configuration.
    edge_normal : (V, 2) float64
        Outward unit normal of the edge from each vertex to the next [-].
    body_size : (B,) float64
        Largest bounding-box side of each body [m] (scale of the narrow phase's tolerances).
    body_aabb : (B, 4) float64
        ``xmin, ymin, xmax, ymax`` [m] of each body, inflated by alert / 2.
    pairs : PairBuffers
        Broad-phase state: ``pairs.pair_body[:pair_count]`` are the candidate pairs (a < b, sorted).
    contact_body, contact_point, contact_normal, contact_gap, contact_key
        Output arrays of capacity ``contact_capacity`` (shapes and units as in :class:`Contacts`);
        rows ``[:contact_count]`` are valid.
    contact_count : int
        Number of contacts found by the last call.

    Arrays can be replaced by larger ones during a call: take them from the instance (or from
    :meth:`view`) after each call, never keep references across calls.
    """

    def __init__(self, body_vert_start, pair_capacity: int | None = None, contact_capacity: int | None = None):
        body_vert_start = np.asarray(body_vert_start)
        check_topology(body_vert_start)
        self._checked_vert_start = body_vert_start
        self.body_count = body_vert_start.shape[0] - 1
        self.vertex_count = int(body_vert_start[-1])
        self.vert_world = np.zeros((self.vertex_count, 2), dtype=np.float64)
        self.edge_normal = np.zeros((self.vertex_count, 2), dtype=np.float64)
        self.body_size = np.zeros(self.body_count, dtype=np.float64)
        self.body_aabb = np.zeros((self.body_count, 4), dtype=np.float64)
        self.pairs = PairBuffers(self.body_count, pair_capacity)
        if contact_capacity is None:
            contact_capacity = 2 * self.pairs.pair_capacity
        self._allocate_contacts(max(int(contact_capacity), 2))
        self.contact_count = 0
        self._checked_inputs: tuple = ()
        """(vert_local, body_dynamic, body_vert_start) the launchers last checked against these arrays."""
        self._checked_pairs = None  # the pair array of that check (candidate_pairs may replace it)

    def _allocate_contacts(self, capacity: int) -> None:
        self._checked_inputs = ()  # new arrays: the next call checks them again
        self.contact_body = np.zeros((capacity, 2), dtype=np.int32)
        self.contact_point = np.zeros((capacity, 2), dtype=np.float64)
        self.contact_normal = np.zeros((capacity, 2), dtype=np.float64)
        self.contact_gap = np.zeros(capacity, dtype=np.float64)
        self.contact_key = np.zeros(capacity, dtype=np.int64)

    @property
    def contact_capacity(self) -> int:
        return self.contact_gap.shape[0]

    def checked_for(self, vert_local, body_dynamic, body_vert_start) -> bool:
        """True when the last detection checked these very arrays against the buffers' current ones: the
        next one can go straight to the fused kernel (:func:`_detect`)."""
        checked = self._checked_inputs
        return (
            len(checked) == 3
            and checked[0] is vert_local
            and checked[1] is body_dynamic
            and checked[2] is body_vert_start
            and self.pairs.pair_body is self._checked_pairs
        )

    @property
    def pair_count(self) -> int:
        return self.pairs.pair_count

    @property
    def pair_body(self) -> np.ndarray:
        """(P, 2) int32 view of the candidate pairs of the last call."""
        return self.pairs.pair_body[: self.pairs.pair_count]

    def grow_contacts(self, needed: int) -> None:
        """Make room for at least ``needed`` contacts (capacity doubles until it fits)."""
        capacity = self.contact_capacity
        while capacity < needed:
            capacity *= 2
        if capacity != self.contact_capacity:
            self._allocate_contacts(capacity)

    def view(self) -> Contacts:
        """The contacts of the last call, as views of the first ``contact_count`` rows."""
        n = self.contact_count
        return Contacts(
            self.contact_body[:n],
            self.contact_point[:n],
            self.contact_normal[:n],
            self.contact_gap[:n],
            self.contact_key[:n],
        )


def detect_contacts(body_q, body_vert_start, vert_local, body_dynamic, alert, buffers: ContactBuffers) -> int:
    """Find every contact with gap ≤ ``alert`` in the configuration ``body_q``.

    Parameters
    ----------
    body_q : (B, 3) float64
        Centroid x, y [m] and rotation θ [rad, CCW] from the initial orientation (for the
        Moreau–Jean scheme: the intermediate configuration q_m).
    body_vert_start : (B+1,) int64
        CSR vertex offsets (the one ``buffers`` was made for, or one with the same layout).
    vert_local : (V, 2) float64
        Convex CCW polygons relative to the body centroid at θ = 0 [m].
    body_dynamic : (B,) bool
        True for blocks, False for supports (support–support pairs are never tested).
    alert : float
        Alert distance [m] (≥ 0).
    buffers : ContactBuffers
        Reused work and output arrays.

    Returns
    -------
    contact_count : int
        The contacts are ``buffers.view()`` (rows ``[:contact_count]`` of ``buffers.contact_*``):
        sorted by pair (a, b), at most two per pair, ordered along the reference edge within a pair.
        The result depends on the inputs only (not on earlier calls).
    """
    if body_vert_start is not buffers._checked_vert_start:
        check_topology(body_vert_start)
        buffers._checked_vert_start = body_vert_start
    alert = float(alert)
    if not alert >= 0.0:
        raise ValueError(f"detect_contacts: alert distance must be >= 0, got {alert}")
    if not buffers.checked_for(vert_local, body_dynamic, body_vert_start):
        # Shapes and dtypes as the stage launchers check them, once per model and buffers.
        vertex_count, body_count = check_vertices("world_vertices", "vert_local", vert_local, body_vert_start)
        check_array("world_vertices", "out", buffers.vert_world, (vertex_count, 2), np.float64)
        check_pair_inputs(body_count, body_dynamic, buffers.pairs)
    check_array("world_vertices", "body_q", body_q, (buffers.body_count, 3), np.float64)
    pairs = buffers.pairs
    while True:  # one kernel call, again only to choose the sweep axis (first call) or to grow
        pair_count, n = _detect(
            body_q, body_vert_start, vert_local, body_dynamic, alert,
            buffers.vert_world, buffers.body_aabb, pairs.axis, pairs.body_order, pairs.pair_body,
            pairs.pair_scratch, pairs.body_counter, buffers.edge_normal, buffers.body_size,
            buffers.contact_body, buffers.contact_point, buffers.contact_normal, buffers.contact_gap,
            buffers.contact_key,
        )  # fmt: skip
        if n >= 0:
            break
        if pair_count == _NOT_FINITE:
            _raise_non_finite(body_q)
        if pair_count == _NO_AXIS:
            pairs.choose_axis(buffers.body_aabb)
        else:  # ≤ 2 contacts per pair: room for 2 P contacts and the narrow phase never overflows
            pairs.grow(pair_count)
            buffers.grow_contacts(2 * pair_count)
    pairs.pair_count = pair_count
    buffers.contact_count = n
    buffers._checked_inputs = (vert_local, body_dynamic, body_vert_start)
    buffers._checked_pairs = pairs.pair_body
    return n


def _raise_non_finite(body_q) -> None:
    bad = int(np.flatnonzero(~np.isfinite(body_q).all(axis=1))[0])
    raise FloatingPointError(f"detect_contacts: body {bad} has a non-finite pose {body_q[bad]}")


_NOT_FINITE = -1
_NO_AXIS = -2


@njit
def _detect(
    body_q, body_vert_start, vert_local, body_dynamic, alert,
    vert_world, body_aabb, axis, body_order, pair_body, pair_scratch, counter, edge_normal, body_size,
    contact_body, contact_point, contact_normal, contact_gap, contact_key,
):  # fmt: skip
    # The stages of detect_contacts in one call (each a kernel of .broadphase / .narrowphase):
    #   any pose not finite                                  → (_NOT_FINITE, -1)
    #   world vertices, boxes grown by alert/2
    #   no sweep axis yet (first call)                       → (_NO_AXIS, -1): the launcher chooses it
    #   sweep and prune                                      → P pairs
    #   P beyond the pair capacity or 2P beyond the contact capacity → (P, -1): the launcher grows
    #   edge normals, narrow phase                           → (P, C)
    for b in range(body_q.shape[0]):
        for k in range(3):
            if not np.isfinite(body_q[b, k]):
                return _NOT_FINITE, -1
    _world_vertices(body_q, body_vert_start, vert_local, vert_world)
    _body_aabbs(vert_world, body_vert_start, 0.5 * alert, body_aabb)
    if axis < 0:
        return _NO_AXIS, -1
    pair_count = _sweep_and_prune(body_aabb, body_dynamic, axis, body_order, pair_body, pair_scratch, counter)
    if pair_count > pair_body.shape[0] or 2 * pair_count > contact_gap.shape[0]:
        return pair_count, -1
    _edge_normals(vert_world, body_vert_start, edge_normal, body_size)
    n = _narrowphase(
        vert_world, edge_normal, body_size, body_vert_start, pair_body, pair_count, alert,
        contact_body, contact_point, contact_normal, contact_gap, contact_key,
    )  # fmt: skip
    return pair_count, n
