"""Hard steps: capture the steps that cost the engine most in ensemble runs, and replay rule variants on them.

    python -m benchmarks.solver_lab hard capture [--cases h32 h64] [--copy 0] [--min-units 1000]
                                                 [--motions A,F …] [--duration S] [--dir DIR] [--set FIELD=V+…]
    python -m benchmarks.solver_lab hard replay --variants main ns-… [--min-units 2500] [--out FILE.json] [--dir DIR]
    python -m benchmarks.solver_lab hard table FILE.json [FILE.json …]
    python -m benchmarks.solver_lab hard stages [--dir DIR] [--min-units 400] --out FILE.json

A whole run is chaotic (an amplitude changed by 1e-6 gives another trajectory, ensemble.py), so a change of
the stalled-step rules cannot be judged on one run; replaying the same captured steps through ``dispatch.solve``
is deterministic. ``capture`` runs each case under the ensemble's motions (ensemble.MOTIONS, copy ``--copy``,
ensemble.DURATION) with the engine as it is, and keeps the input dispatch.solve got at every step that took
``--min-units`` sweep units or more (body pairs, packed rows, v_free, warm start r, status, μ, tolerance,
cap) in ``data/hard/<case>-a<A>-f<F>-c<copy>-<step>.npz``, with the units and residual the engine spent on it
(``index-<case>-c<copy>.json``). The per-step units of the run are printed beside the run's total so that they can be
checked against an ensemble file of the same engine (the same motion and copy give the same units).
``--dir`` captures into (and replays from) another directory than ``data/hard``: a set per engine, since a
capture describes the engine that ran it (``data/hard`` is that of 88c12c6 for h32 / h64). ``--set`` runs the
capture with the engine's Tuning changed as a replay variant's (``FIELD=VALUE[+…]``, kept in the index as
``override``): the steps of a variant's trajectory, which leaves main's at its first changed step.

``replay`` solves each kept step with ``--min-units`` or more by dispatch.solve from its warm start, once per
variant: a variant is a set of fields of the engine's Tuning (engine/tuning.py) changed for the replay
(VARIANTS below; the old module-constant names of LEGACY still accepted), handed to dispatch.solve. Per step: units, converged, and the method that finished it
(the last one stalled.py resumed; "momentum0" for momentum's own first solve, "bodies" for stalled.py's
body-order stage ahead of its round-robin). ``table`` prints, per
variant: total units, steps converged, steps above 10 000 units, ratio to the first file's total, and
which method finished how many steps. ``stages`` splits each kept step's units by stage of the chain
(momentum's first stage until its stall window, the body-order stage's calls, each resume of the round-robin)
with the residual history of momentum (the first stage re-run with caps 1, 2, … its sweeps: it keeps no
history) and of the stage (``bodies.body_order_sweeps``' history), the sweep at which each first came within
2× the tolerance, and its lowest residual: where a dear step spends its units, and whether in a tail.
"""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from benchmarks.solver_lab.problems import DATA
from masonrycli.engine import bodies, dispatch, stalled
from masonrycli.engine.tuning import TUNING, Tuning

HARD = DATA / "hard"
BIG = 10_000
"""Units above which a step counts as one of the costliest (the distribution's tail in the table)."""

VARIANTS: dict[str, dict[str, object]] = {
    "main": {},
    "stall300": {"first_stall": 300},
    "stall200": {"first_stall": 200},
    "stall1000": {"first_stall": 1000},
    "shares.1-.3": {"newton_shares": (0.1, 0.3)},
    "shares.25-.3": {"newton_shares": (0.25, 0.3)},
    "shares.15-.5": {"newton_shares": (0.15, 0.5)},
    "shares.15-.15": {"newton_shares": (0.15, 0.15)},
    "nlast0": {"newton_last_round": 0},
    "nlast2": {"newton_last_round": 2},
    "nbudget1": {"newton_budget": 1},
    "nbudget3": {"newton_budget": 3},
    "first1000": {"first_budget": 1000},
    "first4000": {"first_budget": 4000},
    "order-tfam": {"methods": ("newton", "turning", "faces", "alternating", "momentum")},
    "order-tn": {"methods": ("turning", "newton", "alternating", "momentum", "faces")},
    "no-momentum": {"methods": ("newton", "turning", "alternating", "faces")},
    "ahead1": {"newton_ahead": 1},
    "ahead1-nlast2": {"newton_ahead": 1, "newton_last_round": 2},
    "ahead2-nlast2": {"newton_ahead": 2, "newton_last_round": 2},
    "first1000-nb4": {"first_budget": 1000, "newton_budget": 4},
    "first500-nb8": {"first_budget": 500, "newton_budget": 8},
    "no-alternating": {"methods": ("newton", "turning", "momentum", "faces")},
}
"""Named replay variants: fields of the engine's Tuning and their values (the λ and polish-window variants of
"Hard steps" set newton.py module constants, which nothing sets any more: not replayable by name)."""

