"""Banded LU without pivoting: the direct solve of a Newton step (:mod:`masonrycli.engine.newton`).

The Newton matrix of a step lives on the 3B velocity dofs of the blocks, and a contact couples only the two
bodies it joins. With the bodies numbered so that neighbours have close numbers, the matrix is banded: on
the walls (blocks numbered course by course, as the builders emit them) a block touches blocks at most one
course away, 16 numbers on the 32- and 64-course walls, so a half-bandwidth of 3 · 16 + 2 = 50 dofs
(measured on the captured stalled steps; reverse Cuthill–McKee gives 23–46 blocks there, no better).
Gaussian elimination then stays inside the band: n · w² multiply-adds (n = 3B, w the half-bandwidth),
3e3 · 50² ≈ 7e6 at 992 blocks.

No pivoting, as scipy's splu ran these matrices before (symmetric mode, diag_pivot_thresh = 0). The Newton
matrix is M + H G Hᵀ with G per contact upper triangular: a sliding contact ties r_t to r_n by μ, so G is
not symmetric and a diagonal entry of the matrix can be negative (seen on random problems), but the pivots
stay away from 0 on the captured stalled steps and the solve matches a dense one with partial pivoting
(tests/test_engine_banded.py). A pivot that is 0 or not finite ends the factorisation; the caller counts the
Newton step as rejected, and the Newton step's Armijo search rejects a poor direction anyway.

Storage: the band by rows, ``band[i, j − i + w] = A[i, j]`` for |i − j| ≤ w, shape (n, 2w + 1); the
factorisation overwrites it with L (unit lower, below the diagonal) and U (on and above).
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine._jit import njit


@njit
def band_lu(band, n, w):
    # In place, Doolittle by columns, without pivoting:
    #   for k in 0 … n−1:
    #       p = A[k, k]; stop (return k) if p is 0 or not finite
    #       u = A[k, k+1 … k+w]                      (copied: a buffer of its own lets LLVM vectorise below)
    #       for i in k+1 … min(n−1, k+w):              (rows below the pivot, inside the band)
    #           l = A[i, k] / p; A[i, k] = l
    #           A[i, k+1 … k+w] −= l · u             (contiguous: row i's column j sits at j − i + w)
    # Fill-in stays inside the band. Returns −1, or the first column whose pivot is 0 or not finite.
    u = np.empty(w, np.float64)
    for k in range(n):
        p = band[k, w]
        if p == 0.0 or not np.isfinite(p):
            return k
        last = min(n - 1, k + w)
        m = last - k
        for t in range(m):
            u[t] = band[k, w + 1 + t]
        for i in range(k + 1, last + 1):
            o = k - i + w
            a = band[i, o]
            if a == 0.0:  # no coupling of row i to column k (yet): nothing to eliminate
                continue
            lik = a / p
            band[i, o] = lik
            row = band[i, o + 1 : o + 1 + m]
            for t in range(m):
                row[t] -= lik * u[t]
    return -1


@njit
def band_solve(band, n, w, x):
    # x ← A⁻¹ x from band_lu's factors: L y = x forward (unit diagonal), U x = y backward.
    for i in range(n):
        s = x[i]
        for j in range(max(0, i - w), i):
            s -= band[i, j - i + w] * x[j]
        x[i] = s
    for i in range(n - 1, -1, -1):
        s = x[i]
        for j in range(i + 1, min(n - 1, i + w) + 1):
            s -= band[i, j - i + w] * x[j]
        x[i] = s / band[i, w]


def body_order(contact_body, coupled, bodies) -> tuple[np.ndarray, int]:
    """(position (B,) of each body in the band, half-bandwidth in bodies): the bodies' own numbering if no
    coupled pair is further apart in it than in reverse Cuthill–McKee's, else that ordering. ``coupled``
    (C,) bool marks the contacts whose two bodies both move (the others add nothing off the diagonal)."""
    a = contact_body[coupled, 0].astype(np.int64)
    b = contact_body[coupled, 1].astype(np.int64)
    position = np.arange(bodies)
    if a.size == 0:
        return position, 0
    natural = int(np.abs(a - b).max())
    # scipy imported here: only a stalled step's Newton gets here, and importing it at the top cost every
    # start of masonry ~0.15 s of CPU (importing the CLI and the time loop: 0.73 -> 0.58 s)
    import scipy.sparse as sp
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    graph = sp.csr_matrix((np.ones(a.size), (a, b)), shape=(bodies, bodies))
    order = reverse_cuthill_mckee((graph + graph.T).tocsr(), symmetric_mode=True)
    rcm = np.empty(bodies, np.int64)
    rcm[order] = np.arange(bodies)
    width = int(np.abs(rcm[a] - rcm[b]).max())
    if width < natural:
        return rcm, width
    return position, natural
