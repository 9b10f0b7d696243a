"""The square-root views (``layout.SQRT_FIELDS``): the mapping against a plain-Python reference, and the
recorded colours, ranges and tick labels of the "p √" tab read back, computed again here independently."""

from __future__ import annotations

import math

import numpy as np
import pytest

from masonrycli.recording import Recorder
from masonrycli.recording import colormap as cm
from masonrycli.recording.colour_range import ColourRange, positions, sqrt_scale
from masonrycli.recording.layout import FIELD_BY_KEY, FIELD_TABS, FILL, SQRT_FIELDS, SQRT_TABS, build_blueprint
from masonrycli.recording.readback import blueprint_views, field_frames
from masonrycli.scenario.builtin import paper_loading

import recording_fixtures as fx
from recording_fixtures import strict_rerun, temporal_rows  # noqa: F401 (strict_rerun: autouse)


def reference_position(kind: str, value: float, lo: float, hi: float) -> float:
    """Where ``value`` sits on the square-root map of [lo, hi], one value at a time: √(|value| / |end|) of
    the map from zero towards the end on the value's side, zero at 1 (negative), 0 (positive) or ½ (signed);
    beyond an end, beyond 0 or 1 in the same way."""
    if math.isnan(value):
        return math.nan
    if kind == "negative":  # zero at 1, lo at 0; a value above 0 lies above 1
        return 1.0 - math.sqrt(value / lo) if value <= 0.0 else 1.0 + math.sqrt(value / -lo)
    if kind == "positive":
        return math.sqrt(value / hi) if value >= 0.0 else -math.sqrt(-value / hi)
    if value < 0.0:
        return 0.5 - 0.5 * math.sqrt(value / lo)
    return 0.5 + 0.5 * math.sqrt(value / hi)


@pytest.mark.parametrize("kind, lo, hi", [("negative", -8e5, 0.0), ("positive", 0.0, 3e4), ("signed", -2e-3, 0.01)])
def test_sqrt_scale_matches_a_plain_reference_inside_beyond_and_nan(kind, lo, hi):
    rng = np.random.default_rng(7)
    end = max(-lo, hi)
    values = np.r_[rng.uniform(-1.5 * end, 1.5 * end, 400), lo, hi, 0.0, np.nan]
    got = sqrt_scale(kind, positions(kind, values, lo, hi))
    expected = [reference_position(kind, float(v), lo, hi) for v in values]
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12, equal_nan=True)
    inside = (values >= lo) & (values <= hi)
    assert np.all((got[inside] >= 0.0) & (got[inside] <= 1.0))
    assert np.all(got[values < lo] < 0.0) and np.all(got[values > hi] > 1.0)  # beyond stays beyond
    linear = positions(kind, values, lo, hi)
    np.testing.assert_allclose(sqrt_scale(kind, got, inverse=True), linear, rtol=1e-12, atol=1e-12, equal_nan=True)


def test_sqrt_ticks_are_the_values_of_evenly_spaced_colours():
    """[−800, 0] kPa: −800, −450, −200, −50, 0 (each tick's value at its colour, t² of the range from zero)."""
    np.testing.assert_allclose(ColourRange("negative", -8e5, 0.0).ticks(5, "sqrt"), [-8e5, -4.5e5, -2e5, -5e4, 0.0])
    np.testing.assert_allclose(ColourRange("positive", 0.0, 4.0).ticks(5, "sqrt"), [0.0, 0.25, 1.0, 2.25, 4.0])
    np.testing.assert_allclose(ColourRange("signed", -2.0, 8.0).ticks(5, "sqrt"), [-2.0, -0.5, 0.0, 2.0, 8.0])
    for r in (ColourRange("negative", -8e5, 0.0), ColourRange("signed", -2.0, 8.0)):
        ticks = r.ticks(5, "sqrt")  # each tick's colour position is where the tick stands on the bar
        np.testing.assert_allclose(sqrt_scale(r.kind, r.position(ticks)), np.linspace(0.0, 1.0, 5), atol=1e-12)


def heavy_tailed_frames(static, q0, count: int) -> list:
    """Frames whose p is a heavy-tailed field (the bulk at tens of kPa, a few blocks at MN) growing over the
    run, with a NaN block, a block in tension (above the one-sided range) and one far below it."""
    rng = np.random.default_rng(11)
    out = []
    for k in range(count):
        f = fx.frame(static, q0, 10 * (k + 1), rng)
        p = -np.abs(rng.lognormal(np.log(3e4), 1.2, len(q0))) * (1.0 + 0.3 * k)
        p[2], p[5], p[9] = np.nan, 5e3, -5e7
        f.tensors["cell_spherical_stress"] = p
        out.append(f)
    return out


