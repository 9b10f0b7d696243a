"""Peak resident memory (RSS) of a whole `masonry` run against its length.

``--case wall`` (default): the 51-block wall shaken at 1 m/s, 2 Hz, every step recorded
(``--record-every 1``), with the recording and the history, for 1 s and for 20 s of simulated time (1 001
and 20 001 frames). ``--case steps``: what the run itself keeps per step, without outputs — one block at
rest on the ground, dt = 1e-5 s (10⁵ and 2·10⁶ steps for 1 s and 20 s), no recording, no history. Each
run is its own process; its peak RSS comes from ``os.wait4`` (``ru_maxrss``, kB on Linux). The outputs are
written to a temporary folder and removed. Accuracy is not at stake here (the same run, only longer):
the history's last frame (wall) or the summary (steps, out, bare) is checked to be at the requested time.

``--case out``: the wall at rest (``--amp 0``), every step recorded, the recording only (``--out``, no
history): the recording's memory against its frame count. ``--case bare``: the same run with
``--no-recording``, what the run needs without outputs. ``--blocks N`` (wall, out, bare): a wall of N blocks.

    .venv/bin/python benchmarks/bench_memory.py [--case wall|steps|out|bare] [--durations 1 20] [--blocks 51]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def peak_rss(duration: float, folder: Path, blocks: int = 51) -> tuple[float, float, int, float]:
    """(peak RSS MB, wall time s, frames, output MB) of one run."""
    rrd, npz = folder / f"w{duration:g}.rrd", folder / f"w{duration:g}.npz"
    argv = [sys.executable, "-m", "masonrycli", "simulate", "wall", "--duration", f"{duration:g}"]
    argv += ["--blocks", str(blocks), "--record-every", "1", "--out", str(rrd), "--history", str(npz)]
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, env=dict(os.environ, RERUN_ANALYTICS="0"), stdout=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"run of {duration:g} s failed")
    h = np.load(npz)
    assert abs(float(h["time"][-1]) - duration) < 1e-9, h["time"][-1]
    size = (rrd.stat().st_size + npz.stat().st_size) / 1e6
    frames = len(h["time"])
    rrd.unlink()
    npz.unlink()
    return usage.ru_maxrss / 1024, wall, frames, size


BLOCK = """
[run]
dt = 1e-5
[[block]]
polygon = [[-0.1, 0.0], [0.1, 0.0], [0.1, 0.6], [-0.1, 0.6]]
[[support]]
name = "ground"
polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]
"""


def peak_rss_steps(duration: float, folder: Path) -> tuple[float, float, int, float]:
    """(peak RSS MB, wall time s, steps, 0) of a run of one block writing nothing."""
    scenario = folder / "block.toml"
    scenario.write_text(BLOCK)
    argv = [sys.executable, "-m", "masonrycli", "run", str(scenario), "--duration", f"{duration:g}"]
    argv += ["--no-recording"]
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, env=dict(os.environ, RERUN_ANALYTICS="0", COLUMNS="200"), stdout=subprocess.PIPE)
    said = proc.stdout.read().decode()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    steps = round(duration / 1e-5)
    if os.waitstatus_to_exitcode(status) != 0 or f"{steps} (t = {duration:.4f} s)" not in said:
        raise SystemExit(f"run of {duration:g} s failed:\n{said}")
    return usage.ru_maxrss / 1024, wall, steps, 0.0


def peak_rss_at_rest(duration: float, folder: Path, blocks: int = 51, record: bool = True):
    """(peak RSS MB, wall time s, frames, output MB) of the wall at rest recorded every step, with the
    recording only (``record``) or with ``--no-recording``; the summary must say the run reached ``duration``
    (1 ms steps, the default)."""
    rrd = folder / f"r{duration:g}.rrd"
    argv = [sys.executable, "-m", "masonrycli", "simulate", "wall", "--duration", f"{duration:g}", "--amp", "0"]
    argv += ["--blocks", str(blocks), "--record-every", "1", *(["--out", str(rrd)] if record else ["--no-recording"])]
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, env=dict(os.environ, RERUN_ANALYTICS="0", COLUMNS="200"), stdout=subprocess.PIPE)
    said = proc.stdout.read().decode()
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    steps = round(duration / 1e-3)
    if os.waitstatus_to_exitcode(status) != 0 or f"{steps} (t = {duration:.4f} s)" not in said:
        raise SystemExit(f"run of {duration:g} s failed:\n{said}")
    size = rrd.stat().st_size / 1e6 if record else 0.0
    rrd.unlink(missing_ok=True)
    return usage.ru_maxrss / 1024, wall, steps + 1, size


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--durations", type=float, nargs="+", default=[1.0, 20.0])
    parser.add_argument("--case", choices=("wall", "steps", "out", "bare"), default="wall")
    parser.add_argument("--blocks", type=int, default=51, help="blocks of the wall (wall, out, bare)")
    args = parser.parse_args()
    measure = {
        "wall": lambda d, f: peak_rss(d, f, args.blocks),
        "steps": peak_rss_steps,
        "out": lambda d, f: peak_rss_at_rest(d, f, args.blocks, record=True),
        "bare": lambda d, f: peak_rss_at_rest(d, f, args.blocks, record=False),
    }[args.case]
    rows = []
    with tempfile.TemporaryDirectory(prefix="masonry-bench-memory-") as tmp:
        measure(0.01, Path(tmp))  # numba cache warm, not measured
        for duration in args.durations:
            rows.append((duration, *measure(duration, Path(tmp))))
    what = {
        "wall": f"{args.blocks}-block wall, --record-every 1, recording + history",
        "steps": "one block, dt 1e-5",
        "out": f"{args.blocks}-block wall, --amp 0, --record-every 1, recording only",
        "bare": f"{args.blocks}-block wall, --amp 0, --record-every 1, --no-recording",
    }[args.case]
    print(f"load average {os.getloadavg()[0]:.1f}; {what}")
    print(f"| simulated | {'steps' if args.case == 'steps' else 'frames'} | outputs | wall time | peak RSS |")
    print("|---|---|---|---|---|")
    for duration, rss, wall, frames, size in rows:
        print(f"| {duration:g} s | {frames} | {size:.0f} MB | {wall:.0f} s | {rss:.0f} MB |")
    if len(rows) >= 2:
        print(f"peak RSS ratio {rows[-1][0]:g} s / {rows[0][0]:g} s: {rows[-1][1] / rows[0][1]:.2f}")


if __name__ == "__main__":
    main()
