"""What each colour tab of a recording draws over the run: refits and washed-out frames, read back.

    .venv/bin/python -m benchmarks.bench_colours RUN.rrd [BASE.rrd]

Per field view (the six fields' tabs and the square-root ones, ``layout.COLOURED``), over the frames after
t = 0 read back with ``readback.field_frames`` (the ranges logged and the hover values, float32):

* ``refits``: frames whose logged range differs from the frame before's;
* ``washed``: the share of frames where at least half of the defined cells are drawn in the tenth of the
  colour bar next to zero (|value| <= 0.1 × the range end on its side on a linear tab, 0.01 × on a
  square-root one: the same tenth of the bar) — the bulk of the field pale (blues, diverging) or dark
  (viridis) whatever its gradients;
* ``median``: the median over frames of the cells' median distance from the zero end, in bar lengths.

With ``BASE.rrd`` (the same command at another revision) both side by side, how many (frame, field) ranges
differ, and whether the four paper fields' ranges are the same at 0.1 s and 5 s when recorded (the paper's
instants: 0.1 s on the walls, 5 s on the arch and the aqueduct).
"""

from __future__ import annotations

import argparse
import os

import numpy as np

os.environ.setdefault("RERUN_ANALYTICS", "0")
PAPER_INSTANTS = (0.1, 5.0)


def tab_figures(frames: dict) -> dict[str, tuple[int, float, float]]:
    """Field view name -> (refits, washed-out share %, median distance from zero) over frames after t = 0."""
    steps = sorted(s for s in frames if frames[s].get("time", 0.0) > 0.0)
    out = {}
    for name in frames[steps[-1]]["ranges"]:
        key, sqrt = name.split("@")[0], name.endswith("@sqrt")
        last, refits, washed, medians = None, 0, 0, []
        for s in steps:
            lo, hi = frames[s]["ranges"][name]
            refits += last is not None and (lo, hi) != last
            last = (lo, hi)
            v = frames[s]["values"][key]
            v = v[np.isfinite(v)]
            if v.size == 0:
                continue
            share = np.where(v < 0, v / lo if lo < 0 else 0.0, v / hi if hi > 0 else 0.0)  # of the end, 0 … 1
            at = np.clip(np.abs(share), 0.0, 1.0)
            at = np.sqrt(at) if sqrt else at
            washed += (at <= 0.1).mean() >= 0.5
            medians.append(float(np.median(at)))
        out[name] = (refits, 100.0 * washed / len(steps), float(np.median(medians)) if medians else float("nan"))
    return out


def paper_ranges(frames: dict) -> dict[float, dict]:
    """Paper instant recorded (0.1 s: the walls' figures, 5 s: the arch's and the aqueduct's) -> the four
    paper fields' ranges there."""
    from masonrycli.recording.layout import PAPER_FIELDS

    out = {}
    for instant in PAPER_INSTANTS:
        at = [s for s in frames if abs(frames[s].get("time", -1.0) - instant) < 1e-9]
        if at:
            out[instant] = {f.key: frames[at[0]]["ranges"][f.key] for f in PAPER_FIELDS}
    return out


def main(argv=None) -> None:
    from masonrycli.recording.readback import field_frames

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run", help="recording (.rrd)")
    parser.add_argument("base", nargs="?", help="the same run at another revision (.rrd)")
    args = parser.parse_args(argv)
    new = field_frames(args.run)
    old = field_frames(args.base) if args.base else None
    figures, before = tab_figures(new), tab_figures(old) if old else {}
    print(f"{args.run}" + (f" against {args.base}" if old else ""))
    for name, (refits, washed, median) in figures.items():
        line = f"  {name.removeprefix('cell_').removeprefix('block_'):26s}"
        if old:
            b = before.get(name)
            line += "  refits    - -> " if b is None else f"  refits {b[0]:4d} -> "
            line += f"{refits:4d}  washed " + ("    - -> " if b is None else f"{b[1]:5.1f} -> ")
            line += f"{washed:5.1f} %  median " + ("    - -> " if b is None else f"{b[2]:.3f} -> ") + f"{median:.3f}"
        else:
            line += f"  refits {refits:4d}  washed {washed:5.1f} %  median {median:.3f}"
        print(line)
    if old:
        differ = sum(
            old.get(s, {}).get("ranges", {}).get(k) != r
            for s in new
            for k, r in new[s]["ranges"].items()
            if "@" not in k
        )
        print(f"  (frame, field) ranges that differ: {differ}")
        p_old = paper_ranges(old)
        for instant, ranges in paper_ranges(new).items():
            print(f"  the four paper fields' ranges at t = {instant:g} s the same: {ranges == p_old.get(instant)}")


if __name__ == "__main__":
    main()
