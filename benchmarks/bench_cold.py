"""The first run's cold start: ``masonry simulate wall --freq 2 --amp 1`` (README, Quick start) with an empty
numba cache, then again from the cache it filled.

Each round makes a fresh empty ``NUMBA_CACHE_DIR`` and runs the command twice in child processes, cold then
cached, in a fresh working directory (the recording goes to its ``recordings/``). The CPU time of a child is
its user + system time (``resource.getrusage(RUSAGE_CHILDREN)`` before and after); the minimum over the
rounds is kept, as the machine is shared. With ``--base REV`` the rounds alternate between that revision's
``masonrycli`` (``git archive``, bench_kernel.checkout) and this tree's, in alternating order (base, new;
new, base; ...), so that both see the same load.

``--kernels`` adds one cold run whose child records its compilations (masonrycli.engine.compile_log, from
numba's compile events): per kernel its compile CPU time (thread time, its callees' compilations
subtracted), its signatures, and whether a Python call compiled it (a launcher) or only a kernel calling it
(typing the caller). The events do not cover the cache's lookups and writes, the imports, or the run
itself: the rest of the CPU.

    .venv/bin/python -m benchmarks.bench_cold [--rounds 3] [--base REV] [--kernels] [--json FILE]
        [-- COMMAND ...]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ["simulate", "wall", "--freq", "2", "--amp", "1"]


def _child_env(tree: str, cache: str) -> dict:
    """``tree``'s masonrycli first on the path (the rest from this tree), the numba cache in ``cache``."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, RERUN_ANALYTICS="0")
    env["PYTHONPATH"] = os.pathsep.join(p for p in (tree, str(ROOT), env.get("PYTHONPATH", "")) if p)
    return env


def _timed(argv: list[str], tree: str, cache: str, cwd: str) -> tuple[float, float]:
    """(CPU s, wall s) of ``argv`` in a child process running ``tree`` with NUMBA_CACHE_DIR = ``cache``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(argv, env=_child_env(tree, cache), cwd=cwd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        sys.exit(f"bench_cold: {' '.join(argv)} failed ({done.returncode}):\n{done.stderr[-2000:]}")
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), wall


def rounds(command: list[str], n: int, trees: dict[str, str]) -> dict[str, dict]:
    """Cold and cached CPU and wall times of ``command`` over ``n`` rounds for each of ``trees`` (name: source
    tree), each run pair with a new empty cache, the trees' order alternating from round to round."""
    argv = [sys.executable, "-m", "masonrycli", *command]
    out: dict[str, dict] = {name: defaultdict(list) for name in trees}
    for k in range(n):
        for name in list(trees) if k % 2 == 0 else list(trees)[::-1]:
            with tempfile.TemporaryDirectory(prefix="bench_cold-") as tmp:
                cache = os.path.join(tmp, "numba-cache")
                os.mkdir(cache)
                for kind in ("cold", "cached"):
                    cpu, wall = _timed(argv, trees[name], cache, tmp)
                    out[name][f"{kind}_cpu"].append(cpu)
                    out[name][f"{kind}_wall"].append(wall)
    return {name: dict(times) for name, times in out.items()}


# The child of --kernels -------------------------------------------------------------------------------------


def _record_compiles(path: str, command: list[str]) -> None:
    """Run the masonry command in this process with its compilations recorded
    (masonrycli.engine.compile_log); write them to ``path`` as JSON."""
    from masonrycli.engine.compile_log import recorded_compiles

    cpu0 = time.process_time()
    sys.argv = ["masonry", *command]
    from masonrycli.__main__ import main

    with recorded_compiles() as compiles:
        try:
            main()
        except SystemExit as stop:
            if stop.code not in (None, 0):
                raise
    with open(path, "w", encoding="utf-8") as f:
        json.dump({"rows": [c._asdict() for c in compiles], "process_cpu": time.process_time() - cpu0}, f)


