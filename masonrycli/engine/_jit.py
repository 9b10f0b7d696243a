"""The one place where the engine's numba compilation flags are set.

Every kernel of ``masonrycli.engine`` is decorated with :data:`njit` (never ``numba.njit`` directly), so
that changing a flag changes it everywhere.

- ``cache=True``: compiled machine code is cached next to the sources (``__pycache__``), so a second
  start does not recompile.
- no ``fastmath``: it allows reassociation and contraction, which change results in the last bits from
  one build or machine to the next. The engine promises bit-identical output for the same input, and
  the contact geometry relies on exact comparisons (ties between faces, points on clipping planes).
- no ``parallel``: threads would make the order of floating-point reductions, hence the results,
  depend on scheduling.
"""

from __future__ import annotations

import functools

import numba

njit = functools.partial(numba.njit, cache=True)
"""``numba.njit`` with the engine's flags. Use as ``@njit`` or ``@njit(...)``."""

__all__ = ["njit"]
