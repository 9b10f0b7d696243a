"""The two private pieces of rerun-sdk 0.41 the recording relies on, in one place.

Checked against rerun-sdk 0.41; if an upgrade renames either, only this module changes.

- ``STRIP_TYPE`` / ``VEC2_TYPE``: the Arrow types of a batch of 2-D line strips. The public
  ``rr.LineStrips2D.columns`` takes Python lists and loops over every strip; building the ragged Arrow
  array ourselves from numpy offsets is what keeps a 248-block recording cheap, and it needs the exact
  datatype the SDK declares (``LineStrip2DBatch._ARROW_DATATYPE``; no public accessor exists).
- ``viewer_pid``: the process id of a viewer spawned by ``rerun.experimental.ViewerClient.spawn``
  (``ViewerClient._pid``), so a viewer that does not quit can be killed with its process group instead
  of being left running after a screenshot.
"""

from __future__ import annotations

from typing import Final

import rerun as rr

STRIP_TYPE: Final = rr.components.LineStrip2DBatch._ARROW_DATATYPE
"""list<fixed_size_list<float32, 2>>: one line strip."""
VEC2_TYPE: Final = STRIP_TYPE.value_type
"""fixed_size_list<float32, 2>: one point of a strip."""


def viewer_pid(viewer) -> int | None:
    """Process id of a spawned viewer, None once it has quit (or if the client did not spawn one)."""
    return viewer._pid
