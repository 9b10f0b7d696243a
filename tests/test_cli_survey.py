"""A heritage researcher's traced wall on the command line: check, limit and run a GeoJSON in Lambert-93 with
slightly non-convex stones and tracing slips (--convex-hull, --trim-overlaps, --units, --flip-y)."""

import json

import numpy as np
import pytest
import surveyed_wall

from cli_helpers import assert_one_line_error, invoke, words


@pytest.fixture
def traced(tmp_path):
    """72 stones traced to the mm in Lambert-93, slips of up to 1 mm a vertex, 4 stones dented 2 mm."""
    path = tmp_path / "wall.geojson"
    surveyed_wall.write(path, offset=surveyed_wall.LAMBERT93, dent=2e-3, dents=4)
    return path


def test_check_a_traced_wall_reads_it_with_the_options_it_names(traced):
    result = invoke("check", traced)  # each refusal names the option that mends it
    assert_one_line_error(result, 'block 4 ("id-4"): polygon is not convex', "add (651000, 6861000)", "--convex-hull")
    result = invoke("check", traced, "--convex-hull")
    assert_one_line_error(result, "overlap by", "--trim-overlaps 0.003")
    result = invoke("check", traced, "--convex-hull", "--trim-overlaps", "0.003")
    assert result.exit_code == 0, result.output
    said = words(result.output)
    assert "wall.geojson — valid" in said and "72" in said
    assert "read moved by (-651000, -6861000) m" in said
    assert "4 non-convex polygons read as their convex hulls (--convex-hull)" in said
    assert "overlapping pairs trimmed along the chord of their overlap" in said


def test_the_reading_options_are_refused_for_what_is_no_geometry_file(tmp_path):
    assert_one_line_error(
        invoke("check", "wall", "--units", "mm"), "--units: reads a GeoJSON / WKT file; wall is not one"
    )
    assert_one_line_error(invoke("limit", "arch", "--flip-y"), "--flip-y: reads a GeoJSON / WKT file")
    assert_one_line_error(
        invoke("check", tmp_path / "w.geojson", "--units", "ft"), "--units ft: expected one of m, cm, mm"
    )
    assert_one_line_error(
        invoke("run", "x.geojson", "--trim-overlaps", "0.5"), "--trim-overlaps 0.5: must be in (0, 0.1]"
    )


def test_limit_of_a_wall_in_lambert93_is_that_of_the_wall_at_the_origin(tmp_path):
    # the same stones (exact, no slip) at the origin and 6 861 km north: the same joints, the same λ
    exact = dict(slip=0.0, ndigits=9)
    surveyed_wall.write(tmp_path / "local.geojson", **exact)
    surveyed_wall.write(tmp_path / "l93.geojson", offset=surveyed_wall.LAMBERT93, **exact)
    local = invoke("limit", tmp_path / "local.geojson", "--json")
    far = invoke("limit", tmp_path / "l93.geojson", "--json")
    assert local.exit_code == 0 and far.exit_code == 0, far.output
    lam = [json.loads(r.stdout)["load_factor"] for r in (local, far)]
    assert lam[1] == pytest.approx(lam[0], rel=1e-6)  # the LP solved to its tolerance at 234 m, not 0


def test_a_wall_in_millimetres_with_y_down_checks_as_in_metres_with_y_up(tmp_path):
    surveyed_wall.write(tmp_path / "m.geojson", slip=0.0, ndigits=9)
    surveyed_wall.write(tmp_path / "mm.geojson", slip=0.0, ndigits=6, scale=1000.0, flip_y=True)
    result = invoke("check", tmp_path / "mm.geojson", "--units", "mm", "--flip-y")
    metres = invoke("check", tmp_path / "m.geojson")
    assert result.exit_code == 0 and metres.exit_code == 0, result.output
    mass = [next(ln for ln in r.output.splitlines() if "mass" in ln).split("│")[2] for r in (result, metres)]
    assert mass[0] == mass[1]


