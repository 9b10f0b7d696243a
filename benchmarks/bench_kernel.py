"""Kernel benchmark: time per contact·sweep of the NLGS sweep, one git revision against another, on the very
same captured steps, and whether both give the same bits.

    .venv/bin/python -m benchmarks.bench_kernel --base REV [--new REV] [--case wall-248] [--duration 1]
        [--every 10] [--rounds 5] [--stage float64|float32] [--base-env K=V ...] [--new-env K=V ...]
        [--json PATH]

1. The working tree runs ``--case`` for ``--duration`` simulated seconds and keeps the inputs of every
   ``--every``-th call that ``dispatch.solve`` makes to ``dispatch.first_stage`` (the float64 first stage of
   each step's accelerated solve), then the outputs the working tree gives for them. A revision older than
   engine/dispatch.py runs the same calls as ``nlgs._nlgs_interleaved``'s 11-argument form (:func:`first_stage`).
2. Each revision (``git archive`` of its ``masonrycli`` and ``geometry_library``; ``--new`` defaults to the working tree) is
   timed in a fresh process of its own, with its own numba flags and a numba cache of its own (the working
   tree's own cache, as in bench_frames: :func:`worker_env`): every captured call once (compile, and the
   bits of v, r, status, sweeps and residual), then the whole set ``PASSES`` times, CPU time
   (``time.process_time``) per pass.
3. Rounds alternate the order of the revisions (base, new; new, base; …): the minimum over rounds and
   passes is reported in ns per contact·sweep (CPU time / Σ contacts × sweeps, the sweeps each revision
   made), with new ÷ base, and whether every output of the two revisions is bit-identical.

``--stage float32`` captures and times the default solver's first stage instead
(``lane_sweeps32.first_stage``: the float32 16-lane sweeps, then the float64 ones to the step's end), from a run
with the default solver; its calls take that function's 11 arguments (…, status, stall window, stall window
near the tolerance), and a revision without it cannot be timed so.

``--base-env`` / ``--new-env`` ``KEY=VALUE``: environment variables of that side's workers only, so that one
revision can be timed against itself under other numba settings (``--base worktree --new worktree --new-env
NUMBA_CPU_FEATURES=…``: the same source compiled for another instruction set; numba keys its cache by the
CPU name and features, so both sides keep their own entries in the working tree's cache).

For changes that keep the results (compiler flags, memory layout, inlining): a revision that changes the
sweep counts changes the work, and the ratio then mixes speed per sweep with sweeps.
"""

from __future__ import annotations

import argparse
import hashlib
import io
import json
import os
import pickle
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("RERUN_ANALYTICS", "0")
ROOT = Path(__file__).resolve().parent.parent
WORKTREE = "worktree"
"""``--base`` / ``--new`` value naming the checkout this file is in, as it is on disk."""
PASSES = 3
"""Timed passes over the captured calls per worker process (its minimum is kept)."""
STAGES = ("float64", "float32")
"""``--stage`` values: dispatch.first_stage (float64 lane sweeps, solver nlgs-accel) or lane_sweeps32.first_stage
(the default's float32 start and float64 end)."""


def capture(case: str, duration: float, every: int, stage: str = "float64") -> list[tuple]:
    """Inputs of every ``every``-th call of ``dispatch.first_stage`` made by ``dispatch.solve`` on ``case``, in
    the 11-argument form (…, status, True, stall window) that ``nlgs._nlgs_interleaved`` took; ``stage``
    "float32": of ``lane_sweeps32.first_stage`` in a run of the default solver, its own 11 arguments."""
    sys.path.insert(0, str(ROOT))
    if stage == "float32":
        return _capture32(case, duration, every)
    from benchmarks.solver_cases import FLOAT64, make_scenario
    from masonrycli.engine import dispatch
    from masonrycli.run import Simulation, simulate

    kernel, calls, seen = dispatch.first_stage, [], [0]

    def keep(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall, lanes=True, *growth):
        # growth (Tuning.lane_growth) is not kept: the captured calls run at each revision's shipped one
        if lanes and seen[0] % every == 0:  # the lane sweeps, as every revision runs the first stage
            calls.append((contact_body[:count].copy(), pack[:count].copy(), count, mu, tolerance, cap)
                         + (v.copy(), r[:count].copy(), status[:count].copy(), True, stall))  # fmt: skip
        seen[0] += lanes
        return kernel(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall, lanes, *growth)

    dispatch.first_stage = keep
    try:
        scenario = make_scenario(case, duration, solver=FLOAT64)  # the float64 first stage it times
        simulate(scenario, [], sim=Simulation(scenario))
    finally:
        dispatch.first_stage = kernel
    return calls


