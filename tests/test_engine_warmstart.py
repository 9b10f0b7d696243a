"""engine.warmstart: the previous step's impulses carried over by contact key."""

from __future__ import annotations

import numpy as np

from masonrycli.engine.warmstart import WarmStart


def test_remembered_keys_are_sorted_stably_and_found_again():
    rng = np.random.default_rng(4)
    warm = WarmStart(4)  # grows when a step has more contacts
    for count in (0, 1, 7, 60):
        key = np.sort(rng.integers(0, 40, count)) * 4 + rng.integers(0, 4, count)  # near-sorted, as detected
        key[: count // 2] = rng.permutation(key[: count // 2])
        r = rng.standard_normal((count + 3, 2))
        warm.remember(key, r, count)
        order = np.argsort(key, kind="stable")
        np.testing.assert_array_equal(warm.key, key[order])
        np.testing.assert_array_equal(warm.r[:count], r[:count][order])
        unique = np.unique(key)
        out = np.full((unique.size, 2), np.nan)
        assert warm.start(unique, unique.size, out) == unique.size
        first = {k: r[i] for i, k in reversed(list(enumerate(key)))}  # the first of equal keys, as searchsorted
        np.testing.assert_array_equal(out, np.reshape([first[k] for k in unique], (-1, 2)))
        fresh = np.full((2, 2), np.nan)
        assert warm.start(np.array([-1, 10**6]), 2, fresh) == 0 and not fresh.any()
