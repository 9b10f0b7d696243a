"""LMGC90's NLGS iterations per step against the wall's height, beside ours, on the walls h8 … h64.

Standalone script, run with the *reference* venv's interpreter (never imported by the tests, never a
dependency of the project; install: benchmarks/LMGC90.md)::

    /work/lmgc-venv/bin/python benchmarks/lmgc90_height.py --walls h8:1.0,h16:1.0,h32:0.4,h64:0.3 \
        --ours-python /work/main/.venv/bin/python --out height.json

Issue 10 asks our solver's sweeps per step to grow at most 4× from a wall of 8 courses to one of 64; ours
grow ~35×. This script measures the reference code's own growth on the same walls and motion.

* Walls: the height series of the solver lab (benchmarks/solver_cases.py: ``h8``, ``h16``, ``h32``,
  ``h64``, 8–64 courses of a 4.5 m running-bond wall, blocks 0.30 × 0.20 m), each block extruded to a
  1.0 m deep prism for LMGC90 (lmgc90_reference.prism; LMGC90 through compas_lmgc90 is 3-D only), the
  ground a driven prism at v_x = 1 m/s · sin(2π · 2 Hz · t); ρ 2500, μ 0.6, dt 1e-3, θ 0.5, alert 1e-3 m.
  ``--walls`` gives each wall's simulated duration (``name:seconds``).
* LMGC90: nlgs_3D with the ``matched-check1`` settings of lmgc90_binding (norm 'Quad ', relax 1.0,
  convergence checked after every iteration, so the counter is exact) but the cap raised to ``--cap``
  iterations (default 20 000) and the tolerance ``--tol`` (default 1.666e-4, LMGC90's relative norm;
  ``--tol`` 1e-5 for a tighter run). Per step: LMGC90's iteration counter (``get_nlgs3D_loop``; each
  convergence check adds one more sweep that the counter does not count), contacts
  (``lmgc90_get_nb_inters``), whether the cap was reached; CPU time of the stepping loop.
* Ours (``--ours-python``, the project venv, in a subprocess): the default solver and ``--solver nlgs``
  (``--solvers``) on ``solver_cases.make_scenario(wall, duration)``, default settings (tolerance 1e-5 m/s
  RMS contact-law violation, cap 100 000); per step the solver's sweep units (``StepStats.iterations``,
  what bench_solver and the solver lab count), contacts, converged or not.
* Both: top-course slip at the end (mean x displacement of the top course relative to the ground's) as a
  check that the two codes solve the same problem; summaries over the whole run and over the first
  ``--window`` seconds (default 0.3), so that walls run for different durations are compared like with like.

``--budget`` (or a third field of ``--walls``, ``h64:0.3:1400``) caps the CPU seconds of each LMGC90 wall run: past it the run stops after the current step and
our engine runs over the same steps. ``--codes lmgc,ours`` chooses what runs; one JSON document goes to stdout (and to ``--out``, per-step
arrays included), progress to stderr. Figures: benchmarks/LMGC90.md, "Height series".
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

from lmgc90_binding import CONFIGS, Lmgc
from lmgc90_reference import ALERT, AMPLITUDE, DT, FREQUENCY, MU, RHO, THETA, prism

ROOT = Path(__file__).resolve().parent.parent
WALL_LENGTH = 4.5  # as benchmarks/solver_cases.py (checked against it in the ours subprocess)


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def height_prisms(courses: int):
    """The blocks and ground of the lab's wall of ``courses`` courses as prisms; the course of each block."""
    sys.path.insert(0, str(ROOT))
    import numpy as np

    from geometry_library.builders import build_wall

    assembly = build_wall(blocks=None, courses=courses, length=WALL_LENGTH)
    bodies = [*assembly.blocks, *assembly.supports]
    prisms = [prism(np.asarray(b.polygon.exterior.coords)[:-1]) for b in bodies]
    return prisms, [int(b.name.split("-")[0][1:]) for b in assembly.blocks]


def summary(iterations, capped, window_steps: int | None = None, unconverged=None) -> dict:
    """Mean, median, max of the per-step counts (over the first ``window_steps`` steps if given)."""
    import numpy as np

    it = np.asarray(iterations)[:window_steps]
    out = {
        "steps": len(it),
        "mean": float(it.mean()),
        "median": float(np.median(it)),
        "p90": float(np.percentile(it, 90)),
        "max": int(it.max()),
        "capped": int(np.asarray(capped)[:window_steps].sum()),
    }
    if unconverged is not None:
        out["unconverged"] = int(np.asarray(unconverged)[:window_steps].sum())
    return out


