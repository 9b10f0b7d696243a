"""The stalled-step methods (masonrycli.engine.stalled), forced on small problems whose answer is known:
plain Gauss–Seidel's velocities (unique) and the contact law."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np

from masonrycli.engine import bodies, dispatch, faces, stalled
from masonrycli.engine.tuning import TUNING
from tests.test_engine_nlgs import _stack_problem

ROBIN = replace(TUNING, bodies_units=0)
"""Most tests here are of the round-robin: momentum in body order ahead of it is off (bodies_units = 0) unless a
test turns it back on."""


def _solve(problem, solver, tolerance, cap=100000, tuning=ROBIN):
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = problem
    count = body.shape[0]
    model = SimpleNamespace(friction=mu, tolerance=tolerance, max_iterations=cap, solver=solver)
    v, r, status = v0.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    its, res = dispatch.solve(body, pack, count, model, v, r, status, tuning)
    return v, r, its, res


def test_a_stalled_accelerated_solve_ends_converged_on_gauss_seidel_velocities():
    # A momentum window of 1 sweep sends the step to stalled.py at once, and first budgets of 1 unit make it
    # go round the four methods many times (budgets 1, 2, 4, …): every resume must carry its method's
    # iterate on, and the step must end converged with v the velocity of its impulses.
    problem = _stack_problem(6)
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = problem
    v_gs, _, _, _ = _solve(problem, "nlgs", 1e-10)
    v, r, its, res = _solve(problem, "nlgs-accel", 1e-10, tuning=replace(ROBIN, first_stall=1, first_budget=1))
    assert res <= 1e-10
    np.testing.assert_allclose(v, v_gs, atol=1e-8)
    np.testing.assert_allclose(v.ravel(), v0.ravel() + m_inv @ h @ r.ravel(), atol=1e-12)
    assert its > 1


def test_each_method_alone_finishes_the_step():
    # The round-robin with one method at a time: each converges to the same velocities from its own start.
    problem = _stack_problem(6)
    v_gs, _, _, _ = _solve(problem, "nlgs", 1e-10)
    # alone, newton must go on past its one round
    quick = replace(ROBIN, first_stall=1, first_budget=3, newton_last_round=99)
    for method in TUNING.methods:
        v, r, its, res = _solve(problem, "nlgs-accel", 1e-10, tuning=replace(quick, methods=(method,)))
        assert res <= 1e-10, method
        np.testing.assert_allclose(v, v_gs, atol=1e-8, err_msg=method)


def test_at_the_cap_the_lowest_residual_is_kept_and_the_step_counts_unconverged():
    problem = _stack_problem(10)
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = problem
    cap = 40
    v, r, its, res = _solve(problem, "nlgs-accel", 1e-14, cap=cap, tuning=replace(ROBIN, first_stall=1, first_budget=2))
    # faces count a face sweep as up to INNER_ROUNDS units (each point visited at most that many times) and
    # may pass the cap by their last sweep (with the lane sweeps' first stage: 4 units given, 8 done)
    assert cap <= its <= cap + faces.INNER_ROUNDS and res > 1e-14
    np.testing.assert_allclose(v.ravel(), v0.ravel() + m_inv @ h @ r.ravel(), atol=1e-12)
    # the state kept is one of the methods' iterates after a sweep: impulses inside the Coulomb cone
    assert (r[:, 1] >= 0).all() and (np.abs(r[:, 0]) <= mu * r[:, 1] + 1e-15).all()


def test_a_method_that_ends_a_round_no_lower_than_before_is_dropped(monkeypatch):
    # The round-robin alone, with scripted methods: "turning" improves every round, "newton" gets twice the
    # budget in the first round only, "alternating" ends its second round where it ended its first (it
    # cycles), "faces" stalls inside its first budget. Only "turning" goes on, with doubling budgets, until
    # it meets the tolerance; every unit is counted.
    script = {
        "turning": [1e-3, 1e-4, 1e-5, 1e-7],
        "newton": [1e-4, 1e-9],
        "alternating": [1e-3, 1e-3, 1e-9],
        "faces": [1e-3],
    }
    calls = []

    def scripted(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit, tuning):
        calls.append((name, units))
        state.v, state.residual = v_free + len(calls), script[name].pop(0)
        return units // 2 if name == "faces" else units

    monkeypatch.setattr(stalled, "_resume", scripted)
    tuning = replace(
        ROBIN,
        methods=("turning", "newton", "alternating", "faces"),
        newton_budget=2,
        newton_last_round=0,
        first_budget=10,
    )
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    its, res = stalled.continue_stalled(
        None, None, count, 0.5, 1e-6, 10**6, v, r, status, np.zeros((2, 3)), r, 7, 1e-2, tuning
    )
    assert calls == [
        ("turning", 10),
        ("newton", 20),
        ("alternating", 10),
        ("faces", 10),
        ("turning", 20),
        ("alternating", 20),
        ("turning", 40),
        ("turning", 80),
    ]
    assert res == 1e-7 and its == 7 + 10 + 20 + 10 + 5 + 20 + 20 + 40 + 80
    assert (v == 8).all()  # the state of the method that met the tolerance (set at the 8th call)


def test_newton_stopping_inside_its_budget_is_resumed_in_the_next_round(monkeypatch):
    # Scripted: newton's sweeps stall inside its first budget (half of it done) without meeting the
    # tolerance; unlike the other methods it is not dropped for that, and its second resume finishes.
    script = {"newton": [1e-4, 1e-7], "turning": [1e-3, 1e-3], "faces": [1e-3]}
    calls = []

    def scripted(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit, tuning):
        calls.append((name, units))
        state.v, state.residual = v_free + len(calls), script[name].pop(0)
        return units // 2 if name in ("newton", "faces") else units

    monkeypatch.setattr(stalled, "_resume", scripted)
    tuning = replace(
        ROBIN,
        methods=("newton", "turning", "faces"),
        newton_budget=2,
        newton_last_round=1,
        newton_ahead=0,
        first_budget=10,
    )
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    its, res = stalled.continue_stalled(
        None, None, count, 0.5, 1e-6, 10**6, v, r, status, np.zeros((2, 3)), r, 7, 1e-2, tuning
    )
    assert calls == [("newton", 20), ("turning", 10), ("faces", 10), ("newton", 40)]
    assert res == 1e-7 and its == 7 + 10 + 10 + 5 + 20
    assert (v == 4).all()


def test_newton_ahead_makes_its_second_resume_before_the_others_start(monkeypatch):
    # Scripted: with newton_ahead = 1 newton's two resumes (budgets of rounds 0 and 1) come first; it then
    # leaves (newton_last_round = 1: two resumes), and the others go round from their first budget.
    script = {"newton": [1e-4, 1e-4], "turning": [1e-3, 1e-4, 1e-7], "faces": [1e-3]}
    calls = []

    def scripted(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit, tuning):
        calls.append((name, units))
        state.v, state.residual = v_free + len(calls), script[name].pop(0)
        return units // 2 if name == "faces" else units

    monkeypatch.setattr(stalled, "_resume", scripted)
    tuning = replace(
        ROBIN,
        methods=("newton", "turning", "faces"),
        newton_budget=2,
        newton_last_round=1,
        newton_ahead=1,
        first_budget=10,
    )
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    its, res = stalled.continue_stalled(
        None, None, count, 0.5, 1e-6, 10**6, v, r, status, np.zeros((2, 3)), r, 7, 1e-2, tuning
    )
    assert calls == [("newton", 20), ("newton", 40), ("turning", 10), ("faces", 10), ("turning", 20), ("turning", 40)]
    assert res == 1e-7 and its == 7 + 20 + 40 + 10 + 5 + 20 + 40
    assert (v == 6).all()


def test_momentum_in_body_order_goes_first_and_finishes_the_step(monkeypatch):
    problem = _stack_problem(6)
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = problem
    v_gs, _, _, _ = _solve(problem, "nlgs", 1e-10)

    def never(*args):
        raise AssertionError("the round-robin ran")

    monkeypatch.setattr(stalled, "_resume", never)
    tuning = replace(ROBIN, first_stall=1, bodies_units=16_000)
    v, r, its, res = _solve(problem, "nlgs-accel", 1e-10, tuning=tuning)
    assert res <= 1e-10
    np.testing.assert_allclose(v, v_gs, atol=1e-8)
    np.testing.assert_allclose(v.ravel(), v0.ravel() + m_inv @ h @ r.ravel(), atol=1e-12)


def test_a_body_order_solve_that_misses_hands_over_with_its_units_counted(monkeypatch):
    calls = []

    def scripted(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit, tuning):
        calls.append((name, units))
        state.v, state.residual = v_free + len(calls), 1e-7
        return units

    monkeypatch.setattr(bodies, "body_order_sweeps", lambda *args, **kw: (37, 1e-3))
    monkeypatch.setattr(stalled, "_resume", scripted)
    tuning = replace(ROBIN, bodies_units=50, methods=("turning",), first_budget=10)
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    its, res = stalled.continue_stalled(
        None, None, count, 0.5, 1e-6, 10**6, v, r, status, np.zeros((2, 3)), r, 7, 1e-2, tuning
    )
    assert calls == [("turning", 10)] and its == 7 + 37 + 10 and res == 1e-7


def test_the_body_order_stage_gets_the_hand_over_rule(monkeypatch):
    # the tuning's numbers reach the stage's kernel (window, level, cycling windows; bodies module).
    seen = []
    monkeypatch.setattr(bodies, "body_order_sweeps", lambda *args, **kw: seen.append(args[5:]) or (37, 1e-7))
    tuning = replace(ROBIN, bodies_units=50, bodies_window=3, bodies_level=2.5, bodies_cycling=2)
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    its, res = stalled.continue_stalled(
        None, None, count, 0.5, 1e-6, 10**6, v, r, status, np.zeros((2, 3)), r, 7, 1e-2, tuning
    )
    assert its == 7 + 37 and res == 1e-7
    assert [s[:1] + s[4:] for s in seen] == [(50, TUNING.bodies_stall, 3, 2.5, 2)]


def _scripted_stage(monkeypatch, reason, converges_at_reentry):
    # The stage's kernel stood in for: its first call stops for `reason` at 37 units; a later call (the
    # re-entry) gets the run the first left and converges or not. Returns the list of its calls.
    calls = []

    def stage(*args, stage=None, **kw):
        calls.append(("stage", args[5], stage))
        if len(calls) == 1:
            stage.carry[bodies.C_REASON] = reason
            return 37, 1e-3
        args[6][:] = 42.0  # v: the stage's iterate, adopted if it converges
        return 20, 1e-7 if converges_at_reentry else 2e-3

    monkeypatch.setattr(bodies, "body_order_sweeps", stage)
    return calls


def _robin_that_never_converges(monkeypatch, calls):
    def scripted(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit, tuning):
        calls.append((name, units))
        state.v, state.residual = v_free + len(calls), 1e-3 + 1e-6 * len(calls)
        return units

    monkeypatch.setattr(stalled, "_resume", scripted)


ROBIN_AFTER_STAGE = replace(ROBIN, methods=("newton", "turning"), first_budget=10, bodies_units=50, bodies_cycling=4)
"""The tuning of the re-entry tests: a stage of 50 units ahead of a round-robin of newton and turning."""


def _continue(cap=10**6, bodies_reenter=2):
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    tuning = replace(ROBIN_AFTER_STAGE, bodies_reenter=bodies_reenter)
    its, res = stalled.continue_stalled(
        None, None, count, 0.5, 1e-6, cap, v, r, status, np.zeros((2, 3)), r, 7, 1e-2, tuning
    )
    return its, res, v


def test_a_stage_that_handed_over_re_enters_after_newton_for_the_rest_of_its_units(monkeypatch):
    # module doc, "Re-entry": after bodies_reenter = 2 round-robin resumes (newton's two, in round 0) the
    # stage goes on from its own run for the units it had left (50 - 37), and its converged iterate is kept.
    calls = _scripted_stage(monkeypatch, bodies.STOP_CYCLING, True)
    _robin_that_never_converges(monkeypatch, calls)
    its, res, v = _continue(bodies_reenter=2)
    assert [c[:2] for c in calls] == [("stage", 50), ("newton", 20), ("newton", 40), ("stage", 13)]
    assert calls[3][2] is calls[0][2]  # the same run goes on
    assert its == 7 + 37 + 20 + 40 + 20 and res == 1e-7 and (v == 42.0).all()


def test_a_stage_re_enters_once_and_only_after_the_hand_over_rule(monkeypatch):
    # Not converged at its re-entry: the round-robin goes on and the stage does not come back. A stage that
    # stopped for its stall window or budget does not re-enter at all; nor with bodies_reenter = 0.
    for reason, reenter, expect in [
        (bodies.STOP_CYCLING, 2, 1),
        (bodies.STOP_STALL, 2, 0),
        (bodies.STOP_BUDGET, 2, 0),
        (bodies.STOP_CYCLING, 0, 0),
    ]:
        calls = _scripted_stage(monkeypatch, reason, False)
        _robin_that_never_converges(monkeypatch, calls)
        _continue(cap=7 + 37 + 400, bodies_reenter=reenter)
        assert sum(c[0] == "stage" for c in calls) == 1 + expect, (reason, reenter)
        assert [c[0] for c in calls][-1] != "stage"  # the round-robin had the last word, to its cap


def test_a_stage_re_enters_when_the_round_robin_ends_before_its_turn(monkeypatch):
    # All methods dropped (newton after its two resumes, turning when a round ends no lower than the last)
    # before the bodies_reenter-th resume: the stage still gets the units it had left.
    calls = _scripted_stage(monkeypatch, bodies.STOP_CYCLING, True)
    _robin_that_never_converges(monkeypatch, calls)
    its, res, v = _continue(bodies_reenter=99)
    assert [c[:2] for c in calls] == [
        ("stage", 50),
        ("newton", 20),
        ("newton", 40),
        ("turning", 10),
        ("turning", 20),
        ("stage", 13),
    ]
    assert its == 7 + 37 + 20 + 40 + 10 + 20 + 20 and res == 1e-7 and (v == 42.0).all()
