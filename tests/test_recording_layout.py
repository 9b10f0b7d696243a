"""The recording's layout, read back: the embedded blueprint's views and tabs, the paper-figure tabs (only under
the paper's loading, structure and instant), where the viewer opens (sim_time followed, t = 0 as built), and
every tab name fitting its tab bar (tests/test_recording.py holds the file's frames and colours, test_recording_series.py its plots)."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli import recording as rec_mod
from masonrycli.recording import Recorder, inspect_recording
from masonrycli.recording import colormap as cm
from masonrycli.recording.layout import FIELD_TABS, FILL, LIVE_TAB, MAGNIFIED_TAB, PLOT_NAMES, SQRT_TABS
from masonrycli.recording.readback import blueprint_views, field_frames
from masonrycli.scenario.builtin import paper_loading

import recording_fixtures as fx
from recording_fixtures import (  # noqa: F401 (fixtures: strict_rerun autouse, wall, written)
    strict_rerun,
    temporal_rows,
    wall_fixture,
    written_fixture,
)

static_value = fx.static_value


def test_embedded_blueprint_has_the_views(written, wall, tmp_path):
    path, *_, rec = written
    views = blueprint_views(path)
    spatial = {n for n, v in views.items() if v["kind"] == "2D" and v["origin"] == "/structure/plane"}
    assert {LIVE_TAB, MAGNIFIED_TAB, *FIELD_TABS.values(), *SQRT_TABS.values()} == spatial
    # the magnified view's factor (set at close) is in the Legend: in the tab's name it was cut
    assert rec.magnify > 0 and f"× {rec.magnify:g}" in static_value(path, "/run/legend", "TextDocument:text")[0]
    assert sum(v["kind"] == "TimeSeries" for v in views.values()) == 9
    assert views["Run"]["origin"] == "/run/metadata" and views["Legend"]["origin"] == "/run/legend"
    assert not any(v["pinned"] for v in views.values())  # no paper instant for a synthetic run
    # A wall long enough for the paper's instant gets the four figures, pinned to t = 0.1 s on sim_time.
    static, q0 = wall
    paper = {**fx.METADATA, "scenario": "wall", "duration_s": 1.0, "supports": paper_loading("wall")}
    with Recorder(tmp_path / "w.rrd", static, paper) as rec:
        for f in fx.frames(static, q0, 11):  # to step 100, t = 0.1 s
            rec.log_frame(f)
    views = blueprint_views(tmp_path / "w.rrd")
    pinned = {n: v["pinned"] for n, v in views.items() if v["pinned"]}
    assert sorted(pinned) == ["Fig. III.2", "Fig. III.3", "Fig. III.4", "Fig. III.5"]
    assert (
        "the paper's figures, pinned at t = 0.1 s"
        in static_value(tmp_path / "w.rrd", "/run/legend", "TextDocument:text")[0]
    )
    assert set(pinned.values()) == {("sim_time", 0.1, 0.1)}


def test_the_blueprint_opens_following_sim_time(written):
    """A file opens with the cursor at the start of the time line, before the first frame (the solver
    health of step 1): paused there, every live tab was empty. Following opens on the last frame."""
    from masonrycli.recording.readback import blueprint_time_panel

    assert blueprint_time_panel(written[0]) == {"timeline": "sim_time", "play_state": "following"}


@pytest.mark.parametrize(
    "supports",
    [
        {"ground": "record of acceleration (synthetic-1.AT2, 301 samples, 0-3 s, baseline-corrected) × 2 along (1, 0)"},
        {"ground": "sine 1 m/s · sin(2π·5 Hz·t) along (1, 0)"},
        {},
    ],
)
def test_no_paper_figure_tabs_under_another_loading(wall, tmp_path, supports):
    """The paper's figures show the paper's loading: a wall shaken by a record (at rest at 0.1 s) opened
    on tabs named "Fig. III.2 … at t = 0.1 s"."""
    static, q0 = wall
    meta = {**fx.METADATA, "scenario": "wall", "duration_s": 1.0, "supports": supports}
    with Recorder(tmp_path / "w.rrd", static, meta) as rec:
        rec.log_frame(fx.frames(static, q0, 1)[0])
    views = blueprint_views(tmp_path / "w.rrd")
    assert not any(v["pinned"] or name.startswith("Fig.") for name, v in views.items())


@pytest.mark.parametrize(("every", "pinned"), [(10, True), (25, True), (30, False), (200, False)])
def test_paper_figure_tabs_only_when_a_frame_is_recorded_at_the_instant(wall, tmp_path, every, pinned):
    """``simulate wall --record-every 30`` records steps 90 and 120: the tabs named "Fig. III.2 … at t = 0.1 s"
    showed step 90 (200: the structure as built, no stress yet)."""
    static, q0 = wall
    meta = {**fx.METADATA, "scenario": "wall", "duration_s": 1.0, "dt_s": 1e-3, "record_every": every}
    with Recorder(tmp_path / "w.rrd", static, meta | {"supports": paper_loading("wall")}) as rec:
        for f in fx.frames(static, q0, 100 // every + 2, every=every):  # past 0.1 s: the paper's instant reached
            rec.log_frame(f)
    views = blueprint_views(tmp_path / "w.rrd")
    assert any(v["pinned"] and name.startswith("Fig. III.2") for name, v in views.items()) == pinned, views


@pytest.mark.parametrize(("structure", "pinned"), [({"builder": "wall", "blocks": 248}, True), ({}, False)])
def test_paper_figure_tabs_only_for_the_papers_structure(wall, tmp_path, structure, pinned):
    """A user's wall.toml of its own blocks (the scenario named "wall" after the file; no builder) shaken at
    1 m/s, 2 Hz opened on tabs "Fig. III.2 … at t = 0.1 s", the paper's figure numbers on another structure."""
    static, q0 = wall
    meta = {**fx.METADATA, "scenario": "wall", "duration_s": 1.0, "supports": paper_loading("wall")}
    with Recorder(tmp_path / "w.rrd", static, meta | {"structure": structure}) as rec:
        for f in fx.frames(static, q0, 12):  # to step 110: past the paper's instant
            rec.log_frame(f)
    views = blueprint_views(tmp_path / "w.rrd")
    assert any(v["pinned"] and name.startswith("Fig. III.2") for name, v in views.items()) == pinned, views


