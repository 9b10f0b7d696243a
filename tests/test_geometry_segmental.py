"""The arch builder's segmental ring (``rise`` < span / 2): a circular arc through both springings and the
crown, radial joints at equal angles, a skewback stone on each pier carrying the inclined springing joint.

The geometry is checked against its definition (R_i = (s²/4 + f²)/(2 f), sin α = s / (2 R_i)), not
against coordinates the builder printed; the limit analysis of the same ring is in
tests/test_limit_ring_mechanisms.py.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from test_geometry_builders import max_pairwise_overlap

from geometry_library import AqueductSpec, GeometryError, build_arch, is_convex, validate_assembly
from masonrycli.scenario.builtin import builtin

from cli_helpers import assert_one_line_error, invoke

Y_S = 17 * 0.20  # the default piers' top


@pytest.mark.parametrize(
    "span, rise, ring, voussoirs, pier",
    [(8.0, 2.0, 0.5, 30, 1.0), (8.0, 3.0, 0.6, 21, 0.9), (3.6, 0.6, 0.35, 12, 0.9), (8.0, 0.5, 0.4, 25, 0.9)],
)
def test_a_segmental_ring_lies_on_its_circle_with_radial_joints_on_skewbacks(span, rise, ring, voussoirs, pier):
    a = build_arch(span=span, rise=rise, ring_thickness=ring, voussoirs=voussoirs, pier_width=pier)
    radius = (span**2 / 4 + rise**2) / (2 * rise)
    alpha = math.asin(span / (2 * radius))
    centre = np.array([0.0, Y_S - (radius - rise)])

    names = [b.name for b in a.blocks]
    assert a.block_count == 4 * 17 + voussoirs + 2
    assert names[34] == "left-skewback" and names[35 + voussoirs] == "right-skewback"
    assert max_pairwise_overlap(a) < 1e-9
    assert all(is_convex(b.vertices) for b in a.blocks)
    assert validate_assembly(a) == []

    ring_blocks = a.blocks[35 : 35 + voussoirs]
    assert [b.name for b in ring_blocks] == [f"v{k:02d}" for k in range(1, voussoirs + 1)]
    for b in ring_blocks:
        xy = b.vertices
        r = np.hypot(*(xy - centre).T)
        np.testing.assert_allclose(np.sort(r), [radius] * 2 + [radius + ring] * 2, rtol=1e-12)
        ang = np.arctan2(*(xy - centre).T[::-1])
        assert ang.max() - ang.min() == pytest.approx(2 * alpha / voussoirs, rel=1e-9)
        # each vertex's partner at the other radius lies on the same ray from the centre: radial joints
        inner, outer = xy[r < radius + ring / 2], xy[r > radius + ring / 2]
        assert sorted(np.round(np.arctan2(*(inner - centre).T[::-1]), 9)) == sorted(
            np.round(np.arctan2(*(outer - centre).T[::-1]), 9)
        )
    crown_y = max(b.vertices[:, 1].max() for b in ring_blocks) - ring  # the extrados crown, less the ring
    intrados_y = [v[1] for b in ring_blocks for v in b.vertices if abs(v[0]) < 1e-12]
    if voussoirs % 2 == 0:
        assert min(intrados_y) == pytest.approx(Y_S + rise, abs=1e-12)
    assert crown_y == pytest.approx(Y_S + rise, rel=0.02)  # within the chord's sag

    # the skewback: the springing voussoir's face, up to t cos α above the pier top, level to the outer face
    left = a.blocks[34].vertices
    x_e, y_e = -(radius + ring) * math.sin(alpha), Y_S + ring * math.cos(alpha)
    expected = {(-span / 2, Y_S), (-span / 2 - pier, Y_S), (-span / 2 - pier, y_e), (x_e, y_e)}
    assert {tuple(np.round(p, 9)) for p in left} == {tuple(np.round(p, 9)) for p in expected}
    face = ring_blocks[0].polygon.intersection(a.blocks[34].polygon)
    assert face.length == pytest.approx(ring, rel=1e-9)  # the whole springing joint rests on it
    right = a.blocks[35 + voussoirs].vertices
    assert sorted(map(tuple, np.round(right * [-1, 1], 9))) == sorted(map(tuple, np.round(left, 9)))


def test_a_rise_of_half_the_span_is_the_semicircle_bit_for_bit():
    semi, same = build_arch(span=8.0), build_arch(span=8.0, rise=4.0)
    assert [b.name for b in semi.blocks] == [b.name for b in same.blocks]
    for p, q in zip(semi.blocks + semi.supports, same.blocks + same.supports):
        assert np.array_equal(p.vertices, q.vertices)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(span=8.0, rise=4.5), "rise 4.5 m is more than half the span .4 m."),
        (dict(rise=0.0), "rise must be"),
        (dict(rise=1e-6), "rise 1e-06 m is absurd"),
    ],
)
def test_a_rise_beyond_the_semicircle_or_absurd_is_refused(kwargs, match):
    with pytest.raises(GeometryError, match=match):
        build_arch(**kwargs)


def test_a_rise_leaving_a_sliver_of_a_skewback_is_refused():
    """Rise 1.7999999 m on the default 3.6 m span: springing joints all but vertical, skewbacks 2e-8 m thick
    (the engine hit its sweep cap at 6 steps/s). The skewback is t cos α with cos α = (R − F)/R; at the
    largest rise the message gives, 0.1 mm or a little more."""
    with pytest.raises(GeometryError, match=r"rise 1.7999999 m leaves skewbacks 1.9e-05 mm thick .* at most 1.7994 m"):
        build_arch(rise=1.7999999)
    for rise in (1.7994, 1.79):
        a = build_arch(rise=rise)
        radius = (1.8**2 + rise**2) / (2 * rise)
        skew = a.blocks[34].vertices[:, 1]
        assert skew.max() - skew.min() == pytest.approx(0.35 * (radius - rise) / radius, rel=1e-9)
        assert skew.max() - skew.min() >= 1e-4


def test_the_aqueduct_refuses_a_segmental_arch():
    with pytest.raises(GeometryError, match="the aqueduct's arch is semicircular"):
        AqueductSpec(rise=1.0).build()
    assert_one_line_error(invoke("build", "aqueduct", "--rise", "1", "--out", "x.geojson"), "No such option: --rise")


def test_build_and_simulate_take_rise(tmp_path):
    out = tmp_path / "bridge.geojson"
    result = invoke("build", "arch", "--span", "8", "--rise", "2", "--ring-thickness", "0.5", "--out", out)
    assert result.exit_code == 0, result.output
    names = [f["properties"]["name"] for f in json.loads(out.read_text())["features"]]
    assert "left-skewback" in names and "right-skewback" in names
    assert builtin("arch", span=8.0, rise=2.0, ring_thickness=0.5).assembly.block_count == 98 + 2
    assert_one_line_error(
        invoke("build", "arch", "--span", "8", "--rise", "5", "--out", tmp_path / "x.geojson"),
        "--rise and --span: rise 5 m is more than half the span",
    )
