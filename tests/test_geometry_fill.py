"""Fill over a structure (geometry_library/fill.py) against shapely's polygon algebra and a closed form, and
the model's carried mass against the parallel-axis theorem."""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import box
from shapely.ops import unary_union

from geometry_library.blocks import Block, GeometryError
from geometry_library.builders import build_aqueduct, build_arch
from geometry_library.fill import fill_over
from masonrycli.model import build_model
from masonrycli.scenario.builtin import builtin

BRIDGE = dict(span=8.0, rise=2.0, ring_thickness=0.5, pier_width=3.0, pier_courses=5)


def test_semicircle_filled_to_its_crown_holds_the_closed_form_area():
    """Fill to the crown of the default semicircle (R_e = 2.15 m, 30 chords of 6°, piers' outer faces at
    ±2.7 m): the box 5.4 × 2.15 m less the fan under the extrados chords, 30 × ½ R_e² sin 6°."""
    assembly = build_arch(fill_to=2.15, fill_density=1800.0)
    re, outer = 2.15, 2.7
    area = 2 * outer * re - 30 * 0.5 * re * re * math.sin(math.radians(6.0))
    carried = sum(b.carried_mass for b in assembly.blocks)
    assert carried == pytest.approx(1800.0 * area * 1.0, rel=1e-12)
    assert assembly.blocks[0].carried_mass == 0.0  # the pier's bottom course is buried, not under fill


@pytest.mark.parametrize("fill", [dict(fill_cover=0.4), dict(fill_to=1.5)])
def test_each_blocks_fill_is_the_region_above_it_up_to_the_level(fill):
    """Per block, the fill is the part of the box over its exposed top, up to the level, that no block
    occupies (shapely: the strip over its top edge minus the union of the blocks); fill_to = 1.5 m is below
    the crown (3 m over the springing line at 1 m): the ring stands proud of it, no fill over the crown."""
    assembly = build_arch(**BRIDGE, **fill)
    blocks = assembly.blocks
    level = 1.0 + fill["fill_to"] if "fill_to" in fill else max(b.polygon.bounds[3] for b in blocks) + 0.4
    solid = unary_union([b.polygon for b in blocks])
    got = fill_over(blocks, level, -7.0, 7.0)
    for k, block in enumerate(blocks):
        if not block.name.startswith("v") and not block.name.endswith("skewback"):
            assert got.area[k] == 0.0
            continue
        xy = np.asarray(block.polygon.exterior.coords)
        top = xy[:, 1].max()
        if block.name == "left-skewback":
            lo, hi = -7.0, xy[xy[:, 1] == top, 0].max()
        elif block.name == "right-skewback":
            lo, hi = xy[xy[:, 1] == top, 0].min(), 7.0
        else:  # a voussoir's extrados chord: its two highest vertices
            upper = xy[np.argsort(xy[:-1, 1])[-2:]]
            lo, hi = upper[:, 0].min(), upper[:, 0].max()
        pieces = box(lo, xy[:, 1].min(), hi, max(level, top)).difference(solid)
        # the fill is what of the box reaches the level (not the void under the ring)
        region = unary_union([p for p in getattr(pieces, "geoms", [pieces]) if p.bounds[3] >= level - 1e-9])
        region = region.intersection(box(lo, -1.0, hi, level))
        if region.area < 1e-12:
            assert got.area[k] == pytest.approx(0.0, abs=1e-12)
            continue
        assert got.area[k] == pytest.approx(region.area, rel=1e-9)
        np.testing.assert_allclose(got.centroid[k], [region.centroid.x, region.centroid.y], atol=1e-9)


def test_a_carried_mass_moves_the_centre_of_mass_and_adds_its_parallel_axis_inertia():
    """A 1 × 1 block of 100 kg carrying 300 kg at (1, 1): centre (0.5, 0.5) + ¾ (0.5, 0.5), inertia
    100/6 + 100 |Δ|² + 300 |Δ'|²."""
    from geometry_library.blocks import Assembly
    from masonrycli.scenario.scenario import Material, RunConfig, Scenario

    block = Block(box(0, 0, 1, 1), "b", 100.0, 1.0, carried_mass=300.0, carried_at=(1.0, 1.0))
    sc = Scenario(name="t", run=RunConfig(), material=Material(density=100.0), assembly=Assembly((block,)), motions=())
    m = build_model(sc)
    np.testing.assert_allclose(m.body_q0[0, :2], [0.875, 0.875])
    d_block, d_mass = 2 * 0.375**2, 2 * 0.125**2
    assert m.body_mass[0] == 400.0
    assert m.body_inertia[0] == pytest.approx(100.0 / 6 + 100 * d_block + 300 * d_mass, rel=1e-12)
    assert m.block_carried_mass[0] == 300.0


