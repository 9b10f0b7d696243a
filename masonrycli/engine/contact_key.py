"""Contact key: which features of two bodies touch, as one int64 that survives from step to step.

The key identifies the same physical contact from one step to the next; the solver warm-starts each
contact from the impulse of the previous step's contact with the same key.

A contact always sits at a *vertex* of one body against an *edge* of the other: an incident end that
survived clipping is the incident polygon's vertex against the reference edge; an end clipped at a side
plane is the reference polygon's vertex (that end of the reference edge) against the incident edge (see
:mod:`.narrowphase` for the reference/incident faces and the clipping). The key encodes that pair of
features rather than "which face was the reference", so it does not change when the reference face flips
between two nearly coincident faces (a joint starting to open, a block starting to rock). Where two
corners nearly coincide (the incident vertex within ``snap = max(alert, tol)`` of the side plane: a
column, the vertical joints of a course), which of the two is "inside" flips with rounding and tiny
motions, so the end is then always labelled with the corner of body a, against the edge of body b::

    key = a << 40 | b << 17 | owner_is_b << 16 | vertex << 8 | edge

    bits 40..62  a           first body (a < b), < 2**23
    bits 17..39  b           second body, < 2**23
    bit  16      owner_is_b  1 if the vertex belongs to b (the edge then belongs to a), 0 otherwise
    bits  8..15  vertex      local index of the vertex in its polygon, < 256
    bits  0..7   edge        local index of the edge in the other polygon (edge k joins vertices
                             k and k+1), < 256

Limits: fewer than 2**23 = 8 388 608 bodies and at most 256 vertices per polygon (checked by
:func:`check_topology`). Keys are non-negative and unique within a step. :func:`decode_contact_key`
unpacks them.
"""

from __future__ import annotations

import numpy as np

from ._jit import kernel_only, njit

__all__ = ["KEY_LIMIT_BODIES", "KEY_LIMIT_VERTICES", "check_topology", "decode_contact_key"]

KEY_LIMIT_BODIES = 1 << 23
"""Body indices must be below this for the contact key to be unique."""
KEY_LIMIT_VERTICES = 256
"""Vertex count per polygon must be at most this for the contact key to be unique."""


@kernel_only
def _make_key(a, b, owner_is_b, vertex, edge):
    # The bit layout of the module doc; the fields' limits (check_topology) keep them from overlapping.
    return (
        (np.int64(a) << 40)
        | (np.int64(b) << 17)
        | (np.int64(owner_is_b) << 16)
        | (np.int64(vertex) << 8)
        | np.int64(edge)
    )


@kernel_only
def _end_label(side, t0, ivtx, e, e2, k, length, snap, ref_is_b):
    # Feature label (owner_is_b, vertex, edge) of one end of the clipped incident segment.
    #   raw:  clipped at side s → R's vertex (e or e2) against I's incident edge k
    #         not clipped       → I's vertex ivtx against R's reference edge e
    #   aligned corners: if the incident vertex lies within `snap` of the side plane (|t0 − 0| or
    #   |t0 − L| ≤ snap), the end is at two nearly coincident corners, one of R and one of I; which one
    #   is "inside" flips with rounding and tiny motions (a column, the vertical joints of a course),
    #   so the label is always the corner of body a, against the edge of body b.
    # snap < 0 gives the raw label.
    if side >= 0:
        rv = e if side == 0 else e2
        aligned = (t0 >= -snap) if side == 0 else (t0 <= length + snap)
    else:
        if t0 <= length - t0:
            rv = e
            aligned = t0 <= snap
        else:
            rv = e2
            aligned = t0 >= length - snap
    if aligned:
        if ref_is_b:
            return 0, ivtx, e  # a is the incident body: its vertex, against b's reference edge
        return 0, rv, k  # a is the reference body: its vertex, against b's incident edge
    if side >= 0:
        return (1 if ref_is_b else 0), rv, k
    return (0 if ref_is_b else 1), ivtx, e


@njit(inline="always")
def first_at_least(key, n, k, lo):
    # The first row i ≥ lo of the sorted key[:n] with key[i] ≥ k, or n (what np.searchsorted finds when
    # every row before lo is < k): the search of warmstart._warm_start and joints._key_row, whose keys come
    # almost in order, so i is usually within a row or two of lo:
    #   gallop from lo: probe lo, lo + 1, lo + 3, lo + 7 … until a key ≥ k (or the end); then bisect
    #   between the last probe below and that one
    # Written out, not np.searchsorted: numba compiled its generic comparisons for ~0.5 s of CPU.
    hi = lo
    step = 1
    while hi < n and key[hi] < k:  # every row ≤ hi is < k
        lo = hi + 1
        hi = lo + step - 1
        step *= 2
    if hi > n:
        hi = n
    while lo < hi:  # rows < lo are < k; row hi is ≥ k, or hi = n
        mid = (lo + hi) >> 1
        if key[mid] < k:
            lo = mid + 1
        else:
            hi = mid
    return lo


def check_topology(body_vert_start) -> None:
    """Raise ValueError unless the CSR vertex offsets fit the kernels and the contact key.

    ``body_vert_start (B+1,)`` int64: starts at 0, every polygon has 3..256 vertices, B < 2**23.
    """
    body_vert_start = np.asarray(body_vert_start)
    if body_vert_start.ndim != 1 or body_vert_start.shape[0] < 1 or body_vert_start.dtype != np.int64:
        raise ValueError("body_vert_start must be a 1-D int64 array of B+1 offsets")
    if body_vert_start[0] != 0:
        raise ValueError("body_vert_start[0] must be 0")
    body_count = body_vert_start.shape[0] - 1
    if body_count >= KEY_LIMIT_BODIES:
        raise ValueError(f"{body_count} bodies: the contact key allows fewer than {KEY_LIMIT_BODIES}")
    counts = np.diff(body_vert_start)
    bad = np.flatnonzero((counts < 3) | (counts > KEY_LIMIT_VERTICES))
    if bad.size:
        raise ValueError(f"body {bad[0]} has {counts[bad[0]]} vertices: polygons need 3..{KEY_LIMIT_VERTICES}")


def decode_contact_key(key):
    """Unpack contact keys (scalar or array) into ``(a, b, owner_is_b, vertex, edge)``.

    ``vertex`` is a local vertex index of body b if ``owner_is_b`` else of body a; ``edge`` is a local
    edge index of the other body.
    """
    key = np.asarray(key, dtype=np.int64)
    return (
        key >> 40,
        (key >> 17) & (KEY_LIMIT_BODIES - 1),
        (key >> 16) & 1,
        (key >> 8) & 0xFF,
        key & 0xFF,
    )
