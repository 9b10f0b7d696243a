"""LMGC90 reference benchmark: the 51-block shaken wall in LMGC90 itself and in our engine, in one run.

Standalone script, run with the *reference* venv's interpreter (never imported by the tests, never a
dependency of the project)::

    python3 -m venv /work/lmgcvenv
    /work/lmgcvenv/bin/pip install compas_lmgc90==0.1.11     # manylinux cp311 wheel; pulls compas,
                                                              # compas_dem, compas_viewer (PySide6), numpy,
                                                              # scipy, shapely from PyPI
    /work/lmgcvenv/bin/python benchmarks/lmgc90_reference.py > lmgc90.json

Options: ``--repeat N`` (default 3, median taken), ``--duration S`` (default 1.0 simulated second),
``--configs shipped,matched,matched-check10`` (LMGC90 solver settings, below; also ``matched-check1``),
``--ours-python PATH`` (default ``/work/venv/bin/python``: our engine is timed in a subprocess of the
project venv), ``--skip-ours``. One JSON document goes to stdout, progress to stderr. A default run
takes ~10 min of one core, most of it the ``shipped`` LMGC90 settings (~2.5 min per run); use
``--configs matched`` for a ~1 min run.

What is compared (findings and measured figures: benchmarks/LMGC90.md):

* LMGC90 through ``compas_lmgc90`` 0.1.11, the only LMGC90 build on PyPI. It wraps LMGC90's *3-D* rigid
  chain only (RBDY3 bodies, POLYR polyhedral contactors, PRPRx detection "STO", nlgs_3D with stored
  Delassus loops, Moreau–Jean θ); the binary has no RBDY2/POLYG/PLPLx module at all. So the wall is
  3-D: each 0.30 × 0.20 m block of ``geometry_library.builders.build_wall(blocks=51)`` is extruded to a
  1.0 m deep prism (our blocks are 1.0 m thick too), the ground support is a driven prism. **This is a
  3-D vs 2-D comparison**: LMGC90 puts 4 contact points on each face-to-face joint, our engine 2, so
  LMGC90 has ~2.4x the contacts per step (measured), each a 3×3 local problem instead of 2×2;
  ``us_per_contact_iteration`` and the per-step fit below normalise for the contact count.
* Same physics otherwise: ρ = 2500 kg/m³, gravity −9.81 (LMGC90's is hard-wired in the binding),
  IQS_CLB Coulomb law μ = 0.6, alert distance 1e-3 m, dt = 1e-3 s, θ = 0.5, 1 s, ground velocity
  v_x = 1·sin(2π·2·t) m/s (LMGC90 driven dof ``[0, 1, 4π, −π/2, 1, 0]``:
  V(t) = [v0 + v1·cos(v2·t + v3)]·min(1, v4 + v5·t)), every other ground dof fixed. The mean
  x-displacements of the top and bottom courses at the end are reported for both as a sanity check.
* LMGC90's NLGS settings are private module variables of the binding's Fortran wrapper (no API):
  ``shipped`` runs them as built — norm 'QM/16', tol 1.666e-4, relax 0.1, convergence checked every
  gs_it1 = 50 sweeps, at most gs_it2 = 500 checks (25 000 sweeps). The other configurations patch them
  in memory (ctypes; offsets verified against this exact wheel's SHA-256 and the shipped values, else
  they are skipped) to LMGC90's usual rigid-block settings and our cap: ``matched`` = norm 'Quad ',
  tol 1.666e-4, relax 1.0, check every 50 sweeps, at most 20 checks (1000 sweeps, our
  ``max_iterations``); ``matched-check10`` / ``matched-check1`` check every 10 sweeps / every sweep
  (cap 1000 iteration sweeps; each check is one extra sweep). Our engine checks its quadratic norm
  after every sweep at no extra cost (tol 1.666e-4, cap 1000); LMGC90's iteration counts are multiples
  of gs_it1.
* Timing: wall-clock of the stepping loop only (setup and our numba compile/cache load excluded;
  LMGC90's first step includes its one-time detection-box set-up), median of ``--repeat`` runs, per
  simulated second. LMGC90 is stepped through the binding's C entry point ``lmgc90_compute_one_step``
  (what ``Solver.run`` calls, minus the per-step copy of all bodies and contacts into Python objects and
  the COMPAS mesh updates); ours through ``masonrycli.run.simulate`` (frames every 10 steps, tensors
  included, no recording). Iterations per step are LMGC90's own counter (``nlgs_3D::get_nlgs3D_loop``:
  iteration sweeps, without the check sweep done every gs_it1); ``sweeps_per_step`` adds the check
  sweeps. Contacts per step: ``lmgc90_get_nb_inters``. ``fit_*``: least-squares split of the first
  run's per-step times into a cost per step outside the sweeps and a cost per contact per sweep.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

# the ctypes binding is a sibling module: this script's folder is first on sys.path when it runs
from lmgc90_binding import CONFIGS, SHIPPED, Lmgc

ROOT = Path(__file__).resolve().parent.parent
DT, THETA, RHO, MU, ALERT = 1e-3, 0.5, 2500.0, 0.6, 1e-3
AMPLITUDE, FREQUENCY = 1.0, 2.0
DEPTH = 1.0
BLOCKS = 51


def log(*a):
    print(*a, file=sys.stderr, flush=True)


# --------------------------------------------------------------------------------------------------
# geometry


def prism(xy, depth: float = DEPTH) -> dict:
    """The 2-D polygon ``xy`` ((V, 2) vertices, no closing repeat) extruded to a 3-D prism for
    ``Solver.geometry_from_v_f``: (x, y) → (x, z), depth along y in [−depth/2, depth/2], every face wound
    outwards."""
    import numpy as np

    n = len(xy)
    v = [[x, -depth / 2, y] for x, y in xy] + [[x, depth / 2, y] for x, y in xy]
    faces = [list(range(n)), list(range(n, 2 * n))]
    faces += [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    V = np.array(v)
    c = V.mean(axis=0)
    out = []
    for f in faces:  # wind every face outwards
        p = V[f]
        if np.dot(np.cross(p[1] - p[0], p[2] - p[0]), p.mean(axis=0) - c) < 0:
            f = f[::-1]
        out.append(f)
    return {"vertices": v, "faces": out}


def wall_prisms():
    """The 51 blocks and the ground of ``build_wall(blocks=51)`` as 3-D prisms (:func:`prism`).
    Returns (blocks as {"vertices", "faces"}, course of each block)."""
    sys.path.insert(0, str(ROOT))
    import numpy as np

    from geometry_library.builders import build_wall

    assembly = build_wall(blocks=BLOCKS)
    bodies = [*assembly.blocks, *assembly.supports]
    prisms = [prism(np.asarray(b.polygon.exterior.coords)[:-1]) for b in bodies]
    courses = [int(b.name.split("-")[0][1:]) for b in assembly.blocks]
    return prisms, courses


# --------------------------------------------------------------------------------------------------
# LMGC90 through compas_lmgc90 (the ctypes binding: lmgc90_binding.py)


def run_lmgc(lmgc: Lmgc, prisms, courses, config: dict, duration: float) -> dict:
    import numpy as np
    from compas_lmgc90.solver import Solver

    t_setup = time.perf_counter()
    solver = Solver(dt=DT, theta=THETA, density=RHO)
    solver.geometry_from_v_f(prisms)
    g = len(prisms) - 1  # the ground, last
    solver.v_drvdof[g] = {i: np.zeros(6) for i in range(1, 7)}
    w = 2 * math.pi * FREQUENCY  # A sin(wt) = A cos(wt − π/2)
    solver.apply_velocity(g, "Vx", np.array([[0.0, AMPLITUDE, w, -math.pi / 2, 1.0, 0.0]]))
    solver.contact_law("IQS_CLB", MU, alert=ALERT)
    solver.preprocess()
    if lmgc.patchable:
        lmgc.write_settings(config)
    elif config != SHIPPED:
        raise RuntimeError(lmgc.why_not)
    settings = lmgc.read_settings() if lmgc.patchable else dict(SHIPPED, note="not verified")
    q0 = lmgc.bodies()
    setup_s = time.perf_counter() - t_setup

    n_steps = max(1, round(duration / DT))
    iterations = np.zeros(n_steps, dtype=np.int64)
    contacts = np.zeros(n_steps, dtype=np.int64)
    step = lmgc.lib.lmgc90_compute_one_step
    nb_inters = lmgc.lib.lmgc90_get_nb_inters
    step_s = np.zeros(n_steps)
    clock = time.perf_counter
    t0 = clock()
    for k in range(n_steps):
        t = clock()
        step()
        step_s[k] = clock() - t
        iterations[k] = lmgc.nlgs_loop()[0]
        contacts[k] = nb_inters()
    wall = clock() - t0

    q1 = lmgc.bodies()
    pairs = {}
    for it in lmgc.inters():
        key = (min(it.icdbdy, it.ianbdy), max(it.icdbdy, it.ianbdy))
        pairs[key] = pairs.get(key, 0) + 1
    solver.finalize()
    cap = config["gs_it1"] * config["gs_it2"]
    dx = [q1[i][0] - q0[i][0] for i in range(len(q0))]
    top, bottom = max(courses), min(courses)
    return {
        "setup_s": setup_s,
        "wall_s": wall,
        "steps": n_steps,
        "iterations": iterations,
        "contacts": contacts,
        "step_s": step_s,
        "sweeps": iterations + iterations // config["gs_it1"],
        "sweeps_per_step": float(np.mean(iterations + iterations // config["gs_it1"])),
        "steps_at_cap": int((iterations >= cap).sum()),
        "contacts_per_pair_final": float(np.mean(list(pairs.values()))) if pairs else 0.0,
        "pairs_final": len(pairs),
        "dx_top_course": float(np.mean([d for d, c in zip(dx, courses) if c == top])),
        "dx_bottom_course": float(np.mean([d for d, c in zip(dx, courses) if c == bottom])),
        "dx_ground": float(dx[-1]),
        "settings": settings,
    }


def split_step_time(step_s, sweeps, contacts) -> dict:
    """Least-squares fit of the per-step wall time t_k = a + b · sweeps_k · contacts_k: ``a`` is the
    per-step cost outside the sweeps (detection, Delassus assembly, integration), ``b`` the cost of one
    contact in one NLGS sweep (LMGC90: check sweeps counted as sweeps)."""
    import numpy as np

    x = np.asarray(sweeps, dtype=float) * np.asarray(contacts, dtype=float)
    A = np.column_stack([np.ones_like(x), x])
    (a, b), *_ = np.linalg.lstsq(A, np.asarray(step_s, dtype=float), rcond=None)
    return {"fit_us_per_step_outside_nlgs": 1e6 * float(a), "fit_ns_per_contact_sweep": 1e9 * float(b)}


def bench_lmgc(configs, repeat, duration):
    import numpy as np

    lmgc = Lmgc()
    prisms, courses = wall_prisms()
    out = {}
    for name in configs:
        if name != "shipped" and not lmgc.patchable:
            out[name] = {"skipped": lmgc.why_not}
            log(f"lmgc90 {name}: skipped ({lmgc.why_not})")
            continue
        runs = []
        for r in range(repeat):
            res = run_lmgc(lmgc, prisms, courses, CONFIGS[name], duration)
            log(
                f"lmgc90 {name} run {r + 1}/{repeat}: {res['wall_s']:.2f} s, "
                f"{res['iterations'].mean():.1f} it/step, {res['contacts'].mean():.1f} contacts"
            )
            runs.append(res)
        first = runs[0]
        deterministic = all(np.array_equal(r["iterations"], first["iterations"]) for r in runs)
        wall = statistics.median(r["wall_s"] for r in runs)
        it, nc = first["iterations"], first["contacts"]
        out[name] = {
            "settings": first["settings"],
            "wall_per_sim_s": wall / duration,
            "runs_s": [round(r["wall_s"], 3) for r in runs],
            "setup_s": round(statistics.median(r["setup_s"] for r in runs), 3),
            "iterations_per_step": float(it.mean()),
            "iterations_per_step_median": float(np.median(it)),
            "iterations_max": int(it.max()),
            "sweeps_per_step": first["sweeps_per_step"],
            "steps_at_cap": first["steps_at_cap"],
            "contacts_per_step": float(nc.mean()),
            "us_per_step": 1e6 * wall / first["steps"],
            # whole-step time (detection, assembly, NLGS) per contact per iteration sweep
            "us_per_contact_iteration": 1e6 * wall / max(int((it * nc).sum()), 1),
            **split_step_time(first["step_s"], first["sweeps"], nc),
            "contacts_per_joint_final": first["contacts_per_pair_final"],
            "joints_final": first["pairs_final"],
            "dx_top_course_m": first["dx_top_course"],
            "dx_bottom_course_m": first["dx_bottom_course"],
            "dx_ground_m": first["dx_ground"],
            "iterations_identical_across_runs": deterministic,
            "steps": first["steps"],
        }
    return out, lmgc


# --------------------------------------------------------------------------------------------------
# our engine, in the project venv

OURS = r"""
import json, statistics, sys, time
sys.path.insert(0, ROOT)
import numpy as np
from masonrycli.scenario.motion import Sine
from masonrycli.run import Simulation, simulate
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