LEGACY = {
    "momentum.STALL_SWEEPS": "first_stall",
    "nlgs.LANES": "lanes",
    "newton.NEWTON_SHARES": "newton_shares",
    **{f"stalled.{f.upper()}": f for f in (
        "bodies_units", "bodies_stall", "bodies_window", "bodies_level", "bodies_cycling", "bodies_far",
        "bodies_strong", "bodies_cycling_far", "bodies_reenter", "first_budget", "methods", "newton_budget",
        "newton_last_round", "newton_ahead",
    )},
}  # fmt: skip
"""The module constants the JOURNAL's commands set (``--set momentum.STALL_SWEEPS=200``), by the Tuning field that
replaced each: those commands still run."""


def _key(case: str, motion, copy: int, step: int) -> str:
    return f"{case}-a{motion[0]:g}-f{motion[1]:g}-c{copy}-{step}"


def capture(
    cases: list[str],
    copy: int,
    min_units: int,
    motions=None,
    duration: float | None = None,
    directory=None,
    override: str | None = None,
    solver: str = "nlgs-accel",
) -> None:
    """Run ``cases`` under the ensemble's motions; keep the steps of ``min_units`` or more (module doc), with
    the Tuning fields of ``override`` (``FIELD=VALUE[+…]``) changed for the capture, by ``solver`` (kept with each
    step: its replay runs the same path)."""
    directory = directory or HARD  # read at the call: tests point HARD elsewhere
    directory.mkdir(parents=True, exist_ok=True)
    tuning = tuning_of(_parse(override)) if override else TUNING
    _capture_cases(cases, copy, min_units, motions, duration, directory, override, solver, tuning)


def _capture_cases(cases, copy, min_units, motions, duration, directory, override, solver, tuning) -> None:
    from benchmarks.solver_lab import ensemble

    for case in cases:
        index_path = directory / f"index-{case}-c{copy}.json"  # one a capture process: cases run in parallel
        index = json.loads(index_path.read_text()) if index_path.exists() else {}
        for motion in motions or ensemble.MOTIONS:
            kept, units = _capture_run(
                case, motion, copy, min_units, duration or ensemble.DURATION, directory, solver, tuning
            )
            if override:
                for entry in kept.values():
                    entry["override"] = override
            index.update(kept)
            index_path.write_text(json.dumps(index, indent=1))
            u = np.array(units)
            print(
                f"{case} A {motion[0]:g} f {motion[1]:g} copy {copy}: {u.size} steps, total {u.sum()} units,"
                f" kept {len(kept)} (≥ {min_units}), {int((u >= 2500).sum())} of ≥ 2500",
                flush=True,
            )


def _capture_run(case, motion, copy, min_units, duration, directory, solver, tuning) -> tuple[dict, list[int]]:
    from benchmarks.solver_cases import CASES
    from benchmarks.solver_lab.ensemble import COPY_STEP
    from masonrycli.run import Simulation
    from masonrycli.scenario.motion import Sine
    from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

    builder, options, _, _ = CASES[case]
    amplitude, frequency, phase = motion
    ground = Sine(amplitude=amplitude * (1.0 + copy * COPY_STEP), frequency=frequency, phase=phase)
    scenario = scenario_from_builder(
        builder, options, RunConfig(duration=duration, solver=solver), Material(), {"ground": ground}
    )
    sim = Simulation(scenario, tuning=tuning)
    solve = dispatch.solve
    step, kept, units = [0], {}, []

    def watched(contact_body, pack, count, model, v, r, status, tuning=TUNING):
        inputs = {
            "body": contact_body[:count].copy(),
            "pack": pack[:count].copy(),
            "v_free": v.copy(),
            "r_warm": r[:count].copy(),
            "status": status[:count].copy(),
        }
        out = solve(contact_body, pack, count, model, v, r, status, tuning)
        if out[0] >= min_units:
            name = _key(case, motion, copy, step[0])
            params = {"mu": model.friction, "tolerance": model.tolerance, "cap": model.max_iterations}
            depth = getattr(model, "block_depth", 0.0)
            np.savez_compressed(directory / f"{name}.npz", **inputs, **params, solver=model.solver, depth=depth)
            kept[name] = {"case": case, "step": step[0], "units": int(out[0]), "residual": float(out[1])}
            kept[name].update(params, contacts=int(count), bodies=int(v.shape[0]), solver=model.solver)
        return out

    dispatch.solve = watched
    try:
        for _ in range(sim.model.n_steps):
            units.append(int(sim.step().iterations))
            step[0] += 1
    finally:
        dispatch.solve = solve
    return kept, units


