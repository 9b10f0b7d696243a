"""What a stalled accelerated solve does: momentum in body order, then five methods taken in turn.

    continue_stalled (the step's first stage stopped at its stall window above the tolerance):
        stage: momentum in body order (bodies.py) from the warm start, ≤ BODIES_UNITS sweep units;
               done if it meets the tolerance; handed over early when its residual cycles
               ("Hand-over", "Sooner" below)
        round-robin, round k = 0, 1, …: each method of METHODS still active (newton, turning,
        alternating, momentum, faces) resumes from its own iterate for FIRST_BUDGET · 2^k units
        (newton: NEWTON_BUDGET × that, its second resume right after its first, none after
        NEWTON_LAST_ROUND); done when one meets the tolerance; after BODIES_REENTER resumes a
        handed-over stage goes on once ("Re-entry"); a method that stalls inside its budget or ends a
        round no lower than an earlier one is dropped (newton excepted)
        at the cap: the round-robin's state of lowest residual, the step counted unconverged

The paragraphs below are the why, each with its measurements, in the order the rules were added; the
round-robin's own case ("Gauss–Seidel with momentum … converges most steps") comes after the stage's.

First, from the step's warm start, momentum sweeps that visit the contacts body by body
(:mod:`masonrycli.engine.bodies`) for at most BODIES_UNITS sweep units (stall window BODIES_STALL sweeps;
they hand over to the round-robin earlier when their residual cycles, "Hand-over" below).
On 64 hard steps of the 32- and 64-course walls' ensemble runs, alone, they converge all 64 in 150 139
units where the round-robin below took 956 975 (benchmarks/JOURNAL.md, "New methods on hard steps"); the
same steps replayed through nlgs.solve with this stage ahead of the round-robin take 218 460 (0.23×),
none above 13 209 units; all 342 kept steps of ≥ 2500 units 1 207 789 against 3 291 823 (0.37×), none
unconverged against 5. Ensembles of 48 short runs a wall: mean sweep units a step 0.70× [90 %: 0.61,
0.80] on the 32-course wall, 0.65× [0.59, 0.72] on the 64-course wall, unconverged steps 5 → 7 and
13 → 2. Only a step they do not finish goes on to the round-robin described next, which is what the
rest of this doc measured before that stage existed.

Since the stage finishes nearly every step the tall walls hand over, momentum's stall window decides
how much a hard step spends before it starts: 500 sweeps until 2026-11-27, then 200 (momentum.py's doc:
ensembles 0.61× / 0.88× / 0.97× mean units on the 32-, 64-course and 248-block walls). The order of the
round-robin behind the stage no longer matters there: newton, first, finishes nearly all it gets, and
momentum second (newton, momentum, turning, alternating, faces) gave every replayed hard step of five
sets its units under the order below (benchmarks/JOURNAL.md, "Momentum's stall window").

Hand-over (on since 2026-11-27: 8 windows of 500 sweeps at level 1.8, this part's last paragraph). On the
248-block wall the stage finished none of 21 captured steps of ≥ 2500 units: it spent its 16 000 units on
each, and the round-robin then finished 20 of them in ~600 (newton's first resume). On the 32- and 64-course
walls it finishes 178 of 179 and 142 of 142 stalled steps, a few only after 3000–7000 sweeps. Their residual
histories (benchmarks/JOURNAL.md, "The body-order stage's hand-over") tell most of them apart: where the stage
fails, its residual cycles (stick/slip) around a level 1.4–6× the lowest residual, reached in an early dip,
and new lows by a hair keep restarting any stall window; where it succeeds slowly, the residual stays near its
low (level within 1.05–1.5× on most). So with BODIES_CYCLING > 0, every BODIES_WINDOW sweeps the window's
level (geometric mean of its residuals) is compared with BODIES_LEVEL × the lowest residual so far, and
BODIES_CYCLING such windows in a row hand the step over (bodies._cycling_windows). The round-robin starts
from the warm start and momentum's iterate, not from the stage's, so a step the stage would not have
finished ends with the same solution in fewer units. With 500 × 1.8 × 4: replayed, the 248-block wall's
21 steps 402 494 → 173 892 units, the 32-course wall's 192 steps 534 217 → 520 829, the 64-course
wall's 150 665 570 → 668 013, as many converged; ensembles of 48 runs a wall, mean units a step 0.954
[0.931, 0.975] (248-block wall, unconverged 3 → 3), 0.995 [0.974, 1.016] (32 courses, 7 → 8), 1.001
[0.985, 1.019] (64 courses, 2 → 3). Not on: more unconverged steps on the tall walls, and a step that
cycles for 2000 sweeps and then converges is handed to a round-robin that may cost 10× more (the
64-course wall's 1.15 m/s 1.7 Hz step 128: 10 041 → 98 160 units).

With window 200 (momentum.STALL_SWEEPS, since 674490b) and re-entry, 4 × 1.4 made the 32-course wall's
ensemble 1.024 [0.986, 1.066] (unconverged 1 → 3): it hands over steps the stage finishes after 2000–4000
sweeps (on the 255 steps of ≥ 2500 units of main's own 48 runs, 32 steps in 22 runs), and newton's solution of
such a step differs from the stage's by 4e-3–1.4e-2 m/s (both meet the 1e-5 m/s residual; the stage run on to
a residual of 1.3e-7 or 2.5e-6 is 1.7–3.5e-2 m/s from either), so the run leaves main's path; on those paths,
17 of 25 changed runs met more steps of ≥ 2500 units (2 fewer). Cycling = 8 windows (not before sweep 4000) at
level 1.8 hands over 3 of the 255 (1.6 × 8: 7) and keeps most of the gain on steps the stage never finishes
(wall-248's 45 hard steps of the ed257db set replayed: 955 083 → 671 907 units; 4 × 1.4: 491 776). Ensembles
of 48 runs a wall against main's (benchmarks/JOURNAL.md, "The hand-over, again"): mean units a step 0.983
[0.972, 0.993] on the 248-block wall, 0.994 [0.985, 0.999] on the 64-course wall, 1.000 [0.988, 1.015] on the
32-course wall; unconverged 0 → 0, 4 → 4, 1 → 0. So BODIES_CYCLING = 8, BODIES_LEVEL = 1.8,
BODIES_WINDOW = 500.

Re-entry (with the hand-over, on with it). A handed-over stage keeps its run
(bodies.Stage: iterate, extrapolation, stall window) and, after BODIES_REENTER = 2 of the round-robin's
resumes (newton's two in round 0, which finish the 248-block wall's steps), goes on for the units it had
left, once, as one long run would; also when the round-robin ends first. Step 128 above then costs
15 142 (after 1 resume 11 719, but the 32-course wall's step 121, which newton's second resume finishes,
8581 → 20 604; after round 0, 23 145). Replayed, the same as the hand-over alone but for the 248-block
wall's one unconverged step, which pays the stage's remaining units again (37 294 → 49 345, main's
figure): 402 494 → 185 943. At the cap the round-robin's lowest residual is adopted, never the
stage's (adopting it when lowest put h32 runs on trajectories with 13 unconverged steps against 7).
Ensembles of 48 runs a wall against main with momentum.STALL_SWEEPS 500 (benchmarks/JOURNAL.md, "A way
back to the stage"): 0.960 [0.937, 0.980] on the 248-block wall (unconverged 3 → 3), 0.996 [0.977,
1.017] on the 32-course wall (7 → 8), 0.994 [0.982, 1.005] on the 64-course wall (2 → 3; step 128 15 142
units): the hand-over's extra unconverged steps, met on other trajectories, remain. It ships with the
hand-over at 8 × 1.8 (above; BODIES_CYCLING = 0 turns both off).

Sooner (since 2026-11-28). The 8-window rule left the 248-block wall's dearest steps at ~7900 stage units each:
the stage cycles there at window levels 3–12 × the tolerance, far above anything it finishes, and newton's
first resume then finishes in 600–1400. Where the stage fails on that wall its lowest residual stays above
2 × the tolerance (the benchmark run's step 989: 3.8 ×, levels 7.7–9.6 ×) or its level above 3 × its low;
the slow finishers of the 32-course wall sit at 1.0–1.9 × the tolerance with levels ≤ 1.9 × their low. So
BODIES_CYCLING_FAR = 2 cycling windows in a row (not before sweep 1000) hand over when the low is above
BODIES_FAR = 2 × the tolerance or each window's level above BODIES_STRONG = 3 × the low. A step the stage would
not have finished gets the same solution (the round-robin starts from the warm start) in fewer units; on the
captured steps none the stage finishes is handed over. Replayed (benchmarks/JOURNAL.md, "Where the dear steps of
the benchmark's wall-248 run go"): the benchmark run's 58 steps of ≥ 400 units 51 875 → 45 952 (step 989 9569 →
3646), 16 hard steps of three other wall-248 runs 165 204 → 105 975, 38 of two 32-course runs 249 469 → 239 527.
Ensembles of 48 runs a wall against main: mean units a step 0.977 [0.965, 0.988] (248-block wall), 0.998
[0.996, 1.000] (32 and 64 courses), unconverged 1 → 1, 9 → 9, 2 → 2.

Gauss–Seidel with momentum (the default solver, :mod:`masonrycli.engine.momentum`) converges most steps in
tens to hundreds of sweeps. On tall walls that slide it can stall: momentum drives the step into a
stick/slip cycle, the residual wanders above the tolerance, and the solve stops after momentum's stall
window. No single method finishes every such step. Measured on 35 of the 108 steps that stall over the first
0.2 s of the walls of 32 and 64 courses (benchmarks/JOURNAL.md, "Stalled steps"; each method alone from the
step's warm start, tolerance 1e-5 m/s, cap 50 000 sweep units):

* Momentum whose sweep direction turns at every restart ("turning": forward until the residual jumps,
  then backward, …) converges 34 of them, most in 125–5005 sweeps, where momentum in one direction cycles
  on 22. A sliding block lifts one corner of its bed joint, the other corner takes the load, the block
  slides back: a one-way sweep can repeat that cycle for ever, and a restart is the sign of it.
* Gauss–Seidel with alternating sweep direction (forward, backward, forward, …) converges 33 (the
  32-course wall's in 227–6377 sweeps), where one-way plain sweeps stall on 11.
* Momentum in one direction, continued past its window, converges the 64-course wall's first steps (a
  cold start: load travelling through 64 courses) in 1846–8041 sweeps, where the others need up to 5× more.
* Faces (:mod:`masonrycli.engine.faces`) from momentum's stalled iterate converge 33, at ~2× a point
  sweep's cost per unit, and finish first on a few (the 64-course wall's step 1: 3465 units).

So the methods are run round-robin from their own states, each for a budget of sweep units that doubles
every round (FIRST_BUDGET, 2 × FIRST_BUDGET, …), until one meets the tolerance or the step's cap is
spent. A step that one method solves in U units costs at most about 4 × 2U plus momentum's first try,
whichever method that is. A method is dropped when it stalls inside its budget (its own stall window)
or ends a round no lower than it ended an earlier one (it cycles: the 32-course wall's step 99 of one run
reached the cap before this rule, and takes 27 240 units with it, faces finishing). Not newton: its sweeps
start from a new Newton iterate at each resume, so their stall or residual says little of that iterate; it
leaves after round NEWTON_LAST_ROUND. At the cap the
state with the lowest residual is kept and the step is counted unconverged, as before: a step that needs
10 000 units of the one method that converges it costs about 50 000 in this round-robin (the 64-course
wall's step 108 of one run, faces alone 9924: 51 926 units), which is why the default cap
(``RunConfig.max_iterations``) is 100 000 and not the 50 000 of plain Gauss–Seidel's days: at 50 000 that
step ended unconverged at the cap; at 100 000 the 64-course wall's first 0.2 s has none (mean 1780 sweep
units a step against 1799), and runs with no step above 50 000 are bit-identical. On the 35 steps (before the drop rule) this
finishes all of them in 159 597 sweep units (5.9 s CPU); with the three methods
other than "turning" it took 225 016 units and missed one (the 64-course wall's step 99, where only faces
get there, in 44 797 units alone); "turning" alone 164 706 units, one missed. The fixed chain this module
replaced (faces for at most 5000 units, plain sweeps from the warm start, faces to the cap) took
17 816–23 714 units on each of seven sliding steps of the 32-course wall captured from its own run.

Alart–Curnier Newton (:mod:`masonrycli.engine.newton`, "newton": 10 Newton steps from the warm start,
then turning sweeps from its iterate; 40 more in its second resume) goes first, with twice the others'
budget, in the first two rounds only, and the drop rules leave it alone. On the 98 stalled steps of the
32- and 64-course walls' first 0.2 s, replayed, the round-robin takes 212 312 units with it against
408 422 without (0.52×); it finishes most of them, the 64-course wall's 51 404-unit step in ~2700.
Second in the order and in the first round only it took 256 810 (291 118 on the acengine branch, where
a Newton step solved by scipy's splu counted 200 units). Whole runs (sweep units a step, mean / max,
none unconverged): first 0.2 s of the 32-course wall 1108 / 38 137 against 1353 / 27 240, of the
64-course wall 1302 / 17 584 against 1780 / 51 926, the 248-block wall's 1 s 163 / 10 309 against
151 / 3196 (another path from step 400 on). Ensembles of short runs: benchmarks/JOURNAL.md, "Alart–Curnier
in the engine".

Newton's second resume comes right after its first (NEWTON_AHEAD), before the other methods' first
round: in the round-robin a step that newton finishes in its second resume first paid the four other
methods' 8000 units of round 0, and such steps are most of the costliest (in ensemble runs of the
32-course wall, replayed: 40 of its 61 steps above 10 000 units, at 12 574–18 794 units each). Replayed (benchmarks/JOURNAL.md, "Hard steps"; 342
steps of ≥ 2500 units from 24 ensemble runs): 3 291 823 units → 2 769 636 (0.84×; the 32-course wall's
1 501 801 → 1 171 832, the 64-course wall's 1 790 022 → 1 597 804), as many converged; the 886 steps of
1000–2500 units 1 273 140 → 1 275 355 (steps newton's first resume finishes do not change). So "newton"
leaves after its second resume, i.e. takes part in round 0 only (NEWTON_LAST_ROUND counts its resumes).
Whole runs (ensembles of 48 runs a wall against main's): mean units a step 0.948× on the 32-course wall,
0.983× on the 64-course wall (unconverged steps 13 → 10), 0.994× on the 248-block wall: not worse, a
smaller gain than the replay's (other trajectories, other hard steps). The aqueduct's settlement, where a
step that another method finished in round 0 now pays newton's second resume first, took 60 503 units
over 0.2 s against 55 512 (one run).
"""

