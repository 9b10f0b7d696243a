"""Reading big ground-motion records: CPU seconds of the readers and of ``simulate wall --record``.

Writes records of ``--rows`` samples (default 3 million: 4 h at 200 Hz) in a temporary folder — CSV
``time,velocity`` (2 columns), ``time,vx,vy`` (3), ``time;velocity`` with decimal commas, one velocity
a line (read with a time step, ``--record-dt``), and a PEER .AT2 of 5 samples a line — then times
``load_record_csv`` / ``load_at2`` (CPU time, minimum of ``--repeat``) and, with ``--command``, the
whole ``masonry simulate wall --record FILE --duration 0.05 --no-recording`` in a fresh process
(its CPU time, user + system, minimum of ``--repeat``).

    .venv/bin/python -m benchmarks.bench_records [--rows 3000000] [--repeat 3] [--command]
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

from masonrycli.records.read import load_at2, load_record_csv

TIME_STEP = 0.005
"""s, the samples' spacing (the one-column file is read with it)."""


def write_records(folder: str, rows: int) -> dict[str, str]:
    """The five record files of ``rows`` samples (dt 5 ms, a 1.3 Hz burst on noise), by name."""
    t = np.arange(rows) * TIME_STEP
    rng = np.random.default_rng(0)
    a = 0.05 * np.sin(2 * np.pi * 1.3 * t) * np.exp(-(((t - t[-1] / 2) / (t[-1] / 4 + 1)) ** 2))
    a = a + 0.001 * rng.standard_normal(rows)
    ts, vs = [f"{x:.3f}" for x in t], [f"{x:.6e}" for x in a]
    files = {
        "2 columns": ("r2.csv", "time,velocity\n", (f"{x},{y}" for x, y in zip(ts, vs))),
        "3 columns": ("r3.csv", "time,vx,vy\n", (f"{x},{y},{y}" for x, y in zip(ts, vs))),
        "decimal commas": ("eu.csv", "time;velocity\n", (f"{x};{y:.6f}".replace(".", ",") for x, y in zip(ts, a))),
        "1 column": ("r1.csv", "velocity\n", iter(vs)),
        ".AT2": (
            "r.AT2",
            f"PEER NGA STRONG MOTION DATABASE RECORD\nSYNTHETIC\nACCELERATION TIME SERIES IN UNITS OF G\n"
            f"NPTS= {rows:7d}, DT=   .0050 SEC\n",
            ("".join(f"{x:15.7E}" for x in a[i : i + 5]) for i in range(0, rows, 5)),
        ),
    }
    paths = {}
    for label, (name, head, lines) in files.items():
        paths[label] = os.path.join(folder, name)
        with open(paths[label], "w") as fh:
            fh.write(head + "\n".join(lines) + "\n")
    return paths


def read_seconds(path: str, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if path.endswith(".AT2"):
                load_at2(path)
            else:
                load_record_csv(path, time_step=TIME_STEP if path.endswith("r1.csv") else None)
        best = min(best, time.process_time() - start)
    return best


def command_seconds(path: str, repeat: int) -> float:
    """CPU seconds (user + system) of the whole command, in a fresh process, minimum of ``repeat``."""
    args = [sys.executable, "-m", "masonrycli", "simulate", "wall", "--record", path, "--duration", "0.05"]
    if path.endswith("r1.csv"):
        args += ["--record-dt", str(TIME_STEP)]
    best = float("inf")
    for _ in range(repeat):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run(
            [*args, "--no-recording"], check=True, capture_output=True, env=os.environ | {"RERUN_ANALYTICS": "0"}
        )
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        best = min(best, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=3_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--command", action="store_true", help="time simulate wall --record too")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        paths = write_records(folder, args.rows)
        print(f"{args.rows} samples; CPU s, minimum of {args.repeat}")
        for label, path in paths.items():
            line = f"{label:>15}: read {read_seconds(path, args.repeat):6.2f} s"
            if args.command:
                line += f", simulate wall --record {command_seconds(path, args.repeat):6.2f} s"
            print(line, flush=True)


if __name__ == "__main__":
    main()
