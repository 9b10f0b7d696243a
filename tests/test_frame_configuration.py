"""Which configuration a :class:`~masonrycli.outputs.frame.Frame`'s contacts belong to: the step's intermediate
one, q_m = q_n + (1 − θ)·dt·v_n = block_q − θ·dt·block_v (its end-of-step pose and velocity), where the engine
detected them and the block stress takes its centroids (engine/integrate.py, run.py). A student's hand
computation of a block's stress with the frame's end-of-step centroids was off by 8.8e-5 relative, with the
average of two frames' centroids by 3.8e-7; with q_m it is the engine's to rounding.

The stress here is computed independently of masonrycli.analysis: DESIGN.md's σ_b = (1/V_b) Σ GI ⊗ R, with V_b
the polygon's shoelace area times the thickness, R the force on the block (+contact_force on body b, − on a)."""

from __future__ import annotations

import numpy as np

from masonrycli import api


def _stress(frame, centroids: np.ndarray, volume: np.ndarray) -> np.ndarray:
    """(N, 2, 2) σ_b = (1/V_b) Σ_contacts GI ⊗ R, plain loops over the frame's contacts."""
    sigma = np.zeros((len(volume), 2, 2))
    for (a, b), point, force in zip(frame.contact_body, frame.contact_point, frame.contact_force, strict=True):
        for body, on in ((a, -force), (b, force)):
            if body < len(volume):  # supports get no stress
                sigma[body] += np.outer(point - centroids[body], on)
    return sigma / volume[:, None, None]


def _volumes(scenario) -> np.ndarray:
    """m³: each block's polygon area (shoelace) times the thickness."""
    areas = []
    for block in scenario.assembly.blocks:
        x, y = np.asarray(block.vertices, dtype=float).T
        areas.append(0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    return np.array(areas) * scenario.material.thickness


def test_a_frame_s_contacts_give_its_block_stress_at_the_step_s_intermediate_configuration():
    options = {"blocks": 12, "amp": 0.5, "freq": 3.0, "duration": 0.2, "theta": 0.6}  # θ ≠ ½: not the midpoint
    frames = []
    api.simulate("wall", on_frame=frames.append, **options)
    sc = api.scenario("wall", **options)
    assert not any(b.carried_mass for b in sc.assembly.blocks)  # G is the block's centroid (tensors.py)
    volume, theta, dt = _volumes(sc), sc.run.theta, sc.run.dt
    for frame in frames[-3:]:  # shaken: the blocks move, so the configurations differ
        engine = frame.tensors["block_stress"]
        scale = np.abs(engine).max()
        intermediate = frame.block_q[:, :2] - theta * dt * frame.block_v[:, :2]
        assert np.abs(_stress(frame, intermediate, volume) - engine).max() <= 1e-12 * scale
        end_of_step = np.abs(_stress(frame, frame.block_q[:, :2], volume) - engine).max()
        assert end_of_step > 1e-7 * scale  # the end-of-step centroids are not the contacts' configuration