def tuning_of(overrides: dict[str, object]) -> Tuning:
    """The shipped tuning with ``overrides`` (field → value; a LEGACY name for its field); an unknown name is a
    TypeError of dataclasses.replace."""
    return replace(TUNING, **{LEGACY.get(name, name): value for name, value in overrides.items()})


def _model(z) -> SimpleNamespace:
    """The model fields dispatch.solve reads, as the step was captured: μ, tolerance, cap, solver and the
    structure's depth (sets captured before 28 Nov carry no solver: ``nlgs-accel``; none before the depth: 0,
    the plain stall window)."""
    return SimpleNamespace(
        friction=float(z["mu"]), tolerance=float(z["tolerance"]), max_iterations=int(z["cap"]),
        solver=str(z["solver"]) if "solver" in z.files else "nlgs-accel",
        block_depth=float(z["depth"]) if "depth" in z.files else 0.0,
    )  # fmt: skip


def replay_step(name: str, directory=None, tuning: Tuning = TUNING) -> dict:
    """One kept step through dispatch.solve with ``tuning`` from its warm start: units, residual, the method that
    finished."""
    z = np.load((directory or HARD) / f"{name}.npz")
    body, pack, count = z["body"].astype(np.int32), z["pack"], z["body"].shape[0]
    v, r, status = z["v_free"].copy(), z["r_warm"].copy(), z["status"].copy()
    model = _model(z)
    log = []
    resume = stalled._resume

    def logged(method, state, *args):
        done = resume(method, state, *args)
        log.append((method, done, float(state.residual)))
        return done

    entry = []
    finish = stalled.continue_stalled

    def entered(*args):
        entry.append((int(args[11]), float(args[12])))  # momentum's units and residual at its stall
        return finish(*args)

    stalled._resume, stalled.continue_stalled = logged, entered
    try:
        t = time.process_time()
        units, residual = dispatch.solve(body, pack, count, model, v, r, status, tuning)
        cpu = time.process_time() - t
    finally:
        stalled._resume, stalled.continue_stalled = resume, finish
    converged = residual <= model.tolerance
    first = "bodies" if entry else "momentum0"  # handed to stalled.py, finished before its round-robin
    by = (log[-1][0] if log else first) if converged else "-"
    return {
        "units": int(units),
        "residual": float(residual),
        "converged": bool(converged),
        "by": by,
        "methods": [[m, d, f"{res:.2e}"] for m, d, res in log],
        "cpu_s": round(cpu, 4),
        "stalled_at": entry[0] if entry else None,
    }


def replay(
    variants: list[str], min_units: int, max_units: int | None, out: Path | None, cases=None, directory=None
) -> dict:
    """Each variant over the kept steps with min_units ≤ engine units < max_units; results to ``out``."""
    directory = directory or HARD
    index = {n: e for path in sorted(directory.glob("index-*.json")) for n, e in json.loads(path.read_text()).items()}
    names = sorted(
        n
        for n, e in index.items()
        if e["units"] >= min_units
        and (max_units is None or e["units"] < max_units)
        and e["case"] in (cases or [e["case"]])
    )
    doc = {
        "dir": str(directory),
        "min_units": min_units,
        "max_units": max_units,
        "steps": names,
        "engine": {n: index[n]["units"] for n in names},
        "variants": {},
    }
    for variant in variants:
        overrides = VARIANTS[variant] if variant in VARIANTS else _parse(variant)
        tuning = tuning_of(overrides)
        results = {}
        t = time.process_time()
        for name in names:
            results[name] = replay_step(name, directory, tuning)
        doc["variants"][variant] = {"overrides": {k: str(v) for k, v in overrides.items()}, "steps": results}
        print(summary_line(variant, results, doc["engine"]) + f" ({time.process_time() - t:.0f} CPU s)", flush=True)
        if out is not None:
            out.write_text(json.dumps(doc, indent=1))
    return doc