def scenario():
    motion = Sine(direction=(1.0, 0.0), amplitude=AMPLITUDE, frequency=FREQUENCY)
    run = RunConfig(duration=DURATION, dt=DT, theta=THETA, tolerance=1.666e-4, max_iterations=1000,
                    alert_distance=ALERT)
    material = Material(density=RHO, thickness=DEPTH, friction=MU)
    return scenario_from_builder("wall", {"blocks": BLOCKS}, run, material, {"ground": motion})

t = time.perf_counter()
simulate(scenario(), steps=10)  # numba compile / cache load, excluded
compile_s = time.perf_counter() - t
runs, results, sims = [], [], []
for _ in range(REPEAT):
    sc = scenario()
    t = time.perf_counter()
    sim = Simulation(sc)
    setup_s = time.perf_counter() - t
    q0 = sim.state.body_q.copy()
    step_s, per_step = [], []  # per step: seconds; (sweeps, contacts) (the run keeps only their totals)
    def timed(step=sim.step, clock=time.perf_counter, out=step_s, counts=per_step):
        t = clock()
        stats = step()
        out.append(clock() - t)
        counts.append((stats.iterations, stats.contact_count))
        return stats
    sim.step = timed
    t = time.perf_counter()
    res = simulate(sc, sim=sim)
    runs.append(time.perf_counter() - t)
    results.append((res, np.array(per_step, dtype=np.int64).reshape(-1, 2)))
    sims.append((sim, q0, setup_s, np.array(step_s)))
    print(f"ours run {len(runs)}/{REPEAT}: {runs[-1]:.2f} s", file=sys.stderr, flush=True)
