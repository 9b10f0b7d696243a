"""The NLGS local solve and sweep checked against the contact law itself (QuantEcon style): the
returned impulses must satisfy Signorini and Coulomb, not match stored numbers."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.engine import momentum, nlgs, power
from masonrycli.engine.tuning import TUNING

RNG = np.random.default_rng(20261121)


def _packed_row(w, bias, mu):
    """A packed row (as a one-row pack) built by the engine's own _prepare from an equivalent one-contact geometry would
    hide bugs shared by both; build it here from W directly, as the definition says."""
    p = np.zeros(nlgs.PACK_WIDTH)
    wtt, wtn, wnn = w
    det = wtt * wnn - wtn * wtn
    p[nlgs.P_WTT], p[nlgs.P_WTN], p[nlgs.P_WNN] = wtt, wtn, wnn
    p[nlgs.P_ITT], p[nlgs.P_ITN], p[nlgs.P_INN] = wnn / det, -wtn / det, wtt / det
    dp, dm = wnn - mu * wtn, wnn + mu * wtn
    p[nlgs.P_ISP] = 1 / dp if dp > 0 else 0.0
    p[nlgs.P_ISM] = 1 / dm if dm > 0 else 0.0
    p[nlgs.P_BIAS] = bias
    return p.reshape(1, -1)


def _random_w():
    # Positive definite 2x2 with a realistic t–n coupling.
    a = RNG.normal(size=(2, 2))
    m = a @ a.T + 0.1 * np.eye(2)
    return m[0, 0], m[0, 1], m[1, 1]


@pytest.mark.parametrize("trial", range(400))
def test_local_solve_satisfies_signorini_coulomb(trial):
    w = _random_w()
    mu = RNG.uniform(0.0, 1.2)
    bias = RNG.choice([0.0, RNG.uniform(0, 0.5)])
    u_free = RNG.normal(size=2)
    rt, rn, status = nlgs._local_solve(u_free[0], u_free[1], _packed_row(w, bias, mu), 0, mu)
    W = np.array([[w[0], w[1]], [w[1], w[2]]])
    ut, un = u_free + W @ np.array([rt, rn])
    scale = 1.0 + np.abs(u_free).max()
    tol = 1e-12 * scale
    assert rn >= 0.0
    assert un + bias >= -tol
    assert abs(rn * (un + bias)) <= 1e-10 * scale * (1 + rn)
    assert abs(rt) <= mu * rn + tol
    if status == nlgs.STATUS_OPEN:
        assert rt == 0.0 and rn == 0.0 and u_free[1] + bias >= 0
    elif status == nlgs.STATUS_STICK:
        assert abs(ut) <= tol
    else:
        assert abs(abs(rt) - mu * rn) <= tol
        assert rt * ut <= tol  # friction opposes sliding
        assert abs(ut) > 0 or mu == 0.0 or rn == 0.0


def test_local_solve_is_unique_case():
    """A contact pressed down with a small tangential velocity sticks; a large one slides."""
    mu = 0.5
    p = _packed_row((2.0, 0.0, 2.0), 0.0, mu)
    rt, rn, st = nlgs._local_solve(0.1, -1.0, p, 0, mu)
    assert st == nlgs.STATUS_STICK and rn == pytest.approx(0.5) and rt == pytest.approx(-0.05)
    rt, rn, st = nlgs._local_solve(3.0, -1.0, p, 0, mu)
    assert st == nlgs.STATUS_SLIP and rn == pytest.approx(0.5) and rt == pytest.approx(-0.25)
    rt, rn, st = nlgs._local_solve(3.0, 0.2, p, 0, mu)
    assert st == nlgs.STATUS_OPEN and rt == 0.0 and rn == 0.0


def test_open_contact_inside_alert_may_close_but_not_cross():
    """Gap g > 0: the normal velocity may reach −g/dt (closing exactly) but no further."""
    mu, dt, gap = 0.6, 1e-3, 2e-4
    p = _packed_row((1.0, 0.0, 1.0), gap / dt, mu)
    rt, rn, st = nlgs._local_solve(0.0, -0.1, p, 0, mu)  # slower than g/dt = 0.2 m/s: stays open
    assert st == nlgs.STATUS_OPEN
    rt, rn, st = nlgs._local_solve(0.0, -0.5, p, 0, mu)  # faster: stopped at −g/dt
    assert rn == pytest.approx(0.3) and st == nlgs.STATUS_STICK


# --- The Delassus assembly and the contact power, against dense matrices built here in numpy ----------


def _random_contacts(n_contacts=7, seed=3):
    """Three blocks and one support (inverse mass 0), contacts between random pairs a < b."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(4, 3))
    inv_mass = np.array([1 / 2.0, 1 / 3.5, 1 / 1.2, 0.0])
    inv_inertia = np.array([1 / 0.4, 1 / 0.9, 1 / 0.15, 0.0])
    pairs = [(0, 1), (0, 3), (1, 2), (2, 3), (0, 2)]
    body = np.array([pairs[i % len(pairs)] for i in range(n_contacts)], dtype=np.int32)
    point = q[body[:, 0], :2] + rng.normal(scale=0.3, size=(n_contacts, 2))
    angle = rng.uniform(0, 2 * np.pi, n_contacts)
    normal = np.column_stack([np.cos(angle), np.sin(angle)])
    gap = rng.normal(scale=1e-3, size=n_contacts)
    return q, inv_mass, inv_inertia, body, point, normal, gap


