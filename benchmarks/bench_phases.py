"""Where a step's CPU time goes, phase by phase, for one git revision against another, and whether both give
the same bits.

    .venv/bin/python -m benchmarks.bench_phases --base REV [--new REV] [--case wall-248] [--duration 1]
        [--rounds 3] [--no-record] [--json PATH]

Each revision (``git archive`` of its ``masonrycli`` and ``geometry_library``, as benchmarks/bench_kernel.py does; ``--new``
defaults to the working tree) runs ``--case`` in fresh processes of its own, with a numba cache of its
own (bench_kernel.worker_env), rounds alternating the order (base, new; new, base; …). A run is the solver benchmark's
(bench_solver.run_masonry: the scenario built first, then ``simulate`` timed, a Rerun recording every 10
steps unless ``--no-record``), after a 0.02 s warm-up run, with the step's launchers wrapped to add up
their CPU time (``time.process_time``, ~0.7 µs a call on this machine):

* ``before_solve`` (fused.before_solve: q_m, detection, warm start, v_free), ``prepare``
  (nlgs.prepare_contacts), ``solve`` (dispatch.solve; within it ``solve.sweeps``, the float64 first stage
  and the interleaved sweeps: dispatch.first_stage and interleaved.sweeps, or nlgs._nlgs_interleaved in a
  revision before engine/dispatch.py; the default's lane_sweeps32.first_stage, within it ``solve.sweeps32``,
  its float32 sweeps with their set-up, and ``solve.polish64``, the float64 lane sweeps after them, set-up
  included; and ``solve.stalled``, stalled.py's methods), ``contact_power``, ``after_solve``;
* outside the solver: ``tensors`` (TensorComputer.step), ``monitor`` (CollapseMonitor.update),
  ``frame`` (Simulation.frame, every recorded frame), ``record`` (Recorder.on_frame and close);
* ``rest``: the run's CPU time minus all of the above (the loop, the statistics, Python between calls).

Reported: for each phase the minimum over rounds in ms a step, and CPU s per simulated s; ``bits``: whether
the two revisions end with the same q, v and impulses and made the same sweeps and residuals at every
step (a digest; a revision that changes any of them is not a like-for-like comparison).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("RERUN_ANALYTICS", "0")
ROOT = Path(__file__).resolve().parent.parent
PHASES = (
    "before_solve", "prepare", "solve", "solve.sweeps", "solve.sweeps32", "solve.polish64", "solve.stalled",
    "contact_power", "after_solve",
    "tensors", "monitor", "frame", "record", "rest",
)  # fmt: skip


def _timed(owner, name: str, key: str, totals: dict) -> None:
    """Replace ``owner.name`` by a wrapper adding its CPU time to ``totals[key]`` (if ``owner`` has it)."""
    inner = getattr(owner, name, None)
    if inner is None:
        return

    def timed(*args, **kwargs):
        start = time.process_time()
        try:
            return inner(*args, **kwargs)
        finally:
            totals[key] = totals.get(key, 0.0) + time.process_time() - start

    setattr(owner, name, timed)


def worker(package_root: str, case: str, duration: float, record: bool) -> None:
    """In a fresh process: one timed run of ``case`` with the ``masonrycli`` under ``package_root`` (JSON out)."""
    sys.path[:0] = [package_root, str(ROOT)]  # masonrycli, geometry_library from package_root; benchmarks here
    import numpy as np

    from benchmarks import bench_solver
    from masonrycli.engine import fused, interleaved, nlgs, power, stalled

    try:  # the float32 first stage (solver nlgs-accel32, the default since 878c068)
        from masonrycli.engine import lane_sweeps, lane_sweeps32
    except ImportError:
        lane_sweeps = lane_sweeps32 = None
    from masonrycli.recording import Recorder

    try:  # solve() and the first stage: engine/dispatch.py; nlgs.solve and nlgs._nlgs_interleaved before it
        from masonrycli.engine import dispatch
    except ImportError:
        dispatch = nlgs
    assert Path(nlgs.__file__).is_relative_to(package_root), nlgs.__file__
    totals: dict[str, float] = {}
    for owner, name, key in (
        (fused, "before_solve", "before_solve"), (nlgs, "prepare_contacts", "prepare"), (dispatch, "solve", "solve"),
        (nlgs, "_nlgs_interleaved", "solve.sweeps"), (dispatch, "first_stage", "solve.sweeps"),
        (interleaved, "sweeps", "solve.sweeps"), (lane_sweeps32, "first_stage", "solve.sweeps"),
        (lane_sweeps32, "lane_sweeps32", "solve.sweeps32"), (lane_sweeps, "_lane_sweeps", "solve.polish64"),
        (stalled, "continue_stalled", "solve.stalled"),
        (power, "contact_power", "contact_power"), (fused, "after_solve", "after_solve"),
        (Recorder, "on_frame", "record"), (Recorder, "close", "record"),
    ):  # fmt: skip
        _timed(owner, name, key, totals)
    history: list[tuple] = []
    simulation = bench_solver.Simulation

    def instrumented(scenario):
        sim = simulation(scenario)
        _timed(sim.tensors, "step", "tensors", totals)
        _timed(sim.monitor, "update", "monitor", totals)
        _timed(sim, "frame", "frame", totals)
        step = sim.step

        def logged_step():
            stats = step()
            history.append((stats.iterations, stats.residual, stats.contact_count))
            return stats

        sim.step = logged_step
        instrumented.sim = sim
        return sim

    bench_solver.Simulation = instrumented
    bench_solver.run_masonry(case, 0.02, record)  # warm-up (compiled kernels loaded)
    totals.clear()
    history.clear()
    run = bench_solver.run_masonry(case, duration, record)
    sim = instrumented.sim
    totals["rest"] = run["cpu_s"] - sum(v for k, v in totals.items() if "." not in k)
    digest = hashlib.sha256(np.array(history).tobytes())
    for array in (sim.state.body_q, sim.state.body_v, sim.solver.contact_r):
        digest.update(np.ascontiguousarray(array).tobytes())
    steps = len(history)
    print(json.dumps({"cpu_s": run["cpu_s"], "sim_s": run["sim_s"], "steps": steps, "digest": digest.hexdigest(),
                      "ms_per_step": {k: 1e3 * v / steps for k, v in totals.items()}}))  # fmt: skip


def compare(base: str, new: str, case: str, duration: float, rounds: int, record: bool) -> dict:
    """Time ``base`` and ``new`` in alternating fresh processes (module doc)."""
    from benchmarks.bench_kernel import checkout, worker_env

    results: dict[str, list] = {"base": [], "new": []}
    with tempfile.TemporaryDirectory() as tmp:
        roots = {name: checkout(rev, Path(tmp) / name) for name, rev in (("base", base), ("new", new))}
        for k in range(rounds):
            for name in ("base", "new") if k % 2 == 0 else ("new", "base"):
                env = worker_env(roots[name], Path(tmp))
                cmd = [sys.executable, __file__, "--worker", roots[name], case, str(duration), str(int(record))]
                out = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, env=env)
                if out.returncode:
                    raise SystemExit(f"bench_phases: {name} worker failed:\n{out.stderr}")
                results[name].append(json.loads(out.stdout.splitlines()[-1]))
    row = {"case": case, "duration": duration, "rounds": rounds, "record": record}
    for name, rev in (("base", base), ("new", new)):
        runs = results[name]
        row[name] = {
            "revision": rev,
            "cpu_per_sim_s": min(r["cpu_s"] / r["sim_s"] for r in runs),
            "ms_per_step": {p: min(r["ms_per_step"].get(p, 0.0) for r in runs) for p in PHASES},
        }
    row["bit_identical"] = len({r["digest"] for runs in results.values() for r in runs}) == 1
    return row


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", default="HEAD", help="git revision (or 'worktree')")
    parser.add_argument("--new", default="worktree", help="git revision (default: the working tree)")
    parser.add_argument("--case", default="wall-248", help="benchmarks.solver_cases case")
    parser.add_argument("--duration", type=float, default=1.0, help="simulated s")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--no-record", action="store_true", help="no Rerun recording")
    parser.add_argument("--json", type=Path)
    parser.add_argument("--worker", nargs=4, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        root, case, duration, record = args.worker
        return worker(root, case, float(duration), bool(int(record)))
    row = compare(args.base, args.new, args.case, args.duration, args.rounds, not args.no_record)
    b, n = row["base"], row["new"]
    print(f"{'phase (ms a step)':18} {b['revision']:>12} {n['revision']:>12}   new/base")
    for p in PHASES:
        x, y = b["ms_per_step"][p], n["ms_per_step"][p]
        print(f"{p:18} {x:12.4f} {y:12.4f}   {y / x if x else float('nan'):.3f}")
    x, y = b["cpu_per_sim_s"], n["cpu_per_sim_s"]
    print(f"{'CPU s per sim s':18} {x:12.3f} {y:12.3f}   {y / x:.3f}")
    print(
        f"bit-identical: {row['bit_identical']} ({row['case']}, {row['duration']} s, minimum of {row['rounds']} rounds)"
    )
    if args.json:
        args.json.write_text(json.dumps(row, indent=1) + "\n")
    return row


if __name__ == "__main__":
    main()
