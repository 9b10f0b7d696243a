"""The cells' fixed topology, built once at set-up from the blocks touching initially: each block's fan of
triangles over its angularly consecutive neighbours (the paper's Fig. I.1, slivers dropped: ``MIN_ANGLE``),
which the cell strain rate integrates over, and the two neighbours of a block in a one-block chain (a bare
ring's voussoir), which the chain strain rate follows. numpy only; the definitions: :mod:`masonrycli.analysis.tensors`."""

from __future__ import annotations

import math

import numpy as np

MIN_ANGLE = math.radians(10.0)
"""``build_triangles`` drops fan triangles whose smallest angle is below this: across a ring of voussoirs
the fan of a block is a sliver (11 mm high on a 414 mm base in the arch) whose gradient across the ring
is noise."""


def build_triangles(centroids0: np.ndarray, touching_pairs: np.ndarray) -> np.ndarray:
    """The cells' triangles (the paper's Fig. I.1), fixed for the whole run.

    For each block i, its neighbours (blocks touching it initially; supports are not grains) sorted by
    the direction of G_j − G_i; each two angularly consecutive neighbours j, k less than 180° apart
    give the triangle (i, j, k) — j and k need not touch. Triangles whose smallest angle is below
    ``MIN_ANGLE`` are dropped (slivers across a ring). A gap of 180° or more is the cell's free edge.

    Args:
        centroids0: (N, 2) initial block centroids, m.
        touching_pairs: (P, 2) int, pairs of bodies in contact in the initial configuration (e.g. the
            distinct ``contact_body`` rows of the first detection). Order within a pair, repeats, and
            pairs involving supports (index ≥ N) are allowed; the latter are ignored.

    Returns:
        (T, 3) int64 rows (apex i, j, k), counter-clockwise in the initial configuration, sorted
        lexicographically (deterministic); the cell of i is the rows whose first entry is i. (0, 3)
        when no block has a well-shaped triangle (e.g. a column).
    """
    points = np.asarray(centroids0, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 2:
        raise ValueError(f"centroids0 must have shape (N, 2), got {points.shape}")
    n = points.shape[0]
    apex, first, second = _fan_pairs(n, _block_pairs(touching_pairs, n), points)
    p0, p1, p2 = points[apex], points[first], points[second]
    # smallest angle: the one opposite the shortest side, from the area and the two sides around it
    sides = np.stack([np.hypot(*(p2 - p1).T), np.hypot(*(p0 - p2).T), np.hypot(*(p1 - p0).T)], axis=1)
    area2 = (p1[:, 0] - p0[:, 0]) * (p2[:, 1] - p0[:, 1]) - (p1[:, 1] - p0[:, 1]) * (p2[:, 0] - p0[:, 0])
    s = np.sort(sides, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        sin_min = area2 / (s[:, 1] * s[:, 2])
    keep = (area2 > 0) & (np.arcsin(np.clip(sin_min, 0.0, 1.0)) >= MIN_ANGLE)
    tri = np.stack([apex, first, second], axis=1)[keep].astype(np.int64)
    order = np.lexsort((tri[:, 2], tri[:, 1], tri[:, 0]))
    return np.ascontiguousarray(tri[order]).reshape(-1, 3)


def chain_neighbours(block_count: int, touching_pairs: np.ndarray) -> np.ndarray:
    """(N, 2) int64: the two neighbouring blocks of each block in a one-block chain, (−1, −1) otherwise.

    A block is in a one-block chain when it touches exactly two blocks and no support initially (a
    voussoir of a bare ring, the springing voussoirs included). ``touching_pairs`` as for
    ``build_triangles``, supports included.
    """
    n = int(block_count)
    pairs = np.asarray(touching_pairs, dtype=np.int64).reshape(-1, 2)
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    on_support = np.zeros(n, bool)
    for side in range(2):
        mine, other = pairs[:, side], pairs[:, 1 - side]
        on_support[mine[(mine < n) & (other >= n)]] = True
    blocks = _block_pairs(pairs, n)
    both = np.concatenate([blocks, blocks[:, ::-1]])
    both = both[np.lexsort((both[:, 1], both[:, 0]))]
    count = np.bincount(both[:, 0], minlength=n)
    out = np.full((n, 2), -1, np.int64)
    chain = (count == 2) & ~on_support
    start = np.r_[0, np.cumsum(count)[:-1]]
    out[chain, 0] = both[start[chain], 1]
    out[chain, 1] = both[start[chain] + 1, 1]
    return out


def _block_pairs(touching_pairs, n: int) -> np.ndarray:
    """(P, 2) distinct block pairs (lo < hi) of ``touching_pairs``, supports and self-pairs left out."""
    pairs = np.asarray(touching_pairs, dtype=np.int64).reshape(-1, 2)
    lo, hi = np.minimum(pairs[:, 0], pairs[:, 1]), np.maximum(pairs[:, 0], pairs[:, 1])
    valid = (lo >= 0) & (hi < n) & (lo != hi)
    keys = np.unique(lo[valid] * n + hi[valid])
    return np.stack([keys // max(n, 1), keys % max(n, 1)], axis=1)


def _fan_pairs(n: int, pairs: np.ndarray, points: np.ndarray):
    """Candidate fan triangles (apex, j, k): angularly consecutive neighbours less than π apart."""
    apex = np.concatenate([pairs[:, 0], pairs[:, 1]])
    other = np.concatenate([pairs[:, 1], pairs[:, 0]])
    d = points[other] - points[apex]
    angle = np.arctan2(d[:, 1], d[:, 0])
    order = np.lexsort((other, angle, apex))
    apex, other, angle = apex[order], other[order], angle[order]
    count = np.bincount(apex, minlength=n)
    start = np.r_[0, np.cumsum(count)[:-1]]
    # next neighbour counter-clockwise, cyclic within each apex's run
    pos = np.arange(apex.size)
    nxt = pos + 1
    last = pos == start[apex] + count[apex] - 1
    nxt[last] = start[apex[last]]
    gap = np.mod(angle[nxt] - angle, 2.0 * np.pi)
    ok = (count[apex] >= 2) & (gap > 0.0) & (gap < np.pi)
    return apex[ok], other[ok], other[nxt][ok]