def run_lmgc(lmgc: Lmgc, courses: int, duration: float, config: dict, budget: float) -> dict:
    """LMGC90 on the wall of ``courses`` courses for ``duration`` s, or fewer steps: it stops after the step
    that takes its stepping loop past ``budget`` CPU seconds."""
    import numpy as np
    from compas_lmgc90.solver import Solver

    prisms, course = height_prisms(courses)
    t = time.process_time()
    solver = Solver(dt=DT, theta=THETA, density=RHO)
    solver.geometry_from_v_f(prisms)
    g = len(prisms) - 1
    solver.v_drvdof[g] = {i: np.zeros(6) for i in range(1, 7)}
    w = 2 * np.pi * FREQUENCY
    solver.apply_velocity(g, "Vx", np.array([[0.0, AMPLITUDE, w, -np.pi / 2, 1.0, 0.0]]))
    solver.contact_law("IQS_CLB", MU, alert=ALERT)
    solver.preprocess()
    lmgc.write_settings(config)
    settings = lmgc.read_settings()
    q0 = lmgc.bodies()
    setup_cpu = time.process_time() - t

    n = max(1, round(duration / DT))
    iterations = np.zeros(n, dtype=np.int64)
    contacts = np.zeros(n, dtype=np.int64)
    step, nb_inters = lmgc.lib.lmgc90_compute_one_step, lmgc.lib.lmgc90_get_nb_inters
    t = time.process_time()
    for k in range(n):
        step()
        iterations[k] = lmgc.nlgs_loop()[0]
        contacts[k] = nb_inters()
        if (k + 1) % 50 == 0:
            log(f"  lmgc90 step {k + 1}/{n}: {time.process_time() - t:.0f} s CPU, it {iterations[k]}, c {contacts[k]}")
        if time.process_time() - t > budget:
            iterations, contacts = iterations[: k + 1], contacts[: k + 1]
            break
    cpu = time.process_time() - t
    q1 = lmgc.bodies()
    solver.finalize()
    dx = np.array([q1[i][0] - q0[i][0] for i in range(len(q0))])
    course = np.array(course)
    cap = config["gs_it1"] * config["gs_it2"]
    return {
        "blocks": len(course),
        "cpu_s": cpu,
        "setup_cpu_s": setup_cpu,
        "duration_s": round(len(iterations) * DT, 6),
        "stopped_by_budget": len(iterations) < n,
        "iterations": iterations.tolist(),
        "contacts": contacts.tolist(),
        "capped": (iterations >= cap).tolist(),
        "cap": cap,
        "top_slip_m": float(dx[: len(course)][course == course.max()].mean() - dx[-1]),
        "settings": settings,
    }


OURS = r"""
import json, sys, time
sys.path.insert(0, ROOT)
import numpy as np
from benchmarks.solver_cases import CASES, WALL_LENGTH, course_of, make_scenario, slips
from masonrycli.run import Simulation, simulate

assert CASES[CASE][1] == {"blocks": None, "courses": COURSES, "length": WALL_LENGTH} and WALL_LENGTH == LENGTH
simulate(make_scenario(CASE, 0.01, solver=SOLVER), steps=2)  # numba compile / cache load, excluded
sc = make_scenario(CASE, DURATION, solver=SOLVER)
sim = Simulation(sc)
m = sim.model
n = m.block_count
q0, g0 = m.body_q0[:n, 0].copy(), m.body_q0[n, 0]
per_step = []
def counted(step=sim.step, out=per_step):
    stats = step()
    out.append((stats.iterations, stats.contact_count, int(not stats.converged)))
    return stats
sim.step = counted
t = time.process_time()
res = simulate(sc, sim=sim)
cpu = time.process_time() - t
a = np.array(per_step, dtype=np.int64).reshape(-1, 3)
q = sim.state.body_q
top, _ = slips(q0, q[:n, 0], float(q[n, 0] - g0), course_of(m.block_name))
print(json.dumps({"status": res.status, "blocks": n, "cpu_s": cpu, "iterations": a[:, 0].tolist(),
                  "contacts": a[:, 1].tolist(), "unconverged": a[:, 2].tolist(), "top_slip_m": top,
                  "settings": {"solver": SOLVER, "tolerance": sc.run.tolerance,
                               "max_iterations": sc.run.max_iterations}}))
"""


