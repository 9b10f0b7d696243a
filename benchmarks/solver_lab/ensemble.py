"""Ensembles of short runs: a solver change judged on many trajectories at once, as a distribution.

    python -m benchmarks.solver_lab ensemble run --cases h32 h64 [--duration 0.15] [--motions A,F[,PHASE] …]
                                                 [--copies K] [--jitter EPS] [--set FIELD=VALUE[+…]]
                                                 --out FILE.json
    python -m benchmarks.solver_lab ensemble compare A.json[,A2.json …] B.json[,…] [--shift-copy K]

A step solved differently within the tolerance puts a run on another trajectory, with other hard steps:
one run's mean sweep units a step moves by tens of % with any change of the solver's path (on the
32-course wall by up to 10× for an amplitude changed by 1e-6), so a change worth 5–15 % cannot be read
from one run. ``run`` therefore runs each case (a wall of :mod:`benchmarks.solver_cases`, at its dt, μ
and default solver) once per ground motion of a set — the paper's sine with other amplitudes and
frequencies, v(t) = A sin(2π f t + φ) — and ``--copies K`` times per motion (amplitude × (1 + k · 1e-6),
k = 0 … K − 1: other trajectories of the same motion), for a short time, without recording, and keeps per run: mean, max and total sweep units a step (``StepStats.iterations``: the
solver's work in sweep equivalents, the figure of the run's history), unconverged steps, CPU s of the
time loop, and every step's units. The JSON also holds the git commit of the engine that ran (the
checkout ``masonrycli`` was imported from, and whether its ``masonrycli/`` had uncommitted changes).

``compare`` pairs the runs of two files by (case, motion, duration, copy) and prints, per case, the ratio B/A
of each run's mean sweep units summarised: geometric mean, median, min, max, runs better / worse /
equal, a bootstrap 90 % interval of the geometric mean (resampling the runs, fixed seed: deterministic),
the ratio of the summed units, unconverged steps of A and B, and the CPU ratio (indicative only on a
shared machine; the counts are deterministic whatever the load).

Another engine (a branch's checkout): run the command from that checkout, so its ``masonrycli`` is the
one imported — ``cd CHECKOUT && PYTHONPATH=$PWD python -m benchmarks.solver_lab ensemble run …`` once
the checkout has this module (a branch rebased on main), or, for a checkout without it,
``PYTHONPATH=CHECKOUT python /path/to/benchmarks/solver_lab/ensemble.py run …`` (this file imports only
``benchmarks.solver_cases`` and ``masonrycli``, both taken from CHECKOUT).

The ratios a mere change of path makes (the null distribution, to read B/A against): ``compare A.json
A.json --shift-copy 1`` pairs each copy k with copy k + 1 of the same engine; ``--jitter EPS`` multiplies
every amplitude by 1 + EPS and keeps the nominal motion as the key.
"""

from __future__ import annotations

import json
import math
import subprocess
import time
from pathlib import Path

import numpy as np

DURATION = 0.15
"""s: the walls' hard steps (stick–slip transitions of the base) fall in 50–150 ms for these motions."""
AMPLITUDES = (0.85, 1.0, 1.15, 1.3)
FREQUENCIES = (1.7, 2.0, 2.3)
MOTIONS = tuple((a, f, 0.0) for a in AMPLITUDES for f in FREQUENCIES)
"""(amplitude m/s, frequency Hz, phase rad): 12 motions around the paper's (1 m/s, 2 Hz), peak ground
accelerations 0.93–1.92 g, all above μ g = 0.6 g so every wall slides on its base. Phase 0: the ground
starts at rest as in the paper (a phase would start it with a velocity jump)."""
COPY_STEP = 1e-6
"""Copy k of a motion has its amplitude × (1 + k · COPY_STEP): another trajectory of the same motion (a
change of 1e-6 moves a wall's run as much as any change of the solver's path does)."""
BOOTSTRAP, SEED = 10_000, 0


def parse_motion(text: str) -> tuple[float, float, float]:
    """``"A,F"`` or ``"A,F,PHASE"`` → (amplitude, frequency, phase)."""
    parts = [float(x) for x in text.split(",")]
    if len(parts) not in (2, 3):
        raise ValueError(f"motion {text!r}: expected AMPLITUDE,FREQUENCY[,PHASE]")
    return (parts[0], parts[1], parts[2] if len(parts) == 3 else 0.0)


