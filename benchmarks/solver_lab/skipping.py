"""Another idea for the ordinary steps (:mod:`benchmarks.solver_lab.ordinary`): the engine's accelerated solve
leaving out of the sweeps the contacts with no warm impulse that are open by more than a margin at the warm
start, every left-out contact checked open at the end (else the step goes on with all of them)."""

from __future__ import annotations

import time

import numpy as np

from benchmarks.solver_lab.ordinary import CAP, STALL, TOLERANCE, Step, _accelerated, kernel_args
from masonrycli.engine import nlgs


def _normal_margin(v, body, pack):
    """u_n + max(g, 0)/dt of each contact at velocities v (m/s): > 0 open."""
    b = body.astype(np.int64)
    dv = v[b[:, 1]] - v[b[:, 0]]
    un = (
        dv[:, 0] * pack[:, nlgs.P_NX]
        + dv[:, 1] * pack[:, nlgs.P_NY]
        + v[b[:, 1], 2] * pack[:, nlgs.P_NB]
        - v[b[:, 0], 2] * pack[:, nlgs.P_NA]
    )
    return un + pack[:, nlgs.P_BIAS]


def solve_skipping(step: Step, margin: float, clock=None):
    """The engine's accelerated solve on the contacts that can act: a contact with no warm impulse that is
    open by more than ``margin`` m/s at the warm start is left out of the sweeps (visiting it would find it
    open and change nothing, as long as it stays open); the RMS still divides by all C contacts. At the end
    every left-out contact must be open at the final velocities, else the step goes on with all contacts
    (counted in ``fallback``). Returns (sweeps, residual, v, r, left out, fallback); ``clock`` (a list) gets
    the CPU seconds of the kernel calls and the final test."""
    d = step.arrays("engine")
    st = np.zeros(step.count, dtype=np.int8)
    v0 = step.v_free.copy()
    args = kernel_args({})
    _accelerated(
        d["body"], d["pack"], step.count, step.mu, TOLERANCE, 0, v0, d["r_warm"].copy(), st, STALL, *args, np.zeros(0)
    )
    act = (d["r_warm"] != 0).any(axis=1) | (_normal_margin(v0, d["body"], d["pack"]) <= margin)
    idx = np.flatnonzero(act)
    body, pack, r = np.ascontiguousarray(d["body"][idx]), np.ascontiguousarray(d["pack"][idx]), d["r_warm"][idx].copy()
    v = step.v_free.copy()
    t = time.process_time()
    its, res = _accelerated(
        body, pack, idx.size, step.mu, TOLERANCE, CAP, v, r, st[idx], STALL, *args, np.zeros(0), step.count
    )
    out = d["r_warm"].copy() * 0.0
    out[idx] = r
    ok = bool((_normal_margin(v, d["body"][~act], d["pack"][~act]) >= 0.0).all())
    if clock is not None:
        clock.append(time.process_time() - t)
    if not ok:
        v = step.v_free.copy()
        its2, res = _accelerated(
            d["body"], d["pack"], step.count, step.mu, TOLERANCE, CAP, v, out, st, STALL, *args, np.zeros(0)
        )
        its += its2
    return its, res, v, out, step.count - idx.size, not ok
