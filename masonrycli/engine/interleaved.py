"""The sweeps of a step in interleaved order: the contacts copied into K runs visited in turn, swept by
momentum (:mod:`masonrycli.engine.momentum`) or plainly (``nlgs._nlgs``), copied back; :func:`sweeps`
launches them. The accelerated solvers' first stage uses 8 runs and vectors instead
(:mod:`masonrycli.engine.lanes`, :mod:`masonrycli.engine.lane_sweeps`; dispatch.first_stage); plain "nlgs",
stalled.py's and newton.py's sweeps use these (and the first stage with the lab's ``Tuning.lanes`` off).

Detection order puts a pair's two or three contact points, and the pairs of one block, next to each
other: each visit then reads the velocities the visit before has just written, and the sweep runs at
the latency of that chain. Visiting K = ``nlgs.INTERLEAVE`` runs of the contacts in turn

    order = run 0's 1st, run 1's 1st, …, run K−1's 1st, run 0's 2nd, …   (runs: C/K contacts each)

gives the processor K independent chains to overlap: 15–35 % less time per contact·sweep on the
paper's structures, the same sweep counts to ±4 (measured on captured steps of the 51- and 248-block
walls, 8- and 32-course walls, arch and aqueduct). The rows are copied into that order (so the sweep
reads memory in sequence), solved, and r, status copied back.

One kernel per sweep (:func:`_accelerated`, :func:`_plain`), chosen by the launcher
:func:`sweeps`: a kernel holds the machine code of every sweep it may call, so one kernel
taking the choice as an argument compiled both (the plain sweep is 1.5 s of CPU the default solver's
first run does not need).
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine import momentum
from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import INTERLEAVE, PACK_WIDTH, _nlgs


@njit(inline="always")
def _in_order(contact_body, pack, count, r, status):
    # order = the interleaved visit order above; (bodies, pack rows, r, status) copied into it.
    # Returns (order, bodies, pack, r, status) in that order.
    k = INTERLEAVE
    run = (count + k - 1) // k
    order = np.empty(count, np.int64)
    i = 0
    for j in range(run):
        for q in range(k):
            c = q * run + j
            if c < count:
                order[i] = c
                i += 1
    body_o = np.empty((count, 2), np.uint32)  # unsigned: v[a] then compiles without a wrap-around test
    pack_o = np.empty((count, PACK_WIDTH), np.float64)
    r_o = np.empty((count, 2), np.float64)
    status_o = np.empty(count, np.int8)
    for i in range(count):
        c = order[i]
        body_o[i, 0] = contact_body[c, 0]
        body_o[i, 1] = contact_body[c, 1]
        for j in range(PACK_WIDTH):  # not pack_o[i, :] = pack[c, :]: numba's slice copy cost ~20 ns a row more
            pack_o[i, j] = pack[c, j]
        r_o[i, 0] = r[c, 0]
        r_o[i, 1] = r[c, 1]
    return order, body_o, pack_o, r_o, status_o


@njit(inline="always")
def _back(order, count, r_o, status_o, r, status):
    # r, status of contact order[i] ← row i of the sweep's arrays.
    for i in range(count):
        c = order[i]
        r[c, 0] = r_o[i, 0]
        r[c, 1] = r_o[i, 1]
        status[c] = status_o[i]


@njit
def _accelerated(contact_body, pack, count, mu, tolerance, max_iterations, v, v_flat, r, status, stall, flip=False):
    # in order → momentum._momentum_sweeps(stall window ``stall``, ``flip``; v_flat: v viewed as (3B,)) → back.
    # Returns (iterations, residual).
    order, body_o, pack_o, r_o, status_o = _in_order(contact_body, pack, count, r, status)
    iterations, residual = momentum._momentum_sweeps(
        body_o, pack_o, count, mu, tolerance, max_iterations, v, v_flat, r_o, status_o, stall, flip
    )
    _back(order, count, r_o, status_o, r, status)
    return iterations, residual


@njit
def _plain(contact_body, pack, count, mu, tolerance, max_iterations, v, r, status, alternate=False):
    # in order → nlgs._nlgs(``alternate``) → back. Returns (iterations, residual).
    order, body_o, pack_o, r_o, status_o = _in_order(contact_body, pack, count, r, status)
    iterations, residual = _nlgs(body_o, pack_o, count, mu, tolerance, max_iterations, v, r_o, status_o, alternate)
    _back(order, count, r_o, status_o, r, status)
    return iterations, residual


MOMENTUM, TURNING, PLAIN, ALTERNATING = "momentum", "turning", "plain", "alternating"
"""The sweeps :func:`sweeps` runs (``mode``; the first three are stalled.py's method names):
MOMENTUM: Gauss–Seidel with momentum (momentum.py), every sweep forward;
TURNING: the same, its direction turning at every restart (a one-way sweep can repeat a stick/slip cycle);
PLAIN: plain Gauss–Seidel, every sweep forward; ALTERNATING: plain, forward, backward, forward, …."""


def sweeps(contact_body, pack, count, mu, tolerance, max_iterations, v, r, status, mode, stall=0):
    """The sweeps of ``mode`` (MOMENTUM, TURNING, PLAIN, ALTERNATING) in interleaved order, until
    ``tolerance``, ``max_iterations`` or a stall: ``stall`` sweeps without a new lowest residual for the
    momentum modes, nlgs.PLAIN_STALL (compiled in) for the plain ones, which take no ``stall``. Returns
    (iterations, residual). Two kernels rather than one with the choice as an argument: a run compiles only
    the sweep it uses (the plain one cost 1.5 s of the first run's compilation)."""
    if mode == MOMENTUM or mode == TURNING:
        if not v.flags.c_contiguous:  # v.reshape would copy: the sweep's flat view of v must be v
            raise ValueError("the body velocities v must be a C-contiguous array")
        args = (contact_body, pack, count, mu, tolerance, max_iterations, v, v.reshape(-1), r, status)
        if mode == TURNING:
            return _accelerated(*args, stall, True)
        return _accelerated(*args, stall)  # flip omitted: compiled out
    args = (contact_body, pack, count, mu, tolerance, max_iterations, v, r, status)
    if mode == ALTERNATING:
        return _plain(*args, True)
    if mode == PLAIN:
        return _plain(*args)
    raise ValueError(f"interleaved.sweeps: no sweep mode {mode!r} (momentum, turning, plain, alternating)")
