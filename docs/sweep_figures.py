"""Make the README's sweep figures: the 51-block wall's state map (frequency × amplitude) and a
fragility curve of the same wall from generated records. Run from the repository root:

    .venv/bin/python docs/sweep_figures.py [--fragility-only]

The records are synthetic (tests/synthetic_records.py: a tapered sum of sines with random phases,
written as PEER .AT2 files), so nothing is downloaded.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
from synthetic_records import band_limited, write_at2  # noqa: E402

IMAGES = ROOT / "docs" / "images"
ENV = os.environ | {"RERUN_ANALYTICS": "0"}


def masonry(*args) -> None:
    cmd = [sys.executable, "-m", "masonrycli", *map(str, args)]
    print("$ masonry " + " ".join(map(str, args)), flush=True)
    subprocess.run(cmd, check=True, env=ENV, cwd=ROOT)


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        if "--fragility-only" not in sys.argv:
            masonry(
                "sweep", "wall", "--param", "freq=1:4:4", "--param", "amp=0.25:1.5:6", "--duration", 2,
                "--out", f"{tmp}/wall.parquet", "--plot", IMAGES / "sweep-wall-state-map.png", "--force",
            )  # fmt: skip
        records = Path(tmp) / "records"
        records.mkdir()
        rng = np.random.default_rng(2026)
        for k in range(6):
            freqs = np.sort(rng.uniform(0.8, 4.0, 4))
            amps = 0.1 / freqs * rng.uniform(0.5, 1.5, 4)  # displacement falls with frequency
            t, u, v, a = band_limited(3.0, 0.01, freqs, amps, seed=k)
            write_at2(records / f"synthetic-{k + 1}.AT2", a / 9.80665, 0.01)
        masonry(
            "sweep", "wall", "--records", records, "--scale", "0.5:3:6", "--duration", 3, "--im", "pgv",
            "--out", f"{tmp}/wall-ida.parquet", "--plot", IMAGES / "sweep-wall-fragility.png", "--force",
        )  # fmt: skip


if __name__ == "__main__":
    main()