def _dense_h(q, body, point, normal):
    """H (3B × 2C): column 2c is the unit tangential impulse t of contact c, column 2c+1 the normal one,
    acting on b (+) and a (−) at the contact point; t = (n_y, −n_x) (masonrycli.engine.contact)."""
    h = np.zeros((3 * q.shape[0], 2 * body.shape[0]))
    for c, (a, b) in enumerate(body):
        n = normal[c]
        t = np.array([n[1], -n[0]])
        for col, d in ((2 * c, t), (2 * c + 1, n)):
            for k, sign in ((b, 1.0), (a, -1.0)):
                arm = point[c] - q[k, :2]
                h[3 * k : 3 * k + 2, col] += sign * d
                h[3 * k + 2, col] += sign * (arm[0] * d[1] - arm[1] * d[0])
    return h


def test_prepare_matches_dense_delassus():
    q, inv_mass, inv_inertia, body, point, normal, gap = _random_contacts()
    mu, dt = 0.6, 1e-3
    count = body.shape[0]
    pack = np.zeros((count, nlgs.PACK_WIDTH))
    nlgs._prepare(body, point, normal, gap, count, q, inv_mass, inv_inertia, mu, dt, pack)
    h = _dense_h(q, body, point, normal)
    m_inv = np.diag(np.column_stack([inv_mass, inv_mass, inv_inertia]).ravel())
    w = h.T @ m_inv @ h
    for c in range(count):
        block = w[2 * c : 2 * c + 2, 2 * c : 2 * c + 2]
        got = np.array([[pack[c, nlgs.P_WTT], pack[c, nlgs.P_WTN]], [pack[c, nlgs.P_WTN], pack[c, nlgs.P_WNN]]])
        np.testing.assert_allclose(got, block, rtol=1e-12, atol=1e-14)
        inv = np.array([[pack[c, nlgs.P_ITT], pack[c, nlgs.P_ITN]], [pack[c, nlgs.P_ITN], pack[c, nlgs.P_INN]]])
        np.testing.assert_allclose(inv @ block, np.eye(2), atol=1e-10)
        wtn, wnn = block[0, 1], block[1, 1]
        assert pack[c, nlgs.P_ISP] == pytest.approx(1 / (wnn - mu * wtn) if wnn - mu * wtn > 0 else 0.0)
        assert pack[c, nlgs.P_ISM] == pytest.approx(1 / (wnn + mu * wtn) if wnn + mu * wtn > 0 else 0.0)
        assert pack[c, nlgs.P_BIAS] == pytest.approx(max(gap[c], 0.0) / dt)
    # The sweep's relative velocity is Hᵀ v and its push is M⁻¹ H Δr.
    rng = np.random.default_rng(5)
    v = rng.normal(size=(4, 3))
    u = h.T @ v.ravel()
    for c in range(count):
        ut, un = nlgs._relative_velocity(v, body[c, 0], body[c, 1], pack, c)
        np.testing.assert_allclose([ut, un], u[2 * c : 2 * c + 2], rtol=1e-12, atol=1e-12)
    dr = rng.normal(size=2)
    pushed = v.copy()
    nlgs._push(pushed, body[2, 0], body[2, 1], pack, 2, dr[0], dr[1])
    expected = v.ravel() + m_inv @ h[:, 4:6] @ dr
    np.testing.assert_allclose(pushed.ravel(), expected, rtol=1e-12, atol=1e-12)
    assert np.all(pushed[3] == v[3])  # the support's imposed velocity is untouched (+0)


