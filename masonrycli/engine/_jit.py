"""One place for the numba flags of every kernel.

``cache=True`` so the second start skips compilation; no ``fastmath``: results must be exact and
bit-identical run after run (fastmath may reorder floating-point sums).
"""

import functools

import numba

njit = functools.partial(numba.njit, cache=True)
