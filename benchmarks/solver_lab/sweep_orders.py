"""The orders in which the ordinary-step variants (:mod:`benchmarks.solver_lab.ordinary`, ``order``) visit the
contacts in a sweep: the engine's (detection order in interleaved runs), and the orders tried against it."""

from __future__ import annotations

import numpy as np

from masonrycli.engine import nlgs

ORDERS = ("engine", "detection", "reverse", "up", "down", "up-pure", "down-pure", "random", "by-b", "by-b-pure")
"""Sweep orders: the engine's (detection order, 4 interleaved runs), detection order alone, the engine's
reversed; by contact height (point y, ties by x) up or down, with the engine's interleaving or pure; random;
by the higher body of the pair first (by-b: a block's contacts with the blocks below and left of it together)."""


def interleave(count: int) -> np.ndarray:
    """The engine's visiting order (dispatch.first_stage)."""
    k = nlgs.INTERLEAVE
    run = (count + k - 1) // k
    return np.array([q * run + j for j in range(run) for q in range(k) if q * run + j < count], dtype=np.int64)


def sweep_order(name: str, point: np.ndarray, body: np.ndarray) -> np.ndarray:
    c = point.shape[0]
    if name.startswith("by-b"):
        o = np.lexsort((body[:, 0], body[:, 1]))
        return o if name.endswith("pure") else o[interleave(c)]
    if name in ("engine", "reverse"):
        o = interleave(c)
        return o[::-1].copy() if name == "reverse" else o
    if name == "detection":
        return np.arange(c)
    if name == "random":
        return np.random.default_rng(0).permutation(c)
    by_y = np.lexsort((point[:, 0], point[:, 1]))
    if name.startswith("down"):
        by_y = by_y[::-1]
    return by_y if name.endswith("pure") else by_y[interleave(c)]