def test_contact_power_matches_dense_definitions():
    q, inv_mass, inv_inertia, body, point, normal, gap = _random_contacts(seed=11)
    dt, count = 1e-3, body.shape[0]
    pack = np.zeros((count, nlgs.PACK_WIDTH))
    nlgs._prepare(body, point, normal, gap, count, q, inv_mass, inv_inertia, 0.6, dt, pack)
    rng = np.random.default_rng(13)
    r = rng.normal(size=(count, 2))
    v_old, v_new = rng.normal(size=(4, 3)), rng.normal(size=(4, 3))
    v_old[3, 2] = v_new[3, 2] = 0.0
    dynamic = np.array([True, True, True, False])
    force = np.zeros((count, 2))
    support_force = np.zeros((1, 2))
    dissipated, work = power._contact_power(body, pack, r, count, v_old, v_new, dynamic, 3, dt, force, support_force)
    h = _dense_h(q, body, point, normal)
    u_mean = h.T @ (0.5 * (v_old + v_new)).ravel()
    assert dissipated == pytest.approx(-(r.ravel() @ u_mean), rel=1e-12)
    t = np.column_stack([normal[:, 1], -normal[:, 0]])
    impulse = r[:, :1] * t + r[:, 1:] * normal  # on b; a gets the opposite
    np.testing.assert_allclose(force, impulse / dt, rtol=1e-12)
    # The support (body 3) receives +P where it is b and −P where it is a; it does work on the blocks
    # with the opposite force, at its mean velocity.
    on_support = np.where(body[:, 1:] == 3, 1.0, 0.0) * impulse - np.where(body[:, :1] == 3, 1.0, 0.0) * impulse
    np.testing.assert_allclose(support_force[0], on_support.sum(axis=0) / dt, rtol=1e-12)
    v_support = 0.5 * (v_old[3, :2] + v_new[3, :2])
    assert work == pytest.approx(-(on_support.sum(axis=0) @ v_support), rel=1e-12)


def _slow_sweep(body, w_blocks, h, m_inv, v, r, mu, bias, order=None):
    """One Gauss–Seidel sweep written out with the dense H and M⁻¹ (numpy, one contact at a time, in
    ``order`` or in index order), updating the flat v and r in place; returns its RMS of |W_αα Δr_α| (m/s),
    the stopping quantity of dispatch.solve."""
    e2 = 0.0
    for c in range(body.shape[0]) if order is None else order:
        w = w_blocks[c]
        u_free = h[:, 2 * c : 2 * c + 2].T @ v - w @ r[c]
        row = _packed_row((w[0, 0], w[0, 1], w[1, 1]), bias[c], mu)
        rt, rn, _ = nlgs._local_solve(u_free[0], u_free[1], row, 0, mu)
        dr = np.array([rt, rn]) - r[c]
        v += m_inv @ h[:, 2 * c : 2 * c + 2] @ dr
        r[c] = (rt, rn)
        e2 += float((w @ dr) @ (w @ dr))
    return np.sqrt(e2 / body.shape[0])


def _slow_sweeps(body, w_blocks, h, m_inv, v, r, mu, bias, sweeps):
    """``sweeps`` dense Gauss–Seidel sweeps from impulses r; returns (v, r, the last sweep's residual)."""
    v = v.ravel().copy()
    v += m_inv @ h @ r.ravel()
    for _ in range(sweeps):
        residual = _slow_sweep(body, w_blocks, h, m_inv, v, r, mu, bias)
    return v.reshape(-1, 3), r, residual


