"""The use rule's hold on a signed scale (``SHRINK_AFTER``, ``HOLD_SPAN``): one frame whose bulk spans less than
MIN_SPAN of the range (but at least HOLD_SPAN) keeps it, the second in a row refits it. Checked against a slow
plain-Python reference of the whole refit decision, frame by frame and in batches cut anywhere."""

from __future__ import annotations

import math

import numpy as np
import pytest

from masonrycli.recording.colour_range import HOLD_SPAN, MIN_SPAN, SHRINK_AFTER, RangeTracker, fit_range


def reference(kind: str, floor: float, frames: np.ndarray, shrink_after: int) -> tuple[list, list[str]]:
    """The range of each frame and why (fit / kept / short kept / refit), one value at a time: refitted
    (``fit_range``) when more than 2 % (rounded down) of the defined cells lie outside, or when the bulk —
    the defined cells sorted, 1 % (rounded down) left out at each end — spans less than 0.35 of the range,
    or less than 0.45 in ``shrink_after`` frames in a row."""
    current, short, out, why = None, 0, [], []
    for row in frames:
        cells = sorted(float(x) for x in row if math.isfinite(x))
        n = len(cells)
        if current is None:
            current, short = fit_range(row, kind, floor), 0
            out.append(current)
            why.append("fit")
            continue
        outside = sum(1 for x in cells if x < current.lo or x > current.hi)
        if n == 0:
            span = 1.0
        else:
            k = math.floor(0.01 * n)
            span = (min(cells[n - 1 - k], current.hi) - max(cells[k], current.lo)) / (current.hi - current.lo)
        if outside > math.floor(0.02 * n):
            current, short, reason = fit_range(row, kind, floor), 0, "refit"
        elif span >= 0.45:
            short, reason = 0, "kept"
        elif span >= 0.35 and short + 1 < shrink_after:
            short, reason = short + 1, "short kept"
        else:
            current, short, reason = fit_range(row, kind, floor), 0, "refit"
        out.append(current)
        why.append(reason)
    return out, why


def dipping_frames(kind: str, count: int = 160, seed: int = 4) -> np.ndarray:
    """300 cells a frame at a steady amplitude with dips: one frame to 0.5-0.6 × (the bulk then spans under
    MIN_SPAN but over HOLD_SPAN of a range fitted before), two frames in a row, and deeper ones (0.2 ×)."""
    rng = np.random.default_rng(seed)
    amplitude = np.ones(count)
    for start in range(6, count - 4, 9):
        kind_of_dip = (start // 9) % 3
        if kind_of_dip == 0:
            amplitude[start] = rng.uniform(0.5, 0.6)
        elif kind_of_dip == 1:
            amplitude[start : start + 2] = rng.uniform(0.5, 0.6)
        else:
            amplitude[start] = 0.2
    frames = amplitude[:, None] * rng.standard_normal((count, 300))
    frames[:, 11] = np.nan  # undefined cells do not count
    frames[40] = np.nan  # nor does a frame without one
    return {"signed": frames, "negative": -np.abs(frames), "positive": np.abs(frames)}[kind]


def test_the_hold_is_on_the_signed_scale_alone():
    assert SHRINK_AFTER == {"signed": 2, "negative": 1, "positive": 1}
    assert (HOLD_SPAN, MIN_SPAN) == (0.35, 0.45)


@pytest.mark.parametrize("kind", ["signed", "negative", "positive"])
def test_update_and_follow_give_the_reference_ranges(kind):
    frames = dipping_frames(kind)
    expected, why = reference(kind, 1e-9, frames, SHRINK_AFTER[kind])
    one = RangeTracker(kind, floor=1e-9)
    assert [one.update(v) for v in frames] == expected
    for cuts in ([], [1], [7, 8, 9], [50, 51, 97], list(range(3, 160, 13))):  # batches cut anywhere
        batch = RangeTracker(kind, floor=1e-9)
        ranges = []
        for part in np.split(frames, cuts):
            ranges += batch.follow(part)[0]
        assert ranges == expected, cuts
        assert batch.changes == one.changes
    if kind == "signed":  # every case happened: a short frame kept, a second one refitted, a deep one at once
        assert why.count("short kept") >= 5 and why.count("refit") >= 5
        without = reference(kind, 1e-9, frames, 1)[0]  # the rule before: every short frame refits
        changes = [sum(a != b for a, b in zip(r[1:], r[:-1])) for r in (expected, without)]
        assert changes[0] < changes[1], changes  # 20 against 26 here
    else:
        assert "short kept" not in why
        assert reference(kind, 1e-9, frames, 2)[0] != expected  # a hold would have changed these ranges


def test_no_frame_of_a_signed_field_is_short_twice_in_a_row_nor_under_hold_span():
    frames = dipping_frames("signed", seed=9)
    tracker = RangeTracker("signed", floor=1e-9)
    ranges = tracker.follow(frames)[0]
    short_before = False
    for r, v in zip(ranges, frames):
        if not np.isfinite(v).any():
            continue
        span = r.span(v)
        assert span >= HOLD_SPAN
        assert not (span < MIN_SPAN and short_before)
        short_before = span < MIN_SPAN
