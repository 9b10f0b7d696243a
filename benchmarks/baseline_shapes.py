"""How much the quadratic baseline correction changes a record's acceleration, by shape of record: the figures
behind ``BASELINE_CHANGE`` (masonrycli/scenario/caveats.py), the warning of a record that does not start and
end at rest. A measurement, not a speed benchmark.

    .venv/bin/python -m benchmarks.baseline_shapes [--count 1500] [--seed 1]

For each shape: the largest change of the acceleration (the correction's straight line, at an end of the
record) over the record's PGA, and the PGA as applied over the PGA of the samples; median, 99th percentile and
maximum over ``--count`` records. Shapes:

* sines from rest, a = A sin(2π f t) over n whole cycles (a shake table's input): change 6/(2π n) of A;
* the test suite's tapered synthetic records (tests/synthetic_records.py), at rest at both ends;
* decaying noise bursts, 10-40 s at 100 Hz, envelope (t/tp) e^(1 − t/tp), tp 1.5-5 s: white noise,
  Kanai–Tajimi-filtered (firm soil, ωg = 15.6 rad/s, ζg = 0.6) and Clough–Penzien (that, high-passed at
  ωf = 1.6 rad/s, ζf = 0.6: no content at 0 Hz, as a real ground motion). The first two are never-processed
  records, rich in drift; the correction is what brings them back (their PGV changes by 30 % and more).
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy.signal import lsim, lti

from masonrycli.records.motion import Record

KANAI_TAJIMI = lti([2 * 0.6 * 15.6, 15.6**2], [1, 2 * 0.6 * 15.6, 15.6**2])
CLOUGH_PENZIEN = lti([1, 0, 0], [1, 2 * 0.6 * 1.6, 1.6**2])
BURSTS = ("white", "kanai-tajimi", "clough-penzien")


def bursts(kind: str, count: int, seed: int, longest: float = 40.0):
    """``count`` decaying noise bursts ``(t, a)`` of ``kind`` (one of ``BURSTS``), 10 s to ``longest`` long."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        t = np.arange(round(rng.uniform(10.0, longest) / 0.01) + 1) * 0.01
        tp = rng.uniform(1.5, 5.0)
        w = rng.standard_normal(t.size)
        if kind != "white":
            w = lsim(KANAI_TAJIMI, w, t)[1]
        if kind == "clough-penzien":
            w = lsim(CLOUGH_PENZIEN, w, t)[1]
        yield t, (t / tp) * np.exp(1.0 - t / tp) * w


def change(t, a) -> tuple[float, float]:
    """(largest change of the acceleration / PGA, applied PGA / PGA) of the record ``a`` at times ``t``."""
    m = Record(time=t, value=a, quantity="acceleration")
    applied, largest = m.baseline_change
    return largest / m.peak_acceleration, applied / m.peak_acceleration


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--count", type=int, default=1500)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    for f, length in ((2, 1), (1, 1), (2, 2), (2, 3), (2, 5), (5, 10), (10, 20)):
        t = np.arange(round(length * 200) + 1) / 200
        c, r = change(t, np.sin(2 * np.pi * f * t))
        print(f"sine from rest {f} Hz × {length} s ({f * length} cycles): change {c:.1%} of PGA, PGA ×{r:.4f}")
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
    from synthetic_records import band_limited

    # the shapes the tests build (grep "band_limited(" tests): (duration, dt, frequencies, amplitudes, seed)
    shapes = [
        *((0.2, 0.0005, [2.0], [0.01], 0), (0.2, 0.01, [2.0], [0.001], 0), (0.2, 0.01, [3.0, 5.0], [0.004, 0.002], 4)),
        *((0.3, 0.01, [2.0], [0.01], 1), (0.3, 0.01, [3.0, 5.0], [0.002, 0.001], 4), (0.5, 0.01, [2.0], [0.01], 0)),
        *((0.4, 0.005, [2.0, 4.0], [0.01, 0.005], 1), (1.5, 0.005, [1.5, 3.0], [0.01, 0.004], 2)),
        *((1.5, 0.01, [1.0, 2.5], [0.003, 0.001], 0), (2.0, 0.01, [1.5, 3.0], [0.01, 0.004], 3)),
        *((1.0, 0.01, [1.0 + 0.4 * s, 2.5], [0.03, 0.01], s) for s in range(6)),
        *((0.2, 0.01, [3.0 + k], [0.004], k) for k in range(4)),
    ]
    suite = [band_limited(d, dt, f, a, seed=s)[::3] for d, dt, f, a, s in shapes]
    worst = max(change(t, a)[0] for t, a in suite)
    print(f"tests/synthetic_records.py band_limited ({len(suite)} records): largest change {worst:.1e} of PGA")
    for kind in BURSTS:
        got = np.array([change(t, a) for t, a in bursts(kind, args.count, args.seed)])
        c, r = got[:, 0], np.abs(got[:, 1] - 1.0)
        print(
            f"{kind} bursts ({args.count}): change / PGA median {np.median(c):.2%} p99 {np.percentile(c, 99):.2%} "
            f"max {c.max():.2%}; |PGA ratio − 1| p99 {np.percentile(r, 99):.2%} max {r.max():.2%}"
        )


if __name__ == "__main__":
    main()
