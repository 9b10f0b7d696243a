"""The contact solve's tuning: how a step's first stage runs and how a stalled step is finished.

One frozen value, :data:`TUNING` (the shipped numbers), handed down from the :class:`~masonrycli.engine.solver.Solver`
to ``dispatch.solve`` and on to :func:`masonrycli.engine.stalled.continue_stalled`; nothing in the engine reads a
module global for these. The solver lab and the tests try other values by passing another instance
(``dataclasses.replace(TUNING, bodies_cycling=4)``), never by patching a module. Each field says what it counts,
in which units, and the benchmarks/JOURNAL.md section its value came from; the methods themselves are described
in :mod:`masonrycli.engine.momentum` (the first stage's stall window), :mod:`masonrycli.engine.stalled` (the
body-order stage and the round-robin) and :mod:`masonrycli.engine.newton`.

The constants a kernel compiles in (the plain sweep's stall window, the interleaving, the lane counts) are not
here: they are module constants that nothing sets, and a value here is always a kernel argument.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Tuning:
    """The first stage's and the stalled-step methods' numbers (module doc); the defaults are the shipped ones."""

    lanes: bool = True
    """The accelerated solve's first stage by :mod:`masonrycli.engine.lane_sweeps` (8 runs, 8 contacts visited
    at once in vectors) and, for "nlgs-accel32", its float32 start; False: by the scalar momentum sweep in
    nlgs.INTERLEAVE runs (interleaved._accelerated), the default until the lane sweeps replaced it
    (benchmarks/JOURNAL.md, explicit vectors addendum)."""

    lane_growth: float = 1.1
    """Adaptive restart of the lane sweeps (the first stage with ``lanes``, float32 and float64): a sweep whose
    residual exceeds the last one's by more than this factor drops the momentum (β = 0; momentum module doc).
    The scalar momentum sweeps and the body-order stage compile in momentum.RESTART_GROWTH, this default
    (1.3 or more diverged on the 248-block wall, 1.05–1.2 all converged: "nlgs-accel: Gauss–Seidel with
    Nesterov momentum"). A kernel argument, so the lab tries other values in process ("Issue 10's aim on a
    Zen 4 CPU")."""

    first_stall: int = 200
    """Accelerated sweeps without a new lowest residual after which the first stage hands the step to
    stalled.py (momentum module doc, "Stall window"): 200 rather than 500, mean sweep units a step 0.614× on the
    32-course wall's ensembles ("Momentum's stall window and the round-robin's order")."""

    bodies_units: int = 16_000
    """Sweep units that momentum in body order (:mod:`masonrycli.engine.bodies`) gets alone, before the
    round-robin; 0: no body-order stage ("New methods on hard steps")."""
    bodies_stall: int = 8000
    """The body-order stage's sweeps without a new lowest residual after which the round-robin takes over
    ("The body-order stage on the 248-block wall")."""
    bodies_window: int = 500
    """Sweeps over which the hand-over rule takes the stage's residual level (stalled module doc, "Hand-over")."""
    bodies_level: float = 1.8
    """A window whose level (geometric mean of its residuals) is above this × the stage's lowest residual
    cycles ("The hand-over, again")."""
    bodies_cycling: int = 8
    """Cycling windows in a row after which the stage hands over to the round-robin (0: never, and no
    re-entry; 8: not before sweep 4000; "The hand-over, again")."""
    bodies_far: float = 2.0
    """× the tolerance: a stage whose lowest residual is still above this hands over after
    ``bodies_cycling_far`` cycling windows in a row instead of ``bodies_cycling`` (stalled module doc, "Sooner";
    "Where the dear steps of the benchmark's wall-248 run go")."""
    bodies_strong: float = 3.0
    """So does a stage whose windows' level is above this × its lowest residual, ``bodies_cycling_far`` windows
    in a row ("Sooner")."""
    bodies_cycling_far: int = 2
    """Windows in a row of the sooner hand-over (0: off; 2: not before sweep 1000; "Sooner")."""
    bodies_reenter: int = 2
    """After a hand-over, the round-robin's resumes (in its order, newton's ahead counted) after which the stage
    goes on from where it stopped, once, for the rest of its ``bodies_units``; it does also if the round-robin
    ends first. 0: never (stalled module doc, "Re-entry"; "A way back to the stage")."""

    first_budget: int = 2000
    """Sweep units each round-robin method gets in the first round; doubled every round ("Stalled steps: four
    methods in turn")."""
    methods: tuple[str, ...] = ("newton", "turning", "alternating", "momentum", "faces")
    """The order in which a round visits the methods (stalled module doc, "Why"): the one that finishes most
    stalled steps first ("Momentum's stall window and the round-robin's order")."""
    newton_budget: int = 2
    """newton's budget in a round, in units of the others' ("Alart–Curnier in the engine")."""
    newton_last_round: int = 1
    """The last resume (0-based) newton makes, its k-th with the budget of round k: it finishes most steps it
    finishes in its first two budgets ("Alart–Curnier in the engine")."""
    newton_ahead: int = 1
    """Further resumes newton makes right after its first, in round 0, before the other methods start
    (stalled module doc, "Newton ahead"; "Hard steps: the costliest steps")."""
    newton_shares: tuple[float, ...] = (0.15, 0.3)
    """Share of a newton resume's budget spent on Newton steps: in its first resume (10 steps of the first
    2 × 2000 units), then in every later one (40 of 8000: a step that gets there needs more of them); the rest
    goes to sweeps from the Newton iterate (newton module doc; "Alart–Curnier in the engine")."""


TUNING = Tuning()
"""The shipped tuning: what every run uses."""
