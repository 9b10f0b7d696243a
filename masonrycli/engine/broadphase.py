"""Broad phase of contact detection: world vertices, bounding boxes, sweep-and-prune.

Array conventions (see ``docs/architecture.md``): bodies are blocks ``0..N-1`` then supports
``N..N+S-1`` (``B = N + S``); polygon vertices are stored in CSR form, ``body_vert_start (B+1,) int64``
and ``vert_local (V, 2)`` [m], counter-clockwise, relative to the body's centroid at θ = 0.

The kernels (``_name``) work on flat float64 / integer arrays and never allocate; the launchers
(public functions) check shapes and dtypes, allocate on request, and grow :class:`PairBuffers` when the
number of candidate pairs exceeds its capacity.
"""

from __future__ import annotations

import math

import numpy as np

from ._arrays import check_array, check_vertices
from ._jit import kernel_only, njit

__all__ = ["PairBuffers", "body_aabbs", "candidate_pairs", "check_pair_inputs", "world_vertices"]


# --------------------------------------------------------------------------------------------------
# World vertices
# --------------------------------------------------------------------------------------------------


@njit
def _world_vertices(body_q, body_vert_start, vert_local, out):
    # for each body b: (c, s) = (cos θ_b, sin θ_b)
    #     for each vertex k of b: out[k] = (x_b, y_b) + [[c, -s], [s, c]] · vert_local[k]
    for b in range(body_vert_start.shape[0] - 1):
        x = body_q[b, 0]
        y = body_q[b, 1]
        c = math.cos(body_q[b, 2])
        s = math.sin(body_q[b, 2])
        for k in range(body_vert_start[b], body_vert_start[b + 1]):
            lx = vert_local[k, 0]
            ly = vert_local[k, 1]
            out[k, 0] = x + (c * lx - s * ly)
            out[k, 1] = y + (s * lx + c * ly)


def world_vertices(body_q, body_vert_start, vert_local, out=None):
    """World coordinates of every polygon vertex.

    Parameters
    ----------
    body_q : (B, 3) float64
        Centroid x, y [m] and rotation θ [rad, CCW] from the initial orientation.
    body_vert_start : (B+1,) int64
        CSR offsets: the vertices of body b are rows ``body_vert_start[b]:body_vert_start[b+1]``.
    vert_local : (V, 2) float64
        Vertices relative to the body centroid at θ = 0 [m], CCW.
    out : (V, 2) float64, optional
        Where to write; allocated if None.

    Returns
    -------
    vert_world : (V, 2) float64
        ``x_b + R(θ_b) · vert_local`` [m] (``out`` if it was given).
    """
    where = "world_vertices"
    vertex_count, body_count = check_vertices(where, "vert_local", vert_local, body_vert_start)
    check_array(where, "body_q", body_q, (body_count, 3), np.float64)
    if out is None:
        out = np.empty((vertex_count, 2), dtype=np.float64)
    check_array(where, "out", out, (vertex_count, 2), np.float64)
    _world_vertices(body_q, body_vert_start, vert_local, out)
    return out


# --------------------------------------------------------------------------------------------------
# Bounding boxes
# --------------------------------------------------------------------------------------------------


@njit
def _body_aabbs(vert_world, body_vert_start, margin, out):
    # for each body b: box = [min x, min y, max x, max y] over its world vertices, then grown by
    # `margin` on every side (margin = alert / 2, so that two boxes overlap whenever the bodies could
    # be closer than the alert distance along x or y).
    for b in range(body_vert_start.shape[0] - 1):
        k0 = body_vert_start[b]
        xmin = vert_world[k0, 0]
        xmax = xmin
        ymin = vert_world[k0, 1]
        ymax = ymin
        for k in range(k0 + 1, body_vert_start[b + 1]):
            x = vert_world[k, 0]
            y = vert_world[k, 1]
            if x < xmin:
                xmin = x
            if x > xmax:
                xmax = x
            if y < ymin:
                ymin = y
            if y > ymax:
                ymax = y
        out[b, 0] = xmin - margin
        out[b, 1] = ymin - margin
        out[b, 2] = xmax + margin
        out[b, 3] = ymax + margin


