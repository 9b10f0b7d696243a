"""Retake the screenshots of docs/scenarios.md and the README from the headless Rerun viewer.

Run the scenarios of docs/scenarios.md (its "Reproduce" section) with ``--out X.rrd``, then, from the
repository root::

    python docs/scenario_screenshots.py RUN_DIR docs/images

For each recording found in RUN_DIR: the whole window at the paper's instant (the recording opens on its
first paper-figure tab), the structure panel of each of the four paper-figure tabs (pinned to the paper's
instant), the magnified deformed shape and the joint states at the last frame. Prints the views' error
reports (``[]`` when healthy) and the files written.

A limit analysis's recording (``masonry limit arch --out limit-arch.rrd``, run in RUN_DIR) gives
docs/images/limit-arch.png (README, docs/limit.md): the whole window as the recording opens (the mechanism
beside the arch, its colour bar and the Limit analysis panel), what a reader sees first.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from PIL import Image

from masonrycli.recording import screenshot_recording

SHOTS = {  # recording -> (instant s, image stem, tabs to keep: tab index -> suffix)
    "wall51": (0.1, "wall51-t0.1", {1: "fig-III.2", 2: "fig-III.3", 3: "fig-III.4", 4: "fig-III.5"}),
    # tab 8: the spherical stress on the square-root scale ("p √"), live, at the same instant
    "wall248": (0.1, "wall248-t0.1", {1: "fig-III.2", 2: "fig-III.3", 3: "fig-III.4", 4: "fig-III.5", 8: "p-sqrt"}),
    "arch": (5.0, "arch-t5", {1: "fig-III.7", 2: "fig-III.8", 3: "fig-III.9", 4: "fig-III.10", 10: "magnified"}),
    "aqueduct": (
        5.0,
        "aqueduct-t5",
        {1: "fig-III.7", 2: "fig-III.8", 3: "fig-III.9", 4: "fig-III.10", 10: "magnified"},
    ),
    # a 1 s run has no paper-figure tabs: tab 1 is the live volumetric strain rate, 6 the magnified shape
    # (after Stress p, p √ and Stress q)
    "aqueduct-shaken": (1.0, "aqueduct-shaken-t1", {1: "volumetric-strain-rate", 6: "magnified"}),
}
STRUCTURE_PANEL = (
    0,
    38,
    1150,
    878,
)  # the left column of the 1920 × 1080 window with its whole tab bar, legend excluded
WINDOW_WIDTH = 1440  # the whole-window images are downscaled to this width


def _window(rrd: Path, target: Path, **where) -> None:
    """The whole window of ``rrd`` (``screenshot_recording``'s ``where``: an instant, or at open), downscaled to
    WINDOW_WIDTH, saved as ``target``; the views' reports printed."""
    with tempfile.TemporaryDirectory() as tmp:
        window = Path(tmp) / "window.png"
        print(f"{rrd}: {screenshot_recording(rrd, window, timeout=300, tabs_dir=tmp, **where)}")
        image = Image.open(window).convert("RGB")
        image.resize((WINDOW_WIDTH, round(image.height * WINDOW_WIDTH / image.width))).save(target, optimize=True)
        print(f"  {target}")


def main(run_dir: str, out_dir: str) -> None:
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if (Path(run_dir) / "limit-arch.rrd").exists():  # a limit analysis opens on its one view: shown at open
        _window(Path(run_dir) / "limit-arch.rrd", out / "limit-arch.png", at_open=True)
    for name, (instant, stem, tabs) in SHOTS.items():
        rrd = Path(run_dir) / f"{name}.rrd"
        if not rrd.exists():
            continue
        with tempfile.TemporaryDirectory() as tmp:
            window = Path(tmp) / "window.png"
            reports = screenshot_recording(rrd, window, time_s=instant, timeout=300, tabs_dir=tmp)
            print(f"{rrd}: {reports}")
            image = Image.open(window).convert("RGB")
            scale = WINDOW_WIDTH / image.width
            small = image.resize((WINDOW_WIDTH, round(image.height * scale)))
            small.save(out / f"{stem}-main.png", optimize=True)
            if name == "wall51":  # the README's screenshot
                small.save(out / "wall-viewer.png", optimize=True)
            for index, suffix in tabs.items():
                tab = Path(tmp) / f"tab{index}.png"
                if tab.exists():
                    target = out / f"{stem}-{suffix}.png"
                    Image.open(tab).convert("RGB").crop(STRUCTURE_PANEL).save(target, optimize=True)
                    print(f"  {target}")
            print(f"  {out / f'{stem}-main.png'}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    main(sys.argv[1], sys.argv[2])