def _parse(text: str) -> dict[str, object]:
    """``"first_stall=300+first_budget=1000"`` → overrides (values by Python's literal syntax)."""
    import ast

    overrides = {}
    for part in text.split("+"):
        key, value = part.split("=")
        overrides[key] = ast.literal_eval(value)
    return overrides


def summary_line(variant: str, results: dict, engine: dict | None = None) -> str:
    u = np.array([s["units"] for s in results.values()])
    missed = sum(not s["converged"] for s in results.values())
    same = ""
    if engine:
        same = f", {sum(results[n]['units'] == engine[n] for n in results)} steps as captured"
    return (
        f"| {variant} | {u.sum()} | {len(u) - missed} / {len(u)} | {int((u > BIG).sum())} |"
        f" {int(((u >= 2500) & (u <= BIG)).sum())} | {int(u.max())} |{same}"
    )


def table(paths: list[Path]) -> None:
    """Per variant of the replay files: totals, converged, tail, finishing method (module doc)."""
    base = None
    print("| variant | units | ratio | converged | > 10 000 | 2500–10 000 | max | finished by |\n" + "|---" * 8 + "|")
    for path in paths:
        doc = json.loads(Path(path).read_text())
        for variant, v in doc["variants"].items():
            res = v["steps"]
            u = np.array([s["units"] for s in res.values()])
            base = base or u.sum()
            missed = sum(not s["converged"] for s in res.values())
            by: dict[str, int] = {}
            for s in res.values():
                by[s["by"]] = by.get(s["by"], 0) + 1
            finished = ", ".join(f"{k} {n}" for k, n in sorted(by.items(), key=lambda kv: -kv[1]))
            print(
                f"| {variant} | {u.sum()} | {u.sum() / base:.3f} | {len(u) - missed} / {len(u)} | {int((u > BIG).sum())} |"
                f" {int(((u >= 2500) & (u <= BIG)).sum())} | {int(u.max())} | {finished} |"
            )


def _first_below(history: np.ndarray, level: float) -> int | None:
    k = np.nonzero(history <= level)[0]
    return int(k[0]) + 1 if k.size else None


def stage_split(name: str, directory=None, tuning: Tuning = TUNING) -> dict:
    """One kept step: units and residual history per stage of the chain (module doc, ``stages``), with the
    engine's ``tuning``."""
    from masonrycli.engine import lane_sweeps

    z = np.load((directory or HARD) / f"{name}.npz")
    body, pack, count = z["body"].astype(np.int32), z["pack"], z["body"].shape[0]
    tol, mu, cap = float(z["tolerance"]), float(z["mu"]), int(z["cap"])

    def first_stage(sweeps):
        v, r, st = z["v_free"].copy(), z["r_warm"].copy(), z["status"].copy()
        return lane_sweeps._lane_sweeps(body, pack, count, mu, tol, sweeps, v, r, st, tuning.first_stall)

    sweeps = first_stage(cap)[0]
    h = np.array([first_stage(k)[1] for k in range(1, sweeps + 1)])
    out = {"tolerance": tol, "momentum": {"units": int(sweeps), "history": h.tolist()}, "stage": [], "resumes": []}
    calls, resume, order = [], stalled._resume, bodies.body_order_sweeps

    def recorded(*args, **kwargs):
        kwargs["history"] = history = np.full(64_000, np.nan)
        done, residual = order(*args, **kwargs)
        reason = int(kwargs["stage"].carry[bodies.C_REASON]) if kwargs.get("stage") is not None else -1
        calls.append(
            {"units": int(done), "residual": residual, "reason": reason, "history": history[~np.isnan(history)]}
        )
        return done, residual

    def logged(method, state, *args):
        done = resume(method, state, *args)
        out["resumes"].append([method, int(done), float(state.residual)])
        return done

    bodies.body_order_sweeps, stalled._resume = recorded, logged
    try:
        v, r, st = z["v_free"].copy(), z["r_warm"].copy(), z["status"].copy()
        out["units"], out["residual"] = (
            float(x) for x in dispatch.solve(body, pack, count, _model(z), v, r, st, tuning)
        )
    finally:
        bodies.body_order_sweeps, stalled._resume = order, resume
    for part, hist in [(out["momentum"], h)] + [(c, c["history"]) for c in calls]:
        part.update(low=float(hist.min()), low_at=int(hist.argmin()) + 1, within2=_first_below(hist, 2 * tol))
    for c in calls:
        c["sweeps"], c["history"] = len(c["history"]), c["history"].tolist()
        out["stage"].append(c)
    return out


