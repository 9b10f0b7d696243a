"""The stalled-step methods (masonrycli.engine.stalled), forced on small problems whose answer is known:
plain Gauss–Seidel's velocities (unique) and the contact law."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from masonrycli.engine import bodies, faces, momentum, nlgs, stalled
from tests.test_engine_nlgs import _stack_problem


@pytest.fixture(autouse=True)
def _round_robin_only(monkeypatch):
    # Most tests here are of the round-robin: momentum in body order ahead of it is off (BODIES_UNITS = 0)
    # unless a test turns it back on.
    monkeypatch.setattr(stalled, "BODIES_UNITS", 0)


def _solve(problem, solver, tolerance, cap=100000):
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = problem
    count = body.shape[0]
    model = SimpleNamespace(friction=mu, tolerance=tolerance, max_iterations=cap, solver=solver)
    v, r, status = v0.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    its, res = nlgs.solve(body, pack, count, model, v, r, status)
    return v, r, its, res


def test_a_stalled_accelerated_solve_ends_converged_on_gauss_seidel_velocities(monkeypatch):
    # A momentum window of 1 sweep sends the step to stalled.py at once, and first budgets of 1 unit make it
    # go round the four methods many times (budgets 1, 2, 4, …): every resume must carry its method's
    # iterate on, and the step must end converged with v the velocity of its impulses.
    problem = _stack_problem(6)
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = problem
    v_gs, _, _, _ = _solve(problem, "nlgs", 1e-10)
    monkeypatch.setattr(momentum, "STALL_SWEEPS", 1)
    monkeypatch.setattr(stalled, "FIRST_BUDGET", 1)
    v, r, its, res = _solve(problem, "nlgs-accel", 1e-10)
    assert res <= 1e-10
    np.testing.assert_allclose(v, v_gs, atol=1e-8)
    np.testing.assert_allclose(v.ravel(), v0.ravel() + m_inv @ h @ r.ravel(), atol=1e-12)
    assert its > 1


def test_each_method_alone_finishes_the_step(monkeypatch):
    # The round-robin with one method at a time: each converges to the same velocities from its own start.
    problem = _stack_problem(6)
    v_gs, _, _, _ = _solve(problem, "nlgs", 1e-10)
    monkeypatch.setattr(momentum, "STALL_SWEEPS", 1)
    monkeypatch.setattr(stalled, "FIRST_BUDGET", 3)
    monkeypatch.setattr(stalled, "NEWTON_LAST_ROUND", 99)  # alone, newton must go on past its one round
    for method in stalled.METHODS:
        monkeypatch.setattr(stalled, "METHODS", (method,))
        v, r, its, res = _solve(problem, "nlgs-accel", 1e-10)
        assert res <= 1e-10, method
        np.testing.assert_allclose(v, v_gs, atol=1e-8, err_msg=method)


def test_at_the_cap_the_lowest_residual_is_kept_and_the_step_counts_unconverged(monkeypatch):
    problem = _stack_problem(10)
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = problem
    monkeypatch.setattr(momentum, "STALL_SWEEPS", 1)
    monkeypatch.setattr(stalled, "FIRST_BUDGET", 2)
    cap = 40
    v, r, its, res = _solve(problem, "nlgs-accel", 1e-14, cap=cap)
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

    def scripted(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit):
        calls.append((name, units))
        state.v, state.residual = v_free + len(calls), script[name].pop(0)
        return units // 2 if name == "faces" else units

    monkeypatch.setattr(stalled, "_resume", scripted)
    monkeypatch.setattr(stalled, "METHODS", ("turning", "newton", "alternating", "faces"))
    monkeypatch.setattr(stalled, "NEWTON_BUDGET", 2)
    monkeypatch.setattr(stalled, "NEWTON_LAST_ROUND", 0)
    monkeypatch.setattr(stalled, "FIRST_BUDGET", 10)
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    its, res = stalled.continue_stalled(None, None, count, 0.5, 1e-6, 10**6, v, r, status, np.zeros((2, 3)), r, 7, 1e-2)
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

    def scripted(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit):
        calls.append((name, units))
        state.v, state.residual = v_free + len(calls), script[name].pop(0)
        return units // 2 if name in ("newton", "faces") else units

    monkeypatch.setattr(stalled, "_resume", scripted)
    monkeypatch.setattr(stalled, "METHODS", ("newton", "turning", "faces"))
    monkeypatch.setattr(stalled, "NEWTON_BUDGET", 2)
    monkeypatch.setattr(stalled, "NEWTON_LAST_ROUND", 1)
    monkeypatch.setattr(stalled, "NEWTON_AHEAD", 0)
    monkeypatch.setattr(stalled, "FIRST_BUDGET", 10)
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    its, res = stalled.continue_stalled(None, None, count, 0.5, 1e-6, 10**6, v, r, status, np.zeros((2, 3)), r, 7, 1e-2)
    assert calls == [("newton", 20), ("turning", 10), ("faces", 10), ("newton", 40)]
    assert res == 1e-7 and its == 7 + 10 + 10 + 5 + 20
    assert (v == 4).all()


def test_newton_ahead_makes_its_second_resume_before_the_others_start(monkeypatch):
    # Scripted: with NEWTON_AHEAD = 1 newton's two resumes (budgets of rounds 0 and 1) come first; it then
    # leaves (NEWTON_LAST_ROUND = 1: two resumes), and the others go round from their first budget.
    script = {"newton": [1e-4, 1e-4], "turning": [1e-3, 1e-4, 1e-7], "faces": [1e-3]}
    calls = []

    def scripted(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit):
        calls.append((name, units))
        state.v, state.residual = v_free + len(calls), script[name].pop(0)
        return units // 2 if name == "faces" else units

    monkeypatch.setattr(stalled, "_resume", scripted)
    monkeypatch.setattr(stalled, "METHODS", ("newton", "turning", "faces"))
    monkeypatch.setattr(stalled, "NEWTON_BUDGET", 2)
    monkeypatch.setattr(stalled, "NEWTON_LAST_ROUND", 1)
    monkeypatch.setattr(stalled, "NEWTON_AHEAD", 1)
    monkeypatch.setattr(stalled, "FIRST_BUDGET", 10)
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    its, res = stalled.continue_stalled(None, None, count, 0.5, 1e-6, 10**6, v, r, status, np.zeros((2, 3)), r, 7, 1e-2)
    assert calls == [("newton", 20), ("newton", 40), ("turning", 10), ("faces", 10), ("turning", 20), ("turning", 40)]
    assert res == 1e-7 and its == 7 + 20 + 40 + 10 + 5 + 20 + 40
    assert (v == 6).all()


def test_momentum_in_body_order_goes_first_and_finishes_the_step(monkeypatch):
    problem = _stack_problem(6)
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = problem
    v_gs, _, _, _ = _solve(problem, "nlgs", 1e-10)
    monkeypatch.setattr(momentum, "STALL_SWEEPS", 1)
    monkeypatch.setattr(stalled, "BODIES_UNITS", 16_000)

    def never(*args):
        raise AssertionError("the round-robin ran")

    monkeypatch.setattr(stalled, "_resume", never)
    v, r, its, res = _solve(problem, "nlgs-accel", 1e-10)
    assert res <= 1e-10
    np.testing.assert_allclose(v, v_gs, atol=1e-8)
    np.testing.assert_allclose(v.ravel(), v0.ravel() + m_inv @ h @ r.ravel(), atol=1e-12)


def test_a_body_order_solve_that_misses_hands_over_with_its_units_counted(monkeypatch):
    calls = []

    def scripted(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit):
        calls.append((name, units))
        state.v, state.residual = v_free + len(calls), 1e-7
        return units

    monkeypatch.setattr(stalled, "BODIES_UNITS", 50)
    monkeypatch.setattr(bodies, "body_order_sweeps", lambda *args, **kw: (37, 1e-3))
    monkeypatch.setattr(stalled, "_resume", scripted)
    monkeypatch.setattr(stalled, "METHODS", ("turning",))
    monkeypatch.setattr(stalled, "FIRST_BUDGET", 10)
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    its, res = stalled.continue_stalled(None, None, count, 0.5, 1e-6, 10**6, v, r, status, np.zeros((2, 3)), r, 7, 1e-2)
    assert calls == [("turning", 10)] and its == 7 + 37 + 10 and res == 1e-7


def test_the_body_order_stage_gets_the_hand_over_rule(monkeypatch):
    # stalled.py's constants reach the stage's kernel (window, level, cycling windows; bodies module).
    seen = []
    monkeypatch.setattr(stalled, "BODIES_UNITS", 50)
    monkeypatch.setattr(stalled, "BODIES_WINDOW", 3)
    monkeypatch.setattr(stalled, "BODIES_LEVEL", 2.5)
    monkeypatch.setattr(stalled, "BODIES_CYCLING", 2)
    monkeypatch.setattr(bodies, "body_order_sweeps", lambda *args, **kw: seen.append(args[5:]) or (37, 1e-7))
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    its, res = stalled.continue_stalled(None, None, count, 0.5, 1e-6, 10**6, v, r, status, np.zeros((2, 3)), r, 7, 1e-2)
    assert its == 7 + 37 and res == 1e-7
    assert [s[:1] + s[4:] for s in seen] == [(50, stalled.BODIES_STALL, 3, 2.5, 2)]


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
    def scripted(name, state, contact_body, pack, count, mu, tolerance, units, v_free, limit):
        calls.append((name, units))
        state.v, state.residual = v_free + len(calls), 1e-3 + 1e-6 * len(calls)
        return units

    monkeypatch.setattr(stalled, "_resume", scripted)
    monkeypatch.setattr(stalled, "METHODS", ("newton", "turning"))
    monkeypatch.setattr(stalled, "FIRST_BUDGET", 10)
    monkeypatch.setattr(stalled, "BODIES_UNITS", 50)
    monkeypatch.setattr(stalled, "BODIES_CYCLING", 4)


def _continue(cap=10**6):
    count = 2
    v, r, status = np.zeros((2, 3)), np.zeros((count, 2)), np.zeros(count, dtype=np.int8)
    its, res = stalled.continue_stalled(None, None, count, 0.5, 1e-6, cap, v, r, status, np.zeros((2, 3)), r, 7, 1e-2)
    return its, res, v


def test_a_stage_that_handed_over_re_enters_after_newton_for_the_rest_of_its_units(monkeypatch):
    # module doc, "Re-entry": after BODIES_REENTER = 2 round-robin resumes (newton's two, in round 0) the
    # stage goes on from its own run for the units it had left (50 - 37), and its converged iterate is kept.
    calls = _scripted_stage(monkeypatch, bodies.STOP_CYCLING, True)
    _robin_that_never_converges(monkeypatch, calls)
    monkeypatch.setattr(stalled, "BODIES_REENTER", 2)
    its, res, v = _continue()
    assert [c[:2] for c in calls] == [("stage", 50), ("newton", 20), ("newton", 40), ("stage", 13)]
    assert calls[3][2] is calls[0][2]  # the same run goes on
    assert its == 7 + 37 + 20 + 40 + 20 and res == 1e-7 and (v == 42.0).all()


def test_a_stage_re_enters_once_and_only_after_the_hand_over_rule(monkeypatch):
    # Not converged at its re-entry: the round-robin goes on and the stage does not come back. A stage that
    # stopped for its stall window or budget does not re-enter at all; nor with BODIES_REENTER = 0.
    for reason, reenter, expect in [
        (bodies.STOP_CYCLING, 2, 1),
        (bodies.STOP_STALL, 2, 0),
        (bodies.STOP_BUDGET, 2, 0),
        (bodies.STOP_CYCLING, 0, 0),
    ]:
        calls = _scripted_stage(monkeypatch, reason, False)
        _robin_that_never_converges(monkeypatch, calls)
        monkeypatch.setattr(stalled, "BODIES_REENTER", reenter)
        _continue(cap=7 + 37 + 400)
        assert sum(c[0] == "stage" for c in calls) == 1 + expect, (reason, reenter)
        assert [c[0] for c in calls][-1] != "stage"  # the round-robin had the last word, to its cap


def test_a_stage_re_enters_when_the_round_robin_ends_before_its_turn(monkeypatch):
    # All methods dropped (newton after its two resumes, turning when a round ends no lower than the last)
    # before the BODIES_REENTER-th resume: the stage still gets the units it had left.
    calls = _scripted_stage(monkeypatch, bodies.STOP_CYCLING, True)
    _robin_that_never_converges(monkeypatch, calls)
    monkeypatch.setattr(stalled, "BODIES_REENTER", 99)
    its, res, v = _continue()
    assert [c[:2] for c in calls] == [
        ("stage", 50),
        ("newton", 20),
        ("newton", 40),
        ("turning", 10),
        ("turning", 20),
        ("stage", 13),
    ]
    assert its == 7 + 37 + 20 + 40 + 10 + 20 + 20 and res == 1e-7 and (v == 42.0).all()
