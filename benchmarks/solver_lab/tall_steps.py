"""Tall walls' stalled and hard steps: the engine's chain against the lab's IPM and CPG methods, in sweep units.

    python -m benchmarks.solver_lab tall run --methods engine ipm-pred ipm-pred-close4 cpg-mono --out FILE.json
    python -m benchmarks.solver_lab tall table FILE.json [FILE.json …]
    python -m benchmarks.solver_lab tall factor-units

The steps: every captured step of the 32- and 64-course walls in ``data/stalled`` (stalled_steps.py's capture
of the first 0.2 s, at cbefb3a: the steps whose momentum stalled then) and in ``data/hard-paper-h32`` /
``hard-paper-h64`` (hard_steps.py's capture of the benchmark's trajectory, the paper's 1 m/s 2 Hz shake, 0.2 s,
steps of ≥ 2500 units, at df779f6). Each is solved from its warm start:

    engine            dispatch.solve as it runs today (momentum, stalled.py's body-order stage, round-robin),
                      tolerance 1e-5 m/s, cap 100 000 units; its own unit count
    ipm-pred          methods/ipm_shift.py's: 100 accelerated sweeps, s frozen at μ|u_t| of their velocities,
                      one frozen-shift IPM (ipm.run_ipm "frozen"), then accelerated sweeps to the tolerance
    ipm-pred-close4   the same predictor, ipm-newton to 1e-4 m/s, then accelerated sweeps
    cpg-mono          methods/cpg.py's monotone CPG (s ← μ|u_t| each iteration)
    ipm-pred-bodies   ipm-pred with the engine's body-order momentum (bodies.py, stalled.py's stage, stall
                      window TUNING.bodies_stall, no hand-over) as its closing sweeps (new here)

Units, deterministic and at the compiled floor (so favourable to the lab methods): an engine accelerated
sweep 1 (as the engine counts them); an IPM factorisation FACTOR_UNITS[kind][case] (LAPACK's banded Cholesky
or LU with its two solves, over one engine sweep, measured here: ``factor-units``) plus MATVEC_UNITS for the
iteration's products with H; a CPG matvec 1. The assembly of the band is not counted. The closing sweeps are
the engine's momentum kernel with its own in-sweep stopping test (tolerance 1e-5 m/s, no stall window), as
they would run inside the engine. Each lab method's budget on a step is BUDGET × the engine's units (at least
MIN_BUDGET, at most CAP): a method that misses it is counted at what it spent, flagged, and a step the engine
needs is still needed after it. Accuracy: the lab's RMS law residual of (v(r), r) of every result (law.py), and
``dv``, the largest difference of any velocity component (vx, vy in m/s, ω in rad/s) of the dynamic bodies from the
engine's answer (these steps have no tight reference).
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import cpg, ipm, ipm_shift
from benchmarks.solver_lab.outcome import Clock, Context
from benchmarks.solver_lab.problems import DATA
from benchmarks.solver_lab.stalled_steps import as_problem
from masonrycli.engine import bodies, dispatch
from masonrycli.engine.tuning import TUNING

TOLERANCE, ENGINE_CAP, CAP = 1e-5, 100_000, 50_000
BUDGET, MIN_BUDGET = 2.0, 5000
MATVEC_UNITS = 4
"""An IPM iteration's products with H and Hᵀ (u = H x three times, Hᵀ λ twice, x(λ) once: ~4 sweeps' visits)."""
FACTOR_UNITS = {"chol": {"h32": 45.0, "h64": 39.0}, "lu": {"h32": 100.0, "h64": 92.0}}
"""Banded factorisation + two solves over one engine sweep (``factor-units`` at 03:59 UTC 28 Nov: h32-80, h64-0)."""
SETS = {"stalled": DATA / "stalled", "paper32": DATA / "hard-paper-h32", "paper64": DATA / "hard-paper-h64"}
METHODS = ("engine", "ipm-pred", "ipm-pred-close4", "cpg-mono", "ipm-pred-bodies")
CASES = ("h32", "h64")


def steps() -> list[tuple[str, Path]]:
    """(name, path) of every kept step of h32 and h64 (module doc), in a fixed order."""
    out = []
    for tag, d in SETS.items():
        for path in sorted(d.glob("h*.npz"), key=lambda p: (p.stem.split("-")[0], int(p.stem.rsplit("-", 1)[1]))):
            if _case(path.stem) in CASES:
                out.append((f"{tag}/{path.stem}", path))
    return out


def _case(name: str) -> str:
    """The wall of a step's name ("stalled/h32-80", "paper64/h64-a1-f2-c0-97", or a file stem): "h32"."""
    return name.split("/")[-1].split("-")[0]


