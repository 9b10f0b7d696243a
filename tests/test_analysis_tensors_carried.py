"""A carried fill changes no cell's geometry: the bridge's cells are built on its blocks' own centroids.

The fill is a mass riding on the blocks under it (``Block.carried_mass``); it moves each body's centre of mass
up to 1.2 m into the fill. The cells (the paper's triangulation, strain rate, cumulated strain, the chain's
strain rate) must not follow it: under the same motion of the same stones, the filled arch's kinematic
tensors are the bare arch's (a metamorphic check, independent of how either is computed). The block stress
keeps the body's centre of mass (analysis/tensors.py, "Which point of a block"), checked here against
Σ (I − G) ⊗ F / V summed in numpy.
"""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.run import Simulation
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

BRIDGE = {"span": 8.0, "rise": 2.0, "ring_thickness": 0.5, "pier_width": 3.0, "pier_courses": 5}
KINEMATIC = [
    "cell_strain_rate",
    "cell_strain",
    "chain_strain_rate",
    "cell_principal_strain_rate",
    "cell_principal_strain_rate_angle",
    "cell_volumetric_strain",
    "cell_deviatoric_strain",
]


@pytest.fixture(scope="module")
def arches():
    def sim(**fill):
        return Simulation(scenario_from_builder("arch", {**BRIDGE, **fill}, RunConfig(), Material(), {}))

    return sim(), sim(fill_cover=0.3)


def _turned(theta: np.ndarray, offset: np.ndarray) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * offset[:, 0] - s * offset[:, 1], s * offset[:, 0] + c * offset[:, 1]], axis=1)


def test_the_fill_moves_the_bodies_centres_not_the_blocks_centroids(arches):
    bare, filled = arches
    n = bare.model.block_count
    off = filled.model.block_centroid
    assert np.hypot(*off.T).max() > 1.0  # the piers' top courses: 1.2 m under their centre of mass
    assert not bare.model.block_centroid.any()  # exactly 0: a bare block's body centre is its centroid
    np.testing.assert_allclose(filled.model.body_q0[:n, :2] + off, bare.model.body_q0[:n, :2], atol=1e-12)


def test_a_filled_arch_has_the_bare_arch_cells_under_the_same_motion(arches):
    bare, filled = arches
    n = bare.model.block_count
    np.testing.assert_array_equal(filled.triangles, bare.triangles)
    rng = np.random.default_rng(7)
    off = filled.model.block_centroid
    centroid0 = bare.model.body_q0[:n, :2]
    s = bare.solver
    c = s.detect(bare.state.body_q)
    body, point = s.contact_body[:c].copy(), s.contact_point[:c].copy()
    dt = 1e-3
    for step in range(5):  # the stones' own motion: centroids moved by d, turned by θ, at speeds u, ω
        theta = rng.normal(0.0, 0.02, n)
        q_own = np.c_[centroid0 + rng.normal(0.0, 1e-3, (n, 2)), theta]
        v_own = np.c_[rng.normal(0.0, 0.01, (n, 2)), rng.normal(0.0, 0.01, n)]
        r = _turned(theta, off)  # the centroid seen from the filled body's centre of mass
        omega = v_own[:, 2]
        q_com = np.c_[q_own[:, :2] - r, theta]
        v_com = np.c_[v_own[:, 0] + omega * r[:, 1], v_own[:, 1] - omega * r[:, 0], omega]
        force = rng.normal(0.0, 1e3, (c, 2))
        bare.tensors.step(q_own, v_own, body, point, force, dt)
        filled.tensors.step(q_com, v_com, body, point, force, dt)
    ours, theirs = filled.tensors.fields(), bare.tensors.fields()
    for key in KINEMATIC:  # on the bodies' centres: strain rate 0.047 off (of 0.134 1/s), strain 1.8e-4 (2.3e-4)
        assert np.isfinite(theirs[key]).any(), key
        np.testing.assert_allclose(ours[key], theirs[key], rtol=1e-9, atol=1e-14, err_msg=key)
    # the stress about each body's centre of mass, summed here: (I − G) ⊗ F on b, −F on a
    reference = np.zeros((n, 2, 2))
    for (a, b), p, f in zip(body, point, force):
        for k, sign in ((a, -1.0), (b, 1.0)):
            if k < n:
                reference[k] += sign * np.outer(p - q_com[k, :2], f)
    reference /= filled.model.block_volume[:, None, None]
    np.testing.assert_allclose(ours["block_stress"], reference, rtol=1e-9, atol=1e-9)
