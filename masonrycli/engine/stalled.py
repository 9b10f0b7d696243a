"""What a stalled accelerated solve does: three methods taken in turn, each resumed where it stopped.

Gauss–Seidel with momentum (the default solver, :mod:`masonrycli.engine.momentum`) converges most steps in
tens to hundreds of sweeps. On tall walls that slide it can stall: momentum drives the step into a
stick/slip cycle, the residual wanders above the tolerance, and the solve stops after momentum's stall
window. No single method finishes every such step. Measured on 33 of the 108 steps that stall over the first
0.2 s of the walls of 32 and 64 courses (benchmarks/README.md, "Stalled steps"; each method alone from the
step's warm start, tolerance 1e-5 m/s, cap 50 000 sweep units):

* Gauss–Seidel with alternating sweep direction (forward, backward, forward, …) converges 32 of them (the
  32-course wall's in 227–6377 sweeps), where one-way plain sweeps stall on 10 and momentum cycles on 20:
  reversing the order every sweep breaks the cycle in which a sliding block lifts one corner of its bed
  joint and the other corner takes the load. It fails on the 64-course wall's first step (43 002 sweeps, unconverged) and
  creeps on its third (16 383).
* Momentum itself, continued past its window, converges those first 64-course steps in 1846–8041 sweeps
  (its residual plateaus for hundreds of sweeps there before dropping), and cycles on the sliding steps.
* Faces (:mod:`masonrycli.engine.faces`) from momentum's stalled iterate converge 32 of the 33, at ~2× a
  point sweep's cost per unit, sometimes first (the 64-course wall's step 1: 3465 units against 5471 and
  8327).

So the methods are run round-robin from their own states, each for a budget of sweep units that doubles
every round (FIRST_BUDGET, 2 × FIRST_BUDGET, …), until one meets the tolerance or the step's cap is
spent. A step that one method solves in U units costs at most about 3 × 2U plus momentum's first try,
whichever method that is; a method that stalls inside its budget (its own stall window) is dropped. At
the cap the state with the lowest residual is kept and the step is counted unconverged, as before.
On the 33 steps this finishes all of them in 149 423 sweep units (5.1 s CPU; alternating sweeps alone:
124 500 units, 4.4 s, one step missed); the fixed chain it replaced (faces for at most 5000 units, plain
sweeps from the warm start, faces to the cap) took 17 816–23 714 units on each of seven sliding steps of
the 32-course wall captured from its own run; this takes 704–9399 on six of them and 23 998 on the seventh.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine import faces, nlgs

FIRST_BUDGET = 2000
"""Sweep units each method gets in the first round; doubled every round (module doc)."""

METHODS = ("alternating", "momentum", "faces")
"""The order in which a round visits the methods: the one that finishes most stalled steps first."""


class _State:
    """One method's iterate: velocities (None until first run), impulses, statuses, last residual (m/s)."""

    __slots__ = ("v", "r", "status", "residual")

    def __init__(self, v, r, status, residual):
        self.v, self.r, self.status, self.residual = v, r, status, residual


def continue_stalled(
    contact_body, pack, count, mu, tolerance, cap, v, r, status, v_free, r_warm, iterations, residual
) -> tuple[int, float]:
    """Finish a step whose accelerated solve stalled.

    In: the step's arrays as nlgs.solve has them (``v`` (B, 3) m/s and ``r`` (C, 2) N·s: momentum's stalled
    iterate, consistent; ``status`` (C,)), ``v_free`` (B, 3) the free velocities and ``r_warm`` (C, 2) the
    warm start, ``iterations`` (sweep units) and ``residual`` (m/s) of the momentum solve so far. Out:
    ``v``, ``r``, ``status`` of the method that met ``tolerance`` (or, at ``cap``, of the lowest residual).
    Returns (iterations including the earlier ones, residual)."""
    states = {
        "alternating": _State(None, r_warm[:count].copy(), status[:count].copy(), np.inf),
        "momentum": _State(v.copy(), r[:count].copy(), status[:count].copy(), residual),
        "faces": _State(v.copy(), r[:count].copy(), status[:count].copy(), residual),
    }
    active = list(METHODS)
    budget = FIRST_BUDGET
    while iterations < cap and active:
        for name in list(active):
            units = min(budget, cap - iterations)
            if units <= 0:
                break
            state = states[name]
            done = _resume(name, state, contact_body, pack, count, mu, tolerance, units, v_free)
            iterations += done
            if state.residual <= tolerance:
                _adopt(state, v, r, status, count)
                return iterations, state.residual
            if done < units:  # stalled inside its budget: its own stall window says it will not get there
                active.remove(name)
        budget *= 2
    best = min((s for s in states.values() if s.v is not None), key=lambda s: s.residual)
    _adopt(best, v, r, status, count)
    return iterations, best.residual


def _resume(name, state, contact_body, pack, count, mu, tolerance, units, v_free) -> int:
    # Each method goes on from its own iterate. The sweeps of nlgs rebuild v from v_free and r on entry
    # (v = v_free + M⁻¹ H r), so their state is r alone; faces carry v along with r. Momentum restarts its
    # extrapolation (β = 0) at every resume and gets the whole budget as its stall window: it has already
    # stalled once, and what finishes the steps it finishes is going on through its plateaus.
    if name == "faces":
        done, state.residual = faces.face_sweeps(
            contact_body, pack, count, mu, tolerance, units, state.v, state.r, state.status
        )
        return done
    state.v = v_free.copy()
    accelerate = name == "momentum"
    done, state.residual = nlgs._nlgs_interleaved(
        contact_body,
        pack,
        count,
        mu,
        tolerance,
        units,
        state.v,
        state.r,
        state.status,
        accelerate,
        units,
        not accelerate,
    )
    return done


def _adopt(state, v, r, status, count) -> None:
    v[:] = state.v
    r[:count] = state.r
    status[:count] = state.status