def body_aabbs(vert_world, body_vert_start, alert, out=None):
    """Axis-aligned bounding box of every body, inflated by ``alert / 2`` on each side.

    Parameters
    ----------
    vert_world : (V, 2) float64
        World vertices [m] (see :func:`world_vertices`).
    body_vert_start : (B+1,) int64
        CSR offsets of the vertices.
    alert : float
        Alert distance [m] (≥ 0): two boxes overlap when the bodies may be closer than ``alert``.
    out : (B, 4) float64, optional
        Where to write; allocated if None.

    Returns
    -------
    body_aabb : (B, 4) float64
        ``xmin, ymin, xmax, ymax`` [m] of each body, inflated.
    """
    where = "body_aabbs"
    _, body_count = check_vertices(where, "vert_world", vert_world, body_vert_start)
    if out is None:
        out = np.empty((body_count, 4), dtype=np.float64)
    check_array(where, "out", out, (body_count, 4), np.float64)
    _body_aabbs(vert_world, body_vert_start, 0.5 * float(alert), out)
    return out


# --------------------------------------------------------------------------------------------------
# Sweep and prune
# --------------------------------------------------------------------------------------------------


@kernel_only
def _sort_bodies(body_aabb, axis, body_order):
    # Insertion sort of body_order by the key (box lower bound along `axis`, body index).
    # The order is kept from one step to the next and bodies move little, so it is nearly sorted
    # and the sort is ~linear (the first order is prepared with a stable numpy sort by the launcher).
    # The body index breaks ties: the result depends on the current boxes only.
    for i in range(1, body_order.shape[0]):
        k = body_order[i]
        key = body_aabb[k, axis]
        j = i - 1
        while j >= 0:
            m = body_order[j]
            mk = body_aabb[m, axis]
            if mk > key or (mk == key and m > k):
                body_order[j + 1] = m
                j -= 1
            else:
                break
        body_order[j + 1] = k


@kernel_only
def _counting_sort_pairs(src, n, column, body_count, dst, counter):
    # Stable counting sort of the rows src[:n] by src[:, column] ∈ [0, body_count) into dst[:n].
    for i in range(body_count + 1):
        counter[i] = 0
    for i in range(n):
        counter[src[i, column] + 1] += 1
    for i in range(body_count):
        counter[i + 1] += counter[i]
    for i in range(n):
        k = src[i, column]
        pos = counter[k]
        dst[pos, 0] = src[i, 0]
        dst[pos, 1] = src[i, 1]
        counter[k] = pos + 1


@njit
def _sweep_and_prune(body_aabb, body_dynamic, axis, body_order, pair_body, pair_scratch, counter):
    # 1. sort the bodies by the lower bound of their box along `axis` (see _sort_bodies)
    # 2. sweep: for each body i in that order, walk the following bodies j while
    #        lower_j ≤ upper_i   (boxes overlap along `axis`; sorted, so the first failure ends it)
    #    and keep (min(i, j), max(i, j)) if the boxes also overlap along the other axis and at least
    #    one of the two bodies is dynamic (two supports never interact)
    # 3. radix-sort the pairs by (a, b): stable counting sort by b, then by a — O(P + B), and the
    #    output order depends on the set of pairs only, not on the sweep order.
    # Pairs beyond the capacity are counted but not written; the launcher then grows the buffers and
    # calls again. Returns the number of pairs.
    body_count = body_aabb.shape[0]
    lo = axis
    hi = axis + 2
    olo = 1 - axis
    ohi = 3 - axis
    _sort_bodies(body_aabb, lo, body_order)

    capacity = pair_body.shape[0]
    n = 0
    for i in range(body_count):
        bi = body_order[i]
        upper_i = body_aabb[bi, hi]
        olo_i = body_aabb[bi, olo]
        ohi_i = body_aabb[bi, ohi]
        dyn_i = body_dynamic[bi]
        for j in range(i + 1, body_count):
            bj = body_order[j]
            if not (body_aabb[bj, lo] <= upper_i):
                break
            if not (dyn_i or body_dynamic[bj]):
                continue
            if body_aabb[bj, olo] > ohi_i or olo_i > body_aabb[bj, ohi]:
                continue
            if n < capacity:
                if bi < bj:
                    pair_body[n, 0] = bi
                    pair_body[n, 1] = bj
                else:
                    pair_body[n, 0] = bj
                    pair_body[n, 1] = bi
            n += 1
    if n > capacity:
        return n
    # np.int64, not the literals: numba compiles a callee once per argument type it sees while it infers
    # the caller's types, and the literals 0, 1 and the first type of n (the literal 0) made 4 copies
    n, by_a, by_b = np.int64(n), np.int64(0), np.int64(1)
    _counting_sort_pairs(pair_body, n, by_b, body_count, pair_scratch, counter)
    _counting_sort_pairs(pair_scratch, n, by_a, body_count, pair_body, counter)
    return n


