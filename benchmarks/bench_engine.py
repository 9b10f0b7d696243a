"""Engine benchmarks (DESIGN.md §7): run with ``.venv/bin/python benchmarks/bench_engine.py``.

Measures, on the paper's scenarios at dt = 1e-3 (compile excluded; median of ``--repeat`` runs):

* wall-clock per simulated second for the 51- and 248-block shaken walls and the settling arch;
* NLGS sweeps per step, contacts per step, ns per contact per sweep (time inside the NLGS kernel);
* the share of a step spent on the paper's tensors, and on recording (a run with a Rerun recording vs
  the same run without, in the same process);
* peak memory of a whole run, first-run compile time (empty numba cache) vs cached start (subprocess);
* growth with the block count: ns per contact per sweep of the 248-block wall / the 51-block wall.

Figures are printed as a Markdown table and written to ``benchmarks/results.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
os.environ.setdefault("RERUN_ANALYTICS", "0")


from masonrycli.engine import dispatch  # noqa: E402
from masonrycli.run import Simulation, simulate  # noqa: E402
from masonrycli.scenario.motion import Constant, Sine  # noqa: E402
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder  # noqa: E402

SINE = Sine(direction=(1.0, 0.0), amplitude=1.0, frequency=2.0)
CASES = {
    "wall-51": ("wall", {"blocks": 51}, 1.0, {"ground": SINE}),
    "wall-248": ("wall", {"blocks": 248}, 1.0, {"ground": SINE}),
    "arch-98": ("arch", {}, 5.0, {"right-foundation": Constant(velocity=(0.0, -0.01))}),
}


def make_scenario(case: str, duration: float | None = None):
    builder, options, default_duration, motions = CASES[case]
    run = RunConfig(duration=duration or default_duration)
    return scenario_from_builder(builder, options, run, Material(), motions)


class Probe:
    """Accumulates time spent in the NLGS kernel and in the tensors, by wrapping their launchers."""

    def __init__(self):
        self.nlgs_s = 0.0
        self.tensor_s = 0.0
        self.contact_sweeps = 0
        self._solve = dispatch.solve

    def install(self, sim: Simulation) -> None:
        original_solve = self._solve
        probe = self

        def timed_solve(contact_body, pack, count, model, v, r, status, *tuning):
            t = time.perf_counter()
            its, res = original_solve(contact_body, pack, count, model, v, r, status, *tuning)
            probe.nlgs_s += time.perf_counter() - t
            probe.contact_sweeps += its * count
            return its, res

        dispatch.solve = timed_solve
        original_tensors = sim.tensors.step

        def timed_tensors(*args):
            t = time.perf_counter()
            original_tensors(*args)
            probe.tensor_s += time.perf_counter() - t

        sim.tensors.step = timed_tensors

    def uninstall(self) -> None:
        dispatch.solve = self._solve


def run_once(case: str, record: bool) -> dict:
    sc = make_scenario(case)
    sim = Simulation(sc)
    probe = Probe()
    probe.install(sim)
    sinks = []
    recorder = None
    tmp = None
    if record:
        from masonrycli.execute import recording_static, run_metadata
        from masonrycli.recording import Recorder

        tmp = tempfile.TemporaryDirectory()
        recorder = Recorder(Path(tmp.name) / "bench.rrd", recording_static(sim), run_metadata(sc, sim))
        sinks.append(recorder)
    t = time.perf_counter()
    try:
        result = simulate(sc, sinks, sim=sim)
    finally:
        if recorder is not None:
            recorder.close()
        probe.uninstall()
    wall = time.perf_counter() - t
    if tmp is not None:
        tmp.cleanup()
    steps = result.steps
    return {
        "wall_s": wall,
        "sim_s": result.time,
        "sweeps_per_step": result.tally.sweeps_mean,
        "contacts_per_step": result.tally.contacts_mean,
        "ns_per_contact_sweep": 1e9 * probe.nlgs_s / max(probe.contact_sweeps, 1),
        "nlgs_share": probe.nlgs_s / wall,
        "tensor_share": probe.tensor_s / wall,
        "steps_at_cap": result.tally.capped,
        "steps": steps,
    }


def subprocess_start(cache_dir: str, case: str = "wall-51") -> dict:
    """Time from interpreter start to the end of 10 steps, and peak RSS, in a fresh process."""
    code = (
        "import time, resource, sys; t0 = time.perf_counter();"
        f"sys.path.insert(0, {str(ROOT)!r});"
        "from benchmarks.bench_engine import make_scenario;"
        "from masonrycli.run import simulate;"
        f"r = simulate(make_scenario({case!r}), steps=10);"
        "print(time.perf_counter() - t0, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)"
    )
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True, cwd=ROOT)
    seconds, rss = out.stdout.split()
    return {"start_s": float(seconds), "peak_rss_mb": int(rss) / 1024}


def peak_memory(case: str) -> float:
    code = (
        "import resource, sys;"
        f"sys.path.insert(0, {str(ROOT)!r});"
        "from benchmarks.bench_engine import make_scenario;"
        "from masonrycli.run import simulate;"
        f"simulate(make_scenario({case!r}));"
        "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    return int(out.stdout.strip()) / 1024


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--cases", nargs="*", default=list(CASES))
    parser.add_argument("--no-startup", action="store_true", help="skip the compile / cached-start runs")
    args = parser.parse_args()

    results: dict = {
        "machine": {
            "python": platform.python_version(),
            "cpu_count": os.cpu_count(),
            "processor": platform.processor() or platform.machine(),
        }
    }
    if not args.no_startup:
        with tempfile.TemporaryDirectory() as cache:
            first = subprocess_start(cache)
            cached = subprocess_start(cache)
        results["startup"] = {"first_run_compile_s": first["start_s"], "cached_start_s": cached["start_s"]}
    # Warm-up compiles every kernel (and the recorder) in this process.
    simulate(make_scenario("wall-51", duration=0.02))
    rows = {}
    for case in args.cases:
        plain = [run_once(case, record=False) for _ in range(args.repeat)]
        recorded = [run_once(case, record=True) for _ in range(args.repeat)]
        med = {k: statistics.median(r[k] for r in plain) for k in plain[0]}
        wall_rec = statistics.median(r["wall_s"] for r in recorded)
        med["wall_per_sim_s"] = med["wall_s"] / med["sim_s"]
        med["recording_share"] = (wall_rec - med["wall_s"]) / wall_rec
        med["runs"] = [round(r["wall_s"], 3) for r in plain]
        med["runs_recorded"] = [round(r["wall_s"], 3) for r in recorded]
        med["peak_rss_mb"] = peak_memory(case)
        rows[case] = med
    results["cases"] = rows
    if "wall-51" in rows and "wall-248" in rows:
        results["ratio_ns_per_contact_sweep_248_over_51"] = (
            rows["wall-248"]["ns_per_contact_sweep"] / rows["wall-51"]["ns_per_contact_sweep"]
        )

    print(
        "| case | wall-clock per simulated s | sweeps/step | contacts/step | ns per contact·sweep | "
        "tensors share | recording share | peak RSS |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for case, r in rows.items():
        print(
            f"| {case} | {r['wall_per_sim_s']:.2f} s (runs {r['runs']}) | {r['sweeps_per_step']:.1f} | "
            f"{r['contacts_per_step']:.0f} | {r['ns_per_contact_sweep']:.1f} | {100 * r['tensor_share']:.1f} % | "
            f"{100 * r['recording_share']:.1f} % | {r['peak_rss_mb']:.0f} MB |"
        )
    if "startup" in results:
        s = results["startup"]
        print(
            f"\nstart to 10 steps of wall-51: first run (empty numba cache) {s['first_run_compile_s']:.1f} s, "
            f"cached {s['cached_start_s']:.1f} s"
        )
    if "ratio_ns_per_contact_sweep_248_over_51" in results:
        print(f"ns per contact·sweep, 248 / 51 blocks: {results['ratio_ns_per_contact_sweep_248_over_51']:.2f}")
    (ROOT / "benchmarks" / "results.json").write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