@pytest.mark.parametrize("sweeps", [1, 3, 12])
def test_residual_is_rms_contact_law_violation_of_the_last_sweep(sweeps):
    q, inv_mass, inv_inertia, body, point, normal, gap = _random_contacts(seed=17)
    mu, dt, count = 0.5, 1e-3, body.shape[0]
    pack = np.zeros((count, nlgs.PACK_WIDTH))
    nlgs._prepare(body, point, normal, gap, count, q, inv_mass, inv_inertia, mu, dt, pack)
    h = _dense_h(q, body, point, normal)
    m_inv = np.diag(np.column_stack([inv_mass, inv_mass, inv_inertia]).ravel())
    w_full = h.T @ m_inv @ h
    w_blocks = [w_full[2 * c : 2 * c + 2, 2 * c : 2 * c + 2] for c in range(count)]
    rng = np.random.default_rng(19)
    v0 = rng.normal(scale=0.1, size=(4, 3))
    v0[3] = 0.0
    r0 = np.abs(rng.normal(scale=0.01, size=(count, 2)))
    bias = np.maximum(gap, 0.0) / dt
    v_ref, r_ref, res_ref = _slow_sweeps(body, w_blocks, h, m_inv, v0, r0.copy(), mu, bias, sweeps)
    v, r, status = v0.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    its, res = nlgs._nlgs(body, pack, count, mu, 0.0, sweeps, v, r, status)
    assert its == sweeps
    assert res == pytest.approx(res_ref, rel=1e-9, abs=1e-15)
    np.testing.assert_allclose(r, r_ref, rtol=1e-9, atol=1e-14)
    np.testing.assert_allclose(v, v_ref, rtol=1e-9, atol=1e-12)
    # With a tolerance, the solve stops at the first sweep whose residual meets it.
    v, r = v0.copy(), r0.copy()
    its, res = nlgs._nlgs(body, pack, count, mu, 1e-9, 100000, v, r, status)
    assert res <= 1e-9
    v, r = v0.copy(), r0.copy()
    _, before = nlgs._nlgs(body, pack, count, mu, 0.0, its - 1, v, r, status) if its > 1 else (0, np.inf)
    assert before > 1e-9


@pytest.mark.parametrize("sweeps", [1, 2, 5, 12])
def test_alternating_sweeps_match_the_dense_sweep_forward_then_backward(sweeps):
    # alternate=True (what stalled.py resumes): sweeps 1, 3, 5, … visit the contacts in index order,
    # sweeps 2, 4, … in reverse; the residual is the last sweep's.
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _random_problem(5)
    count = body.shape[0]
    v_ref, r_ref = v0.ravel().copy(), r0.copy()
    v_ref += m_inv @ h @ r_ref.ravel()
    for k in range(sweeps):
        order = range(count) if k % 2 == 0 else range(count - 1, -1, -1)
        res_ref = _slow_sweep(body, w_blocks, h, m_inv, v_ref, r_ref, mu, bias, order)
    v, r, status = v0.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    its, res = nlgs._nlgs(body, pack, count, mu, 0.0, sweeps, v, r, status, True)
    assert its == sweeps
    assert res == pytest.approx(res_ref, rel=1e-9, abs=1e-15)
    np.testing.assert_allclose(r, r_ref, rtol=1e-9, atol=1e-14)
    np.testing.assert_allclose(v.ravel(), v_ref, rtol=1e-9, atol=1e-12)
    if sweeps > 1:  # and it is not the one-way sweep
        v1, r1 = v0.copy(), r0.copy()
        nlgs._nlgs(body, pack, count, mu, 0.0, sweeps, v1, r1, status)
        assert not np.allclose(r1, r, rtol=1e-9, atol=1e-14)


