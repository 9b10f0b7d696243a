"""LMGC90 vs our engine on the paper's 98-block arch or 346-block aqueduct (right foundation settling).

Joint for joint. Three commands, each writing or reading JSON (findings: benchmarks/LMGC90.md, "The arch,
joint for joint" and "The aqueduct, joint for joint")::

    /work/lmgc-venv/bin/python benchmarks/lmgc90_arch.py run lmgc90 --out arch-lmgc90.json
    PYTHONPATH=. .venv/bin/python benchmarks/lmgc90_arch.py run ours --out arch-ours.json
    python benchmarks/lmgc90_arch.py compare arch-lmgc90.json arch-ours.json   # either interpreter

``run`` options: ``--structure arch|aqueduct`` (default arch), ``--times 0.5,1,2,3,5`` (s: snapshots, the
last one is the duration), ``--settlement 0.01`` (m/s downwards, right foundation; 0 for the structure
standing under gravity alone), ``--tolerance`` (ours: m/s, default the scenario's 1e-5; LMGC90: the tol of
its norm, default the config's), ``--cap`` (LMGC90: at most this many NLGS sweeps a step), ``--mu 0.6``
(both codes' friction coefficient), ``--config matched`` (LMGC90's NLGS settings, see
lmgc90_binding.CONFIGS). The findings' ``tight`` LMGC90 run is ``--tolerance 1e-6 --cap 20000``.

* The arch is ``geometry_library.builders.build_arch()`` (98 blocks on two piers, two foundation
  supports), what ``masonry simulate arch`` runs; the aqueduct ``build_aqueduct()`` (the arch and 248
  spandrel wall blocks), what ``masonry simulate aqueduct`` runs. LMGC90 (compas_lmgc90 0.1.11: 3-D only, RBDY3/POLYR,
  PRPRx) gets every block and support extruded to a 1.0 m deep prism (lmgc90_reference.prism), ρ = 2500,
  IQS_CLB μ = 0.6, alert 1e-3 m, dt = 1e-3 s, θ = 0.5, gravity −9.81 (hard-wired); the left foundation is
  fixed on its 6 dofs, the right one driven at Vz = −settlement, its 5 other dofs fixed. Ours:
  ``builtin(structure, settlement=...)`` with the same dt, θ, μ, ρ, alert, thickness 1 m.
* A snapshot per time holds every body's 2-D pose (x, y, θ; LMGC90's x, z and its rotation in the x–z
  plane, plus its largest out-of-plane displacement and tilt) and every contact's bodies, in-plane point
  and normal force (N). ``compare`` (``joints_compare``) reduces both to the measures of ``arch_joints``
  (joint openings, hinges, sliding, per-joint resultants) over the joints of the initial polygons and
  prints a Markdown report. Its keys of the arch's first comparison are unchanged (the saved arch
  comparisons are reproduced bit for bit).
* Cost: CPU seconds of the stepping loop (``time.process_time``). Ours excludes the first step but not a
  kernel numba compiles lazily later (0.4 CPU s for 5 s with a warm cache, 4 s on a cold one).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

# siblings: this script's folder is first on sys.path when it runs
from joints_compare import compare, report  # noqa: E402
from lmgc90_reference import ALERT, DEPTH, DT, MU, RHO, THETA, log, prism  # noqa: E402

STRUCTURES = ("arch", "aqueduct")


def structure_bodies(structure: str = "arch"):
    """(names, (V, 2) vertex arrays of the blocks then the supports, block count N) of the default
    ``structure`` ("arch": build_arch(), "aqueduct": build_aqueduct())."""
    from geometry_library.builders import build_aqueduct, build_arch

    assembly = {"arch": build_arch, "aqueduct": build_aqueduct}[structure]()
    bodies = [*assembly.blocks, *assembly.supports]
    return [b.name for b in bodies], [b.vertices for b in bodies], len(assembly.blocks)


def steps_of(times):
    return [max(1, round(t / DT)) for t in times]


# --------------------------------------------------------------------------------------------------
# LMGC90 (run with the reference venv's interpreter)


def run_lmgc(
    times,
    settlement: float,
    config_name: str,
    tol: float | None = None,
    cap: int | None = None,
    structure="arch",
    mu: float = MU,
) -> dict:
    import numpy as np
    from compas_lmgc90.solver import Solver
    from lmgc90_binding import CONFIGS, Lmgc

    lmgc = Lmgc()
    names, polys, n = structure_bodies(structure)
    solver = Solver(dt=DT, theta=THETA, density=RHO)
    solver.geometry_from_v_f([prism(p) for p in polys])
    left, right = names.index("left-foundation"), names.index("right-foundation")
    for g in (left, right):
        solver.v_drvdof[g] = {i: np.zeros((1, 6)) for i in range(1, 7)}
    # V(t) = [v0 + v1 cos(v2 t + v3)] · min(1, v4 + v5 t) = −settlement
    solver.apply_velocity(right, "Vz", np.array([[-settlement, 0.0, 0.0, 0.0, 1.0, 0.0]]))
    solver.contact_law("IQS_CLB", mu, alert=ALERT)
    solver.preprocess()
    config = dict(CONFIGS[config_name])
    if tol is not None:
        config["tol"] = tol
    if cap is not None:  # at most ``cap`` sweeps: gs_it2 convergence checks every gs_it1 sweeps
        config["gs_it2"] = max(1, cap // config["gs_it1"])
    lmgc.write_settings(config)
    c0, f0 = lmgc.poses()
    step, nb_inters = lmgc.lib.lmgc90_compute_one_step, lmgc.lib.lmgc90_get_nb_inters
    snaps, iterations, contacts = [], [], []
    wanted = steps_of(times)
    cpu0 = time.process_time()
    for k in range(1, max(wanted) + 1):
        step()
        iterations.append(lmgc.nlgs_loop()[0])
        contacts.append(nb_inters())
        if k in wanted:
            snaps.append(lmgc_snapshot(lmgc, k, c0, f0))
            log(f"lmgc90 t = {k * DT:g} s: {time.process_time() - cpu0:.1f} CPU s")
    cpu = time.process_time() - cpu0
    solver.finalize()
    cap = config["gs_it1"] * config["gs_it2"]
    return {
        "code": "lmgc90",
        "config": config_name,
        "settings": lmgc.read_settings(),
        "cpu_s": cpu,
        "iterations_mean": float(np.mean(iterations)),
        "steps_at_cap": int(np.sum(np.array(iterations) >= cap)),
        "contacts_mean": float(np.mean(contacts)),
        "q0": np.column_stack([c0[:, 0], c0[:, 2], np.zeros(len(c0))]).tolist(),
        "snapshots": snaps,
    }


def lmgc_snapshot(lmgc, k, c0, f0) -> dict:
    import numpy as np

    c, f = lmgc.poses()
    rot = np.einsum("bji,bjk->bik", f, f0)  # F(t)ᵀ F(0): initial arm → current arm
    theta = np.arctan2(rot[:, 2, 0], rot[:, 0, 0])  # in the x–z plane, z up (our y)
    q = np.column_stack([c[:, 0], c[:, 2], theta])
    inters = lmgc.inters()
    nb = len(c)
    ids = np.array([[it.icdbdy, it.ianbdy] for it in inters], dtype=np.int64).reshape(-1, 2)
    assert ids.size == 0 or (ids.min() >= 1 and ids.max() <= nb), "LMGC90 body numbers are 1-based"
    return {
        "step": k,
        "t": k * DT,
        "q": q.tolist(),
        "out_of_plane_m": float(np.abs(c[:, 1] - c0[:, 1]).max()),
        "tilt_rad": float(np.arccos(np.clip(rot[:, 1, 1], -1.0, 1.0)).max()),
        "contact_body": (ids - 1).tolist(),
        "contact_point": [[it.coor[0], it.coor[2]] for it in inters],
        # rloc = (t, n, s) in N already: Σ r_n over the foundations' contacts is the arch's weight
        # (202.97 kN at 0.05 s against 203.25 kN)
        "contact_fn": [it.rloc[1] for it in inters],
        "contact_status": [it.status.decode(errors="replace").strip() for it in inters],
    }


# --------------------------------------------------------------------------------------------------
# ours (run with the project venv's interpreter)


def run_ours(times, settlement: float, tolerance: float | None, structure: str = "arch", mu: float = MU) -> dict:
    import numpy as np

    from masonrycli.run import Simulation
    from masonrycli.scenario.builtin import builtin

    wanted = steps_of(times)
    extra = {} if tolerance is None else {"tolerance": tolerance}
    sc = builtin(structure, settlement=settlement, duration=max(wanted) * DT, friction=mu, **extra)
    run, mat = sc.run, sc.material
    assert (run.dt, run.theta, run.alert_distance, mat.friction, mat.density, mat.thickness) == (
        DT,
        THETA,
        ALERT,
        mu,
        RHO,
        DEPTH,
    ), f"the {structure} scenario's defaults are not the LMGC90 run's"
    sim = Simulation(sc)
    q0 = sim.state.body_q.tolist()
    sim.step()  # numba compile / cache load: this first step is timed apart
    snaps, iterations = [], []
    cpu0 = time.process_time()
    for k in range(1, max(wanted) + 1):
        if k > 1:
            iterations.append(sim.step().iterations)
        if k in wanted:
            s, c = sim.solver, sim.last.contact_count
            fn = np.einsum("ci,ci->c", s.contact_force[:c], s.contact_normal[:c])
            snaps.append(
                {
                    "step": k,
                    "t": k * DT,
                    "q": sim.state.body_q.tolist(),
                    "contact_body": s.contact_body[:c].tolist(),
                    "contact_point": s.contact_point[:c].tolist(),
                    "contact_fn": fn.tolist(),
                }
            )
    cpu = time.process_time() - cpu0
    return {
        "code": "ours",
        "tolerance": sc.run.tolerance,
        "solver": sc.run.solver,
        "cpu_s_after_first_step": cpu,
        "iterations_mean": float(np.mean(iterations)) if iterations else 0.0,
        "unconverged_steps": sim.unconverged,
        "q0": q0,
        "snapshots": snaps,
    }


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run")
    r.add_argument("engine", choices=("lmgc90", "ours"))
    r.add_argument("--structure", choices=STRUCTURES, default="arch")
    r.add_argument("--times", default="0.5,1,2,3,5")
    r.add_argument("--settlement", type=float, default=0.01)
    r.add_argument("--tolerance", type=float, default=None, help="m/s, ours; LMGC90: its 'Quad ' norm's tol")
    r.add_argument("--cap", type=int, default=None, help="LMGC90: at most this many NLGS sweeps per step")
    r.add_argument("--config", default="matched")
    r.add_argument("--mu", type=float, default=MU, help="Coulomb friction coefficient of every joint (both codes)")
    r.add_argument("--out", required=True)
    c = sub.add_parser("compare")
    c.add_argument("reference")
    c.add_argument("other")
    c.add_argument("--json", default=None, help="also write the full comparison here")
    args = ap.parse_args(argv)
    if args.command == "compare":
        docs = [json.loads(Path(p).read_text()) for p in (args.reference, args.other)]
        structures = [d.get("structure", "arch") for d in docs]
        assert structures[0] == structures[1], f"the two runs are of different structures: {structures}"
        cmp = compare(*docs, *structure_bodies(docs[0].get("structure", "arch")))
        if args.json:
            Path(args.json).write_text(json.dumps(cmp, separators=(",", ":")) + "\n")
        print(report(cmp, tuple(d["code"] for d in docs)))
        return
    times = sorted(float(t) for t in args.times.split(",") if t)
    if args.engine == "lmgc90":
        doc = run_lmgc(times, args.settlement, args.config, args.tolerance, args.cap, args.structure, args.mu)
    else:
        doc = run_ours(times, args.settlement, args.tolerance, args.structure, args.mu)
    doc.update(
        structure=args.structure,
        settlement=args.settlement,
        times=times,
        dt=DT,
        theta=THETA,
        mu=args.mu,
        rho=RHO,
        alert=ALERT,
    )
    Path(args.out).write_text(json.dumps(doc))
    log(f"{args.engine}: {doc.get('cpu_s', doc.get('cpu_s_after_first_step')):.1f} CPU s, wrote {args.out}")


if __name__ == "__main__":
    main()
