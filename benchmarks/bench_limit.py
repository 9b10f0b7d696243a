"""Limit-analysis benchmark: ``.venv/bin/python benchmarks/bench_limit.py [--repeat 7]``.

For the default wall (51 blocks), arch (98) and aqueduct (346), under the horizontal body force:

* CPU time (``time.process_time``; minimum over interleaved repeats — case after case, round after
  round) of the limit analysis itself: contact detection → joints, LP assembly, HiGHS (interior point
  with crossover, the default), reading the mechanism and the line of thrust; and, separately, of
  building the structure (geometry builder + model), which ``masonry limit`` also pays;
* the wall-clock minimum of the same, and the first call in a fresh process (numba cache load);
* accuracy against a tight solve in the same run: the dual simplex with primal and dual feasibility
  tolerances of 1e-10, its λ and its CPU time (ratio to the default solve).

Prints a Markdown table and writes ``benchmarks/limit_results.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
os.environ.setdefault("RERUN_ANALYTICS", "0")

from masonrycli.limit import LiveLoad, analyse_model  # noqa: E402
from masonrycli.limit.joints import find_joints  # noqa: E402
from masonrycli.limit.problem import load_vectors, solve_limit  # noqa: E402
from masonrycli.model import build_model  # noqa: E402
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder  # noqa: E402

CASES = ("wall", "arch", "aqueduct")
TIGHT = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}
FIRST_CALL = (
    "import time, sys; t = time.perf_counter(); sys.path.insert(0, {root!r});"
    "from masonrycli.limit.command import resolve_structure; from masonrycli.limit import analyse, LiveLoad;"
    "r = analyse(resolve_structure({case!r}, None), LiveLoad()); print(time.perf_counter() - t)"
)


def timed(fn):
    c0, w0 = time.process_time(), time.perf_counter()
    out = fn()
    return out, time.process_time() - c0, time.perf_counter() - w0


def build(case: str):
    return build_model(scenario_from_builder(case, {}, RunConfig(), Material(), {}))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    load = LiveLoad("horizontal")
    first = {
        case: float(
            subprocess.run(
                [sys.executable, "-c", FIRST_CALL.format(root=str(ROOT), case=case)],
                capture_output=True,
                text=True,
                check=True,
            ).stdout.strip()
        )
        for case in CASES
    }
    models = {case: build(case) for case in CASES}
    analyse_model(models["wall"], load)  # warm-up: numba dispatch of the contact detection
    runs = {
        case: {"build_cpu": [], "build_wall": [], "cpu": [], "wall": [], "solve": [], "tight_cpu": []} for case in CASES
    }
    result = {}
    for _ in range(args.repeat):
        for case in CASES:
            _, cpu, wall = timed(lambda case=case: build(case))
            runs[case]["build_cpu"].append(cpu)
            runs[case]["build_wall"].append(wall)
            res, cpu, wall = timed(lambda case=case: analyse_model(models[case], load, case))
            runs[case]["cpu"].append(cpu)
            runs[case]["wall"].append(wall)
            runs[case]["solve"].append(res.solution.solve_time)
            result[case] = res
            model = models[case]
            joints = find_joints(model)
            dead, live, _ = load_vectors(model, load)
            tight, cpu, _ = timed(lambda m=model, j=joints, d=dead, v=live: solve_limit(m, j, d, v, "highs-ds", TIGHT))
            runs[case]["tight_cpu"].append(cpu)
            runs[case]["tight_lambda"] = tight.load_factor
    rows = []
    print(
        "| case | blocks | joints | λ | λ tight (dual simplex 1e-10) | rel. diff | analysis CPU min | wall min "
        "| HiGHS wall min | tight solve CPU min (ratio) | build CPU min | first call, fresh process |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for case in CASES:
        r, t = result[case], runs[case]
        lam, tight = r.load_factor, t["tight_lambda"]
        row = {
            "case": case,
            "blocks": r.model.block_count,
            "joints": r.joints.joint_count,
            "contact_points": r.joints.contact_count,
            "load_factor": lam,
            "load_factor_tight": tight,
            "relative_difference": abs(lam - tight) / tight,
            "analysis_cpu_min_s": min(t["cpu"]),
            "analysis_wall_min_s": min(t["wall"]),
            "highs_wall_min_s": min(t["solve"]),
            "tight_cpu_min_s": min(t["tight_cpu"]),
            "build_cpu_min_s": min(t["build_cpu"]),
            "first_call_wall_s": first[case],
            "hinges": len(r.hinges),
            "sliding_joints": len(r.sliding_joints),
        }
        rows.append(row)
        print(
            f"| {case} | {row['blocks']} | {row['joints']} | {lam:.6f} | {tight:.6f} | {row['relative_difference']:.1e} "
            f"| {row['analysis_cpu_min_s']:.3f} s | {row['analysis_wall_min_s']:.3f} s | {row['highs_wall_min_s']:.3f} s "
            f"| {row['tight_cpu_min_s']:.3f} s (×{row['tight_cpu_min_s'] / row['analysis_cpu_min_s']:.1f}) "
            f"| {row['build_cpu_min_s']:.3f} s | {row['first_call_wall_s']:.2f} s |"
        )
    load_avg = os.getloadavg()
    print(f"\nrepeats {args.repeat}, load average {load_avg[0]:.1f} {load_avg[1]:.1f} {load_avg[2]:.1f}")
    out = {
        "rows": rows,
        "repeat": args.repeat,
        "load_average": load_avg,
        "python": platform.python_version(),
        "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
    }
    (ROOT / "benchmarks" / "limit_results.json").write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