def test_a_solve_that_stops_improving_ends_stall_sweeps_after_its_lowest_residual():
    # These contacts converge to the floating-point floor within 8 sweeps; after that the residual only
    # wanders around 1e-16 m/s. With a tolerance the floor never meets, the solve must stop
    # PLAIN_STALL sweeps after its last new low (unconverged, as at the cap) instead of running to the
    # cap; with tolerance 0 it runs the cap exactly.
    q, inv_mass, inv_inertia, body, point, normal, gap = _random_contacts(seed=3)
    mu, dt, count = 0.5, 1e-3, body.shape[0]
    pack = np.zeros((count, nlgs.PACK_WIDTH))
    nlgs._prepare(body, point, normal, gap, count, q, inv_mass, inv_inertia, mu, dt, pack)
    rng = np.random.default_rng(19)
    v0 = rng.normal(scale=0.1, size=(4, 3))
    v0[3] = 0.0
    r0 = np.abs(rng.normal(scale=0.01, size=(count, 2)))
    status = np.zeros(count, dtype=np.int8)
    # The residual after each of the first sweeps, one call each: the last new low among them.
    lows = []
    for n in range(1, 41):
        v, r = v0.copy(), r0.copy()
        lows.append(nlgs._nlgs(body, pack, count, mu, 0.0, n, v, r, status)[1])
    last_low = max(i for i in range(len(lows)) if lows[i] < min(lows[:i], default=np.inf))
    assert 0.0 < lows[last_low] < 1e-14
    v, r = v0.copy(), r0.copy()
    its, res = nlgs._nlgs(body, pack, count, mu, 1e-300, 10**6, v, r, status)
    assert its == last_low + 1 + nlgs.PLAIN_STALL and res > 1e-300
    v, r = v0.copy(), r0.copy()
    its, _ = nlgs._nlgs(body, pack, count, mu, 0.0, 3 * nlgs.PLAIN_STALL, v, r, status)
    assert its == 3 * nlgs.PLAIN_STALL


# --- The accelerated sweep (solver "nlgs-accel"), against a slow dense implementation ------------------


def _slow_accelerated_sweeps(body, w_blocks, h, m_inv, v, r, mu, bias, sweeps, growth, turning=False):
    """Nesterov-accelerated Gauss–Seidel written out densely: each sweep starts from the extrapolation
    y = x + β (x − x_prev) of the last two sweeps' (v, r), β = (j − 1)/(j + 2) with j the sweeps since the
    last restart, and restarts (j = 1) after a sweep whose residual exceeds ``growth`` × the one before.
    ``turning``: the sweep order reverses at every restart (the kernel's ``flip``)."""
    v = v.ravel().copy()
    v += m_inv @ h @ r.ravel()
    v_prev, r_prev = v.copy(), r.copy()
    beta, j, last, residual, done = 0.0, 1, np.inf, 0.0, 0
    order = list(range(body.shape[0]))
    for done in range(1, sweeps + 1):
        v_y = v + beta * (v - v_prev)
        r_y = r + beta * (r - r_prev)
        v_prev, r_prev = v.copy(), r.copy()
        v, r = v_y, r_y
        residual = _slow_sweep(body, w_blocks, h, m_inv, v, r, mu, bias, order)
        if residual == 0.0:  # an exact solution: the kernel stops there too (residual <= tolerance 0)
            break
        if turning and residual > growth * last:
            order.reverse()
        j = 1 if residual > growth * last else j
        last = residual
        beta = (j - 1.0) / (j + 2.0)
        j += 1
    return v.reshape(-1, 3), r, residual, done


def _random_problem(seed):
    q, inv_mass, inv_inertia, body, point, normal, gap = _random_contacts(n_contacts=9, seed=seed)
    mu, dt, count = 0.5, 1e-3, body.shape[0]
    pack = np.zeros((count, nlgs.PACK_WIDTH))
    nlgs._prepare(body, point, normal, gap, count, q, inv_mass, inv_inertia, mu, dt, pack)
    h = _dense_h(q, body, point, normal)
    m_inv = np.diag(np.column_stack([inv_mass, inv_mass, inv_inertia]).ravel())
    w_full = h.T @ m_inv @ h
    w_blocks = [w_full[2 * c : 2 * c + 2, 2 * c : 2 * c + 2] for c in range(count)]
    rng = np.random.default_rng(seed + 100)
    v0 = rng.normal(scale=0.1, size=(4, 3))
    v0[3] = 0.0
    r0 = np.abs(rng.normal(scale=0.01, size=(count, 2)))
    return body, pack, h, m_inv, w_blocks, v0, r0, mu, np.maximum(gap, 0.0) / dt