def test_the_bridge_fill_is_in_the_model_mass():
    bare, filled = (build_model(builtin("arch", **BRIDGE, **f)) for f in ({}, {"fill_cover": 0.3}))
    fill = sum(b.carried_mass for b in builtin("arch", **BRIDGE, fill_cover=0.3).assembly.blocks)
    n = bare.block_count
    assert filled.body_mass[:n].sum() == pytest.approx(bare.body_mass[:n].sum() + fill, rel=1e-12)
    assert filled.block_carried_mass.sum() == pytest.approx(fill, rel=1e-12)


@pytest.mark.parametrize(
    "options, said",
    [
        (dict(fill_cover=-0.2), "fill_cover -0.2 m must be >= 0 (a cover is measured up from the ring's top"),
        (dict(fill_to=0.5, fill_cover=0.5), "the fill's level is given twice (a height and a cover): give one"),
        (dict(fill_to=2.0, fill_density=-1800.0), "fill_density must be a positive number, got -1800.0"),
        (dict(fill_density=1800.0), "fill_density without fill_to or fill_cover"),
        (dict(fill_to=0.0), "fill_to must be a positive number"),
    ],
)
def test_bad_fill_options_are_one_line(options, said):
    with pytest.raises(GeometryError, match=None) as err:
        build_arch(**BRIDGE, **options)
    assert said in str(err.value) and "\n" not in str(err.value)


def test_the_aqueduct_refuses_fill():
    with pytest.raises(GeometryError, match="spandrel is masonry walls, not fill"):
        build_aqueduct(fill_to=2.0)


@pytest.mark.parametrize("reach, falls", [(0.12, False), (0.25, True)])
def test_the_engine_feels_a_carried_mass_where_it_rides(reach, falls):
    """A 0.2 × 1 m block on the ground carrying three times its mass at (reach, 0.5) (a fill column off to one
    side): the common centre of mass is at x = (0.1 + 3 reach) / 4, over its base (0 … 0.2) for reach 0.12
    (0.115: it stands), past its right toe for reach 0.25 (0.2125: it tips over), which a body force at its
    own centroid, or the mass at its centroid, would never do."""
    from geometry_library.blocks import Assembly, Support
    from masonrycli.run import Simulation
    from masonrycli.scenario.motion import Fixed
    from masonrycli.scenario.scenario import Material, RunConfig, Scenario

    block = Block(box(0, 0, 0.2, 1.0), "b", 2000.0, 1.0, carried_mass=3 * 400.0, carried_at=(reach, 0.5))
    ground = Support(box(-1.0, -0.5, 1.0, 0.0), "ground")
    sc = Scenario(
        name="t",
        run=RunConfig(duration=0.6),
        material=Material(density=2000.0),
        assembly=Assembly((block,), (ground,)),
        motions=(Fixed(),),
    )
    sim = Simulation(sc)
    for _ in range(sc.run.n_steps):
        sim.step()
    turned = abs(float(sim.state.body_q[0, 2]))
    assert (turned > 0.05) is falls, turned


def test_the_fill_survives_geojson_and_a_scenario_file(tmp_path):
    """`masonry build arch --fill-cover … --out x.geojson` and a dumped scenario keep each block's fill."""
    from geometry_library.io import read_geojson, write_geojson
    from masonrycli.scenario.toml_file import dump_scenario, loads_scenario

    scenario = builtin("arch", **BRIDGE, fill_cover=0.3)
    want = [(b.carried_mass, b.carried_at) for b in scenario.assembly.blocks]
    back = read_geojson(write_geojson(scenario.assembly, tmp_path / "b.geojson"))
    assert [(b.carried_mass, b.carried_at) for b in back.blocks] == want
    again = loads_scenario(dump_scenario(scenario))
    assert [(b.carried_mass, b.carried_at) for b in again.assembly.blocks] == want


