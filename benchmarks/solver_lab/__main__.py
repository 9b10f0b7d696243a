"""Solver lab: ``python -m benchmarks.solver_lab capture|table|clusters|stalled|trajectory|ordinary|tail|newton-ordinary|joint-ordinary|ipm-ordinary|ordinary-runs|ensemble|hard|hard-methods|handover|tall``
(see benchmarks/README.md, "Solver lab")."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
os.environ.setdefault("RERUN_ANALYTICS", "0")


def main() -> None:
    from benchmarks.solver_lab import ensemble, handover, hard_methods, hard_steps, tall_steps
    from benchmarks.solver_lab.capture import CASES
    from masonrycli.scenario.scenario import SOLVERS

    ap = argparse.ArgumentParser(prog="python -m benchmarks.solver_lab", description=__doc__)
    sub = ap.add_subparsers(dest="command", required=True)
    cap = sub.add_parser("capture", help="run the cases, keep cold/typical/hard steps with their reference")
    cap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    cap.add_argument(
        "--solver", default=SOLVERS[0], choices=SOLVERS, help="the run's solver (default: the engine's default)"
    )
    tab = sub.add_parser("table", help="run the methods on the captured problems; Markdown table + JSON")
    tab.add_argument("--methods", nargs="+", default=None)
    tab.add_argument("--problems", nargs="+", default=None)
    tab.add_argument("--repeat", type=int, default=3, help="interleaved repeats; CPU-time minimum is kept")
    clu = sub.add_parser("clusters", help="share of an NLGS iterate's velocity error in rigid motion of stick clusters")
    clu.add_argument("specs", nargs="+", metavar="PROBLEM:SWEEPS")
    sta = sub.add_parser("stalled", help="capture the steps stalled.py finishes; run each method alone on them")
    sta.add_argument("action", choices=("capture", "table"))
    sta.add_argument("--cases", nargs="+", default=["h16", "h32", "h64"])
    sta.add_argument("--duration", type=float, default=0.2, help="simulated s per case (capture)")
    sta.add_argument("--steps", nargs="+", default=None, help="table: these kept steps (names, e.g. h32-100)")
    sta.add_argument("--repeat", type=int, default=2, help="table: CPU-time minimum of this many runs")
    sta.add_argument("--methods", nargs="+", default=None, help="table: these methods only (default: all)")
    sta.add_argument(
        "--cap", type=int, default=50_000, help="table: sweep units a step (the engine's since c128652: 100 000)"
    )
    tra = sub.add_parser("trajectory", help="run a case, keep every k-th step (the ordinary-step sample)")
    tra.add_argument("--case", default="wall-248")
    tra.add_argument("--every", type=int, default=5)
    tra.add_argument("--duration", type=float, default=None, help="simulated s (default: the case's)")
    tra.add_argument("--name", default=None, help="data/trajectory/NAME (default: the case's name)")
    ordi = sub.add_parser("ordinary", help="first-stage variants of the accelerated sweep on a trajectory sample")
    ordi.add_argument("--case", default="wall-248")
    ordi.add_argument("--variants", nargs="+", default=None)
    ordi.add_argument("--repeat", type=int, default=3, help="interleaved timing rounds; CPU-time minimum kept")
    tai = sub.add_parser("tail", help="where a sample's ordinary steps spend their sweeps near the tolerance")
    tai.add_argument("--sample", default="wall-248", help="data/trajectory/SAMPLE")
    tai.add_argument("--levels", nargs="+", type=float, default=None, help="in-sweep residuals (m/s)")
    nwo = sub.add_parser("newton-ordinary", help="Newton-type first stages on a trajectory sample's ordinary steps")
    nwo.add_argument("--sample", default="nwt-wall-248", help="data/trajectory/SAMPLE")
    nwo.add_argument("--every", type=int, default=1, help="every k-th ordinary step of the sample")
    nwo.add_argument("--variants", nargs="+", default=None)
    nwo.add_argument("--spread", action="store_true", help="also: how far apart two tight solves are")
    nwo.add_argument("--feasibility", action="store_true", help="also: the oracles' impulses against the cone")
    jor = sub.add_parser("joint-ordinary", help="joint-block Gauss–Seidel on a trajectory sample's ordinary steps")
    jor.add_argument("--sample", default="nwt-wall-248", help="data/trajectory/SAMPLE")
    jor.add_argument("--every", type=int, default=1, help="every k-th ordinary step of the sample")
    jor.add_argument("--repeat", type=int, default=2, help="interleaved timing rounds; CPU-time minimum kept")
    jor.add_argument("--plain", action="store_true", help="also joint-gs (no momentum)")
    ipo = sub.add_parser("ipm-ordinary", help="the interior-point method on a trajectory sample's ordinary steps")
    ipo.add_argument("--sample", default="nwt-wall-248", help="data/trajectory/SAMPLE")
    ipo.add_argument("--every", type=int, default=1, help="every k-th ordinary step of the sample")
    ipo.add_argument("--loose", type=float, nargs="+", default=[1e-4, 3e-5], help="m/s: IPM to this, then sweeps")
    orr = sub.add_parser("ordinary-runs", help="first-stage variants in whole runs (sweeps, unconverged, slips)")
    orr.add_argument("--cases", nargs="+", default=["wall-248"])
    orr.add_argument("--variants", nargs="+", default=None)
    orr.add_argument("--duration", type=float, default=1.0)
    ensemble.add_arguments(sub)
    hard_steps.add_arguments(sub)
    hard_methods.add_arguments(sub)
    handover.add_arguments(sub)
    tall_steps.add_arguments(sub)
    args = ap.parse_args()
    if args.command == "tall":
        tall_steps.main(args)
        return
    if args.command == "handover":
        handover.main(args)
        return
    if args.command == "hard-methods":
        hard_methods.main(args)
        return
    if args.command == "hard":
        hard_steps.main(args)
        return
    if args.command == "ensemble":
        ensemble.main(args)
        return
    if args.command == "ordinary-runs":
        from benchmarks.solver_lab.ordinary_runs import table as runs_table

        for case in args.cases:
            runs_table(case, args.variants, args.duration)
        return
    if args.command == "trajectory":
        from benchmarks.solver_lab.trajectory import capture as capture_trajectory

        capture_trajectory(args.case, args.every, args.duration, args.name)
        return
    if args.command == "newton-ordinary":
        from benchmarks.solver_lab.newton_ordinary import table as newton_table

        newton_table(args.sample, args.every, args.variants, args.spread, args.feasibility)
        return
    if args.command == "ipm-ordinary":
        from benchmarks.solver_lab.ipm_ordinary import table as ipm_table

        ipm_table(args.sample, args.every, tuple(args.loose))
        return
    if args.command == "joint-ordinary":
        from benchmarks.solver_lab.joint_ordinary import table as joint_table

        joint_table(args.sample, args.every, args.repeat, args.plain)
        return
    if args.command == "tail":
        from benchmarks.solver_lab.tail import LEVELS
        from benchmarks.solver_lab.tail import table as tail_table

        tail_table(args.sample, tuple(args.levels or LEVELS))
        return
    if args.command == "ordinary":
        from benchmarks.solver_lab.ordinary import table as ordinary_table

        ordinary_table(args.case, args.variants, args.repeat)
        return
    if args.command == "capture":
        from benchmarks.solver_lab.capture import capture

        capture(args.cases, args.solver)
    elif args.command == "stalled":
        from benchmarks.solver_lab import stalled_steps

        if args.action == "capture":
            stalled_steps.capture(args.cases, args.duration)
        else:
            paths = [stalled_steps.STALLED / f"{n}.npz" for n in args.steps] if args.steps else None
            stalled_steps.table(paths, args.repeat, args.methods or stalled_steps.METHODS, args.cap)
    elif args.command == "clusters":
        from benchmarks.solver_lab.clusters import report

        report(args.specs)
    else:
        from benchmarks.solver_lab.harness import run_table

        run_table(args.methods, args.problems, args.repeat)


if __name__ == "__main__":
    main()