def _stack_problem(n):
    """A column of n unit blocks (1 kg, inertia 1/6 kg·m²) on a fixed support, two contact points per bed
    joint, falling at g·dt and sheared by random horizontal velocities: load must travel the whole height,
    the slow case of Gauss–Seidel."""
    rng = np.random.default_rng(n)
    q = np.zeros((n + 1, 3))
    q[:n, 1] = np.arange(n) + 0.5
    q[n, 1] = -0.5
    inv_mass, inv_inertia = np.r_[np.full(n, 1.0), 0.0], np.r_[np.full(n, 6.0), 0.0]
    body = np.array([(0, n) if i == 0 else (i - 1, i) for i in range(n) for _ in range(2)], dtype=np.int32)
    point = np.array([(x, float(i)) for i in range(n) for x in (-0.5, 0.5)])
    normal = np.array([(0.0, -1.0) if i == 0 else (0.0, 1.0) for i in range(n) for _ in range(2)])
    mu, dt, count = 0.5, 1e-3, body.shape[0]
    pack = np.zeros((count, nlgs.PACK_WIDTH))
    nlgs._prepare(body, point, normal, np.zeros(count), count, q, inv_mass, inv_inertia, mu, dt, pack)
    h = _dense_h(q, body, point, normal)
    m_inv = np.diag(np.column_stack([inv_mass, inv_mass, inv_inertia]).ravel())
    w_full = h.T @ m_inv @ h
    w_blocks = [w_full[2 * c : 2 * c + 2, 2 * c : 2 * c + 2] for c in range(count)]
    v0 = np.zeros((n + 1, 3))
    v0[:n, 0] = rng.normal(scale=0.01, size=n)
    v0[:n, 1] = -9.81 * dt
    return body, pack, h, m_inv, w_blocks, v0, np.zeros((count, 2)), mu, np.zeros(count)


# (problem, sweeps): random problems that reach an exact solution in 44 and 57 sweeps, and a stack on which
# momentum restarts several times within 60 sweeps.
ACCEL_CASES = [(("random", s), n) for s in (5, 41) for n in (1, 2, 5, 30)] + [(("stack", 6), 60)]


@pytest.mark.parametrize("turning", [False, True])
@pytest.mark.parametrize(("problem", "sweeps"), ACCEL_CASES)
def test_accelerated_sweeps_match_a_slow_dense_implementation(problem, sweeps, turning):
    # turning=True: the direction that turns at every restart (stalled.py's "turning" method)
    kind, arg = problem
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _random_problem(arg) if kind == "random" else _stack_problem(arg)
    count = body.shape[0]
    v_ref, r_ref, res_ref, its_ref = _slow_accelerated_sweeps(
        body, w_blocks, h, m_inv, v0, r0.copy(), mu, bias, sweeps, momentum.RESTART_GROWTH, turning
    )
    v, r, status = v0.copy(), r0.copy(), np.zeros(count, dtype=np.int8)
    its, res = momentum._nlgs_accelerated(body, pack, count, mu, 0.0, sweeps, v, r, status, TUNING.first_stall, turning)
    assert its == its_ref
    assert res == pytest.approx(res_ref, rel=1e-8, abs=1e-15)
    np.testing.assert_allclose(r, r_ref, rtol=1e-8, atol=1e-13)
    np.testing.assert_allclose(v, v_ref, rtol=1e-8, atol=1e-11)