def engine_commit() -> dict:
    """Where ``masonrycli`` was imported from, its checkout's commit, the last commit that changed
    masonrycli/, and whether masonrycli/ has uncommitted changes."""
    import masonrycli

    package = Path(masonrycli.__file__).resolve().parent
    root = package.parent

    def git(*args: str) -> str:
        try:
            out = subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True, check=True)
        except (OSError, subprocess.CalledProcessError):
            return ""
        return out.stdout.strip()

    return {
        "path": str(root),
        "commit": git("rev-parse", "HEAD"),
        "engine_commit": git("log", "-1", "--format=%H", "--", "masonrycli"),  # the last one to change it
        "dirty": bool(git("status", "--porcelain", "masonrycli")),
    }


def run_one(
    case: str, motion: tuple[float, float, float], duration: float, jitter: float = 0.0, copy: int = 0, tuning=None
) -> dict:
    """One unrecorded run of ``case`` shaken by ``motion``, amplitude × (1 + jitter + copy · COPY_STEP), with the
    engine's ``tuning`` (engine/tuning.py; None: the shipped one)."""
    from benchmarks.solver_cases import CASES
    from masonrycli.run import Simulation
    from masonrycli.scenario.motion import Sine
    from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

    builder, options, _, motions = CASES[case]
    if list(motions) != ["ground"]:
        raise ValueError(f"{case}: not a case shaken by its ground")
    amplitude, frequency, phase = motion
    ground = Sine(amplitude=amplitude * (1.0 + jitter + copy * COPY_STEP), frequency=frequency, phase=phase)
    scenario = scenario_from_builder(builder, options, RunConfig(duration=duration), Material(), {"ground": ground})
    sim = Simulation(scenario) if tuning is None else Simulation(scenario, tuning=tuning)
    units = []
    t = time.process_time()
    for _ in range(sim.model.n_steps):  # simulate()'s loop without frames or sinks
        units.append(int(sim.step().iterations))
        if sim.diverged():
            break
    cpu = time.process_time() - t
    u = np.array(units, dtype=np.int64)
    return {
        "case": case,
        "amplitude": amplitude,
        "frequency": frequency,
        "phase": phase,
        "duration": duration,
        "jitter": jitter,
        "copy": copy,
        "steps": int(u.size),
        "mean": float(u.mean()),
        "max": int(u.max()),
        "total": int(u.sum()),
        "unconverged": int(sim.unconverged),
        "diverged": sim.diverged(),
        "cpu_s": round(cpu, 3),
        "units": units,
    }


def run(
    cases: list[str],
    motions,
    duration: float,
    out: Path | None,
    jitter: float = 0.0,
    copies: range = range(1),
    override: str = "",
) -> dict:
    """Run every case under every motion; print a line a run and each case's spread; write ``out``.

    ``override`` (``"first_stall=200+bodies_cycling=4"``, as ``hard replay``'s variants: fields of the engine's
    Tuning, engine/tuning.py) changes the engine's tuning for these runs only and is kept in the JSON as
    ``engine["override"]``: a rule change is judged on ensembles before it is written into the engine."""
    tuning = None
    if override:
        from benchmarks.solver_lab.hard_steps import _parse, tuning_of

        tuning = tuning_of(_parse(override))
    return _run(cases, motions, duration, out, jitter, copies, override, tuning)


def _run(cases, motions, duration, out, jitter, copies, override, tuning) -> dict:
    from benchmarks.solver_cases import make_scenario
    from masonrycli.run import simulate

    simulate(make_scenario("h8", 0.003))  # compile or load the engine's kernels outside the timed runs
    engine = engine_commit()
    dirty = " (masonrycli/ modified)" if engine["dirty"] else ""
    print(
        f"checkout {engine['commit'][:10]} (masonrycli/ last changed in {engine['engine_commit'][:10]}){dirty}"
        f" at {engine['path']}; {duration:g} s a run",
        flush=True,
    )
    runs: list[dict] = []
    doc = {"engine": engine, "duration": duration, "jitter": jitter, "runs": runs}
    if override:
        engine["override"] = override
        print(f"engine tuning for these runs: {override}", flush=True)
    for case in cases:
        print(f"\n{case}\n| A m/s | f Hz | φ | copy | mean units | max | unconverged | CPU s |\n" + "|---" * 8 + "|")
        for motion in motions:
            for copy in copies:
                r = run_one(case, motion, duration, jitter, copy, tuning)
                runs.append(r)
                if out is not None:  # after every run: an ensemble stopped halfway keeps what it ran
                    out.write_text(json.dumps(doc, indent=1))
                print(
                    f"| {r['amplitude']:g} | {r['frequency']:g} | {r['phase']:g} | {copy} | {r['mean']:.0f} | {r['max']} |"
                    f" {r['unconverged']} | {r['cpu_s']:.1f} |",
                    flush=True,
                )
        print(spread_line([r["mean"] for r in runs if r["case"] == case]))
    if out is not None:
        print(f"\nwrote {out}")
    return doc


