"""Momentum sweeps in body order (masonrycli.engine.bodies), against a dense numpy reference."""

import numpy as np
import pytest
from test_engine_faces import _faces_problem
from test_engine_nlgs import _dense_h, _packed_row, _random_contacts, _slow_sweeps

from masonrycli.engine import bodies, nlgs
from masonrycli.engine.momentum import RESTART_GROWTH


def _problem(seed):
    q, inv_mass, inv_inertia, body, point, normal, gap = _random_contacts(seed=seed)
    mu, dt, count = 0.5, 1e-3, body.shape[0]
    pack = np.zeros((count, nlgs.PACK_WIDTH))
    nlgs._prepare(body, point, normal, gap, count, q, inv_mass, inv_inertia, mu, dt, pack)
    h = _dense_h(q, body, point, normal)
    m_inv = np.diag(np.column_stack([inv_mass, inv_mass, inv_inertia]).ravel())
    rng = np.random.default_rng(seed + 2)
    v_free = rng.normal(scale=0.1, size=(4, 3))
    v_free[3] = 0.0
    r0 = np.abs(rng.normal(scale=0.01, size=(count, 2)))
    return body, pack, h, m_inv, v_free, r0, mu, np.maximum(gap, 0.0) / dt


def _reference(body, h, m_inv, v_free, r, mu, bias, sweeps):
    """The module doc's sweeps written out with dense H, W and M⁻¹: bodies 0, 1, 2 (3 is the support) in
    turn, each visiting its contacts in index order; extrapolation of all r and v at each sweep's start.
    Returns (v, r, the last sweep's residual)."""
    count = body.shape[0]
    order = [c for k in range(3) for c in range(count) if k in body[c]]
    w_full = h.T @ m_inv @ h
    v = v_free.ravel() + m_inv @ h @ r.ravel()
    r_prev, v_prev = r.copy(), v.copy()
    beta, j, last = 0.0, 1, np.inf
    for _ in range(sweeps):
        v, v_prev = v + beta * (v - v_prev), v.copy()
        r, r_prev = r + beta * (r - r_prev), r.copy()
        e2, seen = 0.0, set()
        for c in order:
            wb = w_full[2 * c : 2 * c + 2, 2 * c : 2 * c + 2]
            u_free = h[:, 2 * c : 2 * c + 2].T @ v - wb @ r[c]
            row = _packed_row((wb[0, 0], wb[0, 1], wb[1, 1]), bias[c], mu)
            rt, rn, _ = nlgs._local_solve(u_free[0], u_free[1], row, 0, mu)
            dr = np.array([rt, rn]) - r[c]
            v += m_inv @ h[:, 2 * c : 2 * c + 2] @ dr
            r[c] = (rt, rn)
            if c not in seen:
                seen.add(c)
                e2 += float((wb @ dr) @ (wb @ dr))
        residual = np.sqrt(e2 / count)
        if residual > RESTART_GROWTH * last:
            j = 1
        last = residual
        beta = (j - 1.0) / (j + 2.0)
        j += 1
    return v.reshape(-1, 3), r, residual, len(order)