@pytest.mark.parametrize("seed", [3, 17, 23, 31])
def test_accelerated_solve_converges_to_the_contact_law_and_the_unique_velocities(seed):
    # Velocities of a frictional contact problem with a positive definite mass are unique (impulses need
    # not be): the accelerated solve, tight, must land on plain Gauss–Seidel's velocities, with impulses
    # satisfying Signorini–Coulomb at them (checked by the local solve written out here, densely).
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _random_problem(seed)
    count = body.shape[0]
    status = np.zeros(count, dtype=np.int8)
    v_acc, r_acc = v0.copy(), r0.copy()
    its_acc, res_acc = momentum._nlgs_accelerated(
        body, pack, count, mu, 1e-13, 200000, v_acc, r_acc, status, TUNING.first_stall
    )
    v_gs, r_gs = v0.copy(), r0.copy()
    its_gs, _ = nlgs._nlgs(body, pack, count, mu, 1e-13, 200000, v_gs, r_gs, status)
    assert res_acc <= 1e-13 and its_acc < 200000 and its_gs < 200000
    np.testing.assert_allclose(v_acc, v_gs, atol=1e-9)
    v_dense = v0.ravel() + m_inv @ h @ r_acc.ravel()
    np.testing.assert_allclose(v_acc.ravel(), v_dense, atol=1e-12)  # v is the velocity of its impulses
    assert np.all(r_acc[:, 1] >= 0.0) and np.all(np.abs(r_acc[:, 0]) <= mu * r_acc[:, 1] * (1 + 1e-12))
    for c in range(count):
        w = w_blocks[c]
        u = h[:, 2 * c : 2 * c + 2].T @ v_dense
        row = _packed_row((w[0, 0], w[0, 1], w[1, 1]), bias[c], mu)
        u_free = u - w @ r_acc[c]
        rt, rn, _ = nlgs._local_solve(u_free[0], u_free[1], row, 0, mu)
        assert np.hypot(*(w @ (np.array([rt, rn]) - r_acc[c]))) <= 1e-11


def test_momentum_carries_load_down_a_stack_in_far_fewer_sweeps():
    # The reason for the default solver: on a 10-block column plain Gauss–Seidel needs ~N² sweeps (load moves
    # one joint per sweep, error decays like a diffusion), the accelerated sweep ~N. Measured: 2529 vs 570
    # sweeps to 1e-10 m/s; both must end on the same (unique) velocities.
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _stack_problem(10)
    count = body.shape[0]
    status = np.zeros(count, dtype=np.int8)
    v_gs, r_gs = v0.copy(), r0.copy()
    its_gs, _ = nlgs._nlgs(body, pack, count, mu, 1e-10, 20000, v_gs, r_gs, status)
    v_acc, r_acc = v0.copy(), r0.copy()
    its_acc, _ = momentum._nlgs_accelerated(body, pack, count, mu, 1e-10, 20000, v_acc, r_acc, status, 200)
    assert its_gs < 20000 and its_acc * 3 < its_gs
    np.testing.assert_allclose(v_acc, v_gs, atol=1e-8)


def test_an_accelerated_solve_that_stops_improving_ends_its_window_after_its_lowest_residual():
    # As for plain sweeps (test above), with the accelerated solve's own window: the solve stops
    # ``stall_after`` sweeps after its last new low when the tolerance is out of reach, so that dispatch.solve
    # can go on by faces; tolerance 0 runs the cap exactly.
    body, pack, h, m_inv, w_blocks, v0, r0, mu, bias = _random_problem(1)  # wanders at ~1e-16 m/s from sweep ~170
    count = body.shape[0]
    status = np.zeros(count, dtype=np.int8)
    lows = []
    for n in range(1, 261):
        v, r = v0.copy(), r0.copy()
        lows.append(momentum._nlgs_accelerated(body, pack, count, mu, 0.0, n, v, r, status, 10**9)[1])
    for window in (3, 20):
        its, res = momentum._nlgs_accelerated(
            body, pack, count, mu, 1e-300, 10**6, v0.copy(), r0.copy(), status, window
        )
        seen = lows[: its - 1]  # the residuals before the last sweep
        last_low = max(i for i in range(len(seen)) if seen[i] < min(seen[:i], default=np.inf))
        assert its == last_low + 1 + window and res > 1e-300
        assert all(x >= seen[last_low] for x in lows[last_low + 1 : its])
    its, _ = momentum._nlgs_accelerated(body, pack, count, mu, 0.0, 150, v0.copy(), r0.copy(), status, 3)
    assert its == 150  # (an exact 0 comes at sweep 211)