def test_limit_of_a_traced_wall_trimmed_is_near_that_of_the_exact_stones(tmp_path):
    # slips of ±0.3 mm a vertex (gaps within the 1 mm at which limit finds joints), overlaps trimmed along their
    # chords: λ within 3 % of the exact stones' (0.5519). Cut through the overlaps' middles, tilted, the
    # ground's top was lowered under other stones: 'no equilibrium', 31 of 72 blocks giving way
    surveyed_wall.write(tmp_path / "exact.geojson", slip=0.0, ndigits=9)
    surveyed_wall.write(tmp_path / "traced.geojson", slip=3e-4, ndigits=6)
    exact = invoke("limit", tmp_path / "exact.geojson", "--json")
    traced = invoke("limit", tmp_path / "traced.geojson", "--trim-overlaps", "0.001", "--json")
    assert exact.exit_code == 0 and traced.exit_code == 0, traced.output
    lam = [json.loads(r.stdout)["load_factor"] for r in (exact, traced)]
    assert lam[1] == pytest.approx(lam[0], rel=0.03)


def block_above_ground(tmp_path, gap: float):
    """A 0.4 × 0.8 m block drawn ``gap`` m above a fixed ground, as a GeoJSON file."""
    block = [[0, gap], [0.4, gap], [0.4, 0.8 + gap], [0, 0.8 + gap], [0, gap]]
    ground = [[-1, -0.5], [1.4, -0.5], [1.4, 0], [-1, 0], [-1, -0.5]]
    features = [
        {"type": "Feature", "properties": {"name": "B"}, "geometry": {"type": "Polygon", "coordinates": [block]}},
        {
            "type": "Feature",
            "properties": {"role": "support"},
            "geometry": {"type": "Polygon", "coordinates": [ground]},
        },
    ]
    path = tmp_path / "gap.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


@pytest.mark.slow
def test_limit_settle_lets_a_block_drawn_apart_come_to_rest_first(tmp_path):
    # 2 mm above its ground: no joint within the engine's 1 mm, nothing holds it, and the refusal names the
    # option; settled, it stands on the ground and tips about its toe at λ = B / H = 0.5 (μ = 0.6: no sliding)
    path = block_above_ground(tmp_path, 0.002)
    assert_one_line_error(invoke("limit", path), "no equilibrium", "--settle 0.5")
    result = invoke("limit", path, "--settle", "0.2", "--json")
    assert result.exit_code == 0, result.output
    answer = json.loads(result.stdout)
    assert answer["load_factor"] == pytest.approx(0.5, rel=1e-3)
    assert answer["settled"]["block"] == "B" and answer["settled"]["largest_move"] == pytest.approx(0.002, rel=0.05)
    table = invoke("limit", path, "--settle", "0.2").output
    assert "settled" in table and "0.2 s under its own weight (--settle)" in table and "touches nothing" not in table


@pytest.mark.slow
def test_limit_settle_refuses_a_wall_that_does_not_stand_as_drawn(tmp_path):
    # 0.3 m above the ground the block falls 0.3 m: far beyond --verify's collapse threshold (0.1 × its radius)
    path = block_above_ground(tmp_path, 0.3)
    result = invoke("limit", path, "--settle", "0.5", "--out", tmp_path / "m.rrd")
    assert_one_line_error(result, "the wall does not stand as drawn", "B moved more than")
    assert not (tmp_path / "m.rrd").exists()
    assert_one_line_error(invoke("limit", path, "--settle", "20"), "--settle 20: must be in (0, 10] s")


@pytest.mark.slow
def test_a_carried_fill_settles_with_its_block(tmp_path):
    # --settle moved each block's polygon and left a carried fill's point where it was drawn: the 0.4 × 0.8 block
    # drawn 2 mm above its ground, carrying its own mass lumped 0.1 m above its top, comes down 2 mm with it
    from geometry_library.io import read_geojson
    from masonrycli.scenario.target import target_scenario
    from masonrycli.settle import settle

    path = block_above_ground(tmp_path, 0.002)
    data = json.loads(path.read_text())
    data["features"][0]["properties"].update(carried_mass=800.0, carried_at=[0.2, 0.902])
    path.write_text(json.dumps(data))
    assert read_geojson(path).blocks[0].carried_at == (0.2, 0.902)
    settled, how = settle(target_scenario(path), 0.2)
    block = settled.assembly.blocks[0]
    drop = 0.002 - block.polygon.bounds[1]  # how far the polygon came down (to its contact with the ground)
    assert drop == pytest.approx(0.002, abs=2e-4) and how.largest_move == pytest.approx(0.002, rel=0.05)
    assert block.carried_at == pytest.approx((0.2, 0.902 - drop), abs=1e-6)