(res, counts), (sim, q0, setup_s, step_s) = results[0], sims[0]
names = [b.name for b in sc.assembly.blocks]
courses = [int(n.split("-")[0][1:]) for n in names]
dx = sim.state.body_q[:, 0] - q0[:, 0]
n = len(names)
top, bottom = max(courses), min(courses)
it, nc = counts[:, 0], counts[:, 1]
wall = statistics.median(runs)
print(json.dumps({
    "status": res.status,
    "wall_per_sim_s": wall / DURATION,
    "runs_s": [round(r, 3) for r in runs],
    "setup_s": round(setup_s, 3),
    "compile_or_cache_s": round(compile_s, 3),
    "iterations_per_step": float(it.mean()),
    "iterations_per_step_median": float(np.median(it)),
    "iterations_max": int(it.max()),
    "sweeps_per_step": float(it.mean()),
    "steps_at_cap": int((it >= 1000).sum()),
    "contacts_per_step": float(nc.mean()),
    "us_per_step": 1e6 * wall / res.steps,
    "us_per_contact_iteration": 1e6 * wall / max(int((it * nc).sum()), 1),
    "step_s": step_s.tolist(),
    "iterations": it.tolist(),
    "contacts": nc.tolist(),
    "dx_top_course_m": float(np.mean([d for d, c in zip(dx[:n], courses) if c == top])),
    "dx_bottom_course_m": float(np.mean([d for d, c in zip(dx[:n], courses) if c == bottom])),
    "dx_ground_m": float(dx[n]),
    "iterations_identical_across_runs": all(np.array_equal(c[:, 0], it) for _, c in results),
    "steps": res.steps,
    "settings": {"norm": "relative quadratic norm of the impulse change, every sweep", "tol": 1.666e-4,
                 "relax": 1.0, "max_iterations": 1000},
}))
"""


def bench_ours(python: str, repeat: int, duration: float) -> dict:
    consts = dict(
        ROOT=str(ROOT),
        AMPLITUDE=AMPLITUDE,
        FREQUENCY=FREQUENCY,
        DURATION=duration,
        DT=DT,
        THETA=THETA,
        ALERT=ALERT,
        RHO=RHO,
        DEPTH=DEPTH,
        MU=MU,
        BLOCKS=BLOCKS,
        REPEAT=repeat,
    )
    code = "".join(f"{k} = {v!r}\n" for k, v in consts.items()) + OURS
    env = dict(os.environ, RERUN_ANALYTICS="0")
    proc = subprocess.run([python, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env)
    sys.stderr.write(proc.stderr)
    if proc.returncode != 0:
        return {"error": f"{python} exited {proc.returncode}", "stderr_tail": proc.stderr[-2000:]}
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    step_s = out.pop("step_s")  # per-step times, iterations and contacts of the first run: for the fit
    out.update(split_step_time(step_s, out.pop("iterations"), out.pop("contacts")))
    return out


# --------------------------------------------------------------------------------------------------


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--configs", default="shipped,matched,matched-check10")
    ap.add_argument("--ours-python", default="/work/venv/bin/python")
    ap.add_argument("--skip-ours", action="store_true")
    args = ap.parse_args(argv)
    configs = [c for c in args.configs.split(",") if c]
    unknown = [c for c in configs if c not in CONFIGS]
    if unknown:
        ap.error(f"unknown config(s) {unknown}; known: {list(CONFIGS)}")

    import compas_lmgc90
    import numpy

    ours = None if args.skip_ours else bench_ours(args.ours_python, args.repeat, args.duration)
    lmgc, lib = bench_lmgc(configs, args.repeat, args.duration)

    ratios = {}
    if ours and "wall_per_sim_s" in ours:
        for name, r in lmgc.items():
            if "wall_per_sim_s" not in r:
                continue
            ratios[name] = {
                "lmgc90_over_ours_wall": r["wall_per_sim_s"] / ours["wall_per_sim_s"],
                "lmgc90_over_ours_per_contact_iteration": r["us_per_contact_iteration"]
                / ours["us_per_contact_iteration"],
                "lmgc90_over_ours_ns_per_contact_sweep_fit": r["fit_ns_per_contact_sweep"]
                / ours["fit_ns_per_contact_sweep"],
                "lmgc90_over_ours_us_per_step_outside_nlgs_fit": r["fit_us_per_step_outside_nlgs"]
                / ours["fit_us_per_step_outside_nlgs"],
                "lmgc90_over_ours_contacts": r["contacts_per_step"] / ours["contacts_per_step"],
                "lmgc90_over_ours_iterations": r["iterations_per_step"] / ours["iterations_per_step"],
            }
    doc = {
        "scenario": {
            "structure": f"running-bond wall, {BLOCKS} blocks 0.30 x 0.20 m (build_wall(blocks={BLOCKS}))",
            "ground": f"v_x = {AMPLITUDE} sin(2 pi {FREQUENCY} t) m/s",
            "friction": MU,
            "density": RHO,
            "dt": DT,
            "theta": THETA,
            "duration_s": args.duration,
            "alert_m": ALERT,
            "repeat": args.repeat,
            "dimension": "LMGC90 3-D (RBDY3/POLYR prisms, depth 1.0 m) vs ours 2-D (thickness 1.0 m)",
        },
        "machine": {
            "python": platform.python_version(),
            "cpu_count": os.cpu_count(),
            "processor": platform.machine(),
            "loadavg_at_end": list(os.getloadavg()),
        },
        "versions": {
            "compas_lmgc90": compas_lmgc90.__version__,
            "numpy": numpy.__version__,
            "lmgc90_so_sha256": lib.sha256,
            "settings_patchable": lib.patchable,
            "why_not_patchable": lib.why_not,
        },
        "ours": ours,
        "lmgc90": lmgc,
        "ratios": ratios,
    }
    print(json.dumps(doc, indent=2))


if __name__ == "__main__":
    main()
