"""masonrycli.recording.colour_range: the two rules (coverage, use) on every frame, the three kinds, the floor."""

from __future__ import annotations

import math

import numpy as np
import pytest

from masonrycli.recording import colormap as cm
from masonrycli.recording.colour_range import (
    BULK_TRIM,
    HOLD_SPAN,
    MIN_SPAN,
    OUTSIDE_SHARE,
    ColourRange,
    RangeTracker,
    fit_range,
)


def outside_share(r: ColourRange, v: np.ndarray) -> float:
    v = v[np.isfinite(v)]
    return float(((v < r.lo) | (v > r.hi)).mean())


def span_share(r: ColourRange, v: np.ndarray) -> float:
    """The use rule's span, written out: the defined cells sorted, 1 % (rounded down) dropped at each end."""
    v = np.sort(v[np.isfinite(v)])
    k = int(0.01 * v.size)
    assert BULK_TRIM == 0.01
    return (min(v[v.size - 1 - k], r.hi) - max(v[k], r.lo)) / (r.hi - r.lo)


@pytest.mark.parametrize("kind", ["signed", "negative", "positive"])
def test_every_frame_keeps_both_rules_on_a_growing_then_calming_field(kind):
    """A field that grows 50× then calms down 50× (as a cumulated strain, a shaking): every frame has
    at most 2 % of its cells outside the range in force and spans at least MIN_SPAN of it — on a signed
    scale at least HOLD_SPAN, and MIN_SPAN again by the next frame (SHRINK_AFTER)."""
    rng = np.random.default_rng(1)
    tracker = RangeTracker(kind, floor=1e-9)
    amplitude = np.r_[np.geomspace(1.0, 50.0, 60), np.geomspace(50.0, 1.0, 60)]
    short_before = False
    for a in amplitude:
        v = a * rng.standard_normal(300)
        v[rng.integers(0, 300, 3)] *= 30.0  # a few outliers (1 %)
        v = {"signed": v, "negative": -np.abs(v), "positive": np.abs(v)}[kind]
        v[5] = np.nan  # undefined cells do not count
        r = tracker.update(v)
        assert outside_share(r, v) <= OUTSIDE_SHARE
        short = span_share(r, v) < MIN_SPAN
        assert not short or (kind == "signed" and span_share(r, v) >= HOLD_SPAN and not short_before)
        short_before = short
        assert r.lo <= 0.0 <= r.hi
        if kind == "negative":
            assert r.hi == 0.0  # one-sided: the map ends at zero
        if kind == "positive":
            assert r.lo == 0.0
    assert 2 <= tracker.changes < len(amplitude) // 2  # refitted when needed, not every frame


def test_a_range_is_kept_while_it_holds_and_ends_are_nice_numbers():
    tracker = RangeTracker("positive", floor=1e-6)
    r = tracker.update(np.linspace(0.0, 0.9, 51))
    assert (r.lo, r.hi) == (0.0, 1.0)
    assert tracker.update(np.linspace(0.1, 0.7, 51)) is r
    assert tracker.update(np.linspace(0.0, 0.3, 51)) is not r  # spans 30 %: refitted
    assert tracker.current.hi == pytest.approx(0.3)


@pytest.mark.parametrize("kind", ["signed", "negative", "positive"])
def test_one_extreme_cell_does_not_hold_a_range_the_other_cells_use_a_sliver_of(kind):
    """After an impact: one cell stays at the range's end, the 299 others are 30× smaller. The min-to-max
    span (the rule before 2026-11-29) was 100 % and kept the range; the bulk spans 3 %: refitted, and the
    extreme cell is counted outside the new range (1 of 300, within the 2 %)."""
    rng = np.random.default_rng(5)
    sign = {"signed": 1.0, "negative": -1.0, "positive": 1.0}[kind]
    violent = sign * rng.uniform(0.0, 1e6, 300)
    if kind == "signed":
        violent = rng.uniform(-1e6, 1e6, 300)
    quiet = violent / 30.0
    quiet[17] = violent[np.argmax(np.abs(violent))]  # the cell that stays extreme
    for batch in (False, True):
        tracker = RangeTracker(kind, floor=1.0)
        first = tracker.follow(violent[None])[0][0] if batch else tracker.update(violent)
        assert max(-first.lo, first.hi) >= 9e5
        assert (min(quiet.max(), first.hi) - max(quiet.min(), first.lo)) / (first.hi - first.lo) >= MIN_SPAN
        if batch:
            ranges, below, above = tracker.follow(quiet[None])
            r, outside = ranges[0], below[0] + above[0]
        else:
            r = tracker.update(quiet)
            outside = sum(r.outside(quiet)[:2])
        assert r is not first and tracker.changes == 2
        assert max(-r.lo, r.hi) <= 1e6 / 30.0 * 1.5  # fitted to the quiet cells (nice rounding: ≤ 1.5×)
        assert outside == 1 and span_share(r, quiet) >= MIN_SPAN


