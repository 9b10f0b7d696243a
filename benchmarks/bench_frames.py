"""What a recorded frame costs, part by part, for one git revision against another, and whether both wrote
the same recording and history.

    .venv/bin/python -m benchmarks.bench_frames --base REV [--new REV] [--rounds 3] [--json PATH]
        [-- simulate wall --blocks 248 --duration 0.2 --record-every 1]

Each revision (``git archive`` of its ``masonrycli`` and ``geometry_library``, as benchmarks/bench_kernel.py does; ``--new``
defaults to the working tree) runs the ``masonry`` command given (default above; ``--out``, ``--history``
and ``--force`` are added) in fresh processes of its own, with a numba cache of its own, rounds
alternating the order (base, new; new, base; …), each after the same run once to warm up (every kernel
loaded). Wrapped to add up their CPU time (``time.process_time``: the whole process, Rerun's threads
included, while the call runs):

* ``frame``: Simulation.frame (within it ``frame.tensors``, TensorComputer.fields; ``frame.joints``,
  the joint openings, block fields and hinges);
* ``history``: HistoryFile.on_frame and close;
* ``record``: Recorder.on_frame, log_step and close (within it ``record.send``, the batches' sends, and
  ``record.resultants``, the joint resultants of the batches);
* ``run``: the whole of ``simulate`` (the engine's steps included).

Reported: the minimum over rounds of each, in ms a recorded frame, and ``same``: whether the two revisions'
recordings hold the same rows (``masonrycli.recording.readback.recording_rows``: every entity's rows,
time columns and component values; the run document's wall time and start time masked) and their
history files the same arrays.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from benchmarks.bench_phases import _timed

os.environ.setdefault("RERUN_ANALYTICS", "0")
ROOT = Path(__file__).resolve().parent.parent
DEFAULT_COMMAND = ("simulate", "wall", "--blocks", "248", "--duration", "0.2", "--record-every", "1")
PARTS = ("frame", "frame.tensors", "frame.joints", "history", "record", "record.send", "record.resultants", "run")


def worker(package_root: str, out: str, command: list[str]) -> None:
    """In a fresh process: the command, once to warm up, then timed (JSON on the last line)."""
    sys.path[:0] = [package_root, str(ROOT)]
    from masonrycli import run
    from masonrycli.analysis.mechanism import JointTracker
    from masonrycli.analysis.tensors import TensorComputer
    from masonrycli.cli.app import app
    from masonrycli.outputs import history
    from masonrycli.recording import overlays, recorder

    assert Path(run.__file__).is_relative_to(package_root), run.__file__
    totals: dict[str, float] = {}
    frames = [0]
    on_frame = history.HistoryFile.on_frame

    def counted(self, frame):
        frames[0] += 1
        return on_frame(self, frame)

    history.HistoryFile.on_frame = counted
    for owner, name, key in (
        (run.Simulation, "frame", "frame"), (TensorComputer, "fields", "frame.tensors"),
        (JointTracker, "opening", "frame.joints"), (JointTracker, "block_fields", "frame.joints"),
        (JointTracker, "hinged", "frame.joints"), (JointTracker, "hinge_points", "frame.joints"),
        (history.HistoryFile, "on_frame", "history"), (history.HistoryFile, "close", "history"),
        (recorder.Recorder, "on_frame", "record"), (recorder.Recorder, "log_step", "record"),
        (recorder.Recorder, "close", "record"), (recorder.Recorder, "flush", "record.send"),
        (overlays, "joint_resultants", "record.resultants"), (run, "simulate", "run"),
    ):  # fmt: skip
        _timed(owner, name, key, totals)
    from masonrycli import execute

    execute.simulate = run.simulate
    files = ["--out", f"{out}.rrd", "--history", f"{out}.npz", "--force"]
    app([*command, *files], standalone_mode=False)  # warm-up: every kernel the run needs loaded
    totals.clear()
    frames[0] = 0
    app([*command, *files], standalone_mode=False)
    print(json.dumps({"frames": frames[0], "ms_per_frame": {k: 1e3 * v / frames[0] for k, v in totals.items()}}))


def same_outputs(a: str, b: str) -> dict[str, bool]:
    """Whether the runs written at ``a`` and ``b`` (stems) recorded the same rows and history arrays."""
    import json

    import numpy as np

    from masonrycli.recording.readback import recording_rows

    with np.load(f"{a}.npz") as x, np.load(f"{b}.npz") as y:
        history = sorted(x.files) == sorted(y.files) and all(
            x[k].dtype == y[k].dtype and np.array_equal(x[k], y[k], equal_nan=x[k].dtype.kind == "f")
            for k in x.files
            if k != "run"
        )
        if history and "run" in x.files:  # the parameters, without the clock and the code (two revisions)
            clock = ("started", "commit", "source_digest")
            run_a, run_b = (json.loads(str(h["run"])) for h in (x, y))
            history = all(run_a.get(k) == run_b.get(k) for k in run_a.keys() | run_b.keys() if k not in clock)
    rows_a, rows_b = recording_rows(f"{a}.rrd"), recording_rows(f"{b}.rrd")
    differ = sorted(k for k in rows_a.keys() | rows_b.keys() if rows_a.get(k) != rows_b.get(k))
    return {"history": history, "recording": not differ, "differ": differ}


def compare(base: str, new: str, command: list[str], rounds: int, keep: Path | None = None) -> dict:
    """Time ``base`` and ``new`` in alternating fresh processes (module doc); ``keep``: a folder where the
    checkouts and numba caches stay between calls (a revision's kernels compiled once)."""
    from benchmarks.bench_kernel import WORKTREE, checkout

    results: dict[str, list] = {"base": [], "new": []}
    with tempfile.TemporaryDirectory() as tmp:
        kept = Path(keep or tmp)
        kept.mkdir(exist_ok=True)
        roots = {}
        for name, rev in (("base", base), ("new", new)):
            sha = (
                rev
                if rev == WORKTREE
                else subprocess.check_output(["git", "-C", str(ROOT), "rev-parse", rev], text=True)
            )
            into = kept / f"src-{sha.strip()}"
            roots[name] = str(into) if into.is_dir() else checkout(rev, into)
        for k in range(rounds):
            for name in ("base", "new") if k % 2 == 0 else ("new", "base"):
                env = dict(os.environ)
                if roots[name] != str(ROOT):  # a checkout: a numba cache of its own (the worktree keeps its own)
                    env["NUMBA_CACHE_DIR"] = str(kept / f"cache-{Path(roots[name]).name}")
                stem = str(Path(tmp) / f"out-{name}")
                cmd = [sys.executable, __file__, "--worker", roots[name], stem, "--", *command]
                out = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp, env=env)
                if out.returncode:
                    raise SystemExit(f"bench_frames: {name} worker failed:\n{out.stderr[-3000:]}")
                results[name].append(json.loads(out.stdout.splitlines()[-1]))
        same = same_outputs(str(Path(tmp) / "out-base"), str(Path(tmp) / "out-new"))
    row = {"command": " ".join(command), "rounds": rounds, "same": same}
    for name, rev in (("base", base), ("new", new)):
        runs = results[name]
        row[name] = {
            "revision": rev,
            "frames": runs[0]["frames"],
            "ms_per_frame": {p: min(r["ms_per_frame"].get(p, 0.0) for r in runs) for p in PARTS},
        }
    return row


