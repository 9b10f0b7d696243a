"""A bridge's fill is drawn in its recordings: one column per block that carries fill, over that block and
moving with it, their areas the fill's (a reference computed here with shapely from the builder's outline:
the box up to the fill level less the blocks' downward shadow); none in a bare arch's recording."""

from __future__ import annotations

import numpy as np
import pytest
import rerun as rr
import shapely
from shapely.geometry import MultiPoint, box
from typer.testing import CliRunner

from geometry_library.builders import build_arch
from masonrycli.cli.app import app
from masonrycli.recording import inspect_recording, screenshot_recording
from masonrycli.recording.carried_fill import FILL_MESH, FILL_OUTLINES, strip_triangles
from masonrycli.recording.layout import BLOCKS, MAGNIFIED, MAGNIFIED_FILL, TRIANGULATION
from masonrycli.recording.limit import OUTLINES, STEPS

import recording_fixtures as fx

BRIDGE = {"span": 8.0, "rise": 2.0, "ring_thickness": 0.5, "pier_width": 3.0, "pier_courses": 5}
COVER, DENSITY = 0.3, 1900.0
OPTIONS = [f"--{k.replace('_', '-')}={v:g}" for k, v in BRIDGE.items()]
FILL = [f"--fill-cover={COVER:g}", f"--fill-density={DENSITY:g}"]
runner = CliRunner()


def invoke(*args):
    result = runner.invoke(app, [str(a) for a in args], terminal_width=200)
    assert result.exit_code == 0, result.output
    return result


def strips(path, entity: str) -> dict[int, list[np.ndarray]]:
    """step -> the closed strips logged at ``entity`` then."""
    out = {}
    for chunk in rr.chunk.RrdReader(str(path)).stream():
        if chunk.entity_path == f"/{entity}" and not chunk.is_static:
            batch = chunk.to_record_batch()
            for step, value in zip(batch.column("step").to_pylist(), batch.column("LineStrips2D:strips").to_pylist()):
                out[step] = [np.array(s, dtype=float) for s in value]
    return out


def shoelace(ring: np.ndarray) -> float:
    x, y = ring[:-1].T  # closed: the first point repeated
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def centroid(ring: np.ndarray) -> np.ndarray:
    return np.asarray(shapely.Polygon(ring).centroid.coords[0])


def reference_fill_area() -> float:
    """The fill's area from its definition: between the piers' outer faces, under the level (COVER over the
    highest stone), above every block (a block's shadow: its hull with itself moved far down)."""
    blocks = build_arch(**BRIDGE).blocks
    xy = np.concatenate([b.vertices for b in blocks])
    low, level, half = xy[:, 1].min(), xy[:, 1].max() + COVER, np.abs(xy[:, 0]).max()
    shadows = [MultiPoint(np.r_[b.vertices, b.vertices - [0.0, 100.0]]).convex_hull for b in blocks]
    return box(-half, low, half, level).difference(shapely.union_all(shadows)).area