def _capture32(case: str, duration: float, every: int) -> list[tuple]:
    from benchmarks.solver_cases import make_scenario
    from masonrycli.engine import lane_sweeps32
    from masonrycli.run import Simulation, simulate

    kernel, calls, seen = lane_sweeps32.first_stage, [], [0]

    def keep(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall, stall_near=0, *growth):
        if seen[0] % every == 0:
            calls.append((contact_body[:count].copy(), pack[:count].copy(), count, mu, tolerance, cap)
                         + (v.copy(), r[:count].copy(), status[:count].copy(), stall, stall_near))  # fmt: skip
        seen[0] += 1
        return kernel(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall, stall_near, *growth)

    lane_sweeps32.first_stage = keep
    try:
        scenario = make_scenario(case, duration)  # the default solver: nlgs-accel32
        simulate(scenario, [], sim=Simulation(scenario))
    finally:
        lane_sweeps32.first_stage = kernel
    return calls


def first_stage():
    """The first stage of the ``masonrycli`` imported, taking a captured call's 11 arguments: dispatch.first_stage,
    or ``nlgs._nlgs_interleaved`` in a revision older than engine/dispatch.py."""
    try:
        from masonrycli.engine import dispatch
    except ImportError:
        from masonrycli.engine import nlgs

        return nlgs._nlgs_interleaved

    def kernel(contact_body, pack, count, mu, tolerance, cap, v, r, status, accelerate, stall):
        return dispatch.first_stage(contact_body, pack, count, mu, tolerance, cap, v, r, status, stall)

    return kernel


def run_calls(kernel, calls) -> tuple[list, str]:
    """Run every captured call on copies of its arrays: (CPU seconds per call, digest of all outputs)."""
    digest, seconds = hashlib.sha256(), []
    for contact_body, pack, count, mu, tolerance, cap, v, r, status, *rest in calls:
        v, r, status = v.copy(), r.copy(), status.copy()
        start = time.process_time()
        sweeps, residual = kernel(contact_body, pack, count, mu, tolerance, cap, v, r, status, *rest)
        seconds.append(time.process_time() - start)
        digest.update(np.array([sweeps * count, residual]).tobytes() + v.tobytes() + r.tobytes() + status.tobytes())
    return seconds, digest.hexdigest()


def worker(package_root: str, capture_file: str, stage: str = "float64") -> None:
    """In a fresh process: time the sweep of the ``masonrycli`` under ``package_root`` (JSON to stdout)."""
    sys.path.insert(0, package_root)
    from masonrycli.engine import nlgs

    assert Path(nlgs.__file__).is_relative_to(package_root), nlgs.__file__
    with open(capture_file, "rb") as f:
        calls = pickle.load(f)
    if stage == "float32":
        from masonrycli.engine import lane_sweeps32

        kernel = lane_sweeps32.first_stage
    else:
        kernel = first_stage()
    _, digest = run_calls(kernel, calls)
    work = 0
    for contact_body, pack, count, mu, tolerance, cap, v, r, status, *rest in calls:
        work += count * kernel(contact_body, pack, count, mu, tolerance, cap, v.copy(), r.copy(), status.copy(),
                               *rest)[0]  # fmt: skip
    best = min(sum(run_calls(kernel, calls)[0]) for _ in range(PASSES))
    print(json.dumps({"cpu_s": best, "contact_sweeps": int(work), "digest": digest}))


def checkout(revision: str, into: Path) -> str:
    """Directory holding ``masonrycli`` and ``geometry_library`` as they are at ``revision`` (the working tree for
    WORKTREE). The revision's own geometry_library, not the working tree's: the base's masonrycli imports the
    names it had then (geometry_library.checks.validate_assembly before 41d2532 moved it: the base worker failed
    with ImportError), and a built-in's blocks are the ones its revision built."""
    if revision == WORKTREE:
        return str(ROOT)
    into.mkdir()
    packages = ["masonrycli", "geometry_library"]
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", revision, *packages], capture_output=True)
    if archive.returncode:
        raise SystemExit(f"bench_kernel: git archive {revision}: {archive.stderr.decode().strip()}")
    with tarfile.open(fileobj=io.BytesIO(archive.stdout)) as tar:
        tar.extractall(into, filter="data")
    return str(into)


def worker_env(root: str, tmp: Path, extra: dict | None = None) -> dict:
    """A worker's environment: a checkout gets a numba cache of its own in ``tmp``; the working tree keeps its
    own (as bench_frames does), so comparing it with itself compiles once, and not at all when its kernels
    are already cached (a test run that compiled them before: 2 full compiles less in bench_phases' test).
    ``extra``: that side's ``--base-env`` / ``--new-env`` variables, set last."""
    env = dict(os.environ)
    if root != str(ROOT):
        env["NUMBA_CACHE_DIR"] = str(tmp / f"cache-{Path(root).name}")
    env.update(extra or {})
    return env