def kernels(command: list[str]) -> dict:
    """One cold run of ``command`` with its compilations recorded (the child above)."""
    with tempfile.TemporaryDirectory(prefix="bench_cold-") as tmp:
        cache = os.path.join(tmp, "numba-cache")
        os.mkdir(cache)
        path = os.path.join(tmp, "compiles.json")
        argv = [sys.executable, str(Path(__file__).resolve()), "--child", path, "--", *command]
        cpu, _ = _timed(argv, str(ROOT), cache, tmp)
        with open(path, encoding="utf-8") as f:
            found = json.load(f)
    table: dict[str, dict] = {}
    for c in found["rows"]:
        k = table.setdefault(c["kernel"], {"cpu": 0.0, "signatures": [], "from_python": False})
        k["cpu"] += c["own_cpu"]
        k["signatures"].append(c["signature"])
        k["from_python"] |= c["depth"] == 0
    return {"kernels": table, "child_cpu": cpu, "process_cpu": found["process_cpu"]}


def _short(name: str) -> str:
    for prefix in ("masonrycli.engine.", "numba."):
        if name.startswith(prefix):
            return name[len(prefix) :] if prefix == "masonrycli.engine." else "numba: " + name[len(prefix) :]
    return name


def kernel_table(found: dict) -> str:
    rows = sorted(found["kernels"].items(), key=lambda kv: -kv[1]["cpu"])
    lines = ["| kernel | compile CPU s | signatures | compiled by |", "|---|---:|---:|---|"]
    for name, k in rows:
        by = "a Python call" if k["from_python"] else "its caller"
        lines.append(f"| `{_short(name)}` | {k['cpu']:.3f} | {len(k['signatures'])} | {by} |")
    total = sum(k["cpu"] for _, k in rows)
    signatures = sum(len(k["signatures"]) for _, k in rows)
    lines.append(
        f"| **{len(rows)} kernels** | **{total:.2f}** | {signatures} | of the run's {found['child_cpu']:.2f} s CPU |"
    )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3, help="cold + cached pairs, each with a new cache")
    parser.add_argument("--kernels", action="store_true", help="also a cold run with its compilations recorded")
    parser.add_argument("--json", type=Path, help="write the figures here")
    parser.add_argument("--base", help="git revision (or source tree) to time against this tree, interleaved")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("command", nargs="*", help="masonry arguments (default: simulate wall --freq 2 --amp 1)")
    args = parser.parse_args()
    command = args.command or DEFAULT
    if args.child:
        _record_compiles(args.child, command)
        return
    result: dict = {"command": "masonry " + " ".join(command), "base": args.base}
    if args.rounds > 0:
        with tempfile.TemporaryDirectory(prefix="bench_cold-base-") as tmp:
            trees = {"new": str(ROOT)}
            if args.base and Path(args.base).is_dir():  # a source tree (an export of a revision)
                trees = {"base": str(Path(args.base).resolve()), **trees}
            elif args.base:
                from benchmarks.bench_kernel import checkout

                trees = {"base": checkout(args.base, Path(tmp) / "base"), **trees}
            times = rounds(command, args.rounds, trees)
        result["times"] = times
        print(f"{result['command']}, {args.rounds} rounds (min / median / max):")
        for name, t in times.items():
            for kind in ("cold", "cached"):
                cpu, wall = sorted(t[f"{kind}_cpu"]), sorted(t[f"{kind}_wall"])
                print(
                    f"  {name if args.base else '':4s} {kind:6s} CPU {cpu[0]:6.2f} / {cpu[len(cpu) // 2]:6.2f} / "
                    f"{cpu[-1]:6.2f} s   wall {wall[0]:6.2f} / {wall[len(wall) // 2]:6.2f} / {wall[-1]:6.2f} s"
                )
    if args.kernels:
        found = kernels(command)
        result["compiles"] = found
        print(kernel_table(found))
    if args.json:
        args.json.write_text(json.dumps(result, indent=1) + "\n")


if __name__ == "__main__":
    main()
