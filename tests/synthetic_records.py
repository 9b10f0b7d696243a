"""Synthetic ground motions with a known integral, and a writer of real-format PEER .AT2 files.

The ground displacement is u(t) = w(t) · Σ_k A_k sin(2π f_k t + φ_k) with the taper w = sin⁴(π t / T):
u, u' and u'' vanish at both ends, so the velocity v = u' and the acceleration a = u'' are known in
closed form, the ground starts and ends at rest, and it ends where it started (∫v dt = u(T) − u(0) = 0).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np


def band_limited(duration: float, dt: float, freqs, amps, seed: int = 0):
    """``(t, u, v, a)`` arrays at t = 0, dt, ..., duration (m, m/s, m/s²)."""
    rng = np.random.default_rng(seed)
    phases = rng.uniform(0.0, 2.0 * np.pi, len(freqs))
    t = np.arange(round(duration / dt) + 1) * dt
    return (t, *closed_form(t, duration, freqs, amps, phases))


def closed_form(t, duration, freqs, amps, phases):
    """u, v, a of the tapered sum at times ``t`` (product rule, w = S⁴ with S = sin(πt/T), C = cos(πt/T))."""
    k = np.pi / duration
    S, C = np.sin(k * t), np.cos(k * t)
    w, w1, w2 = S**4, 4 * k * S**3 * C, k * k * (12 * S**2 * C**2 - 4 * S**4)
    s = s1 = s2 = 0.0
    for f, amp, ph in zip(freqs, amps, phases):
        om = 2 * np.pi * f
        s = s + amp * np.sin(om * t + ph)
        s1 = s1 + amp * om * np.cos(om * t + ph)
        s2 = s2 - amp * om * om * np.sin(om * t + ph)
    return w * s, w1 * s + w * s1, w2 * s + 2 * w1 * s1 + w * s2


def write_at2(path, acc_g, dt: float, title: str = "SYNTHETIC 11/23/26, TEST STATION, 000") -> None:
    """A PEER NGA-West2 style .AT2 file: 3 text lines, ``NPTS=..., DT=... SEC``, 5 samples a line."""
    lines = [
        "PEER NGA STRONG MOTION DATABASE RECORD",
        title,
        "ACCELERATION TIME SERIES IN UNITS OF G",
        f"NPTS= {len(acc_g):6d}, DT= {dt:8.4f} SEC",
    ]
    for i in range(0, len(acc_g), 5):
        lines.append("".join(f"{x:15.7E}" for x in acc_g[i : i + 5]))
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")


def edited_copy(source: Path, target: Path, old: str, new: str) -> Path:
    """``source``'s text with its first ``old`` replaced by ``new``, written at ``target`` (a damaged record)."""
    text = source.read_text()
    assert old in text
    target.write_text(text.replace(old, new, 1))
    return target
