"""A block that falls clear of the model (wholly below every support, nothing left to land on) is in free
fall, not a diverged state: 'masonry simulate wall --duration 1e5' ended "diverged at t = 243 s: a block
reached 1e+03 m/s" (exit 3) where a stone had walked off the shaken ground's end at t ≈ 140 s and fallen
freely since — 9.81 m/s² × 102 s = 1000 m/s. The reference here is free fall itself: v(t) = g·t exactly
for a block that starts beside the ground at rest."""

from __future__ import annotations

import numpy as np
import pytest

from cli_helpers import invoke

SCENARIO = """
name = "stone-beside-the-ground"

[run]
duration = {duration}
dt = 0.01
record_every = 100

[[block]]
name = "on-ground"
polygon = [[-0.2, 0.0], [0.2, 0.0], [0.2, 0.2], [-0.2, 0.2]]

[[block]]
name = "beside"
polygon = [[8.0, {y0}], [8.4, {y0}], [8.4, {y1}], [8.0, {y1}]]
{velocity}

[[support]]
name = "ground"
polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]
"""


def _run(tmp_path, duration, y0, velocity=""):
    path = tmp_path / "s.toml"
    path.write_text(SCENARIO.format(duration=duration, y0=y0, y1=y0 + 0.2, velocity=velocity))
    hist = tmp_path / "h.npz"
    result = invoke("run", path, "--no-recording", "--history", hist)
    return result, hist


def test_a_block_falling_clear_of_the_ground_does_not_make_the_run_diverge(tmp_path):
    # 110 s: the falling block passes 1000 m/s at t = 1000 / 9.81 = 101.9 s (the old code stopped there, exit 3)
    result, hist = _run(tmp_path, 110, -1.0)
    assert result.exit_code == 0, result.output
    h = np.load(hist, allow_pickle=True)
    t, v = h["time"], h["block_v"]
    assert t[-1] == pytest.approx(110.0)
    # free fall: v_y = -g t (θ = 0.5 integrates a constant acceleration exactly)
    np.testing.assert_allclose(v[:, 1, 1], -9.81 * t, rtol=1e-9, atol=1e-9)
    assert np.abs(v[:, 0, :]).max() < 1e-6  # the stone on the ground stays at rest


def test_a_block_above_the_ground_faster_than_the_bound_still_diverges(tmp_path):
    # the same stone 100 m up, above the ground's lowest point (not clear of it), thrown down at 999.9 m/s:
    # g passes it over 1000 m/s within 0.02 s, 50 m before it could reach the ground — diverged as before
    result, _ = _run(tmp_path, 0.05, 100.0, "velocity = [0.0, -999.9, 0.0]")
    assert result.exit_code == 3, result.output
    assert "diverged" in result.output and "m/s" in result.output