def spread_line(means: list[float]) -> str:
    """The spread of one case's per-run means: how far apart single runs are."""
    m = np.asarray(means, dtype=float)
    cv = m.std(ddof=1) / m.mean() if m.size > 1 else 0.0
    return (
        f"per-run mean units: min {m.min():.0f}, median {np.median(m):.0f}, max {m.max():.0f}"
        f" (max/min {m.max() / m.min():.2f}, CV {100 * cv:.0f} %)"
    )


def _key(r: dict, shift: int = 0) -> tuple:
    return (r["case"], r["amplitude"], r["frequency"], r["phase"], r["duration"], r.get("copy", 0) - shift)


def pair_runs(a: dict, b: dict, shift: int = 0) -> dict[str, list[tuple[dict, dict]]]:
    """Case → [(run of A, run of B)] for the motions both files ran, in A's order; ``shift``: B's copy
    k + shift is A's copy k's partner (an engine against itself: the ratios a change of path alone makes)."""
    by_key = {_key(r, shift): r for r in b["runs"]}
    pairs: dict[str, list[tuple[dict, dict]]] = {}
    for r in a["runs"]:
        if _key(r) in by_key:
            pairs.setdefault(r["case"], []).append((r, by_key[_key(r)]))
    return pairs


def summarise(pairs: list[tuple[dict, dict]], resamples: int = BOOTSTRAP, seed: int = SEED) -> dict:
    """Figures of one case's pairs: ratio B/A of the per-run mean units, and the totals (module doc)."""
    ratio = np.array([rb["mean"] / ra["mean"] for ra, rb in pairs])
    total_a = np.array([ra["total"] for ra, _ in pairs], dtype=float)
    total_b = np.array([rb["total"] for _, rb in pairs], dtype=float)
    logs = np.log(ratio)
    pick = np.random.default_rng(seed).integers(0, logs.size, size=(resamples, logs.size))  # resampled runs
    lo, hi = np.percentile(np.exp(logs[pick].mean(axis=1)), [5.0, 95.0])
    sum_lo, sum_hi = np.percentile(total_b[pick].sum(axis=1) / total_a[pick].sum(axis=1), [5.0, 95.0])
    return {
        "runs": int(ratio.size),
        "geomean": float(math.exp(logs.mean())),
        "median": float(np.median(ratio)),
        "min": float(ratio.min()),
        "max": float(ratio.max()),
        "better": int((ratio < 1.0).sum()),
        "worse": int((ratio > 1.0).sum()),
        "equal": int((ratio == 1.0).sum()),
        "interval90": (float(lo), float(hi)),
        "total_ratio": float(total_b.sum() / total_a.sum()),
        "total_interval90": (float(sum_lo), float(sum_hi)),
        "unconverged": (sum(ra["unconverged"] for ra, _ in pairs), sum(rb["unconverged"] for _, rb in pairs)),
        "cpu_ratio": sum(rb["cpu_s"] for _, rb in pairs) / max(sum(ra["cpu_s"] for ra, _ in pairs), 1e-9),
    }


def load(paths: str | Path) -> dict:
    """The runs of one JSON file, or of several (``"a.json,b.json"``: their runs pooled, engine of the first)."""
    docs = [json.loads(Path(p).read_text()) for p in str(paths).split(",")]
    commits = {d["engine"]["commit"] for d in docs}
    if len(commits) > 1:
        print(f"warning: {paths} pools the runs of several engines: {sorted(c[:10] for c in commits)}")
    return {"engine": docs[0]["engine"], "runs": [r for d in docs for r in d["runs"]]}


