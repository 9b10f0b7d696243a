"""Shrinking sweeps (masonrycli.engine.shrink): momentum's sweep with the contacts open at its first sweep
left out, checked every few sweeps and before it stops."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from masonrycli.engine import interleaved, momentum, nlgs, shrink

MU, DT = 0.5, 1e-3


def _column_between_walls(n, seed, side_gap, warm=True):
    """A column of n unit blocks (1 kg, inertia 1/6 kg·m²) on a fixed support, two points per bed joint,
    and each block facing a fixed wall on either side at a gap drawn from ``side_gap`` (m): falling at
    g·dt, sheared by random horizontal velocities, the bed joints warm-started or not (``warm``). Returns (body, pack, v0, r0, bias, w_blocks, h, m_inv)."""
    rng = np.random.default_rng(seed)
    q = np.zeros((n + 1, 3))
    q[:n, 1] = np.arange(n) + 0.5
    body, point, normal = [], [], []
    for i in range(n):
        for x in (-0.5, 0.5):
            body.append((0, n) if i == 0 else (i - 1, i))
            point.append((x, float(i)))
            normal.append((0.0, -1.0) if i == 0 else (0.0, 1.0))
        for side in (-1.0, 1.0):  # the walls: the support's other faces
            body.append((i, n))
            point.append((0.5 * side, i + 0.5))
            normal.append((side, 0.0))
    body, point, normal = np.array(body, np.int32), np.array(point), np.array(normal)
    count = body.shape[0]
    gap = np.where(normal[:, 0] != 0.0, rng.uniform(*side_gap, size=count), 0.0)
    inv_mass, inv_inertia = np.r_[np.full(n, 1.0), 0.0], np.r_[np.full(n, 6.0), 0.0]
    pack = np.zeros((count, nlgs.PACK_WIDTH))
    nlgs._prepare(body, point, normal, gap, count, q, inv_mass, inv_inertia, MU, DT, pack)
    v0 = np.zeros((n + 1, 3))
    v0[:n, 0] = rng.normal(scale=0.01, size=n)
    v0[:n, 1] = -9.81 * DT
    # the dense H (3 (n + 1) × 2 C) and M⁻¹, for the law check
    h = np.zeros((3 * (n + 1), 2 * count))
    for c, (a, b) in enumerate(body):
        nx, ny = normal[c]
        for k, d in enumerate(((ny, -nx), (nx, ny))):  # t, n
            for body_i, sign in ((a, -1.0), (b, 1.0)):
                rx, ry = point[c] - q[body_i, :2]
                h[3 * body_i : 3 * body_i + 3, 2 * c + k] += sign * np.array([d[0], d[1], rx * d[1] - ry * d[0]])
    m_inv = np.diag(np.column_stack([inv_mass, inv_mass, inv_inertia]).ravel())
    w_full = h.T @ m_inv @ h
    w_blocks = [w_full[2 * c : 2 * c + 2, 2 * c : 2 * c + 2] for c in range(count)]
    r0 = np.zeros((count, 2))
    if warm:  # the bed joints not quiet at the first sweep: only walls can be left out
        r0[normal[:, 1] != 0.0, 1] = 1e-3
    return body, pack, v0, r0, np.maximum(gap, 0.0) / DT, w_blocks, h, m_inv


def _solve(kind, problem, tolerance, cap, check_every=1):
    body, pack, v0, r0 = problem[:4]
    count = body.shape[0]
    v, r, status = v0.copy(), r0.copy(), np.zeros(count, np.int8)
    if kind == "momentum":
        its, res = momentum._nlgs_accelerated(body, pack, count, MU, tolerance, cap, v, r, status, cap)
    else:
        its, res = shrink._nlgs_shrinking(body, pack, count, MU, tolerance, cap, v, r, status, cap, check_every)
    return its, res, v, r, status


@pytest.mark.parametrize("check_every", [1, 4, 16])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_contacts_that_stay_open_leave_momentum_unchanged_bit_for_bit(seed, check_every):
    # Walls 5–10 cm away (biases of 50–100 m/s) never close: the left-out visits would each push nothing,
    # so every sweep, the sweep count, the residual and the outputs are momentum's to the bit.
    problem = _column_between_walls(8, seed, (0.05, 0.1))
    for tolerance, cap in ((1e-9, 5000), (0.0, 37)):
        its_m, res_m, v_m, r_m, st_m = _solve("momentum", problem, tolerance, cap)
        its_s, res_s, v_s, r_s, st_s = _solve("shrink", problem, tolerance, cap, check_every)
        assert (its_s, res_s) == (its_m, res_m)
        assert np.array_equal(v_s, v_m) and np.array_equal(r_s, r_m) and np.array_equal(st_s, st_m)


def _law_violation(problem, v, r):
    """Per contact, |W_αα (r_loc − r_α)| at velocities v: how far α is from Signorini–Coulomb (m/s)."""
    body, pack, v0, r0, bias, w_blocks, h, m_inv = problem
    out = np.empty(body.shape[0])
    for c in range(body.shape[0]):
        w = w_blocks[c]
        u_free = h[:, 2 * c : 2 * c + 2].T @ v.ravel() - w @ r[c]
        rt, rn, _ = nlgs._local_solve(u_free[0], u_free[1], pack, c, MU)
        out[c] = np.hypot(*(w @ (np.array([rt, rn]) - r[c])))
    return out


@pytest.mark.parametrize("check_every", [2, 8])
@pytest.mark.parametrize("seed", [4, 5, 6, 7])
def test_contacts_that_close_are_taken_back_and_the_solve_lands_on_the_unique_velocities(seed, check_every):
    # A cold start and walls 0–0.3 mm away (biases 0–0.3 m/s, the shear's order): bed-joint points and
    # walls open at the first sweep close later, so the left-out set changes. Velocities are unique: a tight shrinking solve must land on
    # momentum's, with impulses in the cone, v the velocity of its impulses, and the law held at every
    # contact — the left-out ones included. At the engine's tolerance the shrinking solve stops on a
    # sweep that met it, and its left-out contacts are open with zero impulse.
    problem = _column_between_walls(8, seed, (0.0, 3e-4), warm=False)
    body, pack, v0, r0, bias, w_blocks, h, m_inv = problem
    its_m, res_m, v_m, r_m, _ = _solve("momentum", problem, 1e-13, 200000)
    its_s, res_s, v_s, r_s, _ = _solve("shrink", problem, 1e-13, 200000, check_every)
    assert res_m <= 1e-13 and res_s <= 1e-13 and its_s < 200000
    np.testing.assert_allclose(v_s, v_m, atol=1e-9)
    np.testing.assert_allclose(v_s.ravel(), v0.ravel() + m_inv @ h @ r_s.ravel(), atol=1e-12)
    assert np.all(r_s[:, 1] >= 0.0) and np.all(np.abs(r_s[:, 0]) <= MU * r_s[:, 1] * (1 + 1e-12))
    assert _law_violation(problem, v_s, r_s).max() <= 1e-11
    its, res, v, r, status = _solve("shrink", problem, 1e-5, 200000, check_every)
    assert res <= 1e-5
    open_now = np.array([(h[:, 2 * c + 1] @ v.ravel()) + bias[c] >= 0.0 for c in range(body.shape[0])])
    zero = (r[:, 0] == 0.0) & (r[:, 1] == 0.0)
    assert np.all(open_now[zero])  # a contact without impulse is open: none was left out closing


def test_the_walls_between_which_contacts_close_do_change_the_left_out_set():
    # The case above is the one it means to test: with its walls, some seed's shrinking path differs from
    # momentum's (a left-out contact closed and was taken back), where far walls never do (first test).
    differs = []
    for seed in (4, 5, 6, 7):
        problem = _column_between_walls(8, seed, (0.0, 3e-4), warm=False)
        a = _solve("momentum", problem, 1e-9, 5000)
        b = _solve("shrink", problem, 1e-9, 5000, 8)
        differs.append(not np.array_equal(a[2], b[2]))
    assert any(differs)


def test_the_engine_uses_the_shrinking_sweep_for_the_first_stage_when_asked(monkeypatch):
    # nlgs.solve sends the accelerated first stage to interleaved._shrinking when shrink.CHECK_EVERY > 0
    # (stalled.py's methods keep their own sweeps): the same result as that kernel on the same input.
    problem = _column_between_walls(6, 9, (0.0, 3e-4), warm=False)
    body, pack, v0, r0 = problem[:4]
    count = body.shape[0]
    model = SimpleNamespace(friction=MU, tolerance=1e-9, max_iterations=5000, solver="nlgs-accel")
    outs = []
    for route in ("engine", "kernel"):
        v, r, status = v0.copy(), r0.copy(), np.zeros(count, np.int8)
        if route == "engine":
            monkeypatch.setattr(shrink, "CHECK_EVERY", 8)
            its = nlgs.solve(body, pack, count, model, v, r, status)
            monkeypatch.setattr(shrink, "CHECK_EVERY", 0)
        else:
            its = interleaved._shrinking(body, pack, count, MU, 1e-9, 5000, v, r, status, momentum.STALL_SWEEPS, 8)
        outs.append((its, v, r, status))
    assert outs[0][0] == outs[1][0] and outs[0][0][1] <= 1e-9
    assert all(np.array_equal(x, y) for x, y in zip(outs[0][1:], outs[1][1:]))
