"""What a stalled accelerated solve does: momentum in body order, then five methods taken in turn.

    continue_stalled (the step's first stage stopped at its stall window above the tolerance):
        stage: momentum in body order (bodies.py) from the warm start, ≤ bodies_units sweep units;
               done if it meets the tolerance; handed over early when its residual cycles
               ("Hand-over", "Sooner" below)
        round-robin, round k = 0, 1, …: each method of methods still active (newton, turning,
        alternating, momentum, faces) resumes from its own iterate for first_budget · 2^k units
        (newton: newton_budget × that, its second resume right after its first, none after
        newton_last_round); done when one meets the tolerance; after bodies_reenter resumes a
        handed-over stage goes on once ("Re-entry"); a method that stalls inside its budget or ends a
        round no lower than an earlier one is dropped (newton excepted)
        at the cap: the round-robin's state of lowest residual, the step counted unconverged

Why. Gauss–Seidel with momentum (:mod:`masonrycli.engine.momentum`, the default) converges most steps in
tens to hundreds of sweeps, but on tall walls that slide it can drive a step into a stick/slip cycle (a
sliding block lifts one corner of its bed joint, the other corner takes the load, the block slides back)
and stop at its stall window above the tolerance. No single method finishes every such step; taken in
turn, each resumed from its own state with a budget that doubles every round, they do: on 35 stalled steps
of the 32- and 64-course walls, 159 597 sweep units for all 35, where each method alone missed some
(benchmarks/JOURNAL.md, "Stalled steps: four methods in turn"). A step that one method solves in U units
costs at most about 4 × 2U plus the first stage, whichever method that is. The methods:

* "newton" (:mod:`masonrycli.engine.newton`): Alart–Curnier Newton steps from the warm start, then turning
  sweeps from its iterate. First, with newton_budget × the others' budget, and its second resume right
  after its first (newton_ahead), in round 0 only; the drop rules leave it alone (each resume's sweeps start
  from a new Newton iterate, so their stall says little of it). On 98 stalled steps of the 32- and
  64-course walls it takes the round-robin from 408 422 units to 212 312 ("Alart–Curnier in the engine").
* "turning": momentum whose sweep direction turns at every restart (a one-way sweep can repeat the
  stick/slip cycle for ever, and a restart is the sign of it).
* "alternating": Gauss–Seidel without momentum, forward, backward, forward, ….
* "momentum": the stalled first stage's momentum, continued (it finishes cold starts, where load travels
  through 64 courses, faster than the others).
* "faces" (:mod:`masonrycli.engine.faces`) from momentum's stalled iterate.

Drop rules: a method that stalls inside its budget (its own stall window) or ends a round no lower than an
earlier one (it cycles) leaves; without them the 32-course wall's step 99 of one run reached the cap, with
them it takes 27 240 units. A step that needs 10 000 units of the one method that converges it costs about
50 000 here, which is why the default cap (``RunConfig.max_iterations``) is 100 000.

The stage ahead of the round-robin: momentum in body order (:mod:`masonrycli.engine.bodies`) from the warm
start converges all 64 hard steps of the 32- and 64-course walls' ensemble runs in 150 139 units, where the
round-robin took 956 975 ("New methods on hard steps"). Momentum's stall window (first_stall)
decides how soon a hard step reaches it.

Hand-over: where the stage fails (the 248-block wall's hard steps) its residual cycles at a level well above
its lowest, reached in an early dip, while the round-robin then finishes in ~600 units (newton's first
resume). So every bodies_window sweeps the window's level (geometric mean of its residuals) is compared with
bodies_level × the lowest residual so far, and bodies_cycling such windows in a row hand the step over
(bodies._cycling_windows). The round-robin starts from the warm start, not from the stage's iterate, so a
step the stage would not have finished ends with the same solution in fewer units: wall-248's 45 hard steps
955 083 → 671 907 units ("The hand-over, again"). A quicker trigger (4 windows at 1.4) also handed over
steps the stage finishes slowly, and newton's solution of those, though within the tolerance too, differs
from the stage's: runs left main's path.

Sooner: bodies_cycling_far cycling windows in a row hand over when the stage's lowest residual is above
bodies_far × the tolerance or each window's level above bodies_strong × its low, far from anything the
stage finishes: the benchmark's wall-248 run's 58 steps of ≥ 400 units 51 875 → 45 952 ("Where the dear
steps of the benchmark's wall-248 run go").

Re-entry: a handed-over stage keeps its run (bodies.Stage) and, after bodies_reenter of the round-robin's
resumes, goes on once for the units it had left, as one long run would; also when the round-robin ends
first. A step that cycles for a while and then converges otherwise paid a round-robin 10× dearer (the
64-course wall's step 128: 98 160 units with the hand-over alone, 15 142 with re-entry; "A way back to the
stage"). At the cap the round-robin's lowest residual is adopted, never the stage's.

Newton ahead: a step newton finishes in its second resume used to pay the four other methods' round 0
first; with newton_ahead, 342 replayed steps of ≥ 2500 units 3 291 823 → 2 769 636 units (0.84×), as many
converged ("Hard steps: the costliest steps").

The numbers named here in lower case (bodies_units, first_budget, methods, newton_ahead, …) are the fields of
:class:`masonrycli.engine.tuning.Tuning`, documented there with their units and sources; continue_stalled gets
them from dispatch.solve, which gets them from the Solver.
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine import bodies, faces, interleaved, newton
from masonrycli.engine.tuning import TUNING


class _State:
    """One method's iterate: velocities ``v`` (B, 3; None until its first run), impulses ``r`` (C, 2) N·s,
    ``status`` (C,), its last ``residual`` and the lowest residual it ended a round with, ``low`` (m/s);
    newton's alone: its Newton ``iterate`` (C, 2) N·s, its regularisation ``shift`` ([λ], newton.py) and
    its ``resumes``."""

    __slots__ = ("v", "r", "status", "residual", "low", "iterate", "shift", "resumes")

    def __init__(self, v, r, status, residual):
        self.v, self.r, self.status, self.residual = v, r, status, residual
        self.low = np.inf
        self.iterate = None  # newton: its Newton iterate; r is that of its last sweeps
        self.resumes = 0


def continue_stalled(
    contact_body, pack, count, mu, tolerance, cap, v, r, status, v_free, r_warm, iterations, residual, tuning=TUNING
) -> tuple[int, float]:
    """Finish a step whose accelerated solve stalled.

    In: the step's arrays as dispatch.solve has them (``v`` (B, 3) m/s and ``r`` (C, 2) N·s: momentum's stalled
    iterate, consistent; ``status`` (C,)), ``v_free`` (B, 3) the free velocities and ``r_warm`` (C, 2) the
    warm start, ``iterations`` (sweep units) and ``residual`` (m/s) of the momentum solve so far. Out:
    ``v``, ``r``, ``status`` of the method that met ``tolerance`` (or, at ``cap``, of the lowest residual).
    ``tuning``: the stage's and the round-robin's numbers (:class:`~masonrycli.engine.tuning.Tuning`). Returns (iterations including the earlier ones, residual)."""
    # First momentum in body order from the warm start, alone (bodies module doc: it converges the hard
    # steps in a fraction of the round-robin's units); the round-robin below only if it does not.
    stage = None  # the stage's iterate, kept with its run when the hand-over rule stops it (it may re-enter)
    run, stage_left = None, 0
    if tuning.bodies_units > 0:
        v_b, r_b, status_b = v_free.copy(), r_warm[:count].copy(), status[:count].copy()
        units = min(tuning.bodies_units, cap - iterations)
        run = bodies.new_stage(count, v.shape[0])
        done, residual_b = bodies.body_order_sweeps(
            contact_body,
            pack,
            count,
            mu,
            tolerance,
            units,
            v_b,
            r_b,
            status_b,
            tuning.bodies_stall,
            tuning.bodies_window,
            tuning.bodies_level,
            tuning.bodies_cycling,
            stage=run,
            far=tuning.bodies_far,
            far_cycling=tuning.bodies_cycling_far,
            strong=tuning.bodies_strong,
        )
        iterations += done
        if residual_b <= tolerance or (iterations >= cap and residual_b < residual):
            v[:], r[:count], status[:count] = v_b, r_b, status_b
            return iterations, residual_b
        if iterations >= cap:
            return iterations, residual
        if tuning.bodies_reenter > 0 and run.carry[bodies.C_REASON] == bodies.STOP_CYCLING:
            stage, stage_left = _State(v_b, r_b, status_b, residual_b), tuning.bodies_units - done
    states = {
        "newton": _State(None, r_warm[:count].copy(), status[:count].copy(), np.inf),
        "turning": _State(None, r_warm[:count].copy(), status[:count].copy(), np.inf),
        "alternating": _State(None, r_warm[:count].copy(), status[:count].copy(), np.inf),
        "momentum": _State(v.copy(), r[:count].copy(), status[:count].copy(), residual),  # goes on
        "faces": _State(v.copy(), r[:count].copy(), status[:count].copy(), residual),
    }
    active = list(tuning.methods)
    budget = tuning.first_budget
    round_ = 0
    newton_resumes = 0
    resumes = 0  # the round-robin's, for the stage's re-entry
    while iterations < cap and active:
        # newton makes tuning.newton_ahead more resumes right after its first, in round 0 (module doc)
        for name in [m for m in active for _ in range(1 + tuning.newton_ahead if m == "newton" and round_ == 0 else 1)]:
            state = states[name]
            if name == "newton" and newton_resumes > tuning.newton_last_round:
                if name in active:
                    active.remove(name)
                continue
            if name == "newton":  # its k-th resume gets the budget of round k, ahead or not
                units = min(tuning.first_budget * 2**newton_resumes * tuning.newton_budget, cap - iterations)
                newton_resumes += 1
            else:
                units = min(budget, cap - iterations)
            if units <= 0:
                break
            done = _resume(
                name, state, contact_body, pack, count, mu, tolerance, units, v_free, cap - iterations, tuning
            )
            iterations += done
            if state.residual <= tolerance:
                _adopt(state, v, r, status, count)
                return iterations, state.residual
            resumes += 1
            if stage is not None and resumes == tuning.bodies_reenter:
                iterations += _reenter(
                    stage, run, min(stage_left, cap - iterations), contact_body, pack, count, mu, tolerance, tuning
                )
                if stage.residual <= tolerance:
                    _adopt(stage, v, r, status, count)
                    return iterations, stage.residual
            # The drop rules (module doc). Not newton's: its sweeps' stall or residual says little of its
            # Newton iterate, which goes on at the next resume; it leaves after tuning.newton_last_round only.
            #   done < units: stalled inside its budget, its own stall window says it will not get there
            #   residual ≥ low: a whole budget, doubled, without a new low: it cycles
            if name != "newton" and (done < units or state.residual >= state.low):
                active.remove(name)
            state.low = min(state.low, state.residual)
        budget *= 2
        round_ += 1
    if stage is not None and resumes < tuning.bodies_reenter:  # the round-robin ended first: the stage's turn
        iterations += _reenter(
            stage, run, min(stage_left, cap - iterations), contact_body, pack, count, mu, tolerance, tuning
        )
        if stage.residual <= tolerance:
            _adopt(stage, v, r, status, count)
            return iterations, stage.residual
    # The round-robin's lowest, never the stage's after a hand-over: its iterate cycles (on the 32-course wall's
    # ensemble, adopting it when lowest put runs on other trajectories with 13 unconverged steps against 7)
    best = min((s for s in states.values() if s.v is not None), key=lambda s: s.residual)
    _adopt(best, v, r, status, count)
    return iterations, best.residual


def _reenter(stage, run, units, contact_body, pack, count, mu, tolerance, tuning) -> int:
    # The stage goes on from where its hand-over stopped it, as one long run would (bodies.Stage), for the
    # units it had left, without the hand-over rule (it already handed over) and with its stall window.
    done, stage.residual = bodies.body_order_sweeps(
        contact_body, pack, count, mu, tolerance, units, stage.v, stage.r, stage.status, tuning.bodies_stall, stage=run
    )
    return done


def _resume(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit, tuning) -> int:
    # Each method goes on from its own iterate. The sweeps of nlgs rebuild v from v_free and r on entry
    # (v = v_free + M⁻¹ H r), so their state is r alone; faces carry v along with r. Momentum, turning or
    # not, restarts its extrapolation (β = 0, forward) at every resume and gets the whole budget as its
    # stall window: what finishes the steps it finishes is going on through its plateaus.
    if name == "newton":
        if state.iterate is None:
            state.iterate = state.r.copy()
            state.v = v_free.copy()
            state.shift = [newton.LAMBDA]
        done, state.residual = newton.newton_steps(
            contact_body,
            pack,
            count,
            mu,
            tolerance,
            units,
            limit,
            v_free,
            state.iterate,
            state.r,
            state.v,
            state.status,
            state.shift,
            tuning.newton_shares[min(state.resumes, len(tuning.newton_shares) - 1)],
        )
        state.resumes += 1
        return done
    if name == "faces":
        done, state.residual = faces.face_sweeps(
            contact_body, pack, count, mu, tolerance, units, state.v, state.r, state.status
        )
        return done
    state.v = v_free.copy()
    # turning, alternating, momentum: the sweep modes of the same names
    done, state.residual = interleaved.sweeps(
        contact_body, pack, count, mu, tolerance, units, state.v, state.r, state.status, name, units
    )
    return done


def _adopt(state, v, r, status, count) -> None:
    v[:] = state.v
    r[:count] = state.r
    status[:count] = state.status