class PairBuffers:
    """Work and output arrays of :func:`candidate_pairs`; reuse one instance across time steps.

    Attributes
    ----------
    pair_body : (P_cap, 2) int32
        Candidate pairs (a, b), a < b, sorted by (a, b); rows ``[:pair_count]`` are valid.
    pair_count : int
        Number of valid rows of ``pair_body`` after the last call.
    pair_scratch : (P_cap, 2) int32
        Work array of the two counting-sort passes that order ``pair_body``.
    body_counter : (B + 1,) int64
        Work array of those passes: pairs per body, then each body's first row.
    body_order : (B,) int64
        Bodies sorted along the sweep axis (kept between calls: the next sort starts from it).
    axis : int
        Sweep axis, 0 = x, 1 = y; chosen at the first call as the axis along which the box centres
        spread most (x for a wall, y for a column), then kept so that ``body_order`` stays valid.

    The arrays may be replaced by larger ones when the capacity is exceeded (×2 growth): read them
    from the instance after each call, do not keep references.
    """

    def __init__(self, body_count: int, pair_capacity: int | None = None):
        self.body_count = int(body_count)
        if pair_capacity is None:
            pair_capacity = max(64, 8 * self.body_count)
        self.pair_body = np.zeros((int(pair_capacity), 2), dtype=np.int32)
        self.pair_scratch = np.zeros_like(self.pair_body)
        self.body_counter = np.zeros(self.body_count + 1, dtype=np.int64)
        self.body_order = np.zeros(self.body_count, dtype=np.int64)
        self.axis = -1  # not chosen yet: the first call chooses it and prepares body_order
        self.pair_count = 0

    @property
    def pair_capacity(self) -> int:
        return self.pair_body.shape[0]

    def choose_axis(self, body_aabb) -> None:
        """First call: sweep along the axis of largest spread of the box centres (fewest boxes overlapping
        along the sweep axis), and start from a stable numpy sort so that the kernel's insertion sort
        only ever sees nearly sorted input."""
        centre = body_aabb[:, :2] + body_aabb[:, 2:]
        spread = centre.std(axis=0) if body_aabb.shape[0] else np.zeros(2)
        self.axis = 0 if spread[0] >= spread[1] else 1
        self.body_order[:] = np.argsort(body_aabb[:, self.axis], kind="stable")

    def grow(self, needed: int) -> None:
        """Make room for at least ``needed`` pairs (capacity doubles until it fits)."""
        capacity = self.pair_capacity
        while capacity < needed:
            capacity *= 2
        if capacity != self.pair_capacity:
            self.pair_body = np.zeros((capacity, 2), dtype=np.int32)
            self.pair_scratch = np.zeros_like(self.pair_body)


def check_pair_inputs(body_count: int, body_dynamic, buffers: PairBuffers) -> None:
    """Raise ValueError unless ``body_dynamic`` is (B,) bool for the B bodies ``buffers`` were made for."""
    if body_count != buffers.body_count or body_dynamic.shape != (body_count,):
        raise ValueError(
            f"candidate_pairs: {body_count} boxes, {body_dynamic.shape} body_dynamic, "
            f"buffers for {buffers.body_count} bodies"
        )
    if body_dynamic.dtype != np.bool_:
        raise ValueError(f"candidate_pairs: body_dynamic must be bool, got {body_dynamic.dtype}")


def candidate_pairs(body_aabb, body_dynamic, buffers: PairBuffers) -> int:
    """Pairs of bodies whose (inflated) bounding boxes overlap — sweep and prune.

    Parameters
    ----------
    body_aabb : (B, 4) float64
        ``xmin, ymin, xmax, ymax`` [m] of each body, already inflated by alert / 2 (:func:`body_aabbs`).
        Touching boxes (equal bounds) count as overlapping.
    body_dynamic : (B,) bool
        True for blocks, False for supports; pairs of two supports are skipped.
    buffers : PairBuffers
        Work and output arrays, reused across calls.

    Returns
    -------
    pair_count : int
        Number of pairs; they are ``buffers.pair_body[:pair_count]`` ((a, b) with a < b, sorted by
        (a, b), int32). The order depends on the set of pairs only.
    """
    check_pair_inputs(body_aabb.shape[0], body_dynamic, buffers)
    if buffers.axis < 0:
        buffers.choose_axis(body_aabb)
    while True:
        n = _sweep_and_prune(
            body_aabb,
            body_dynamic,
            buffers.axis,
            buffers.body_order,
            buffers.pair_body,
            buffers.pair_scratch,
            buffers.body_counter,
        )
        if n <= buffers.pair_capacity:
            break
        buffers.grow(n)
    buffers.pair_count = n
    return n