def test_a_frame_under_100_cells_keeps_all_its_cells_in_the_span():
    """Rounded down, 1 % of 99 cells is none: a small structure's ranges are as before (the 51-block wall)."""
    tracker = RangeTracker("positive", floor=1e-6)
    r = tracker.update(np.linspace(0.0, 1.0, 99))
    quiet = np.r_[np.linspace(0.0, 0.02, 98), 0.9]
    assert tracker.update(quiet) is r
    assert tracker.update(np.r_[np.linspace(0.0, 0.02, 99), 0.9]) is not r  # 100 cells: the extreme one left out


def test_small_frames_keep_every_cell_inside_and_the_floor_holds_noise_down():
    v = np.linspace(-1.0, 3.0, 40)  # 2 % of 40 cells rounds down to 0: nothing may be left out
    r = fit_range(v, "signed", 1e-9)
    assert r.lo <= -1.0 and r.hi >= 3.0
    noise = 1e-12 * np.random.default_rng(0).standard_normal(100)
    r = fit_range(noise, "signed", 1e-4)
    assert (r.lo, r.hi) == (-1e-4, 1e-4)


def test_signed_position_is_two_sided_and_ticks_include_zero():
    r = ColourRange("signed", -2.0, 8.0)
    np.testing.assert_allclose(r.position(np.array([-2.0, -1.0, 0.0, 4.0, 8.0, 16.0])), [0, 0.25, 0.5, 0.75, 1, 1.5])
    np.testing.assert_allclose(r.ticks(5), [-2.0, -1.0, 0.0, 4.0, 8.0])
    one_sided = ColourRange("negative", -40e3, 0.0)
    np.testing.assert_allclose(one_sided.ticks(5), [-40e3, -30e3, -20e3, -10e3, 0.0])
    assert one_sided.outside(np.array([-50e3, -1.0, 5.0, np.nan])) == (1, 1, 3)


def test_map_positions_marks_below_and_above():
    lut = cm.BLUES
    colors = cm.map_positions(np.array([-0.1, 0.0, 1.0, 1.2, np.nan]), lut)
    assert list(colors) == [cm.UNDER_RGBA, lut[0], lut[-1], cm.OVER_RGBA, cm.NAN_RGBA]
    assert cm.UNDER_RGBA not in lut and cm.OVER_RGBA not in lut and cm.NAN_RGBA not in lut
    assert math.isclose(cm.unpack_rgba(lut[-1])[:3].mean(), 251, abs_tol=5)  # zero is near white


@pytest.mark.parametrize("kind", ["signed", "negative", "positive"])
def test_follow_gives_the_ranges_and_counts_of_update_frame_by_frame(kind):
    """``follow`` on a batch = ``update`` on each frame in turn (ranges, refits, outside counts), with
    refits, frames without a defined cell and a range carried over from the previous batch."""
    rng = np.random.default_rng(3)
    amplitude = np.r_[np.geomspace(1.0, 50.0, 30), np.full(10, 50.0), np.geomspace(50.0, 0.5, 30)]
    frames = amplitude[:, None] * rng.standard_normal((amplitude.size, 40))
    frames = {"signed": frames, "negative": -np.abs(frames), "positive": np.abs(frames)}[kind]
    frames[:, 7] = np.nan
    frames[12] = np.nan  # a frame with no defined cell
    frames[20, :3] = 1e3 * np.sign(frames[20, :3])  # outliers
    one, batch = RangeTracker(kind, floor=1e-6), RangeTracker(kind, floor=1e-6)
    expected = [one.update(v) for v in frames]
    counts = [r.outside(v)[:2] for r, v in zip(expected, frames)]
    ranges, below, above = [], [], []
    for part in (frames[:25], frames[25:]):  # two batches: the second starts from the first's range
        r, b, a = batch.follow(part)
        ranges += r
        below += b.tolist()
        above += a.tolist()
    assert ranges == expected
    assert list(zip(below, above)) == counts
    assert batch.changes == one.changes >= 3
    assert batch.current == one.current


def test_bulk_ends_are_the_sorted_rows_ranks_with_or_without_undefined_cells():
    # a batch whose cells are all defined takes the two ranks by np.partition: the same values as a sort
    from masonrycli.recording.colour_range import BULK_TRIM, bulk_ends

    rng = np.random.default_rng(11)
    for cells in (1, 2, 7, 248):
        frames = np.round(rng.normal(size=(30, cells)), 1)  # ties
        for holes in (False, True):
            v = frames.copy()
            if holes:
                v[rng.random(v.shape) < 0.2] = np.nan
                v[0, 0] = np.inf
            bottom, top, defined = bulk_ends(v)
            for row, d, lo, hi in zip(v, defined, bottom, top):
                ordered = np.sort(row[np.isfinite(row)])
                assert d == ordered.size
                trim = int(np.floor(BULK_TRIM * d))
                assert (lo, hi) == ((ordered[trim], ordered[max(d - 1 - trim, 0)]) if d else (np.inf, -np.inf))
