"""The 51-block wall on a slippery shaken ground slides as one rigid block (a course assignment's check).

At μ = 0.4 the ground's peak acceleration 2π · 3 Hz · 0.5 m/s = 9.42 m/s² is well above μg = 3.92 m/s², while
the wall, 1.2 m high on a 2.4 m base (B/H = 2 > μ), cannot rock: it slides on the ground, its base joint
passing at most μg to it, so no joint above slides either. Its motion relative to the ground is then that of
one block on a harmonically moving ground under Coulomb friction — DESIGN.md §6 case 2's mechanics — here
integrated independently (explicit small steps, the stick and slip phases as the law states them), not by
the engine.
"""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli import api

MU, AMP, FREQ, G = 0.4, 0.5, 3.0, 9.81


def sliding_block(times: np.ndarray, dt: float = 1e-5) -> np.ndarray:
    """Displacement (m) of a rigid block relative to a ground moving at v_g = AMP sin(2π FREQ t), Coulomb
    friction MU, at ``times``: the relative velocity w obeys w' = −a_g − μ g sign(w) while it slides, and
    stays 0 (stick) while |a_g| ≤ μ g; a slip that would reverse stops at 0 instead when it could stick."""
    omega = 2 * np.pi * FREQ
    n = int(round(times[-1] / dt))
    t = np.arange(n + 1) * dt
    ground_acc = AMP * omega * np.cos(omega * t)
    out = np.empty(n + 1)
    u = w = 0.0
    out[0] = 0.0
    for i in range(n):
        a = ground_acc[i]
        if w == 0.0 and abs(a) <= MU * G:
            w_next = 0.0  # stuck: the friction takes the ground's pull
        else:
            direction = np.sign(w) if w != 0.0 else -np.sign(a)  # from rest, it slides against the pull
            w_next = w + (-a - MU * G * direction) * dt
            if w != 0.0 and np.sign(w_next) != np.sign(w):
                # the slip ends within the step: it sticks if friction can hold it, else reverses
                w_next = 0.0 if abs(ground_acc[i + 1]) <= MU * G else w_next
        u += 0.5 * (w + w_next) * dt
        w = w_next
        out[i + 1] = u
    return np.interp(times, t, out)


@pytest.mark.slow
def test_the_wall_slides_on_its_ground_as_one_block():
    run = api.simulate("wall", amp=AMP, freq=FREQ, friction=MU, duration=1.0, record_every=10)
    columns = run.table(top=True, courses=[1])
    t = columns["time (s)"]
    reference = sliding_block(t)
    assert np.ptp(reference) > 0.03  # it does slide: 3 cm and more, back and forth
    for name in ("course 1 ux rel (m)", "top ux rel (m)"):
        # within 1 mm of the rigid block's relative displacement at every frame (31 mm at t = 0.3 s; the
        # engine's contact tolerance and the stepping of the two integrations differ by ~0.3 mm at 1 s)
        assert np.max(np.abs(columns[name] - reference)) < 1e-3, name
    assert np.max(np.abs(run["block_q"][:, :, 2])) < 1e-3  # no block rotates: nothing rocks
