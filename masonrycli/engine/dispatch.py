"""The one entry point of a step's contact solve: which sweeps solve it, and where a stalled step goes on.

    solve(model, tuning):
        "nlgs": plain sweeps in interleaved order (interleaved.sweeps, PLAIN) to the tolerance, the cap or
            their stall window (nlgs.PLAIN_STALL); a stalled step goes on by faces (faces.py); tolerance 0:
            the solver's sweeps (the accelerated ones: first_stage), exactly the cap
        "nlgs-accel32": first stage lane_sweeps32.first_stage (float32 lane sweeps, then float64 ones)
        "nlgs-accel":   first stage :func:`first_stage` (the float64 lane sweeps; the 4-run scalar momentum
                        sweep with Tuning.lanes off), to the tolerance, the cap or Tuning.first_stall sweeps
                        without a new low (momentum.stall_near near the tolerance)
        an accelerated first stage that stalled: stalled.continue_stalled

Acceleration (solvers "nlgs-accel32", the default, and "nlgs-accel"; "nlgs" is the plain sweep): the
same sweep started from a Nesterov extrapolation of the last two sweeps (:mod:`masonrycli.engine.momentum`),
its first stage visiting the contacts in 8 interleaved runs, 8 contacts at once in vectors
(:mod:`masonrycli.engine.lane_sweeps`; ``Tuning.lanes``). A stalled accelerated solve goes on by the methods of :mod:`masonrycli.engine.stalled` (momentum turning
its direction at restarts, alternating-direction sweeps, momentum resumed, faces, in turn with doubling
budgets). Its iterations count accelerated sweeps (each ~1.1–1.6× the time of a plain one) plus the later
methods' sweep units.

The numbers of the first stage and of the stalled-step methods come in one frozen value
(:class:`masonrycli.engine.tuning.Tuning`) from the Solver; the sweeps themselves are :mod:`masonrycli.engine.nlgs`'s
primitives.
"""

from __future__ import annotations

from masonrycli.engine import faces, interleaved, lane_sweeps, lane_sweeps32, momentum, stalled
from masonrycli.engine.tuning import TUNING

ACCELERATED = ("nlgs-accel", "nlgs-accel32")
"""The solvers whose first stage is momentum's and whose stalled steps go to stalled.py."""


def solve(contact_body, pack, count, model, v, r, status, tuning=TUNING) -> tuple[int, float]:
    """Solve one step's contact problem by NLGS: the engine's one entry point for a contact solver.

    In: ``contact_body`` (C, 2) bodies a < b, ``pack`` (C, PACK_WIDTH) from nlgs.prepare_contacts,
    ``model`` (friction, tolerance m/s, max_iterations, solver "nlgs-accel", "nlgs-accel32" or "nlgs", and
    block_depth for "nlgs-accel32"'s stall window, momentum.stall_near). ``v`` (B, 3): v_free
    in, v_n+1 out. ``r`` (C, 2): starting impulses in, (r_t, r_n) N·s out. ``status`` (C,) int8 out
    (:class:`~masonrycli.engine.contact.ContactStatus`). ``tuning``: the first stage's and the stalled-step
    methods' numbers (:class:`~masonrycli.engine.tuning.Tuning`; the Solver's, the shipped ones by default).

    Returns (iterations, residual): sweeps done, and the last sweep's RMS contact-law violation in m/s
    (nlgs module doc). Another method plugged in beside this one keeps the signature, reports its work in
    sweep equivalents (contact visits / C) and the same residual, so that the history and the
    unconverged count mean the same thing. A plain ("nlgs") solve that stalls continues by faces (nlgs module
    doc, "Stagnation"); its iterations are then the point sweeps plus the faces' sweep units. With an
    accelerated solver ("nlgs-accel32", "nlgs-accel") a stalled solve goes on by the methods of
    :mod:`masonrycli.engine.stalled`, and its iterations add up all of them."""
    mu, tolerance, cap = model.friction, model.tolerance, model.max_iterations
    accelerated = model.solver in ACCELERATED
    if not accelerated or tolerance <= 0.0:
        if accelerated:  # tolerance 0: the first stage's sweeps, exactly the cap (no stall rule at tolerance 0)
            iterations, residual = first_stage(
                contact_body, pack, count, mu, tolerance, cap, v, r, status, tuning.first_stall, tuning.lanes,
                tuning.lane_growth,
            )  # fmt: skip
        else:
            iterations, residual = interleaved.sweeps(
                contact_body, pack, count, mu, tolerance, cap, v, r, status, interleaved.PLAIN
            )
        return _faces_if_stalled(contact_body, pack, count, mu, tolerance, cap, v, r, status, iterations, residual)
    # Accelerated: momentum (the lane sweeps, Tuning.lanes) until its stall window; a stalled step goes on by
    # the methods of stalled.py.
    v_free, r_warm = v.copy(), r[:count].copy()
    if model.solver == "nlgs-accel32" and tuning.lanes:  # the one place float32 is chosen
        iterations, residual = lane_sweeps32.first_stage(
            contact_body, pack, count, mu, tolerance, cap, v, r, status, tuning.first_stall,
            momentum.stall_near(model, tuning), tuning.lane_growth,
        )  # fmt: skip
    else:
        iterations, residual = first_stage(
            contact_body, pack, count, mu, tolerance, cap, v, r, status, tuning.first_stall, tuning.lanes,
            tuning.lane_growth,
        )  # fmt: skip
    if residual <= tolerance or iterations >= cap:
        return iterations, residual
    return stalled.continue_stalled(
        contact_body, pack, count, mu, tolerance, cap, v, r, status, v_free, r_warm, iterations, residual, tuning
    )


def first_stage(
    contact_body, pack, count, mu, tolerance, max_iterations, v, r, status, stall, lanes=True,
    growth=TUNING.lane_growth,
):  # fmt: skip
    """The float64 first stage of an accelerated solve: momentum from the warm start (``v`` enters as v_free)
    until ``tolerance``, ``max_iterations`` or ``stall`` sweeps without a new lowest residual; by the lane
    sweeps (lane_sweeps._lane_sweeps, restarting at ``growth``: Tuning.lane_growth) or, ``lanes`` False (the
    lab's Tuning.lanes), by the 4-run scalar momentum sweep (interleaved.sweeps, momentum.RESTART_GROWTH). The
    benchmarks that capture the first stage hook this function (bench_kernel, bench_idle). Returns
    (iterations, residual)."""
    if lanes:  # no near-tolerance window here (near_level 0: the same stops as with it omitted)
        return lane_sweeps._lane_sweeps(
            contact_body, pack, count, mu, tolerance, max_iterations, v, r, status, stall, 0.0, 0, growth
        )
    return interleaved.sweeps(
        contact_body, pack, count, mu, tolerance, max_iterations, v, r, status, interleaved.MOMENTUM, stall
    )


def _faces_if_stalled(contact_body, pack, count, mu, tolerance, cap, v, r, status, iterations, residual):
    if tolerance > 0.0 and residual > tolerance and iterations < cap:  # stalled, not capped
        units, residual = faces.face_sweeps(contact_body, pack, count, mu, tolerance, cap - iterations, v, r, status)
        iterations += units
    return iterations, residual
