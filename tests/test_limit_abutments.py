"""Solid and fixed abutments (`--abutments solid|fixed`): each pier and its skewback one block, or that block
the rigid foundation. A fixed abutment is the four-hinge reference's rigid springer, so the LP must find the
reference's λ and hinges, at the ordinary μ = 0.6, with no joint sliding."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.ops import unary_union
from test_limit_ring_mechanisms import _joint, _unordered, reference, segmental_reference_ring

from geometry_library.blocks import GeometryError
from geometry_library.builders import build_aqueduct, build_arch
from masonrycli.limit import LiveLoad, analyse
from masonrycli.scenario.builtin import builtin

BRIDGE = dict(span=8.0, rise=2.0, ring_thickness=0.5, pier_width=3.0, pier_courses=5)


def test_a_solid_abutment_is_its_pier_and_skewback_in_one_block():
    courses, solid = build_arch(**BRIDGE), build_arch(**BRIDGE, abutments="solid")
    names = [b.name for b in solid.blocks]
    assert names[0] == "left-abutment" and names[-1] == "right-abutment" and len(names) == 32
    for side in ("left", "right"):
        parts = [b for b in courses.blocks if b.name.startswith(f"{side}-pier") or b.name == f"{side}-skewback"]
        block = solid.blocks[names.index(f"{side}-abutment")]
        assert block.polygon.area == pytest.approx(sum(b.polygon.area for b in parts), rel=1e-12)
        union = unary_union([b.polygon for b in parts])
        assert block.polygon.symmetric_difference(union).area < 1e-9  # exactly the stones it replaces


@pytest.mark.parametrize("voussoirs", [20, 31])
def test_fixed_abutments_are_the_references_rigid_springers(voussoirs):
    """μ = 0.6: the ring on fixed abutments turns on four hinges, as the reference, which knows no sliding."""
    sc = builtin("arch", **BRIDGE, voussoirs=voussoirs, abutments="fixed")
    i, e = segmental_reference_ring(voussoirs)
    i, e = i + (0, 1.0), e + (0, 1.0)  # the springing line: 5 courses of 0.20 m
    expected, (hinged, _) = reference(i, e, "horizontal")
    r = analyse(sc, LiveLoad("horizontal"))
    assert r.load_factor == pytest.approx(expected, rel=1e-6)
    vw = max(2, len(str(voussoirs)))
    want = {_joint(k, voussoirs, "left-foundation", "right-foundation", lambda k: f"v{k + 1:0{vw}d}") for k in hinged}
    assert _unordered(r.hinges) == want and r.sliding_joints == []
    assert r.model.block_count == voussoirs


def test_a_solid_abutment_stands_under_its_arch_and_fill_in_the_engine():
    """The engine at rest for 0.3 s: the bridge on solid abutments, filled, does not move (λ > 0 under the
    dead load: it has an equilibrium)."""
    from masonrycli.run import Simulation

    sc = builtin("arch", **BRIDGE, abutments="solid", fill_cover=0.3, settlement=0.0, duration=0.3)
    sim = Simulation(sc)
    for _ in range(sim.model.n_steps):
        sim.step()
    moved = np.abs(sim.state.body_q[: sim.model.block_count, :2] - sim.model.body_q0[: sim.model.block_count, :2])
    assert moved.max() < 1e-5


def test_bad_abutments_are_one_line():
    with pytest.raises(GeometryError, match="abutments must be one of courses, solid, fixed, got 'hollow'"):
        build_arch(abutments="hollow")
    with pytest.raises(GeometryError, match="the aqueduct's piers are courses"):
        build_aqueduct(abutments="solid")