def test_a_run_ended_before_the_paper_instant_opens_without_its_tabs(wall, tmp_path):
    """Ctrl-C (or --stop-at-collapse) before 0.1 s: no frame at the paper's instant, so its pinned tabs
    were empty and the recording opened on the first. The layout is sent again without them at close."""
    static, q0 = wall
    paper = {**fx.METADATA, "scenario": "wall", "duration_s": 1.0, "supports": paper_loading("wall")}
    with pytest.raises(KeyboardInterrupt):
        with Recorder(tmp_path / "w.rrd", static, paper) as rec:
            for f in fx.frames(static, q0, 5):  # to step 40, t = 0.04 s
                rec.log_frame(f)
            raise KeyboardInterrupt
    views = blueprint_views(tmp_path / "w.rrd")
    assert not any(v["pinned"] or name.startswith("Fig.") for name, v in views.items())
    assert LIVE_TAB in views and rec.paper is None


def test_a_run_s_recording_opens_at_t0_on_the_structure_as_built(tmp_path):
    """A run's first frame is the structure as built, at rest, at t = 0 (the recording began at the first
    computed frame, step 10: scrubbing to the start never showed it): the blocks at their built centroids
    and the ground at its built place (both computed here from the builder's polygons, apart from the
    engine), no joint force yet, the stresses undefined (grey) with the colour range of the next frame;
    the same frames as the history."""
    from shapely.geometry import Polygon

    from geometry_library.builders import build_wall
    from masonrycli.recording.layout import FIELD_BY_KEY, FORCES, HINGES, SUPPORT_OUTLINES

    from cli_helpers import invoke

    rrd, npz = tmp_path / "w.rrd", tmp_path / "w.npz"
    result = invoke("simulate", "wall", "--duration", 0.02, "--out", rrd, "--history", npz)
    assert result.exit_code == 0, result.output
    info = inspect_recording(rrd)
    assert info["frames"] == 3 and info["steps"] == (0, 20) and info["time_span"] == pytest.approx((0.0, 0.02))
    h = np.load(npz)
    assert h["step"].tolist() == [0, 10, 20]  # the history had the initial frame already
    built = build_wall()
    centroids = np.array([Polygon(b.vertices).centroid.coords[0] for b in built.blocks])
    hover = temporal_rows(str(rrd), f"/{rec_mod.layout.BLOCKS}", "Points2D:positions")
    assert sorted(hover) == [0, 10, 20]
    np.testing.assert_allclose(np.array(hover[0]), centroids, atol=1e-6)  # float32 in the file
    assert np.abs(np.array(hover[10]) - centroids).max() > 1e-6  # it moves after: not a static copy
    np.testing.assert_allclose(h["block_q"][0, :, :2], centroids, atol=1e-12)
    ground = np.array(temporal_rows(str(rrd), f"/{SUPPORT_OUTLINES}", "LineStrips2D:strips")[0][0])
    built_ground = np.array(built.supports[0].polygon.exterior.coords)
    assert {tuple(np.round(p, 5)) for p in ground} == {tuple(np.round(p, 5)) for p in built_ground}
    assert temporal_rows(str(rrd), f"/{FORCES}", "Arrows2D:vectors")[0] == []
    assert temporal_rows(str(rrd), f"/{HINGES}", "Points2D:positions").get(0, []) == []
    p = FIELD_BY_KEY["cell_spherical_stress"]
    assert set(temporal_rows(str(rrd), f"/{FILL}", p.colors)[0]) == {cm.NAN_RGBA}
    read = field_frames(rrd)
    assert np.isnan(read[0]["values"]["cell_spherical_stress"]).all()
    assert read[0]["ranges"] == read[10]["ranges"]


