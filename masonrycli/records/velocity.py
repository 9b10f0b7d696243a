"""The velocity history a tabulated record defines: its samples prepared once, then evaluated at any times.

:class:`~masonrycli.records.motion.Record` holds the samples as read (``time`` (n,) s; ``value`` (n,) along a
direction or (n, 2)); :func:`record_arrays` prepares them (direction, scale, window, the nodal
velocities of an acceleration record, its baseline correction) and :func:`record_velocity` evaluates
the velocity at many instants at once.

* ``quantity = "velocity"``: the velocity is interpolated linearly between samples; before the first
  sample it holds the first value, after the last sample it holds the last value.
* ``quantity = "acceleration"``: the acceleration is interpolated linearly between samples and
  integrated exactly from v = 0 at the first sample. At the samples this *is* the cumulative
  trapezoid rule; between samples the velocity follows the exact (quadratic) integral of the linear
  acceleration rather than a chord, so that the velocity is the integral of the interpolated
  acceleration everywhere. Before the first sample v = 0 (the ground is at rest); after the last
  sample the acceleration is taken as zero, so the velocity holds its final integrated value.
* ``baseline = "quadratic"`` (the default for acceleration records): integrated records drift (noise
  and rounding in the samples add up), so the integrated velocity v is corrected by the smallest
  polynomial that brings the ground back to rest where it started. With s = (t − t₀)/T over the
  record (length T), v_c(t) = v(t) − (c₁ s + c₂ s²) where c₁ + c₂ = v(T) (ends at rest) and
  T (c₁/2 + c₂/3) = ∫v dt (ends where it started): c₂ = 3 v(T) − 6 D/T, c₁ = 6 D/T − 2 v(T),
  D = ∫₀ᵀ v dt computed exactly for the piecewise-quadratic v. The acceleration changes by the
  straight line (c₁ + 2 c₂ s)/T. For a record that already ends at rest where it started (a
  processed PEER record) c₁ and c₂ are tiny and the correction is invisible. ``baseline = "none"``
  integrates as is.
* ``window = [a, b]``: only the samples with a <= t <= b are used, moved so that the first of them
  is at t = 0.

Units: m/s, m/s², s.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class RecordArrays(NamedTuple):
    """A record prepared for evaluation (all float64, read-only)."""

    time: np.ndarray
    """(n,) s, the samples used (after the window's shift to t = 0)."""
    value: np.ndarray
    """(n, 2) m/s or m/s², scaled, along x and y."""
    nodal_v: np.ndarray
    """(n, 2) m/s, the velocity at the samples, uncorrected (``value`` for a velocity record)."""
    baseline: np.ndarray
    """(2, 2) m/s, rows c₁ and c₂ (one column per axis), zero when not corrected."""


def record_arrays(time, value, unit_direction, scale: float, window, quantity: str, baseline: str) -> RecordArrays:
    """The samples ``time`` (n,), ``value`` (n,) along ``unit_direction`` or (n, 2), prepared: times
    ``scale``, cut to ``window`` (None: all), integrated for an acceleration ``quantity`` and its
    ``baseline`` correction's coefficients (module docstring)."""
    time = np.asarray(time, dtype=np.float64)
    value = np.asarray(value, dtype=np.float64)
    if value.ndim == 1:
        value = value[:, None] * unit_direction[None, :]
    value = value * scale
    if window is not None:
        keep = (time >= window[0]) & (time <= window[1])
        time, value = time[keep] - time[keep][0], value[keep]
    coefficients = np.zeros((2, 2))
    if quantity == "acceleration":
        # cumulative trapezoid from v = 0 at the first sample
        h = np.diff(time)[:, None]
        nodal_v = np.zeros_like(value)
        nodal_v[1:] = np.cumsum(0.5 * h * (value[:-1] + value[1:]), axis=0)
        if baseline == "quadratic":
            # D = exact integral of the piecewise-quadratic velocity, interval by interval:
            #   ∫₀ʰ (v_i + a_i τ + (a_{i+1} − a_i) τ²/(2h)) dτ = h v_i + h² a_i / 2 + h² (a_{i+1} − a_i) / 6
            d = (h * nodal_v[:-1] + h * h * value[:-1] / 2.0 + h * h * (value[1:] - value[:-1]) / 6.0).sum(axis=0)
            length, v_end = time[-1] - time[0], nodal_v[-1]
            coefficients[1] = 3.0 * v_end - 6.0 * d / length
            coefficients[0] = 6.0 * d / length - 2.0 * v_end
    else:
        nodal_v = value
    if time.flags.writeable:  # without a window, the times given: left as they are
        time = time.copy()
    for a in (time, value, nodal_v, coefficients):
        a.setflags(write=False)
    return RecordArrays(time, value, nodal_v, coefficients)


def correction_acceleration(arrays: RecordArrays) -> np.ndarray:
    """(n, 2) m/s²: what the baseline correction subtracts from the acceleration at the samples, the
    straight line (c₁ + 2 c₂ s)/T (the derivative of c₁ s + c₂ s²); zero when not corrected. The applied
    acceleration is the linear interpolation of ``value`` minus this line, so its peak is at a sample."""
    time, baseline = arrays.time, arrays.baseline
    length = time[-1] - time[0]
    s = ((time - time[0]) / length)[:, None]
    return (baseline[0] + 2.0 * baseline[1] * s) / length


def record_velocity(t: np.ndarray, arrays: RecordArrays, quantity: str, corrected: bool) -> np.ndarray:
    """Velocity (T, 2) m/s at times ``t`` (T,) s of a record prepared by :func:`record_arrays`."""
    time, value, nodal_v, baseline = arrays
    out = np.zeros((t.shape[0], 2), dtype=np.float64)
    if quantity == "velocity":
        out[:, 0] = np.interp(t, time, value[:, 0])
        out[:, 1] = np.interp(t, time, value[:, 1])
        return out
    # exact integral of the piecewise-linear acceleration:
    #   i = interval holding t (clamped), tau = clip(t - t_i, 0, h_i)
    #   v = v_i + a_i tau + (a_{i+1} - a_i) tau^2 / (2 h_i)
    # tau clamps to 0 before the record (v = v_0 = 0) and to h_i after it (v = v_n).
    i = np.clip(np.searchsorted(time, t, side="right") - 1, 0, time.shape[0] - 2)
    h = (time[i + 1] - time[i])[:, None]
    tau = np.clip(t - time[i], 0.0, h[:, 0])[:, None]
    a0, a1 = value[i], value[i + 1]
    out[:] = nodal_v[i] + a0 * tau + (a1 - a0) * (tau * tau) / (2.0 * h)
    if corrected:
        s = (np.clip(t, time[0], time[-1]) - time[0])[:, None] / (time[-1] - time[0])
        out -= baseline[0] * s + baseline[1] * (s * s)
    return out