from __future__ import annotations

import numpy as np

from masonrycli.engine import bodies, faces, newton, nlgs

BODIES_UNITS = 16_000
"""Sweep units that momentum in body order (:mod:`masonrycli.engine.bodies`) gets alone, before the round-robin."""
BODIES_STALL = 8000
"""Its sweeps without a new lowest residual after which the round-robin takes over."""
BODIES_WINDOW = 500
"""Sweeps over which the hand-over rule takes the stage's residual level (module doc, "Hand-over")."""
BODIES_LEVEL = 1.8
"""A window whose level (geometric mean of its residuals) is above this × the stage's lowest residual cycles."""
BODIES_CYCLING = 8
"""Cycling windows in a row after which the stage hands over to the round-robin (0: never; 8, i.e. not before
sweep 4000, since 2026-11-27: module doc "Hand-over")."""

BODIES_FAR = 2.0
"""A stage whose lowest residual is still above this × the tolerance hands over after BODIES_CYCLING_FAR cycling
windows in a row instead of BODIES_CYCLING (module doc, "Sooner")."""
BODIES_STRONG = 3.0
"""So does a stage whose windows' level is above this × its lowest residual, BODIES_CYCLING_FAR windows in a row."""
BODIES_CYCLING_FAR = 2
"""Windows in a row of the sooner hand-over (0: off; 2, i.e. not before sweep 1000, since 2026-11-28)."""