def main(argv=None) -> dict | None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", default="HEAD", help="git revision (or 'worktree')")
    parser.add_argument("--new", default="worktree", help="git revision (default: the working tree)")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--json", type=Path)
    parser.add_argument("--keep", type=Path, help="folder keeping the checkouts and numba caches between calls")
    parser.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    parser.add_argument("command", nargs="*", help="the masonry command (after --)")
    args = parser.parse_args(argv)
    command = args.command or list(DEFAULT_COMMAND)
    if args.worker:
        return worker(*args.worker, command)
    row = compare(args.base, args.new, command, args.rounds, args.keep)
    b, n = row["base"], row["new"]
    print(f"masonry {row['command']}: {n['frames']} frames, minimum of {row['rounds']} rounds")
    print(f"{'part (ms a frame)':18} {b['revision']:>12} {n['revision']:>12}   new/base")
    for p in PARTS:
        x, y = b["ms_per_frame"][p], n["ms_per_frame"][p]
        print(f"{p:18} {x:12.3f} {y:12.3f}   {y / x if x else float('nan'):.3f}")
    print(f"same history: {row['same']['history']}; same recording: {row['same']['recording']} {row['same']['differ']}")
    if args.json:
        args.json.write_text(json.dumps(row, indent=1) + "\n")
    return row


if __name__ == "__main__":
    main()
