"""Gauss–Seidel by faces (masonrycli.engine.faces), against dense-matrix references written out in numpy."""

import numpy as np
from test_engine_nlgs import _dense_h, _random_contacts, _slow_sweeps

from masonrycli.engine import faces, nlgs


def _faces_problem(seed):
    # 12 contacts on the 5 body pairs of _random_contacts, sorted by pair as the detection emits them:
    # faces of 2–3 points.
    q, inv_mass, inv_inertia, body, point, normal, gap = _random_contacts(n_contacts=12, seed=seed)
    order = np.lexsort((body[:, 1], body[:, 0]))
    body, point, normal, gap = body[order], point[order], normal[order], gap[order]
    mu, dt, count = 0.5, 1e-3, body.shape[0]
    pack = np.zeros((count, nlgs.PACK_WIDTH))
    nlgs._prepare(body, point, normal, gap, count, q, inv_mass, inv_inertia, mu, dt, pack)
    h = _dense_h(q, body, point, normal)
    m_inv = np.diag(np.column_stack([inv_mass, inv_mass, inv_inertia]).ravel())
    rng = np.random.default_rng(seed + 100)
    v_free = rng.normal(scale=0.1, size=(4, 3))
    v_free[3] = 0.0
    r0 = np.abs(rng.normal(scale=0.01, size=(count, 2)))
    return body, pack, h, m_inv, v_free, r0, mu, np.maximum(gap, 0.0) / dt


def test_face_sweeps_end_on_the_contact_law_with_velocities_of_their_impulses():
    for seed in (1, 4, 6, 9, 10):  # random geometries on which Gauss–Seidel converges (3 and 14 cycle)
        body, pack, h, m_inv, v_free, r0, mu, bias = _faces_problem(seed)
        count = body.shape[0]
        assert len({tuple(p) for p in body}) < count  # some faces have several points
        v = v_free + (m_inv @ h @ r0.ravel()).reshape(-1, 3)
        r = r0.copy()
        status = np.zeros(count, dtype=np.int8)
        units, res = faces.face_sweeps(body, pack, count, mu, 1e-13, 10**5, v, r, status)
        assert res <= 1e-13 and units >= 1
        # v is v_free + M⁻¹ H r for the impulses returned (dense, written out here)
        np.testing.assert_allclose(v, v_free + (m_inv @ h @ r.ravel()).reshape(-1, 3), atol=1e-12)
        # and r satisfies every contact's law: one more point sweep written out with dense H moves nothing
        w = h.T @ m_inv @ h
        w_blocks = [w[2 * c : 2 * c + 2, 2 * c : 2 * c + 2] for c in range(count)]
        v2, r2, res2 = _slow_sweeps(body, w_blocks, h, m_inv, v_free, r.copy(), mu, bias, 1)
        assert res2 < 1e-12
        np.testing.assert_allclose(r2, r, atol=1e-12)


def test_face_sweeps_count_work_in_sweep_units_and_respect_the_cap():
    body, pack, h, m_inv, v_free, r0, mu, bias = _faces_problem(9)  # ~380 sweep units to 1e-13
    count = body.shape[0]
    v = v_free + (m_inv @ h @ r0.ravel()).reshape(-1, 3)
    r = r0.copy()
    status = np.zeros(count, dtype=np.int8)
    units, res = faces.face_sweeps(body, pack, count, mu, 1e-300, 3, v, r, status)
    # a sweep visits every point at least once: at the cap of 3 units at most one sweep's rounds over it
    assert 3 <= units <= 3 + faces.INNER_ROUNDS and res > 0.0