@pytest.mark.parametrize(
    "carried, said",
    [
        ({"carried_mass": 1e300, "carried_at": [0.5, 1.5]}, "carried_mass 1e+300 kg is absurd"),
        ({"carried_mass": 500.0, "carried_at": [1e9, 1.5]}, "is 1e+09 m from the block's centroid, absurd"),
    ],
)
def test_an_absurd_carried_fill_in_a_file_is_refused_in_one_line(tmp_path, carried, said):
    """A 1 m block carrying 1e300 kg ran and was 'collapsed at t = 0.001 s'; one carrying 500 kg a million km
    away, 'no equilibrium' in limit: a typo in a GeoJSON's properties or a [[block]] table, refused naming it."""
    import json

    from cli_helpers import assert_one_line_error, invoke

    square = [[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]
    ground = [[-1, -1], [2, -1], [2, 0], [-1, 0], [-1, -1]]
    features = [
        {
            "type": "Feature",
            "properties": {"role": r, "name": n, **p},
            "geometry": {"type": "Polygon", "coordinates": [c]},
        }
        for r, n, p, c in (("block", "b", carried, square), ("support", "g", {}, ground))
    ]
    path = tmp_path / "w.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    assert_one_line_error(invoke("check", path), 'block 1 ("b"): carried_', said)
    toml = tmp_path / "w.toml"
    toml.write_text(
        f"[[block]]\nname = 'b'\npolygon = {square[:-1]}\ncarried_mass = {carried['carried_mass']!r}\n"
        f"carried_at = {carried['carried_at']!r}\n[[support]]\nname = 'g'\npolygon = {ground[:-1]}\n"
    )
    assert_one_line_error(invoke("check", toml), said)


def test_a_runs_parameters_say_the_fill_the_view_does_not_draw():
    """The recording draws the blocks, not their fill: a filled bridge's Parameters said a builder option at
    most ('fill_cover', nothing for a GeoJSON of one), not the mass it carries. Now fill_mass_kg, the blocks'
    carried masses; none without a fill."""
    from masonrycli.execute import run_metadata
    from masonrycli.run import Simulation

    filled = builtin("arch", **BRIDGE, fill_cover=0.3)
    meta = run_metadata(filled, Simulation(filled))
    assert meta["fill_mass_kg"] == pytest.approx(sum(b.carried_mass for b in filled.assembly.blocks), rel=1e-12)
    bare = builtin("arch", **BRIDGE)
    assert "fill_mass_kg" not in run_metadata(bare, Simulation(bare))


def test_check_names_the_fill_it_would_run_with(tmp_path):
    """`masonry check` on a scenario file of the filled bridge: a `fill` row with the mass its blocks carry."""
    from cli_helpers import invoke, words

    path = tmp_path / "bridge.toml"
    options = "".join(f"{k} = {v}\n" for k, v in BRIDGE.items())
    path.write_text(f'name = "bridge"\n[structure]\nbuilder = "arch"\n{options}fill_cover = 0.3\n')
    result = invoke("check", str(path), "--no-recording")
    assert result.exit_code == 0, result.output
    fill = sum(b.carried_mass for b in builtin("arch", **BRIDGE, fill_cover=0.3).assembly.blocks)
    assert f"fill {fill:.6g} kg carried by the blocks under it" in words(result.output.replace("│", " "))


def test_fill_slips_are_said_in_the_words_the_user_typed(tmp_path):
    """--fill-density alone said 'without fill_to or fill_cover' (a file's keys) on the command line; a
    [[block]] with carried_at and no carried_mass ran as carrying nothing, without a word."""
    from cli_helpers import assert_one_line_error, invoke

    assert_one_line_error(
        invoke("simulate", "arch", "--fill-density", "1800"), "--fill-density without --fill-to or --fill-cover: give"
    )
    scenario = tmp_path / "s.toml"
    scenario.write_text("[structure]\nbuilder = 'arch'\nfill_density = 1800.0\n")
    assert_one_line_error(invoke("check", scenario), "fill_density without fill_to or fill_cover")  # keys in a file
    square = [[0, 0], [1, 0], [1, 1], [0, 1]]
    scenario.write_text(
        f"[[block]]\nname = 'b'\npolygon = {square}\ncarried_at = [0.5, 1.5]\n"
        "[[support]]\nname = 'g'\npolygon = [[-1, -1], [2, -1], [2, 0], [-1, 0]]\n"
    )
    assert_one_line_error(invoke("check", scenario), "[[block]] #1", "carried_at without carried_mass: give the mass")
