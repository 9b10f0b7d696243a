"""How far the run's drawing reached: the box the structure view must hold at close.

Two boxes (xmin, ymin, xmax, ymax), m, grown batch by batch: what the blocks reached in x (a collapse either
way, but not a block fallen off the supports) and the magnified shape, and what the joint arrows reached
(the Magnified tab has none). ``Recorder`` widens the view to their union at close and moves the colour bars
right of it (``static_content.log_plane``, ``legend_move``).
"""

from __future__ import annotations

import numpy as np


def union(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The box (xmin, ymin, xmax, ymax) holding boxes ``a`` and ``b``."""
    return np.r_[np.minimum(a[:2], b[:2]), np.maximum(a[2:], b[2:])]


def empty_box() -> np.ndarray:
    """A box that holds nothing: any union with it is the other box."""
    return np.array([np.inf, np.inf, -np.inf, -np.inf])


class Reach:
    """The boxes of what was drawn. ``radius``: (N,) m, each block's farthest vertex from its centroid."""

    def __init__(self, radius: np.ndarray) -> None:
        self.radius = radius
        self.extent = empty_box()  # the blocks' x reach, the magnified shape
        self.arrows = empty_box()  # the joint arrows'

    def add_blocks(self, q: np.ndarray, floor: np.ndarray | None) -> None:
        """A batch's block poses ``q`` (F, N, 3); ``floor``: (F,) m, the lowest support vertex's y at each frame
        (None: no support). A block whose top has dropped below it fell off the supports and does not count
        (magnified.send_magnified)."""
        if not q.shape[1]:
            return
        x, r = q[..., 0], np.broadcast_to(self.radius, q.shape[:2])
        if floor is not None:
            on = q[..., 1] + r >= floor[:, None]
            x, r = x[on], r[on]
        if x.size:
            e = self.extent
            e[2], e[0] = max(e[2], float((x + r).max())), min(e[0], float((x - r).min()))

    def add_arrows(self, box: np.ndarray) -> None:
        self.arrows = union(self.arrows, box)

    def add_drawn(self, box: np.ndarray) -> None:
        """A box drawn by the structure itself (the magnified shape)."""
        self.extent = union(self.extent, box)

    def content(self) -> np.ndarray:
        """Everything drawn: blocks, magnified shape and arrows."""
        return union(self.extent, self.arrows)
