"""The NLGS local solve and sweep checked against the contact law itself (QuantEcon style): the
returned impulses must satisfy Signorini and Coulomb, not match stored numbers."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.engine import nlgs

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
