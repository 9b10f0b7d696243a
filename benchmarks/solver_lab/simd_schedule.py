"""Schedules for the coloured sweeps of simd_sweep.py: which contacts a sweep may visit at once.

``colour``: greedy graph colouring, no two contacts of a colour on one movable body (Box2D v3's wide
solver), so a colour's visits can run side by side and the sweep is Gauss–Seidel in colour order.
``levels``: the engine's own interleaved visit order cut into levels of independent visits, so that
running the levels in turn replays the engine's sweep bit for bit (a check of the coloured machinery,
and a measure of how independent the engine's order is).
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine import nlgs
from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import P_IIA, P_IIB, P_IMA, P_IMB

MASK_WORDS = 4
"""Colours are tracked per body as MASK_WORDS 64-bit masks: at most 64·MASK_WORDS colours."""


@njit(cache=False)
def colour(contact_body, pack, count, body_count, out_order, out_start):
    # Greedy colouring in detection order: contact c takes the lowest colour used by no earlier contact
    # on its movable bodies. Then a counting sort: out_order = contacts by colour (detection order within
    # a colour), out_start[k] … out_start[k + 1] the rows of colour k. Returns the number of colours.
    #   used[body] = bitmask of the colours of the contacts seen on body (MASK_WORDS words)
    used = np.zeros((body_count, MASK_WORDS), np.uint64)
    col = np.empty(count, np.int64)
    n_colours = 0
    for c in range(count):
        a = contact_body[c, 0]
        b = contact_body[c, 1]
        move_a = pack[c, P_IMA] > 0.0 or pack[c, P_IIA] > 0.0
        move_b = pack[c, P_IMB] > 0.0 or pack[c, P_IIB] > 0.0
        k = -1
        for w in range(MASK_WORDS):
            m = np.uint64(0)
            if move_a:
                m |= used[a, w]
            if move_b:
                m |= used[b, w]
            free = ~m
            if free != 0:
                # lowest set bit of free
                bit = 0
                while (free >> np.uint64(bit)) & np.uint64(1) == 0:
                    bit += 1
                k = 64 * w + bit
                break
        if k < 0:
            raise ValueError("more colours than MASK_WORDS * 64")
        w = k // 64
        flag = np.uint64(1) << np.uint64(k % 64)
        if move_a:
            used[a, w] |= flag
        if move_b:
            used[b, w] |= flag
        col[c] = k
        if k + 1 > n_colours:
            n_colours = k + 1
    for k in range(n_colours + 1):
        out_start[k] = 0
    for c in range(count):
        out_start[col[c] + 1] += 1
    for k in range(n_colours):
        out_start[k + 1] += out_start[k]
    fill = out_start[:n_colours].copy()
    for c in range(count):
        out_order[fill[col[c]]] = c
        fill[col[c]] += 1
    return n_colours


@njit(cache=False)
def levels(contact_body, pack, count, body_count, out_order, out_start):
    # Level schedule of the engine's visit order (interleaved, nlgs.INTERLEAVE runs): visit p goes to
    #   level(p) = 1 + max(level of the last earlier visit on each of its movable bodies)   (0 if none)
    # so visits of one level share no movable body, and every earlier visit on a body is in an earlier
    # level: running the levels in turn, each level's visits in any order, replays the sequential sweep
    # (each visit reads the velocities it would have read; each body's pushes come in the same order;
    # a support only ever receives ±0, whose order does not matter). Then a counting sort: out_order =
    # visit positions by level (in visit order within a level), out_start as colour(). Returns
    # (levels, visit order: the contact of each position).
    visit = interleaved_order(count, nlgs.INTERLEAVE)
    last = np.full(body_count, -1, np.int64)
    lev = np.empty(count, np.int64)
    n_levels = 0
    for p in range(count):
        c = visit[p]
        a = contact_body[c, 0]
        b = contact_body[c, 1]
        move_a = pack[c, P_IMA] > 0.0 or pack[c, P_IIA] > 0.0
        move_b = pack[c, P_IMB] > 0.0 or pack[c, P_IIB] > 0.0
        lv = 0
        if move_a:
            lv = max(lv, last[a] + 1)
        if move_b:
            lv = max(lv, last[b] + 1)
        if move_a:
            last[a] = lv
        if move_b:
            last[b] = lv
        lev[p] = lv
        n_levels = max(n_levels, lv + 1)
    for k in range(n_levels + 1):
        out_start[k] = 0
    for p in range(count):
        out_start[lev[p] + 1] += 1
    for k in range(n_levels):
        out_start[k + 1] += out_start[k]
    fill = out_start[:n_levels].copy()
    for p in range(count):
        out_order[fill[lev[p]]] = p
        fill[lev[p]] += 1
    return n_levels, visit


LANES = 8


@njit(cache=False)
def interleaved_order(count, k):
    # interleaved.py's visit order with k runs: run 0's j-th contact, run 1's, …, run k−1's, then the
    # (j+1)-th (runs of ⌈count / k⌉ contacts in detection order). Returns the contact of each position.
    run = (count + k - 1) // k
    visit = np.empty(count, np.int64)
    i = 0
    for j in range(run):
        for q in range(k):
            c = q * run + j
            if c < count:
                visit[i] = c
                i += 1
    return visit


@njit(cache=False)
def lanes(contact_body, pack, count, body_count, out_order, out_start):
    # Groups of the 8-run interleaved order: group j = run 0's j-th contact, run 1's, …, run 7's (runs:
    # stretches of detection order, as interleaved.py's 4). A group whose contacts share a movable body is
    # split into groups of one, in the same order, so running the groups in turn is Gauss–Seidel in that
    # order whatever the group's visits do at once. out_start (≥ count + 1 long). Returns the groups.
    out_order[:] = interleaved_order(count, LANES)
    run = (count + LANES - 1) // LANES
    groups = 0
    i = 0
    out_start[0] = 0
    for j in range(run):
        first = i
        for q in range(LANES):  # group j: the next ≤ LANES contacts of that order
            if q * run + j < count:
                i += 1
        clash = False
        for x in range(first, i):
            cx = out_order[x]
            for y in range(first, x):
                cy = out_order[y]
                for sx in range(2):
                    if not _moves(pack, cx, sx):
                        continue
                    for sy in range(2):
                        if _moves(pack, cy, sy) and contact_body[cx, sx] == contact_body[cy, sy]:
                            clash = True
        if clash:
            for x in range(first, i):
                groups += 1
                out_start[groups] = x + 1
        else:
            groups += 1
            out_start[groups] = i
    return groups


@njit(inline="always")
def _moves(pack, c, side):
    if side == 0:
        return pack[c, P_IMA] > 0.0 or pack[c, P_IIA] > 0.0
    return pack[c, P_IMB] > 0.0 or pack[c, P_IIB] > 0.0