@pytest.fixture(scope="module")
def bridge(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bridge")
    rrd, npz = tmp / "bridge.rrd", tmp / "bridge.npz"
    invoke("simulate", "arch", *OPTIONS, *FILL, "--settlement", 0.02, "--duration", 0.05, "--dt", 1e-3,
           "--record-every", 25, "--out", rrd, "--history", npz)  # fmt: skip
    return rrd, np.load(npz), build_arch(**BRIDGE, fill_cover=COVER, fill_density=DENSITY).blocks


def test_one_column_over_each_block_that_carries_fill_their_area_the_fills(bridge):
    rrd, _, blocks = bridge
    first = strips(rrd, FILL_OUTLINES)[0]
    carrying = [b for b in blocks if b.carried_mass > 0]
    assert len(first) == len(carrying) > 20  # the voussoirs and the piers' top courses
    areas = np.array([shoelace(s) for s in first])
    assert (areas > 0).all()  # counter-clockwise, none empty
    assert areas.sum() == pytest.approx(reference_fill_area(), rel=1e-6)  # float32 vertices
    # each column over the block that carries it: its centroid is where that block's fill is lumped, and its
    # mass that block's carried mass
    at = np.array([b.carried_at for b in carrying])
    for ring, area in zip(first, areas):
        k = int(np.argmin(np.hypot(*(at - centroid(ring)).T)))
        assert np.hypot(*(at[k] - centroid(ring))) < 1e-5
        assert DENSITY * area * carrying[k].thickness == pytest.approx(carrying[k].carried_mass, rel=1e-5)


def test_the_columns_move_with_their_blocks(bridge):
    rrd, history, blocks = bridge
    drawn = strips(rrd, FILL_OUTLINES)
    last = max(drawn)
    q0, q = history["block_q"][0], history["block_q"][list(history["step"]).index(last)]
    assert np.abs(q - q0).max() > 1e-4  # the settlement moved the blocks
    at = np.array([b.carried_at if b.carried_mass > 0 else (np.inf, np.inf) for b in blocks])
    for before, after in zip(drawn[0], drawn[last]):
        b = int(np.argmin(np.hypot(*(at - centroid(before)).T)))
        c, s = np.cos(q[b, 2] - q0[b, 2]), np.sin(q[b, 2] - q0[b, 2])
        moved = (before - q0[b, :2]) @ np.array([[c, s], [-s, c]]) + q[b, :2]
        np.testing.assert_allclose(after, moved, atol=2e-5)


def test_the_magnified_tab_draws_the_columns_on_its_magnified_blocks(bridge):
    """The Magnified tab showed the bare ring of a filled bridge: each column now goes with its block there too,
    rigidly, at the magnified pose (turned m θ, moved m times), where the Live view's is at the computed one."""
    rrd, _, blocks = bridge
    columns, ring, live = strips(rrd, MAGNIFIED_FILL), strips(rrd, MAGNIFIED), strips(rrd, FILL_OUTLINES)
    last = max(columns)
    assert sorted(columns) == sorted(ring) and last == max(live)
    for drawn, built in zip(columns[0], live[0]):  # as built at step 0 (0.13 mm off when the poses were rounded)
        np.testing.assert_array_equal(drawn, built)
    at = np.array([b.carried_at if b.carried_mass > 0 else (np.inf, np.inf) for b in blocks])
    for before, after, seen in zip(columns[0], columns[last], live[last]):
        b = int(np.argmin(np.hypot(*(at - centroid(before)).T)))
        (p0, q0), (p1, q1) = ring[0][b][:2], ring[last][b][:2]  # the block's first edge, as built and magnified
        turn = np.arctan2(*(q1 - p1)[::-1]) - np.arctan2(*(q0 - p0)[::-1])
        c, s = np.cos(turn), np.sin(turn)
        np.testing.assert_allclose(after, (before - p0) @ np.array([[c, s], [-s, c]]) + p1, atol=2e-5)
        assert np.abs(after - before).max() > 3 * np.abs(seen - before).max()  # magnified, not the Live pose


def points(path, entity: str) -> dict[int, np.ndarray]:
    out = {}
    for chunk in rr.chunk.RrdReader(str(path)).stream():
        if chunk.entity_path == f"/{entity}" and not chunk.is_static:
            batch = chunk.to_record_batch()
            if "Points2D:positions" in batch.schema.names:
                for step, value in zip(
                    batch.column("step").to_pylist(), batch.column("Points2D:positions").to_pylist()
                ):
                    out[step] = np.array(value, dtype=float)
    return out


def test_the_centroid_dots_and_glyphs_stay_on_their_blocks(bridge):
    """Found with the fill drawn: the dots (hover targets) and stress glyphs of the filled voussoirs stood in
    the fill, at the body's centre of mass, which v01's fill (2.5 times its own mass) pulls far above it."""
    rrd, history, blocks = bridge
    dots = points(rrd, BLOCKS)
    own = np.array([b.polygon.centroid.coords[0] for b in blocks])
    np.testing.assert_allclose(dots[0], own, atol=1e-5)
    last = max(dots)
    q0, q = history["block_q"][0], history["block_q"][list(history["step"]).index(last)]
    c, s = np.cos(q[:, 2] - q0[:, 2]), np.sin(q[:, 2] - q0[:, 2])
    rel = own - q0[:, :2]
    moved = q[:, :2] + np.stack([c * rel[:, 0] - s * rel[:, 1], s * rel[:, 0] + c * rel[:, 1]], axis=1)
    np.testing.assert_allclose(dots[last], moved, atol=2e-5)
    glyphs = strips(rrd, "structure/plane/xy/stress_axes")[0]  # two segments a block, centred on it
    np.testing.assert_allclose([g.mean(axis=0) for g in glyphs[::2]], own, atol=1e-5)
    # the cells' triangles (Strain rate tab) join the same centroids: they joined the centres of mass, in the fill
    corners = np.concatenate(fx.static_value(rrd, f"/{TRIANGULATION}", "LineStrips2D:strips"))
    assert np.hypot(*(corners[:, None] - own[None]).T).min(axis=0).max() < 1e-5


def test_the_legend_says_the_fill_and_its_load(bridge):
    rrd, _, blocks = bridge
    legend = fx.static_value(rrd, "/run/legend", "TextDocument:text")[0]
    load = sum(b.carried_mass for b in blocks) * 9.81 / 1e3
    assert "**Fill**" in legend and "dead load only" in legend and f"{load:.4g} kN per metre of width" in legend


def test_the_magnified_line_of_the_legend_says_the_fill(bridge):
    """The Magnified tab drew the columns' outlines, its legend line said nothing of them, and the Fill line
    under it was cut off the panel in that tab (headless screenshot): the Magnified line says the fill."""
    rrd, _, blocks = bridge
    legend = fx.static_value(rrd, "/run/legend", "TextDocument:text")[0]
    (line,) = [x for x in legend.splitlines() if x.startswith("- **Magnified**")]
    load = sum(b.carried_mass for b in blocks) * 9.81 / 1e3
    assert f"sand outlines = the fill (dead load only, {load:.4g} kN)" in line, line


def test_a_bridge_read_from_geojson_draws_its_fill_as_the_built_in(bridge, tmp_path):
    """'masonry run b.geojson' of the bridge written by 'masonry build arch ... --out b.geojson' drew no fill (the
    file keeps the carried masses, not the level): their level is found again (one fill, one density), and the
    columns are the built-in's. Masses that are not one fill's stay undrawn, the legend says so."""
    import json

    geojson = tmp_path / "b.geojson"
    invoke("build", "arch", *OPTIONS, *FILL, "--out", geojson)
    rrd = tmp_path / "file.rrd"
    invoke("run", geojson, "--duration", 0.001, "--dt", 1e-3, "--out", rrd)
    drawn, built = strips(rrd, FILL_OUTLINES)[0], strips(bridge[0], FILL_OUTLINES)[0]
    assert len(drawn) == len(built) > 20
    for a, b in zip(drawn, built):
        np.testing.assert_allclose(a, b, atol=1e-6)
    data = json.loads(geojson.read_text())
    carrying = [f for f in data["features"] if f["properties"].get("carried_mass")]
    carrying[3]["properties"]["carried_mass"] *= 1.01  # one voussoir's fill 1 % denser: not one fill
    geojson.write_text(json.dumps(data))
    rrd = tmp_path / "other.rrd"
    invoke("run", geojson, "--duration", 0.001, "--dt", 1e-3, "--out", rrd)
    assert f"/{FILL_OUTLINES}" not in set(inspect_recording(rrd)["entity_paths"])
    assert "not drawn" in fx.static_value(rrd, "/run/legend", "TextDocument:text")[0]


def test_a_bare_arch_records_no_fill(tmp_path):
    rrd = tmp_path / "bare.rrd"
    invoke("simulate", "arch", *OPTIONS, "--duration", 0.002, "--dt", 1e-3, "--out", rrd)
    paths = set(inspect_recording(rrd)["entity_paths"])
    assert f"/{FILL_OUTLINES}" not in paths and f"/{FILL_MESH}" not in paths and f"/{MAGNIFIED_FILL}" not in paths
    assert "**Fill**" not in fx.static_value(rrd, "/run/legend", "TextDocument:text")[0]


def test_limit_draws_the_fill_on_both_copies_carried_by_the_mechanism(tmp_path):
    rrd = tmp_path / "limit.rrd"
    invoke("limit", "arch", *OPTIONS, *FILL, "--out", rrd)
    columns, blocks = strips(rrd, FILL_OUTLINES), strips(rrd, OUTLINES)
    n = len(blocks[0]) // 2
    assert len(columns[0]) % 2 == 0
    half = len(columns[0]) // 2
    assert sum(shoelace(s) for s in columns[0][:half]) == pytest.approx(reference_fill_area(), rel=1e-6)
    # rigid: each column of the mechanism copy keeps its distances to some block's vertices (its carrier's)
    moved = 0
    for k in range(half, 2 * half):
        a0, a1 = columns[0][k], columns[STEPS][k]
        keeps = [
            np.allclose(np.hypot(*(a0[:, None] - b0[None]).T), np.hypot(*(a1[:, None] - b1[None]).T), atol=1e-4)
            for b0, b1 in zip(blocks[0][n:], blocks[STEPS][n:])
            if np.abs(b1 - b0).max() > 1e-3  # a block that moves in the mechanism
        ]
        moved += any(keeps)
        np.testing.assert_allclose(columns[0][k - half], columns[STEPS][k - half])  # the structure as built
    assert moved > 5


def test_limit_of_a_bare_arch_draws_no_fill(tmp_path):
    rrd = tmp_path / "bare.rrd"
    invoke("limit", "arch", *OPTIONS, "--out", rrd)
    assert f"/{FILL_OUTLINES}" not in set(inspect_recording(rrd)["entity_paths"])


def test_each_column_is_triangulated_piece_by_piece():
    """A column over a peaked top (two pieces): a fan from its first corner would cross the peak."""
    column = np.array([(0, 0), (1, 0.9), (2, 0), (2, 1), (1, 1), (0, 1)], dtype=float)
    tri = strip_triangles(np.array([0, 6]))
    (ux, uy), (vx, vy) = (column[tri[:, 1]] - column[tri[:, 0]]).T, (column[tri[:, 2]] - column[tri[:, 0]]).T
    area = float(np.sum(np.abs(ux * vy - uy * vx)) / 2)
    assert len(tri) == 4 and area == pytest.approx(shapely.Polygon(column).area)


SAND_SHOWN = (141, 127, 99)
"""The fill's colour as the headless viewer renders it (FILL_RGBA, translucent, over the dark background), measured."""


@pytest.mark.slow  # starts the viewer twice: needs mesa-vulkan-drivers libvulkan1 (test_viewer_screenshot)
def test_the_viewer_shows_the_fill_over_the_ring(bridge, tmp_path):
    from PIL import Image

    bare = tmp_path / "bare.rrd"
    invoke("simulate", "arch", *OPTIONS, "--duration", 0.05, "--dt", 1e-3, "--record-every", 25, "--out", bare)
    sand = {}
    for name, rrd in (("filled", bridge[0]), ("bare", bare)):
        png = tmp_path / f"{name}.png"
        assert screenshot_recording(rrd, png, time_s=0.05, timeout=120) == []
        rgb = np.asarray(Image.open(png).convert("RGB"), dtype=np.int32)
        sand[name] = np.abs(rgb - SAND_SHOWN).sum(axis=-1) < 12
    rows = np.flatnonzero(sand["filled"].any(axis=1))
    assert sand["filled"].sum() > 50_000 and sand["bare"].sum() < 100  # 1920 x 1080: ~120 000 of sand
    assert rows.max() - rows.min() > 100  # a band over the ring, not a line


def test_a_fill_on_blocks_of_two_thicknesses_is_recorded(tmp_path):
    """A survey whose stones carry a thickness column (1 m and 0.8 m) under a traced fill: the run's
    thickness_m is [0.8, 1.0] (9a0e0e6), which the legend's 'kN per metre of width' divided by: 'internal
    error: TypeError' at close, exit 1. The Fill line says the load, 1800 kg/m³ × 0.5 m² a stone × (1 + 0.8) m,
    without a per-metre figure that no single thickness gives."""
    import json

    def feature(ring, **props):
        return {"type": "Feature", "properties": props, "geometry": {"type": "Polygon", "coordinates": [ring]}}

    features = [
        feature([[0, 0], [1, 0], [1, 0.5], [0, 0.5], [0, 0]], name="a", thickness=1.0),
        feature([[1, 0], [2, 0], [2, 0.5], [1, 0.5], [1, 0]], name="b", thickness=0.8),
        feature([[-2, -0.5], [4, -0.5], [4, 0], [-2, 0], [-2, -0.5]], role="support"),
        feature([[0, 0.5], [2, 0.5], [2, 1], [0, 1], [0, 0.5]], role="fill", density=1800),
    ]
    path, rrd = tmp_path / "two.geojson", tmp_path / "two.rrd"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    invoke("run", path, "--duration", 0.001, "--dt", 1e-3, "--out", rrd)
    legend = fx.static_value(rrd, "/run/legend", "TextDocument:text")[0]
    load = 1800 * 0.5 * (1.0 + 0.8) * 9.81 / 1e3
    (line,) = [x for x in legend.splitlines() if x.startswith("- **Fill**")]
    assert f"{load:.4g} kN," in line and "per metre" not in line, line


def test_the_legend_panel_shows_a_bridge_s_fill_line(bridge):
    """A filled bridge's Legend has a Fill line more than a bare arch's: eight lines at 1920 x 1080 where the
    panel under the structure tabs (5 : 1 of the ~1000 px column, a 24 px title bar, ~20 px a line) shows
    seven, the Fill line below its fold (9 lines here: the Magnified line wraps too). The panel's share grows to hold the Legend's lines."""
    import math

    from masonrycli.recording.readback import blueprint_row_shares

    rrd, _, _ = bridge
    legend = fx.static_value(rrd, "/run/legend", "TextDocument:text")[0]
    lines = sum(math.ceil(len(x.replace("**", "")) / 185) for x in legend.splitlines() if x.strip())
    assert lines >= 8, legend  # 9 here: the Magnified line, saying the fill too, wraps
    (tabs, panel), *_ = [s for s in blueprint_row_shares(rrd) if len(s) == 2 and s[0] == 5.0]
    assert 1000.0 * panel / (tabs + panel) >= 24.0 + 20.0 * lines - 1e-3, (tabs, panel)  # float32 shares