def test_every_tab_name_fits_its_tab_bar(written, wall, tmp_path):
    """The quick start's structure panel has 12 tabs (13 with p on the square-root scale) in ~1150 px of a 1920 px window: with names of up to 56
    characters ("Live: joint forces, principal stress, Spherical stress p") four were readable and the first
    was cut; the right column showed three of its six plot tabs. Measured in the headless viewer: about
    5.5 px a character and 33 px a tab besides (12 short tabs took 972 px); the tab bars leave ~70 px to
    their buttons. Every name short, and distinct (a view per name)."""
    static, q0 = wall
    paper = {**fx.METADATA, "scenario": "wall", "duration_s": 1.0, "supports": paper_loading("wall")}
    with Recorder(tmp_path / "w.rrd", static, paper) as rec:
        for f in fx.frames(static, q0, 11):
            rec.log_frame(f)
    views = blueprint_views(tmp_path / "w.rrd")
    structure = [n for n, v in views.items() if v["kind"] == "2D"]
    plots = [n for n, v in views.items() if v["kind"] == "TimeSeries"]
    assert len(structure) == 13 and len(plots) == 9  # distinct: a repeated name would merge two views here
    assert 33 * 13 + 5.5 * sum(map(len, structure)) < 1080
    rows = ([PLOT_NAMES[k] for k in ("energy_kinetic", "energy_balance", "energy_large", "max_displacement")],
            [PLOT_NAMES[k] for k in ("support_velocity", "support_displacement", "residual", "iterations", "contacts")])  # fmt: skip
    assert set(plots) == {n for row in rows for n in row}
    assert all(33 * len(row) + 5.5 * sum(map(len, row)) < 700 for row in rows)