def test_a_settled_traced_wall_at_rest_is_intact(traced, tmp_path):
    # settled, the stones rest on one end of many joints, the other end drawn up to 1 mm open: nothing moves
    # at rest (largest block displacement under 1e-3 mm), so no joint has hinged — it said "damaged, 37 hinges"
    history = tmp_path / "h.npz"
    result = invoke(
        "run", traced, "--convex-hull", "--trim-overlaps", "0.003", "--settle", "0.5",
        "--duration", "0.2", "--no-recording", "--history", history,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert "settled 0.5 s under its own weight (--settle)" in words(result.output)
    assert "intact" in result.output and "damaged" not in result.output
    saved = np.load(history)
    assert np.abs(saved["block_q"][-1, :, :2] - saved["block_q"][0, :, :2]).max() < 1e-6
    assert saved["hinge_count"].max() == 0


def test_check_takes_run_s_settle_and_checks_its_value(traced):
    assert_one_line_error(invoke("check", traced, "--settle", "20"), "--settle 20: must be in (0, 10] s")
    result = invoke("check", traced, "--convex-hull", "--trim-overlaps", "0.003", "--settle", "0.5")
    assert result.exit_code == 0, result.output


@pytest.mark.slow
def test_sweep_reads_a_traced_wall_as_run_does(traced, tmp_path):
    out = tmp_path / "s.csv"
    args = ["--param", "friction=0.5,0.7", "--duration", "0.05", "--workers", "0", "--no-recording", "--out", out]
    assert_one_line_error(invoke("sweep", traced, *args), "not convex", "--convex-hull")
    result = invoke("sweep", traced, *args, "--convex-hull", "--trim-overlaps", "0.003", "--settle", "0.2")
    assert result.exit_code == 0, result.output
    assert "settled 0.2 s under its own weight" in words(result.output) and out.exists()


def test_a_scenario_file_reads_a_traced_wall_with_its_structure_keys(traced, tmp_path):
    # a scenario file gives the foundation its own motion: [structure] takes the options' keys beside file
    scenario = tmp_path / "s.toml"
    head = f'[structure]\nfile = "{traced.name}"\n'
    motion = '[[support]]\nname = "id-73"\nmotion = { kind = "sine", amplitude = 0.3, frequency = 2.0 }\n'
    scenario.write_text(head + motion)
    assert_one_line_error(invoke("check", scenario), "not convex", "convex_hull = true (in [structure])")
    scenario.write_text(head + "convex_hull = true\ntrim_overlaps = 0.003\n" + motion)
    result = invoke("check", scenario)
    assert result.exit_code == 0, result.output
    said = words(result.output)
    assert "4 non-convex polygons read as their convex hulls" in said and "overlapping pairs trimmed" in said
    for bad, message in (
        ("flip_y = 1", "flip_y = 1: must be true or false"),
        ('units = "ft"', "units = 'ft': must be m, cm, mm or metres per unit"),
        ("trim_overlaps = 0.5", "trim_overlaps = 0.5: must be a number in (0, 0.1] m"),
        ("thickness = 2", "thickness: not allowed with file = ... (a geometry file brings its own blocks and supports; "
         "how it is read: units, flip_y, convex_hull, trim_overlaps)"),
    ):  # fmt: skip
        scenario.write_text(head + bad + "\n" + motion)
        assert_one_line_error(invoke("check", scenario), message)


def test_limit_on_a_ground_line_is_that_on_the_foundation_polygon(tmp_path):
    # the exact stones on their foundation polygon, and on the line along its top: the same joints, the same λ
    surveyed_wall.write(tmp_path / "polygon.geojson", slip=0.0, ndigits=9)
    surveyed_wall.write(tmp_path / "line.geojson", slip=0.0, ndigits=9, ground_line=True, mark_ground=False)
    answers = [invoke("limit", tmp_path / f"{name}.geojson", "--json") for name in ("polygon", "line")]
    assert all(a.exit_code == 0 for a in answers), answers[1].output
    lam = [json.loads(a.stdout)["load_factor"] for a in answers]
    assert lam[1] == pytest.approx(lam[0], rel=1e-9)


def test_settle_out_of_range_is_echoed_as_typed(traced):
    assert_one_line_error(invoke("check", traced, "--settle", "1e9"), "--settle 1e9: must be in (0, 10] s")
