"""The residual plot's range counted CHUNK residuals at a time gives what one residual at a time gave."""

from __future__ import annotations

import numpy as np

from masonrycli.recording import residual_range
from masonrycli.recording.residual_range import ResidualRange


def _one_at_a_time(residuals, tolerance):
    # ResidualRange.add before the chunks: numpy's scalar calls, one step at a time
    log10_tolerance = float(np.log10(tolerance)) if tolerance else np.nan
    steps, low_count, worst, best = 0, 0, 0.0, np.inf
    for residual in residuals:
        r = float(residual)
        if not (np.isfinite(r) and r > 0):
            continue
        low = bool(np.log10(r) < log10_tolerance - 1.0)
        steps += 1
        low_count += low
        worst = max(worst, r)
        best = best if low else min(best, r)
    return steps, low_count, worst, best


def test_the_chunks_count_as_one_residual_at_a_time():
    rng = np.random.default_rng(7)
    tolerance = 1e-5
    edge = float(10 ** (np.log10(tolerance) - 1.0))  # a decade under the tolerance: which side is numpy's log10's
    residuals = np.concatenate(
        [
            10 ** rng.uniform(-9, -3, 2 * residual_range.CHUNK + 37),
            [edge, np.nextafter(edge, 0), np.nextafter(edge, 1), 0.0, -1e-6, np.nan, np.inf],
        ]
    )
    rng.shuffle(residuals)
    for n in (0, 5, residual_range.CHUNK, residual_range.CHUNK + 1, len(residuals)):
        kept = ResidualRange(tolerance)
        for r in residuals[:n]:
            kept.add(float(r))
        kept.range()  # counts what is kept
        assert (kept._steps, kept._low, kept._worst, kept._best) == _one_at_a_time(residuals[:n], tolerance)


def test_the_range_is_the_same_whenever_it_is_asked():
    kept = ResidualRange(1e-5)
    for r in (2e-6, 3e-5, 8e-6):
        kept.add(r)
    first = kept.range()
    assert first == kept.range() and first is not None
    lo, hi = first
    assert lo < np.log10(2e-6) and hi > np.log10(3e-5)


def test_numpys_log10_gives_an_arrays_elements_as_it_gives_each_alone():
    # what the chunks rely on (math.log10 differs from numpy's in the last bit for some residuals)
    x = 10 ** np.random.default_rng(3).uniform(-12, 1, 20_000)
    alone = np.array([np.log10(float(v)) for v in x])
    assert np.array_equal(np.log10(x), alone)
    assert np.array_equal(np.log10(x[5:777]), alone[5:777])