@pytest.mark.parametrize("seed", [5, 17])
def test_body_order_sweeps_match_dense_reference(seed):
    body, pack, h, m_inv, v_free, r0, mu, bias = _problem(seed)
    count = body.shape[0]
    for sweeps in (1, 3, 12):
        v_ref, r_ref, res_ref, visits = _reference(body, h, m_inv, v_free, r0.copy(), mu, bias, sweeps)
        v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
        cap = (sweeps * visits - 0.5) / count  # sweep units: exactly `sweeps` sweeps
        units, res = bodies.body_order_sweeps(body, pack, count, mu, 0.0, cap, v, r, status, 10**9)
        assert units == -(-sweeps * visits // count)  # visits / C, rounded up
        assert res == pytest.approx(res_ref, rel=1e-9, abs=1e-15)
        np.testing.assert_allclose(r, r_ref, rtol=1e-9, atol=1e-14)
        np.testing.assert_allclose(v, v_ref, rtol=1e-9, atol=1e-12)


def test_body_order_sweeps_end_on_the_contact_law():
    for seed in (1, 4, 6, 9, 10):  # geometries on which Gauss–Seidel converges (faces test)
        body, pack, h, m_inv, v_free, r0, mu, bias = _faces_problem(seed)
        count = body.shape[0]
        v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
        units, res = bodies.body_order_sweeps(body, pack, count, mu, 1e-13, 10**5, v, r, status, 10**4)
        assert res <= 1e-13 and units >= 1
        # v is v_free + M⁻¹ H r, and one more dense point sweep from r moves nothing
        np.testing.assert_allclose(v, v_free + (m_inv @ h @ r.ravel()).reshape(-1, 3), atol=1e-12)
        w = h.T @ m_inv @ h
        blocks = [w[2 * c : 2 * c + 2, 2 * c : 2 * c + 2] for c in range(count)]
        _, r2, res2 = _slow_sweeps(body, blocks, h, m_inv, v_free, r.copy(), mu, bias, 1)
        assert res2 < 1e-11
        np.testing.assert_allclose(r2, r, atol=1e-11)


def test_body_order_sweeps_stop_at_the_cap():
    body, pack, h, m_inv, v_free, r0, mu, bias = _problem(5)
    count = body.shape[0]
    v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    units, res = bodies.body_order_sweeps(body, pack, count, mu, 1e-300, 7, v, r, status, 10**9)
    assert 7 <= units <= 7 + 2 and res > 0.0  # the sweep that crosses the cap ends (≤ 2 units a sweep)


def _windows_run(residuals, window, level, strong=np.inf, strong_runs=None):
    """bodies._cycling_windows over a residual sequence: the run of cycling windows after each sweep (and the run
    of windows above ``strong`` × the low into ``strong_runs``, a list, if given)."""
    state, best, runs = np.zeros(4), np.inf, []
    for x in residuals:
        best = min(best, x)
        runs.append(bodies._cycling_windows(state, x, best, window, level, strong))
        if strong_runs is not None:
            strong_runs.append(state[3])
    return np.array(runs)


def test_a_stage_that_cycles_above_an_early_dip_counts_cycling_windows():
    # The 248-block wall's failing steps (benchmarks/JOURNAL.md, "Hand-over"): one early dip to a low the
    # stage never sees again, then a stick/slip cycle between 2x and 8x that low.
    cycle = np.tile([4e-5, 1.6e-4, 8e-5, 4e-5], 500)
    residuals = np.concatenate([[3e-4, 2e-5], cycle])
    runs = _windows_run(residuals, 100, 1.8)
    # geometric mean of a cycle ≈ 6.7e-5 = 3.4 × the dip: every window cycles, the run grows by one a window
    np.testing.assert_array_equal(runs[99::100], np.arange(1, len(residuals) // 100 + 1))
    assert (runs[:99] == 0).all()


def test_a_stage_that_converges_slowly_or_sits_near_its_low_counts_none():
    rng = np.random.default_rng(0)
    slow = 1e-4 * 10 ** (-np.arange(4000) / 4000) * (1 + 0.3 * rng.random(4000))  # a decade in 4000 sweeps
    plateau = 2e-5 * (1 + 0.5 * rng.random(4000))  # a plateau a little above its low, as the 64-course wall's
    for residuals in (slow, plateau):
        assert (_windows_run(residuals, 500, 1.8) == 0).all()


def test_the_stage_hands_over_after_that_many_cycling_windows_in_a_row():
    body, pack, h, m_inv, v_free, r0, mu, bias = _problem(5)
    count = body.shape[0]
    history = np.full(400, np.nan)
    v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    bodies.body_order_sweeps(body, pack, count, mu, 1e-300, 300, v, r, status, 10**9, history=history)
    history = history[~np.isnan(history)]
    # Level 1.0: a window whose residuals fell counts as cycling too (its mean is above its last), so on
    # this problem's falling residual the rule hands over within a few windows.
    window, cycling = 7, 3
    runs = _windows_run(history, window, 1.0)
    stop = int(np.argmax(runs >= cycling)) + 1
    assert runs.max() >= cycling and stop < len(history)
    _, members = bodies._body_lists(body, pack, count, v_free.shape[0])
    v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    units, res = bodies.body_order_sweeps(body, pack, count, mu, 1e-300, 300, v, r, status, 10**9, window, 1.0, cycling)
    assert units == -(-stop * members.shape[0] // count) and res == history[stop - 1]
    v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    _, res_off = bodies.body_order_sweeps(body, pack, count, mu, 1e-300, 300, v, r, status, 10**9, window, 1.0, 0)
    assert res_off == history[-1] != res  # cycling = 0: never


def test_a_stage_handed_over_goes_on_as_one_long_run():
    # stalled.py re-enters the stage after a hand-over (its module doc, "Re-entry"): the second call, with the
    # run the first left, must sweep as one uninterrupted call would — same residuals, same impulses and
    # velocities to the bit (the extrapolation, its restart counter and the stall window carried, v not
    # rebuilt from v_free).
    body, pack, h, m_inv, v_free, r0, mu, bias = _problem(5)
    count = body.shape[0]
    probe = np.full(400, np.nan)
    v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    bodies.body_order_sweeps(body, pack, count, mu, 1e-300, 300, v, r, status, 10**9, history=probe)
    tolerance = probe[~np.isnan(probe)][-1]  # the long run meets it at a sweep the split run must meet too
    long_history = np.full(400, np.nan)
    v_long, r_long, status_long = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    units_long, res_long = bodies.body_order_sweeps(
        body, pack, count, mu, tolerance, 10**6, v_long, r_long, status_long, 10**9, history=long_history
    )
    history = np.full(400, np.nan)
    v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    run = bodies.new_stage(count, v_free.shape[0])
    first, _ = bodies.body_order_sweeps(
        body, pack, count, mu, tolerance, 10**6, v, r, status, 10**9, 7, 1.0, 3, history=history, stage=run
    )
    assert run.carry[bodies.C_REASON] == bodies.STOP_CYCLING and 0 < first < units_long
    second, res = bodies.body_order_sweeps(
        body, pack, count, mu, tolerance, 10**6, v, r, status, 10**9, history=history, stage=run
    )
    assert run.carry[bodies.C_REASON] == bodies.STOP_TOLERANCE and res == res_long
    np.testing.assert_array_equal(history, long_history)
    np.testing.assert_array_equal(r, r_long)
    np.testing.assert_array_equal(v, v_long)
    np.testing.assert_array_equal(status, status_long)
    assert units_long <= first + second <= units_long + 1  # each call rounds its visits up to whole units


def test_windows_far_above_the_low_count_as_strong():
    # The 248-block wall's failing steps cycle at 3-12x their low (benchmarks/JOURNAL.md, "Where the dear steps
    # of the benchmark's wall-248 run go"); the stage's strong run counts windows above `strong` x the low.
    cycle = np.tile([4e-5, 1.6e-4, 8e-5, 4e-5], 500)  # geometric mean 6.7e-5: 3.4 x the dip below
    residuals = np.concatenate([[3e-4, 2e-5], cycle])
    for strong, grows in ((3.0, True), (4.0, False)):
        strong_runs = []
        _windows_run(residuals, 100, 1.8, strong, strong_runs)
        expect = np.arange(1, len(residuals) // 100 + 1) if grows else 0
        np.testing.assert_array_equal(np.array(strong_runs)[99::100], expect)


def test_the_stage_hands_over_sooner_far_from_the_tolerance_or_when_strongly_cycling():
    # far_cycling windows in a row hand over when the low is above far x tolerance, or when each window's level
    # is above strong x the low; else the `cycling` windows of the ordinary rule (module doc of stalled.py).
    body, pack, h, m_inv, v_free, r0, mu, bias = _problem(5)
    count = body.shape[0]

    def run(tolerance, cycling, **kw):
        v, r, status = v_free.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
        return bodies.body_order_sweeps(
            body, pack, count, mu, tolerance, 300, v, r, status, 10**9, 7, 1.0, cycling, **kw
        )

    two = run(1e-300, 2)  # the ordinary rule at 2 windows: where the fast rules must stop
    ten = run(1e-300, 10)
    assert two[0] < ten[0]
    assert run(1e-300, 10, far=1.0, far_cycling=2) == two  # the low is far above 1e-300
    assert run(1e-300, 10, strong=1.0, far_cycling=2) == two  # every window that cycles at 1.0 is strong at 1.0
    assert run(1e-300, 10, far=1e300, strong=1e300, far_cycling=2) == ten  # neither: the ordinary rule
    assert run(1e-300, 10, far=1.0, far_cycling=0) == ten  # far_cycling 0: off