def engine(z) -> dict:
    body, pack, count = z["body"].astype(np.int32), z["pack"], z["body"].shape[0]
    v, r = z["v_free"].copy(), z["r_warm"].copy()
    status = z["status"].copy() if "status" in z else np.zeros(count, np.int8)
    model = SimpleNamespace(
        friction=float(z["mu"]), tolerance=TOLERANCE, max_iterations=ENGINE_CAP, solver="nlgs-accel"
    )
    t = time.process_time()
    units, res = dispatch.solve(body, pack, count, model, v, r, status)
    return {"units": int(units), "residual": float(res), "cpu_s": time.process_time() - t, "v": v, "r": r}


class _Counted:
    """Counts ipm.Operators.factor calls by kind while installed (the IPM's factorisations)."""

    def __init__(self):
        self.count = {"chol": 0, "lu": 0}
        self._factor = ipm.Operators.factor

    def __enter__(self):
        counted = self

        def factor(ops, d, sg=None):
            fac = counted._factor(ops, d, sg)
            counted.count[fac[0]] += 1
            return fac

        ipm.Operators.factor = factor
        return self

    def __exit__(self, *exc):
        ipm.Operators.factor = self._factor


def _closing(ctx, r, budget, body_order=False) -> tuple[int, float, np.ndarray]:
    """The engine's momentum sweeps from impulses r (in place) to its tolerance, no stall window; or, with
    ``body_order``, its body-order momentum with the stage's stall window (units as the engine counts them)."""
    p = ctx.p
    v = p.v_free.copy()
    status = np.zeros(p.count, np.int8)
    budget = max(budget, 1)
    if body_order:
        n, res = bodies.body_order_sweeps(
            p.body, ctx.pack, p.count, p.mu, TOLERANCE, budget, v, r, status, TUNING.bodies_stall
        )
    else:
        n, res = dispatch.first_stage(p.body, ctx.pack, p.count, p.mu, TOLERANCE, budget, v, r, status, budget)
    return int(n), float(res), v


def ipm_method(ctx, case, budget, loose, mode, body_order=False) -> dict:
    clock = Clock()
    with _Counted() as counted:
        lam = ipm_shift.predict(ctx, clock)
        v, r, its, _, res = ipm.run_ipm(ctx, TOLERANCE, loose, clock, mode, lam_start=lam)
    units = ipm_shift.PREDICT_SWEEPS + its * MATVEC_UNITS
    units += sum(k * FACTOR_UNITS[kind].get(case, FACTOR_UNITS[kind]["h32"]) for kind, k in counted.count.items())
    closing = 0
    if res > TOLERANCE:
        closing, res, v = _closing(ctx, r, int(budget - units), body_order)
        units += closing
    return {
        "units": int(round(units)),
        "iterations": its,
        "factors": dict(counted.count),
        "closing": closing,
        "residual": res,
        "v": v,
        "r": r,
    }


