"""The solver benchmark of issues 9 and 10: speed *and* accuracy of masonry's contact solvers, side by side,
beside pymunk and LMGC90.

One command (from the repository root, in the project venv; ``pip install -e ".[bench]"`` adds pymunk)::

    .venv/bin/python -m benchmarks.bench_solver [--suite paper height length] [--cases ...]
        [--solvers nlgs-accel nlgs] [--repeat 3] [--duration S] [--lmgc-python PATH]
        [--second-reference nlgs-accel:1e-7:20000 | none] [--json benchmarks/results_solver.json]

Cases: benchmarks/solver_cases.py (the paper's 51- and 248-block walls, an 8 × 6 wall, the arch and the
aqueduct; walls of 8, 16, 32, 64 courses × 15 blocks; 8-course walls of ~500 to ~4000 blocks).

Solvers (``--solvers``, default: every one of ``masonrycli.scenario.scenario.SOLVERS``, the default first): each
case runs with each solver in the same benchmark run, interleaved (repeat 1: case A with solver 1,
solver 2, pymunk, case B …; then repeat 2 …), so a ratio compares runs made under the same load. For each
case and solver:

* CPU seconds per simulated second (``time.process_time``, the minimum over ``--repeat`` repeats), in
  process, with a Rerun recording every 10 steps written to a temporary file (start-up apart: measured
  once, below); and the ratio of each solver's time to the default solver's (for ``nlgs``: how many
  times faster the default is than plain Gauss–Seidel);
* sweeps per step (mean, max; the solver's ``iterations``, in Gauss–Seidel sweep units), unconverged steps
  (residual > tolerance or at the cap), contacts per step, ns per contact per sweep (CPU time inside
  ``dispatch.solve`` / Σ contacts × sweeps);
* accuracy: slip of the top course and mean slip at 0.1 and 0.2 s (solver_cases.slips) against one tight
  solve of the same case in the same run — **plain** ``nlgs`` at tolerance 1e-7 m/s, cap 20000 sweeps,
  whatever the solvers compared — in % (for the arch and the aqueduct, the mean block displacement
  |Δx, Δy| and that of the highest block, in %); an error marked ``≈`` is no larger than the references'
  spread at that sample and measure (below): the reference cannot tell it from zero;

and once per case, the reference (benchmarks/solver_reference.py): the tight solve's unconverged steps
(residual above 1e-7 m/s or at the cap), those at the cap and its largest final residual (on the 32-course
wall it ends at the cap on 195 of 200 steps, on the 64-course one on all 200: it is not a converged solve);
and a second tight solve (``--second-reference SOLVER:TOLERANCE[:CAP]``, default ``nlgs-accel:1e-7:20000``,
the other solver at the same tolerance and cap — the cheapest independent one bench_accuracy measured),
with the same counts, and the *spread*: its slips in % of the first reference's. The second reference is on
by default: it costs about as much as the first (0.2 s of the case, 99802b3: 16 s of CPU on the 248-block
wall against the first's 17 s, 121 s on 32 courses against 84 s; bench_accuracy: 250 s on 64): 138 s of
about 505 s of CPU in a default run (repeat 3) of those two cases, +38 %, not double; and without it an error
on a tall wall cannot be read (bench_accuracy: tight solves of h32 differ by 0.4–0.75 %). ``--second-reference none``
skips it for a speed-only run. The spread of two references is one sample of the reference's uncertainty,
and it depends on the second one: ``nlgs-accel`` at cap 20 000 is the least converged of bench_accuracy's on h32
(worst residual 1.3e-4 m/s; spread 1.36 % top at 0.2 s where tighter pairs differ by 0.4–0.75 %).
The rest, once per case: peak memory (tracemalloc peak of a 0.1 s run with the first solver listed: numpy
buffers, history, frames), pymunk (walls; 100 solver passes, when installed: CPU s per simulated s,
each solver's time over pymunk's, and pymunk's slips against the same tight solve), LMGC90
(``compas_lmgc90``, 3-D prisms; only with ``--lmgc-python``, the interpreter of a separate venv where it
is installed, see LMGC90.md: the 51-block wall through benchmarks/lmgc90_reference.py).

Start-up: wall-clock of ``masonry --help`` and of a fresh process that imports the engine, builds the
51-block wall and runs its first step (numba cache warm), minimum of 3. The table goes to the terminal
(rich, one row per case and solver), everything to ``--json``: ``cases[case]["solvers"][name]`` (its
``error_pct`` and ``unresolved``, step → (top, mean)), ``cases[case]["tight"]`` and ``["second"]`` (the
references: ``unconverged``, ``capped``, ``residual_max``, ``samples``, ``settings``, ``cpu_s``) and
``cases[case]["spread_pct"]``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
import tracemalloc
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

os.environ.setdefault("RERUN_ANALYTICS", "0")
ROOT = Path(__file__).resolve().parent.parent

from benchmarks import pymunk_engine  # noqa: E402
from benchmarks.solver_cases import CASES, is_wall, make_scenario  # noqa: E402
from benchmarks.solver_reference import (  # noqa: E402
    SAMPLES,
    SECOND,
    TIGHT,
    Sampler,
    errors_pct,
    parse_spec,
    spec_of,
    spread_pct,
    unresolved,
)
from benchmarks.solver_reference import run as run_reference  # noqa: E402
from masonrycli.engine import nlgs  # noqa: E402

try:  # the module whose solve() the Solver calls: engine/dispatch.py; nlgs.py in older revisions (bench_phases)
    from masonrycli.engine import dispatch as solve_home  # noqa: E402
except ImportError:
    solve_home = nlgs
from masonrycli.run import Simulation, simulate  # noqa: E402
from masonrycli.scenario.scenario import SOLVERS  # noqa: E402

SUITES = {
    "paper": ["wall-51", "wall-52", "wall-248", "arch", "aqueduct"],
    "height": ["h8", "h16", "h32", "h64"],
    "length": ["l500", "l1000", "l2000", "l4000"],
}
DEFAULT = SOLVERS[0]


class _SolveTimer:
    """Wraps dispatch.solve (as the solver module calls it) to sum CPU time and contact·sweeps."""

    def __init__(self):
        self.cpu = 0.0
        self.contact_sweeps = 0
        self._solve = solve_home.solve

    def __enter__(self):
        def timed(contact_body, pack, count, model, v, r, status, *tuning):
            t = time.process_time()
            its, res = self._solve(contact_body, pack, count, model, v, r, status, *tuning)
            self.cpu += time.process_time() - t
            self.contact_sweeps += its * count
            return its, res

        solve_home.solve = timed
        return self

    def __exit__(self, *exc):
        solve_home.solve = self._solve


def run_masonry(case: str, duration: float | None, record: bool, tuning=None, **run_options) -> dict:
    """One run of ``case``; CPU time of ``simulate`` only (scenario and model built before). ``tuning``: the
    engine's Tuning (engine/tuning.py) if not the shipped one; None keeps Simulation's call as older engines
    take it (bench_phases runs this module against other revisions)."""
    sc = make_scenario(case, duration, **run_options)
    sim = Simulation(sc) if tuning is None else Simulation(sc, tuning=tuning)
    sampler = Sampler(sim, case)
    sinks: list = [sampler]
    recorder = tmp = None
    if record:
        from masonrycli.execute import recording_static, run_metadata
        from masonrycli.recording import Recorder

        tmp = tempfile.TemporaryDirectory()
        recorder = Recorder(Path(tmp.name) / "bench.rrd", recording_static(sim), run_metadata(sc, sim))
        sinks.append(recorder)
    with _SolveTimer() as timer:
        t_wall, t_cpu = time.perf_counter(), time.process_time()
        result = simulate(sc, sinks, sim=sim)
        if recorder is not None:
            recorder.close()
        cpu, wall = time.process_time() - t_cpu, time.perf_counter() - t_wall
    if tmp is not None:
        tmp.cleanup()
    tally = result.tally
    return {
        "cpu_s": cpu,
        "wall_s": wall,
        "sim_s": result.time,
        "sweeps_mean": tally.sweeps_mean,
        "sweeps_max": tally.sweeps_max,
        "unconverged": int(result.unconverged),
        "contacts_mean": tally.contacts_mean,
        "ns_per_contact_sweep": 1e9 * timer.cpu / max(timer.contact_sweeps, 1),
        "nlgs_share": timer.cpu / cpu if cpu > 0 else 0.0,
        "samples": {str(k): v for k, v in sampler.values.items()},
        "blocks": sim.model.block_count,
        "status": result.status,
    }


def peak_memory_mb(case: str, solver: str = DEFAULT) -> float:
    tracemalloc.start()
    run_masonry(case, 0.1, record=False, solver=solver)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 2**20


def startup() -> dict:
    """`masonry --help`, and a fresh process to the end of the first step (numba cache warm): minimum of 3
    of the wall-clock and of the CPU time (user + system) of the child process. On a shared machine the
    CPU time is the figure to read: the wall-clock adds the time spent waiting for a core."""
    import resource

    masonry = str(Path(sys.executable).parent / "masonry")
    first_step = (
        f"import sys; sys.path.insert(0, {str(ROOT)!r});"
        "from benchmarks.solver_cases import make_scenario; from masonrycli.run import simulate;"
        "simulate(make_scenario('wall-51'), steps=1)"
    )
    out = {}
    for name, cmd in (("help", [masonry, "--help"]), ("first_step", [sys.executable, "-c", first_step])):
        wall = cpu = np.inf
        for _ in range(3):
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            t = time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True, cwd=ROOT)
            wall = min(wall, time.perf_counter() - t)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = min(cpu, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
        out[f"{name}_wall_s"], out[f"{name}_cpu_s"] = wall, cpu
    return out


def lmgc90(python: str | None) -> dict:
    if not python:
        return {"available": False, "why": "no --lmgc-python (compas_lmgc90 lives in a separate venv: LMGC90.md)"}
    script = ROOT / "benchmarks" / "lmgc90_reference.py"
    cmd = [python, str(script), "--configs", "matched", "--repeat", "1", "--skip-ours"]
    done = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    if done.returncode != 0:
        return {"available": False, "why": done.stderr.strip().splitlines()[-1] if done.stderr else "failed"}
    return {"available": True, "wall-51": json.loads(done.stdout)}


def summarise(runs: dict[str, list[dict]], tight: dict, pymunk_runs: list[dict], second: dict | None = None) -> dict:
    """One case's row from its repeats: ``runs`` solver → the runs (dicts of run_masonry), ``tight`` the
    reference run and ``second`` the second reference (solver_reference.run; may be None), ``pymunk_runs``
    pymunk's runs (may be empty). Per solver the run of least CPU time, its time per simulated second, its
    slip errors against ``tight``, which of them are no larger than the two references' spread
    (``unresolved``) and, when DEFAULT was run, its time over the default's; pymunk's fastest run and its
    errors against the same reference."""
    spread = spread_pct(tight, second) if second else {}
    solvers = {}
    for name, repeats in runs.items():
        best = dict(min(repeats, key=lambda r: r["cpu_s"]))
        best["cpu_per_sim_s"] = best["cpu_s"] / best["sim_s"]
        best["cpu_runs"] = [round(r["cpu_s"], 3) for r in repeats]
        best["error_pct"] = errors_pct(best["samples"], tight["samples"])
        best["unresolved"] = unresolved(best["error_pct"], spread)
        solvers[name] = best
    if DEFAULT in solvers:
        for row in solvers.values():
            row["over_default"] = row["cpu_per_sim_s"] / solvers[DEFAULT]["cpu_per_sim_s"]
    first = next(iter(solvers.values()))
    row = {
        "blocks": first["blocks"],
        "solvers": solvers,
        "tight": _reference(tight),
    }
    if second:
        row["second"] = _reference(second)
        row["spread_pct"] = spread
    if "nlgs" in solvers and DEFAULT in solvers and DEFAULT != "nlgs":
        row["ratio_nlgs_over_default"] = solvers["nlgs"]["over_default"]
    if pymunk_runs:
        pm = min(pymunk_runs, key=lambda r: r["cpu_s"])
        pm_per_s = pm["cpu_s"] / pm["sim_s"]
        row["pymunk"] = {
            "cpu_per_sim_s": pm_per_s,
            "ratio_over_pymunk": {name: r["cpu_per_sim_s"] / pm_per_s for name, r in solvers.items()},
            "error_pct": errors_pct({str(k): v for k, v in pm["slips"].items()}, tight["samples"]),
        }
        row["pymunk"]["unresolved"] = unresolved(row["pymunk"]["error_pct"], spread)
    return row


def _reference(run: dict) -> dict:
    """What the JSON keeps of a reference run: its effort, how far from converged, its slips, its settings."""
    keys = ("cpu_s", "sweeps_mean", "unconverged", "capped", "residual_max", "samples")
    return {k: run[k] for k in keys if k in run} | {"settings": run.get("options", TIGHT)}


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--suite", nargs="*", default=["paper"], choices=sorted(SUITES))
    parser.add_argument("--cases", nargs="*", help="cases instead of suites (solver_cases.CASES)")
    parser.add_argument(
        "--solvers", nargs="+", default=list(SOLVERS), choices=SOLVERS, help="solvers to run (default: all)"
    )
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--duration", type=float, help="simulated s per run (default: each case's own)")
    parser.add_argument("--no-pymunk", action="store_true")
    parser.add_argument("--lmgc-python", help="interpreter of a venv with compas_lmgc90 installed")
    parser.add_argument(
        "--second-reference",
        default=spec_of(SECOND),
        help="SOLVER:TOLERANCE[:CAP] of the second tight solve, or 'none' to skip it (default: %(default)s)",
    )
    parser.add_argument("--json", type=Path, default=ROOT / "benchmarks" / "results_solver.json")
    args = parser.parse_args(argv)
    second_options = None
    if args.second_reference != "none":
        try:
            second_options = parse_spec(args.second_reference)
        except ValueError as exc:
            parser.error(str(exc))
    cases = args.cases or [c for s in args.suite for c in SUITES[s]]
    unknown = [c for c in cases if c not in CASES]
    if unknown:
        parser.error(f"unknown case(s): {', '.join(unknown)}")
    solvers = list(dict.fromkeys(args.solvers))
    use_pymunk = pymunk_engine.available() and not args.no_pymunk

    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT)
    report = {
        "date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "commit": commit.stdout.strip(),
        "machine": {"python": platform.python_version(), "cpu_count": os.cpu_count(), "load": os.getloadavg()},
        "solvers": solvers,
        "default_solver": DEFAULT,
        "references": [spec_of(TIGHT)] + ([spec_of(second_options)] if second_options else []),
        "startup": startup(),
        "cases": {},
    }
    for solver in solvers:  # compile / load every kernel and the recorder first
        run_masonry("wall-51", 0.02, record=True, solver=solver)
        # A tolerance no solve meets stalls every step into the stalled-step methods (newton, banded,
        # bodies, faces), whose kernels the first run never reached: on a cold numba cache (a fresh
        # checkout) they compiled inside the first timed run, and with --repeat 1 the default's h64 run
        # read 187.8 CPU s per simulated s instead of ~90 (2026-11-27, 026de1f).
        run_masonry("wall-51", 0.02, record=False, solver=solver, tolerance=1e-12)
    runs = {c: {s: [] for s in solvers} for c in cases}
    pymunk_runs: dict[str, list] = {c: [] for c in cases}
    for _ in range(args.repeat):  # interleaved: every case with every solver once, then again
        for case in cases:
            for solver in solvers:
                runs[case][solver].append(run_masonry(case, args.duration, record=True, solver=solver))
            if use_pymunk and is_wall(case):
                pymunk_runs[case].append(pymunk_engine.run_wall(case, args.duration or CASES[case][2]))
    for case in cases:
        tight = run_reference(case, 0.2, **TIGHT)
        second = run_reference(case, 0.2, **second_options) if second_options else None
        row = summarise(runs[case], tight, pymunk_runs[case], second)
        row["peak_memory_mb"] = peak_memory_mb(case, solvers[0])
        report["cases"][case] = row
    report["lmgc90"] = lmgc90(args.lmgc_python)
    args.json.write_text(json.dumps(report, indent=2))
    print_table(report)
    return report


def _err(e: dict, unresolved: dict | None = None, steps=tuple(str(k) for k in SAMPLES)) -> str:
    """Errors top/mean at the samples (0.1 and 0.2 s); '≈' after one no larger than the references' spread
    there."""

    def one(step: str, i: int) -> str:
        return f"{e[step][i]:+.2f}" + ("≈" if (unresolved or {}).get(step, (False, False))[i] else "")

    return " ".join(f"{one(s, 0)}/{one(s, 1)}" if s in e else "–" for s in steps)


def _ref(row: dict) -> str:
    """The tight solve's unconverged (capped) steps and largest residual; the second reference's below."""
    refs = [row["tight"]] + ([row["second"]] if "second" in row else [])
    return "\n".join(f"{r['unconverged']} ({r.get('capped', '?')}) {r.get('residual_max', np.nan):.1e}" for r in refs)


def print_table(report: dict) -> None:
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"masonry solver benchmark — {report['date']}, commit {report['commit']}")
    for col in (
        "case",
        "blocks",
        "solver",
        "CPU s / sim s",
        f"÷ {DEFAULT}",
        "sweeps/step (max)",
        "unconv.",
        "contacts",
        "ns/contact·sweep",
        "error % top/mean 0.1 s 0.2 s",
        "ref. spread % top/mean 0.1 s 0.2 s",
        "ref. unconv. (capped) max residual m/s",
        "peak MB",
        "pymunk s / sim s (solver ÷ pymunk)",
        "pymunk error %",
    ):
        table.add_column(col, justify="right")
    for case, row in report["cases"].items():
        pm = row.get("pymunk")
        for i, (name, r) in enumerate(row["solvers"].items()):
            table.add_row(
                case if i == 0 else "",
                str(row["blocks"]) if i == 0 else "",
                name,
                f"{r['cpu_per_sim_s']:.3f}",
                f"{r['over_default']:.2f}" if "over_default" in r else "–",
                f"{r['sweeps_mean']:.0f} ({r['sweeps_max']})",
                str(r["unconverged"]),
                f"{r['contacts_mean']:.0f}",
                f"{r['ns_per_contact_sweep']:.1f}",
                _err(r["error_pct"], r.get("unresolved")),
                (_err(row["spread_pct"]) if "spread_pct" in row else "–") if i == 0 else "",
                _ref(row) if i == 0 else "",
                f"{row['peak_memory_mb']:.1f}" if i == 0 else "",
                f"{pm['cpu_per_sim_s']:.3f} ({pm['ratio_over_pymunk'][name]:.2f})" if pm else "–",
                _err(pm["error_pct"], pm.get("unresolved")) if pm and i == 0 else "",
                end_section=i == len(row["solvers"]) - 1,
            )
    console = Console(width=220)
    console.print(table)
    refs = report.get("references", [spec_of(TIGHT)])
    console.print(
        f"accuracy: against {refs[0]} (SOLVER:TOLERANCE m/s:CAP sweeps) in the same run, 0.2 s; "
        + (
            f"ref. spread: {refs[1]}'s slips in % of it; ≈: an error no larger than the spread at that sample "
            "and measure, not resolved by the reference"
            if len(refs) > 1
            else "no second reference (--second-reference none): the reference's spread is unknown"
        )
    )
    console.print(
        "ref. unconv. (capped): the references' steps above their tolerance (those at the sweep cap), "
        "and their largest final residual (m/s)"
    )
    s = report["startup"]
    console.print(
        f"start-up (CPU / wall-clock): masonry --help {s['help_cpu_s']:.2f} / {s['help_wall_s']:.2f} s, fresh "
        f"process to the end of the first step {s['first_step_cpu_s']:.2f} / {s['first_step_wall_s']:.2f} s"
    )
    lm = report["lmgc90"]
    console.print("LMGC90: " + (json.dumps(lm["wall-51"])[:300] if lm["available"] else f"not run ({lm['why']})"))


if __name__ == "__main__":
    main()