def stages(min_units: int, out: Path | None, directory=None, tuning: Tuning = TUNING) -> dict:
    """``stage_split`` of every kept step of ≥ ``min_units``, dearest first; one line each, JSON to ``out``."""
    directory = directory or HARD
    index = {n: e for path in sorted(directory.glob("index-*.json")) for n, e in json.loads(path.read_text()).items()}
    names = sorted((n for n, e in index.items() if e["units"] >= min_units), key=lambda n: -index[n]["units"])
    doc = {}
    for name in names:
        doc[name] = s = stage_split(name, directory, tuning)
        tol, m = s["tolerance"], s["momentum"]
        line = f"{name}: {s['units']:.0f} units | momentum {m['units']} (low {m['low'] / tol:.2f}× at {m['low_at']}, ≤ 2× at {m['within2']})"
        for c in s["stage"]:
            line += f" | stage {c['units']} ({c['sweeps']} sweeps, stop {c['reason']}, low {c['low'] / tol:.2f}× at {c['low_at']}, ≤ 2× at {c['within2']})"
        line += "".join(f" | {m_} {d} ({res / tol:.2f}×)" for m_, d, res in s["resumes"])
        print(line, flush=True)
    if out is not None:
        out.write_text(json.dumps(doc))
    return doc


def add_arguments(sub) -> None:
    """The ``hard`` subcommand's parser."""
    hard = sub.add_parser(
        "hard", help="capture the costliest steps of ensemble runs; replay rule variants; split by stage"
    )
    act = hard.add_subparsers(dest="action", required=True)
    c = act.add_parser("capture")
    c.add_argument("--cases", nargs="+", default=["h32", "h64"])
    c.add_argument("--copy", type=int, default=0)
    c.add_argument("--min-units", type=int, default=1000)
    c.add_argument("--motions", nargs="+", default=None, help="A,F[,PHASE] … (default: the ensemble's 12)")
    c.add_argument("--duration", type=float, default=None, help="s (default: the ensemble's)")
    c.add_argument("--dir", type=Path, default=None, help="where the steps go (default data/hard)")
    c.add_argument(
        "--set", default=None, metavar="FIELD=VALUE[+…]", help="Tuning fields for the capture (engine/tuning.py)"
    )
    c.add_argument("--solver", default="nlgs-accel", help="the run's solver (default nlgs-accel, the float64 path)")
    r = act.add_parser("replay")
    r.add_argument(
        "--variants",
        nargs="+",
        default=["main"],
        help=f"names ({', '.join(VARIANTS)}) or FIELD=VALUE[+…] of engine/tuning.py",
    )
    r.add_argument("--min-units", type=int, default=2500)
    r.add_argument("--max-units", type=int, default=None)
    r.add_argument("--cases", nargs="+", default=None)
    r.add_argument("--out", type=Path, default=None)
    r.add_argument("--dir", type=Path, default=None, help="the captured set (default data/hard)")
    t = act.add_parser("table")
    t.add_argument("files", nargs="+", type=Path)
    g = act.add_parser("stages")
    g.add_argument("--min-units", type=int, default=400)
    g.add_argument("--out", type=Path, default=None)
    g.add_argument("--dir", type=Path, default=None, help="the captured set (default data/hard)")


def main(args) -> None:
    if args.action == "capture":
        from benchmarks.solver_lab.ensemble import parse_motion

        motions = [parse_motion(m) for m in args.motions] if args.motions else None
        capture(args.cases, args.copy, args.min_units, motions, args.duration, args.dir, args.set, args.solver)
    elif args.action == "replay":
        replay(args.variants, args.min_units, args.max_units, args.out, args.cases, args.dir)
    elif args.action == "stages":
        stages(args.min_units, args.out, args.dir)
    else:
        table(args.files)