def cpg_method(ctx, budget) -> dict:
    clock = Clock()
    v, r, its, _, restarts, matvecs, res = cpg.run_cpg(ctx, TOLERANCE, clock, False, "each", True, cap=budget // 2)
    return {"units": int(matvecs), "iterations": its, "restarts": restarts, "residual": res, "v": v, "r": r}


def run(methods, out: Path, only=None, cap: int = CAP) -> None:
    doc = json.loads(out.read_text()) if out.exists() else {"steps": {}}
    doc["factor_units"], doc["matvec_units"] = FACTOR_UNITS, MATVEC_UNITS
    for name, path in steps():
        if only and not any(o in name for o in only):
            continue
        z = dict(np.load(path))
        entry = doc["steps"].setdefault(name, {"contacts": int(z["body"].shape[0])})
        prob = as_problem(path)
        ctx = Context(prob)
        eng = engine(z)
        if "engine" in methods or "engine" not in entry:
            entry["engine"] = {k: eng[k] for k in ("units", "residual", "cpu_s")}
            entry["engine"]["law"] = ctx.residual(law.velocity_from_impulse(prob, ctx.H, eng["r"]), eng["r"])
        budget = int(min(cap, max(MIN_BUDGET, BUDGET * entry["engine"]["units"])))
        dyn = prob.inv_mass > 0
        for m in methods:
            if m == "engine":
                continue
            t = time.process_time()
            with np.errstate(all="ignore"):
                if m == "cpg-mono":
                    res = cpg_method(ctx, budget)
                else:
                    loose, mode = (1e-4, "newton") if m == "ipm-pred-close4" else (TOLERANCE, "frozen")
                    res = ipm_method(ctx, _case(name), budget, loose, mode, m == "ipm-pred-bodies")
            cpu = time.process_time() - t
            v_r = law.velocity_from_impulse(prob, ctx.H, res["r"])
            row = {k: val for k, val in res.items() if k not in ("v", "r")}
            row.update(
                cpu_s=cpu,
                budget=budget,
                converged=bool(res["residual"] <= TOLERANCE),
                law=ctx.residual(v_r, res["r"]),
                dv=float(np.abs(v_r[dyn] - eng["v"][dyn]).max(initial=0.0)),
            )
            entry[m] = row
        ipm._operators.clear()
        out.write_text(json.dumps(doc, indent=1))
        print(_row(name, entry, methods), flush=True)


def _cell(m, e) -> str:
    if m == "engine":
        return f"{e['units']}{'' if e['residual'] <= TOLERANCE else '*'}"
    extra = f"{e['iterations']}+{e['closing']}: " if "closing" in e else ""
    return f"{extra}{e['units']}{'' if e['converged'] else '*'} ({e['dv']:.0e})"


def _row(name, entry, methods) -> str:
    cells = (_cell(m, entry[m]) if m in entry else "–" for m in methods)
    return f"| {name} | {entry['contacts']} | " + " | ".join(cells) + " |"


def table(paths: list[Path]) -> None:
    """The run files merged: one row per step, then the totals per wall (module doc)."""
    doc = {"steps": {}}
    for path in paths:  # files of other methods on the same steps add columns
        for name, entry in json.loads(Path(path).read_text())["steps"].items():
            doc["steps"].setdefault(name, {}).update(entry)
    methods = [m for m in METHODS if any(m in e for e in doc["steps"].values())]
    print("| step | contacts | " + " | ".join(methods) + " |\n|---|---|" + "---|" * len(methods))
    for name, entry in doc["steps"].items():
        print(_row(name, entry, methods))
    groups = [(f"{tag} {case}", tag, case) for tag in SETS for case in CASES] + [
        (f"all {case}", "", case) for case in CASES
    ]
    for label, tag, case in groups:
        rows = [e for n, e in doc["steps"].items() if _case(n) == case and n.startswith(tag)]
        if rows:
            print(f"| {label} ({len(rows)}) | | " + " | ".join(_total(m, rows) for m in methods) + " |")


def _total(m, rows) -> str:
    es = [e[m] for e in rows if m in e]
    units = sum(e["units"] for e in es)
    missed = sum(not (e["residual"] <= TOLERANCE if m == "engine" else e["converged"]) for e in es)
    cpu = sum(e["cpu_s"] for e in es)
    steps = f"{len(es)} steps, " if len(es) < len(rows) else ""
    return f"{units} ({steps}{missed} missed, {cpu:.0f} CPU s)"


def factor_units(repeat: int = 7) -> None:
    """FACTOR_UNITS measured: LAPACK banded Cholesky / LU of K = M + Aᵀ D A (+ two solves) against one engine
    momentum sweep, CPU minimum of ``repeat``, on the first kept step of each case."""
    for case in CASES:
        name, path = next(s for s in steps() if _case(s[0]) == case)
        ctx = Context(as_problem(path))
        ops = ipm.Operators(ctx)
        d = np.full((ctx.p.count, 2), 1e6)
        sg = np.where(np.arange(ctx.p.count) % 3 == 0, 1.0, 0.0)
        rhs = np.ones(ops.n)
        best = {"sweep": np.inf, "chol": np.inf, "lu": np.inf}
        for _ in range(repeat):
            r = ctx.p.r_warm.copy()
            t = time.process_time()
            ctx.sweep(r, 200, "nlgs-accel")
            best["sweep"] = min(best["sweep"], (time.process_time() - t) / 200)
            for kind, s in (("chol", None), ("lu", sg)):
                t = time.process_time()
                fac = ops.factor(d, s)
                ops.solve(fac, rhs)
                ops.solve(fac, rhs)
                best[kind] = min(best[kind], time.process_time() - t)
        print(
            f"{name}: {ops.n} dofs, half-bandwidth {ops.w}; sweep {1e6 * best['sweep']:.1f} µs; Cholesky + 2 solves"
            f" {1e3 * best['chol']:.2f} ms = {best['chol'] / best['sweep']:.0f} sweeps; LU + 2 solves"
            f" {1e3 * best['lu']:.2f} ms = {best['lu'] / best['sweep']:.0f} sweeps"
        )


def add_arguments(sub) -> None:
    p = sub.add_parser("tall", help="tall walls' stalled/hard steps: the engine's chain against IPM and CPG")
    act = p.add_subparsers(dest="action", required=True)
    r = act.add_parser("run")
    r.add_argument("--methods", nargs="+", default=list(METHODS), choices=METHODS)
    r.add_argument("--out", type=Path, required=True)
    r.add_argument("--only", nargs="+", default=None, help="steps whose name contains one of these")
    r.add_argument("--cap", type=int, default=CAP, help="a lab method's budget on a step at most (units)")
    t = act.add_parser("table")
    t.add_argument("files", nargs="+", type=Path)
    act.add_parser("factor-units")


def main(args) -> None:
    if args.action == "run":
        run(args.methods, args.out, args.only, args.cap)
    elif args.action == "table":
        table(args.files)
    else:
        factor_units()