BODIES_REENTER = 2
"""After a hand-over, the round-robin's resumes (in its order, newton's ahead counted) after which the stage
goes on from where it stopped, once, for the rest of its BODIES_UNITS (module doc, "Re-entry"); it does
also if the round-robin ends first. 0: never."""

FIRST_BUDGET = 2000
"""Sweep units each method gets in the first round; doubled every round (module doc)."""

METHODS = ("newton", "turning", "alternating", "momentum", "faces")
"""The order in which a round visits the methods: the one that finishes most stalled steps first."""


NEWTON_BUDGET = 2
"""newton's budget in a round, in units of the others' (module doc)."""

NEWTON_LAST_ROUND = 1
"""The last resume (0-based) "newton" makes, its k-th with the budget of round k: it finishes most steps it
finishes in its first two budgets (module doc)."""

NEWTON_AHEAD = 1
"""Further resumes "newton" makes right after its first, in round 0, before the other methods start
(module doc, last paragraph)."""


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
    contact_body, pack, count, mu, tolerance, cap, v, r, status, v_free, r_warm, iterations, residual
) -> tuple[int, float]:
    """Finish a step whose accelerated solve stalled.

    In: the step's arrays as nlgs.solve has them (``v`` (B, 3) m/s and ``r`` (C, 2) N·s: momentum's stalled
    iterate, consistent; ``status`` (C,)), ``v_free`` (B, 3) the free velocities and ``r_warm`` (C, 2) the
    warm start, ``iterations`` (sweep units) and ``residual`` (m/s) of the momentum solve so far. Out:
    ``v``, ``r``, ``status`` of the method that met ``tolerance`` (or, at ``cap``, of the lowest residual).
    Returns (iterations including the earlier ones, residual)."""
    # First momentum in body order from the warm start, alone (bodies module doc: it converges the hard
    # steps in a fraction of the round-robin's units); the round-robin below only if it does not.
    stage = None  # the stage's iterate, kept with its run when the hand-over rule stops it (it may re-enter)
    run, stage_left = None, 0
    if BODIES_UNITS > 0:
        v_b, r_b, status_b = v_free.copy(), r_warm[:count].copy(), status[:count].copy()
        units = min(BODIES_UNITS, cap - iterations)
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
            BODIES_STALL,
            BODIES_WINDOW,
            BODIES_LEVEL,
            BODIES_CYCLING,
            stage=run,
            far=BODIES_FAR,
            far_cycling=BODIES_CYCLING_FAR,
            strong=BODIES_STRONG,
        )
        iterations += done
        if residual_b <= tolerance or (iterations >= cap and residual_b < residual):
            v[:], r[:count], status[:count] = v_b, r_b, status_b
            return iterations, residual_b
        if iterations >= cap:
            return iterations, residual
        if BODIES_REENTER > 0 and run.carry[bodies.C_REASON] == bodies.STOP_CYCLING:
            stage, stage_left = _State(v_b, r_b, status_b, residual_b), BODIES_UNITS - done
    states = {
        "newton": _State(None, r_warm[:count].copy(), status[:count].copy(), np.inf),
        "turning": _State(None, r_warm[:count].copy(), status[:count].copy(), np.inf),
        "alternating": _State(None, r_warm[:count].copy(), status[:count].copy(), np.inf),
        "momentum": _State(v.copy(), r[:count].copy(), status[:count].copy(), residual),  # goes on
        "faces": _State(v.copy(), r[:count].copy(), status[:count].copy(), residual),
    }
    active = list(METHODS)
    budget = FIRST_BUDGET
    round_ = 0
    newton_resumes = 0
    resumes = 0  # the round-robin's, for the stage's re-entry
    while iterations < cap and active:
        # newton makes NEWTON_AHEAD more resumes right after its first, in round 0 (module doc)
        for name in [m for m in active for _ in range(1 + NEWTON_AHEAD if m == "newton" and round_ == 0 else 1)]:
            state = states[name]
            if name == "newton" and newton_resumes > NEWTON_LAST_ROUND:
                if name in active:
                    active.remove(name)
                continue
            if name == "newton":  # its k-th resume gets the budget of round k, ahead or not
                units = min(FIRST_BUDGET * 2**newton_resumes * NEWTON_BUDGET, cap - iterations)
                newton_resumes += 1
            else:
                units = min(budget, cap - iterations)
            if units <= 0:
                break
            done = _resume(name, state, contact_body, pack, count, mu, tolerance, units, v_free, cap - iterations)
            iterations += done
            if state.residual <= tolerance:
                _adopt(state, v, r, status, count)
                return iterations, state.residual
            resumes += 1
            if stage is not None and resumes == BODIES_REENTER:
                iterations += _reenter(
                    stage, run, min(stage_left, cap - iterations), contact_body, pack, count, mu, tolerance
                )
                if stage.residual <= tolerance:
                    _adopt(stage, v, r, status, count)
                    return iterations, stage.residual
            # The drop rules (module doc). Not newton's: its sweeps' stall or residual says little of its
            # Newton iterate, which goes on at the next resume; it leaves after NEWTON_LAST_ROUND only.
            #   done < units: stalled inside its budget, its own stall window says it will not get there
            #   residual ≥ low: a whole budget, doubled, without a new low: it cycles
            if name != "newton" and (done < units or state.residual >= state.low):
                active.remove(name)
            state.low = min(state.low, state.residual)
        budget *= 2
        round_ += 1
    if stage is not None and resumes < BODIES_REENTER:  # the round-robin ended first: the stage's turn
        iterations += _reenter(stage, run, min(stage_left, cap - iterations), contact_body, pack, count, mu, tolerance)
        if stage.residual <= tolerance:
            _adopt(stage, v, r, status, count)
            return iterations, stage.residual
    # The round-robin's lowest, never the stage's after a hand-over: its iterate cycles (on the 32-course wall's
    # ensemble, adopting it when lowest put runs on other trajectories with 13 unconverged steps against 7)
    best = min((s for s in states.values() if s.v is not None), key=lambda s: s.residual)
    _adopt(best, v, r, status, count)
    return iterations, best.residual


def _reenter(stage, run, units, contact_body, pack, count, mu, tolerance) -> int:
    # The stage goes on from where its hand-over stopped it, as one long run would (bodies.Stage), for the
    # units it had left, without the hand-over rule (it already handed over) and with its stall window.
    done, stage.residual = bodies.body_order_sweeps(
        contact_body, pack, count, mu, tolerance, units, stage.v, stage.r, stage.status, BODIES_STALL, stage=run
    )
    return done


def _resume(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit) -> int:
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
            newton.NEWTON_SHARES[min(state.resumes, len(newton.NEWTON_SHARES) - 1)],
        )
        state.resumes += 1
        return done
    if name == "faces":
        done, state.residual = faces.face_sweeps(
            contact_body, pack, count, mu, tolerance, units, state.v, state.r, state.status
        )
        return done
    state.v = v_free.copy()
    accelerate = name != "alternating"
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
        name != "momentum",
    )
    return done


def _adopt(state, v, r, status, count) -> None:
    v[:] = state.v
    r[:count] = state.r
    status[:count] = state.status