def parse_env(pairs: list[str] | None) -> dict:
    """``["KEY=VALUE", …]`` as a dict; a pair without ``=`` is refused (one line, exit 2)."""
    env = {}
    for pair in pairs or []:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            print(f"bench_kernel: environment variable {pair!r}: expected KEY=VALUE", file=sys.stderr)
            raise SystemExit(2)
        env[key] = value
    return env


def compare(
    base: str,
    new: str,
    case: str,
    duration: float,
    every: int,
    rounds: int,
    stage: str = "float64",
    envs: dict | None = None,
) -> dict:
    """Capture, then time ``base`` and ``new`` in alternating fresh processes (module doc); ``envs``: {"base":
    {…}, "new": {…}}, each side's extra environment variables."""
    envs = envs or {}
    with tempfile.TemporaryDirectory() as tmp:
        capture_file = Path(tmp) / "calls.pkl"
        calls = capture(case, duration, every, stage)
        with open(capture_file, "wb") as f:
            pickle.dump(calls, f)
        roots = {name: checkout(rev, Path(tmp) / name) for name, rev in (("base", base), ("new", new))}
        results: dict[str, list] = {"base": [], "new": []}
        for k in range(rounds):
            for name in ("base", "new") if k % 2 == 0 else ("new", "base"):
                env = worker_env(roots[name], Path(tmp), envs.get(name))
                out = subprocess.run(
                    [sys.executable, __file__, "--worker", roots[name], str(capture_file), "--stage", stage],
                    capture_output=True, text=True, cwd=tmp, env=env,
                )  # fmt: skip
                if out.returncode:
                    raise SystemExit(f"bench_kernel: {name} worker failed:\n{out.stderr}")
                results[name].append(json.loads(out.stdout.splitlines()[-1]))
    row = {"case": case, "duration": duration, "every": every, "calls": len(calls), "rounds": rounds,
           "stage": stage}  # fmt: skip
    for name, rev in (("base", base), ("new", new)):
        runs = results[name]
        cpu = min(run["cpu_s"] for run in runs)
        row[name] = {"revision": rev, "env": envs.get(name) or {}, "cpu_s": cpu,
                     "cpu_s_rounds": [run["cpu_s"] for run in runs], "contact_sweeps": runs[0]["contact_sweeps"],
                     "ns_per_contact_sweep": cpu / runs[0]["contact_sweeps"] * 1e9}  # fmt: skip
    row["new_over_base"] = row["new"]["ns_per_contact_sweep"] / row["base"]["ns_per_contact_sweep"]
    row["bit_identical"] = len({run["digest"] for runs in results.values() for run in runs}) == 1
    return row


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", default="HEAD", help="git revision (or 'worktree')")
    parser.add_argument("--new", default=WORKTREE, help="git revision (default: the working tree)")
    parser.add_argument("--case", default="wall-248", help="benchmarks.solver_cases case")
    parser.add_argument("--duration", type=float, default=1.0, help="simulated s of the capture run")
    parser.add_argument("--every", type=int, default=10, help="keep every n-th call")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--stage", choices=STAGES, default="float64", help="which first stage (module doc)")
    parser.add_argument("--base-env", nargs="*", metavar="KEY=VALUE", help="base workers' extra environment")
    parser.add_argument("--new-env", nargs="*", metavar="KEY=VALUE", help="new workers' extra environment")
    parser.add_argument("--json", type=Path)
    parser.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        return worker(*args.worker, args.stage)
    envs = {"base": parse_env(args.base_env), "new": parse_env(args.new_env)}
    row = compare(args.base, args.new, args.case, args.duration, args.every, args.rounds, args.stage, envs)
    for name in ("base", "new"):
        r = row[name]
        rounds = ", ".join(f"{1e9 * s / r['contact_sweeps']:.2f}" for s in r["cpu_s_rounds"])
        print(f"{name:4} {r['revision']:>12}: {r['ns_per_contact_sweep']:.2f} ns per contact·sweep "
              f"({r['cpu_s']:.4f} s CPU, {r['contact_sweeps']} contact·sweeps; rounds {rounds})")  # fmt: skip
    print(f"new / base {row['new_over_base']:.3f}, bit-identical: {row['bit_identical']} "
          f"({row['calls']} calls of {row['case']}, minimum of {row['rounds']} rounds × {PASSES} passes)")  # fmt: skip
    if args.json:
        args.json.write_text(json.dumps(row, indent=1) + "\n")
    return row


if __name__ == "__main__":
    main()
