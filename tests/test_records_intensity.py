"""Intensity measures against closed forms (sine) and an independent SDOF integration (scipy)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from masonrycli.records.intensity import SA_DAMPING, describe, intensity_measures, shaking_support
from masonrycli.records.motion import Record
from masonrycli.scenario.motion import Constant, Fixed, Sine

from cli_helpers import invoke, words


def test_sine_ground_closed_forms():
    # v = A sin(2π f t) over whole cycles: PGA = 2π f A, PGV = A, Arias = π/(2g) (2π f A)^2 D / 2,
    # uniform intensity so D5–95 = 0.9 D
    amp, f, duration, dt = 0.3, 2.0, 5.0, 1e-3
    t = np.arange(round(duration / dt) + 1) * dt
    ims = intensity_measures(Sine(amplitude=amp, frequency=f).velocity_at(t)[:, 0], dt)
    a0 = 2 * np.pi * f * amp
    assert ims["pga"] == pytest.approx(a0, rel=1e-4)
    assert ims["pgv"] == pytest.approx(amp, rel=1e-6)
    assert ims["arias"] == pytest.approx(np.pi / (2 * 9.81) * a0**2 * duration / 2, rel=1e-3)
    assert ims["d5_95"] == pytest.approx(0.9 * duration, rel=1e-2)


def test_spectral_acceleration_matches_independent_sdof():
    rng = np.random.default_rng(2)
    dt, n = 0.005, 2000
    acc = np.convolve(rng.normal(size=n), np.ones(8) / 8, mode="same")  # band-limited noise, m/s²
    v = np.concatenate([[0.0], np.cumsum(acc) * dt])
    period = 0.4
    ims = intensity_measures(v, dt, sa_period=period)
    # u'' + 2ξω u' + ω² u = −a(t), a held over each step (zero-order hold: exact for the step-wise
    # acceleration the differences of v describe); pseudo-Sa = ω² max|u|
    w = 2 * np.pi / period
    a_mat = np.array([[0.0, 1.0], [-w * w, -2 * SA_DAMPING * w]])
    ad, bd, cd, dd, _ = signal.cont2discrete((a_mat, np.array([[0.0], [-1.0]]), np.eye(1, 2), np.zeros((1, 1))), dt)
    _, u, _ = signal.dlsim((ad, bd, cd, dd, dt), acc)
    assert ims["sa"] == pytest.approx(w * w * np.abs(u).max(), rel=0.03)
    assert ims["pga"] == pytest.approx(np.abs(acc).max(), rel=1e-9)


def test_still_ground_and_shaking_support():
    t = np.arange(101) * 0.01
    ims = intensity_measures(Constant(velocity=(0.01, 0)).velocity_at(t)[:, 0], 0.01)
    assert ims == {"pga": 0.0, "pgv": 0.01, "arias": 0.0, "d5_95": 0.0, "sa": 0.0}
    rec = Record(time=(0, 1), value=(1, 2))
    assert shaking_support([Fixed(), Constant(velocity=(0, -0.01)), rec]) == 2
    assert shaking_support([Fixed()]) is None
    assert describe({"pga": 9.80665, "pgv": 1, "arias": 2, "d5_95": 3, "sa": 4}).startswith("PGA 9.81 m/s² (1 g)")


def test_a_run_of_two_steps_has_no_resolved_significant_duration():
    # `masonry simulate wall --duration 0.002` ended in "internal error: IndexError" (exit 1) after
    # writing its outputs: eqsig's D5–95 indexes the samples strictly between 5 % and 95 % of the Arias
    # intensity, and two steps of a sine from rest have none. The other measures stand.
    dt = 1e-3
    t = np.arange(3) * dt
    v = Sine(amplitude=1.0, frequency=2.0).velocity_at(t)[:, 0]
    ims = intensity_measures(v, dt)
    assert np.isnan(ims["d5_95"])
    acc = np.diff(v) / dt
    assert ims["pga"] == pytest.approx(np.abs(acc).max()) and ims["pgv"] == pytest.approx(np.abs(v).max())
    # Arias by the trapezoid rule over the two acceleration samples
    assert ims["arias"] == pytest.approx(np.pi / (2 * 9.81) * dt * (acc[0] ** 2 + acc[1] ** 2) / 2, rel=1e-9)


def test_a_two_step_run_completes():
    # It wrote its outputs, then ended in "internal error: IndexError" (exit 1) computing D5–95.
    result = invoke("simulate", "wall", "--duration", 0.002, "--no-recording")
    assert result.exit_code == 0, result.output
    assert "D5–95 nan s" in words(result.output)
