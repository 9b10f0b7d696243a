"""How well defined is the solver benchmark's accuracy reference, and what does its 0.5 % bar need?

bench_solver judges a solver by the top-course and mean slip at 0.1 and 0.2 s against one "tight" solve
(plain ``nlgs`` at 1e-7 m/s, cap 20 000 sweeps). On tall walls that reference may itself stop at its cap
short of its tolerance, and the walls are hyperstatic (the impulses of one step form a continuum), so two
equally tight solves can take different trajectories. This script measures both sides, one case at a
time (from the repository root, in the project venv)::

    .venv/bin/python -m benchmarks.bench_accuracy --cases h32 [--duration 0.2]
        [--references nlgs:1e-7:20000 nlgs-accel:1e-7:20000] [--solver nlgs-accel]
        [--tolerances 1e-4 3e-5 1e-5 3e-6 1e-6] [--json PATH]

* ``--references``: runs that should agree physically, each ``SOLVER:TOLERANCE[:CAP]`` (cap default: the
  engine's). The first one is bench_solver's. Their *spread* is each one's slips in % of the first's.
* ``--tolerances``: ``--solver`` (default: the engine's default) at each tolerance (the engine's cap); its
  slips in % of *every* reference's, so an error can be read against the references' own spread.

Per run: CPU s of ``simulate`` (no recording, start-up apart, one run: on the shared machine only
ratios mean much), sweeps per step (mean, max; sweep units), unconverged steps (residual above the
tolerance or at the cap), the steps' final residuals (median, max; m/s), and the slips (m) at 0.1 and
0.2 s (benchmarks.solver_cases.slips). Everything goes to ``--json`` (default
``benchmarks/results_solver/accuracy-CASES.json``) and a Markdown table to the terminal.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
from datetime import UTC, datetime
from pathlib import Path

os.environ.setdefault("RERUN_ANALYTICS", "0")
ROOT = Path(__file__).resolve().parent.parent

from benchmarks.solver_cases import CASES  # noqa: E402
from benchmarks.solver_reference import SECOND, TIGHT, errors_pct, parse_spec, run, spec_of  # noqa: E402
from masonrycli.scenario.scenario import SOLVERS  # noqa: E402

BENCH_REFERENCE = spec_of(TIGHT)
"""bench_solver's tight solve as a spec: the first reference by default."""


def compare(runs: dict[str, dict], references: list[str]) -> None:
    """Add to each run ``error_pct``: reference label → its slips in % of that reference's (errors_pct);
    a reference is compared with the references before it only (the first with none)."""
    for label, row in runs.items():
        against = references[: references.index(label)] if label in references else references
        row["error_pct"] = {ref: errors_pct(row["samples"], runs[ref]["samples"]) for ref in against}


def table(case: str, runs: dict[str, dict], references: list[str]) -> str:
    """A Markdown table of one case: a row per run, its error (top / mean, %) against each reference."""
    head = (
        "| run | CPU s | sweeps/step (max) | unconv. | residual median / max m/s | slip top / mean mm 0.1 s | 0.2 s |"
    )
    head += "".join(f" % of {ref} top / mean 0.1 s | 0.2 s |" for ref in references)
    lines = [f"{case}:", head, "|" + "---|" * (7 + 2 * len(references))]
    for label, r in runs.items():
        s = r["samples"]
        cells = [
            label,
            f"{r['cpu_s']:.1f}",
            f"{r['sweeps_mean']:.0f} ({r['sweeps_max']})",
            str(r["unconverged"]),
            f"{r['residual_median']:.1e} / {r['residual_max']:.1e}",
        ]
        cells += [f"{1e3 * s[k][0]:.2f} / {1e3 * s[k][1]:.2f}" if k in s else "–" for k in ("100", "200")]
        for ref in references:
            e = r["error_pct"].get(ref)
            cells += [f"{e[k][0]:+.2f} / {e[k][1]:+.2f}" if e and k in e else "–" for k in ("100", "200")]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", nargs="+", required=True, choices=sorted(c for c in CASES if c[0] in "hw"))
    parser.add_argument("--duration", type=float, default=0.2, help="simulated s (samples at 0.1 and 0.2 s)")
    parser.add_argument("--references", nargs="+", default=[BENCH_REFERENCE, spec_of(SECOND)])
    parser.add_argument("--solver", default=SOLVERS[0], choices=SOLVERS)
    parser.add_argument("--tolerances", nargs="*", type=float, default=[1e-4, 3e-5, 1e-5, 3e-6, 1e-6])
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    try:
        specs = {ref: parse_spec(ref) for ref in args.references}
    except ValueError as exc:
        parser.error(str(exc))
    specs |= {
        spec_of(options): options for options in ({"solver": args.solver, "tolerance": tol} for tol in args.tolerances)
    }
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT)
    report = {
        "date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "commit": commit.stdout.strip(),
        "load": os.getloadavg(),
        "duration": args.duration,
        "references": args.references,
        "cases": {},
    }
    path = args.json or ROOT / "benchmarks" / "results_solver" / f"accuracy-{'-'.join(args.cases)}.json"
    run("wall-51", 0.01, solver=args.solver)  # compile / load the kernels first
    for case in args.cases:
        runs = report["cases"][case] = {}
        for label, options in specs.items():
            runs[label] = run(case, args.duration, **options)
            compare(runs, args.references)
            path.write_text(json.dumps(report, indent=2))  # partial results survive an interrupted run
            print(f"{case} {label}: {runs[label]['cpu_s']:.1f} s CPU", flush=True)
    for case, runs in report["cases"].items():
        print(table(case, runs, args.references))
    return report


if __name__ == "__main__":
    main()