def run_ours(python: str, case: str, courses: int, duration: float, solver: str) -> dict:
    consts = dict(ROOT=str(ROOT), CASE=case, COURSES=courses, LENGTH=WALL_LENGTH, DURATION=duration, SOLVER=solver)
    code = "".join(f"{k} = {v!r}\n" for k, v in consts.items()) + OURS
    env = dict(os.environ, RERUN_ANALYTICS="0")
    proc = subprocess.run([python, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env)
    if proc.returncode != 0:
        return {"error": f"{python} exited {proc.returncode}", "stderr_tail": proc.stderr[-2000:]}
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    out["capped"] = [int(i >= out["settings"]["max_iterations"]) for i in out["iterations"]]
    return out


def summarise(run: dict, window_s: float) -> dict:
    w = round(window_s / DT)
    unconv = run.get("unconverged")
    return {
        "whole": summary(run["iterations"], run["capped"], None, unconv),
        f"first_{window_s:g}_s": summary(run["iterations"], run["capped"], w, unconv),
        "contacts_mean": sum(run["contacts"]) / len(run["contacts"]),
        "top_slip_m": run["top_slip_m"],
        "cpu_s": run["cpu_s"],
        "blocks": run["blocks"],
    }


def growth(doc: dict, window_s: float) -> dict:
    """Per code and wall, the summary over the common prefix (the first ``window_s`` seconds, or fewer steps
    if a run stopped earlier), and the ratio of each taller wall's mean and median to the shortest wall's."""
    runs = [r for walls in doc["results"].values() for r in walls.values() if "iterations" in r]
    common = min([round(window_s / DT), *(len(r["iterations"]) for r in runs)])
    out = {"common_steps": common}
    for code, walls in doc["results"].items():
        rows = {
            w: summary(r["iterations"], r["capped"], common, r.get("unconverged"))
            for w, r in walls.items()
            if "iterations" in r
        }
        if not rows:
            continue
        base = next(iter(rows.values()))
        out[code] = {
            w: row
            | {"mean_over_first": row["mean"] / base["mean"], "median_over_first": row["median"] / base["median"]}
            for w, row in rows.items()
        }
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "--walls",
        default="h8:1.0,h16:1.0,h32:0.4,h64:0.3",
        help="name:duration[:budget], … (h8 h16 h32 h64; budget: CPU s, default --budget)",
    )
    ap.add_argument("--codes", default="lmgc,ours")
    ap.add_argument("--budget", type=float, default=1e9, help="CPU s: LMGC90 stops a wall's run past it")
    ap.add_argument("--cap", type=int, default=20000, help="LMGC90's iteration cap per step")
    ap.add_argument("--tol", type=float, default=1.666e-4, help="LMGC90's tolerance (relative 'Quad ' norm)")
    ap.add_argument("--solvers", default="nlgs-accel32,nlgs", help="ours: solvers to run")
    ap.add_argument("--window", type=float, default=0.3, help="s: common window of the summaries")
    ap.add_argument("--ours-python", default="/work/main/.venv/bin/python")
    ap.add_argument("--out", type=Path)
    args = ap.parse_args(argv)
    walls = []
    for item in args.walls.split(","):
        name, dur, *budget = item.split(":")
        if name not in ("h8", "h16", "h32", "h64") or not dur or len(budget) > 1:
            ap.error(f"--walls: {item!r} is not hN:seconds[:budget] with N in 8, 16, 32, 64")
        walls.append((name, int(name[1:]), float(dur), float(budget[0]) if budget else args.budget))
    codes = args.codes.split(",")
    config = dict(CONFIGS["matched-check1"], tol=args.tol, gs_it2=args.cap)

    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=ROOT)
    doc = {
        "started_utc": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "commit": commit.stdout.strip(),
        "argv": sys.argv,
        "motion": f"ground v_x = {AMPLITUDE} sin(2 pi {FREQUENCY} t) m/s; dt {DT}, theta {THETA}, mu {MU}",
        "machine": {"python": platform.python_version(), "cpu_count": os.cpu_count()},
        "results": {},
    }
    lmgc = None
    if "lmgc" in codes:
        lmgc = Lmgc()
        if not lmgc.patchable:
            sys.exit(f"LMGC90's settings cannot be patched: {lmgc.why_not}")
        doc["results"]["lmgc90"] = {}
    for name, courses, duration, budget in walls:
        if "lmgc" in codes:
            log(f"lmgc90 {name}, {duration} s, tol {args.tol:g}, cap {args.cap}, budget {budget:g} s")
            run = run_lmgc(lmgc, courses, duration, config, budget)
            duration = run["duration_s"]  # ours over the same steps
            run["summary"] = summarise(run, args.window)
            doc["results"]["lmgc90"][name] = run
            s = run["summary"]
            log(f"lmgc90 {name}: {s['whole']} contacts {s['contacts_mean']:.0f} cpu {run['cpu_s']:.0f} s")
        if "ours" in codes:
            for solver in args.solvers.split(","):
                log(f"ours {solver} {name}, {duration} s")
                run = run_ours(args.ours_python, name, courses, duration, solver)
                if "error" not in run:
                    run["summary"] = summarise(run, args.window)
                    log(f"ours {solver} {name}: {run['summary']['whole']} cpu {run['cpu_s']:.0f} s")
                else:
                    log(f"ours {solver} {name}: {run['error']}\n{run['stderr_tail']}")
                doc["results"].setdefault(f"ours {solver}", {})[name] = run
        if args.out:  # after each wall: a late failure keeps the walls done
            args.out.write_text(json.dumps(doc) + "\n")
    doc["growth"] = growth(doc, args.window)
    doc["loadavg_at_end"] = list(os.getloadavg())
    if args.out:
        args.out.write_text(json.dumps(doc) + "\n")
    slim = {k: v for k, v in doc.items() if k != "results"}
    slim["results"] = {
        code: {w: r.get("summary", r) | {"settings": r.get("settings")} for w, r in walls_.items()}
        for code, walls_ in doc["results"].items()
    }
    print(json.dumps(slim, indent=1))


if __name__ == "__main__":
    main()