def compare(path_a: str | Path, path_b: str | Path, shift: int = 0) -> dict[str, dict]:
    """Print the per-case table of B against A; return the figures by case."""
    a, b = load(path_a), load(path_b)
    for name, doc, path in (("A", a, path_a), ("B", b, path_b)):
        e = doc["engine"]
        since = f", masonrycli/ of {e['engine_commit'][:10]}" if "engine_commit" in e else ""
        print(f"{name}: {path}: checkout {e['commit'][:10]}{since}{' (dirty)' * e['dirty']}")
    print(
        "\n| case | runs | B/A geo. mean [90 % interval] | median | min – max | better / worse / equal |"
        " Σ units B/A [90 %] | unconverged A / B | CPU B/A |\n|---|---|---|---|---|---|---|---|---|"
    )
    out = {}
    paired = pair_runs(a, b, shift)
    for case, pairs in paired.items():
        s = out[case] = summarise(pairs)
        lo, hi = s["interval90"]
        print(
            f"| {case} | {s['runs']} | {s['geomean']:.3f} [{lo:.3f}, {hi:.3f}] | {s['median']:.3f} |"
            f" {s['min']:.3f} – {s['max']:.3f} | {s['better']} / {s['worse']} / {s['equal']} |"
            f" {s['total_ratio']:.3f} [{s['total_interval90'][0]:.3f}, {s['total_interval90'][1]:.3f}] |"
            f" {s['unconverged'][0]} / {s['unconverged'][1]} | {s['cpu_ratio']:.2f} |"
        )
    unpaired = len(a["runs"]) + len(b["runs"]) - 2 * sum(len(p) for p in paired.values())
    if unpaired:
        print(f"\n{unpaired} runs without a partner (another motion, duration or case) left out")
    return out


def add_arguments(sub) -> None:
    """The ``ensemble`` subcommand's parser (``sub``: an argparse subparsers object)."""
    ens = sub.add_parser("ensemble", help="many short runs over ground motions; compare two engines' runs")
    act = ens.add_subparsers(dest="action", required=True)
    r = act.add_parser("run", help="run the cases under the motion set; per-run sweep units to --out")
    r.add_argument("--cases", nargs="+", default=["h32", "h64"])
    r.add_argument("--duration", type=float, default=DURATION, help="simulated s a run")
    r.add_argument("--motions", nargs="+", type=parse_motion, default=None, metavar="A,F[,PHASE]")
    r.add_argument("--jitter", type=float, default=0.0, help="amplitudes × (1 + EPS), keyed as nominal")
    r.add_argument("--copies", type=int, default=1, help="runs a motion, amplitude × (1 + k·1e-6), k = 0 …")
    r.add_argument("--first-copy", type=int, default=0, help="k of the first copy (to extend an ensemble)")
    r.add_argument("--out", type=Path, default=None)
    r.add_argument(
        "--set", default="", metavar="FIELD=VALUE[+…]", help="engine Tuning fields for these runs (engine/tuning.py)"
    )
    c = act.add_parser("compare", help="B against A, runs paired by motion")
    c.add_argument("a", help="A's JSON (several: comma-separated, runs pooled)")
    c.add_argument("b", help="B's JSON (several: comma-separated, runs pooled)")
    c.add_argument("--shift-copy", type=int, default=0, help="pair A's copy k with B's copy k + SHIFT")


def main(args) -> None:
    if args.action == "run":
        copies = range(args.first_copy, args.first_copy + args.copies)
        run(args.cases, args.motions or MOTIONS, args.duration, args.out, args.jitter, copies, args.set)
    else:
        compare(args.a, args.b, args.shift_copy)


if __name__ == "__main__":  # another checkout's engine: PYTHONPATH=CHECKOUT python …/ensemble.py run …
    import argparse
    import os
    import sys

    sys.path.pop(0)  # this file's folder: the lab's modules must not shadow anything of CHECKOUT
    os.environ.setdefault("RERUN_ANALYTICS", "0")
    parser = argparse.ArgumentParser(prog="ensemble.py")
    add_arguments(parser.add_subparsers(dest="command", required=True))
    main(parser.parse_args(["ensemble", *sys.argv[1:]]))