def test_the_sqrt_tab_colours_p_on_the_square_root_map_of_the_linear_range(tmp_path):
    """Read back: the "p √" colour component of every frame is the plain reference's position of each block's
    p on the range logged for the linear p tab (the same range: one tracker), through the blues table; magenta
    below, lime above, grey for NaN. Its ticks read the values of evenly spaced colours; the linear tab's
    colours are the linear map's (the paper's figures keep their meaning)."""
    static, q0 = fx.wall(12, 10)  # 2 % of its blocks: the tension block and the one at 50 MPa may lie outside
    frames = heavy_tailed_frames(static, q0, 14)
    path = tmp_path / "sqrt.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=5) as rec:
        for f in frames:
            rec.log_frame(f)
    (sqrt_p,) = SQRT_FIELDS
    linear = FIELD_BY_KEY[sqrt_p.key]
    owner = np.repeat(np.arange(len(q0)), np.diff(static.block_vert_start))
    first_vertex = np.r_[0, np.cumsum(np.diff(static.block_vert_start))[:-1]]
    read = field_frames(path)
    drawn = temporal_rows(path, f"/{FILL}", sqrt_p.colors)
    drawn_linear = temporal_rows(path, f"/{FILL}", linear.colors)
    labels = temporal_rows(path, f"/{sqrt_p.labels}", "Points2D:labels")
    assert sqrt_p.colors != linear.colors and sqrt_p.labels != linear.labels
    lut = cm.BLUES
    for f in frames:
        values = f.tensors[sqrt_p.key]
        lo, hi = read[f.step]["ranges"][sqrt_p.name]
        assert (lo, hi) == read[f.step]["ranges"][linear.key] and hi == 0.0
        colors = np.array(drawn[f.step], dtype=np.uint32)
        assert np.all(colors == colors[first_vertex][owner])  # one colour per block
        expected = []
        for v in values:
            t = reference_position("negative", float(v), lo, hi)
            if math.isnan(t):
                expected.append(cm.NAN_RGBA)
            elif t < 0.0:
                expected.append(cm.UNDER_RGBA)
            elif t > 1.0:
                expected.append(cm.OVER_RGBA)
            else:
                expected.append(int(lut[int(math.floor(t * 255 + 0.5))]))
        np.testing.assert_array_equal(colors[first_vertex], expected)
        t_lin = (values - lo) / (hi - lo)
        lin = np.where(t_lin < 0, cm.UNDER_RGBA, np.where(t_lin > 1, cm.OVER_RGBA, 0))
        inside = np.isfinite(t_lin) & (t_lin >= 0) & (t_lin <= 1)
        lin[inside] = lut[np.rint(t_lin[inside] * 255).astype(int)]
        np.testing.assert_array_equal(np.array(drawn_linear[f.step], dtype=np.uint32)[first_vertex][~np.isnan(values)],
                                      lin[~np.isnan(values)])  # fmt: skip
        span = max(-lo, hi)
        ticks = [cm.tick_label(lo * (1.0 - t) ** 2 + 0.0, "Pa", span, False) for t in (0.0, 0.25, 0.5, 0.75)]
        assert labels[f.step][:6] == [
            *ticks,
            cm.tick_label(0.0, "Pa", span, False),
            f"Spherical stress p, √ scale, t = {f.time:.3f} s",
        ]
        below, above = int((values < lo).sum()), int((values > hi).sum())
        assert above == 1 and labels[f.step][6:] == [
            f"{n} {way}" for n, way in ((below, "below"), (above, "above")) if n
        ]
    # the bulk, pale on the linear map, is not on this one: the median block at the last frame
    last = frames[-1].tensors[sqrt_p.key]
    lo, hi = read[frames[-1].step]["ranges"][sqrt_p.name]
    median = float(np.nanmedian(last))
    assert median / lo < 0.1 < reference_position("negative", median, lo, hi) < 0.9


def test_the_sqrt_tab_follows_its_twin_live_and_the_legend_says_what_it_is(tmp_path):
    static, q0 = fx.wall()
    paper = {**fx.METADATA, "scenario": "wall", "duration_s": 1.0, "supports": paper_loading("wall")}
    path = tmp_path / "w.rrd"
    with Recorder(path, static, paper) as rec:
        for f in fx.frames(static, q0, 11):  # to step 100, t = 0.1 s: the paper's tabs
            rec.log_frame(f)
    (sqrt_p,) = SQRT_FIELDS
    tab = SQRT_TABS[sqrt_p.name]
    views = blueprint_views(path)
    assert views[tab]["origin"] == "/structure/plane" and views[tab]["pinned"] is None  # live, not the paper's
    assert sum(v["pinned"] is not None for v in views.values()) == 4  # the paper's four, linear
    structure_tabs = build_blueprint(paper=(0.1, ("III.2", "III.3", "III.4", "III.5"))).root_container.contents[0]
    names = [v.name for v in structure_tabs.contents[0].contents]
    assert names.index(tab) == names.index(FIELD_TABS[sqrt_p.key]) + 1  # right after its linear twin
    legend = fx.static_value(path, "/run/legend", "TextDocument:text")[0]
    assert f"{tab} = the same on a square-root scale" in legend


def test_the_recorded_strain_rate_ranges_hold_through_one_short_frame(tmp_path):
    """Read back: the volumetric strain rate's ranges logged for a run whose rate dips for one frame, two in a
    row, or deeply, are the plain reference's (test_colour_range_hold), which keeps the range through a single
    short frame; batches of 5 frames cut the dips anywhere."""
    from test_recording_colour_range_hold import dipping_frames, reference

    static, q0 = fx.wall(12, 10)
    rates = 0.01 * dipping_frames("signed", count=60, seed=2)[:, : len(q0)]
    rates[40] = 0.01  # dipping_frames' frame without a defined cell: a uniform one here (a cell is never NaN)
    rng = np.random.default_rng(3)
    frames = []
    for k, v in enumerate(rates):
        f = fx.frame(static, q0, 10 * (k + 1), rng)
        f.tensors["cell_volumetric_strain_rate"] = v
        frames.append(f)
    path = tmp_path / "rates.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=5) as rec:
        for f in frames:
            rec.log_frame(f)
    spec = FIELD_BY_KEY["cell_volumetric_strain_rate"]
    expected, why = reference("signed", spec.floor, rates, 2)
    read = field_frames(path)
    got = [read[f.step]["ranges"][spec.key] for f in frames]
    assert got == [(r.lo, r.hi) for r in expected]
    assert why.count("short kept") >= 2
