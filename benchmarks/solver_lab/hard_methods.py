"""New methods on hard steps: each method alone on a stratified sample of the captured hard steps.

    python -m benchmarks.solver_lab hard-methods run --methods NAME … --out FILE.json [--steps-every 3 10]
    python -m benchmarks.solver_lab hard-methods table FILE.json [FILE.json …]

The hard steps are those the hard capture kept (``data/hard``, benchmarks/solver_lab/hard_steps.py on the
``hard`` branch: nlgs.solve's input at every step of ≥ 1000 sweep units of 12 + 12 ensemble runs of the
32- and 64-course walls, with the engine's units in ``index-<case>-c<copy>.json``). The sample
(:func:`sample`): per case, the steps of ≥ 10 000 engine units sorted by units (largest first), every
``big_every``-th from the first; and of those with 2500–10 000, every ``mid_every``-th. Deterministic.

``run`` solves each sampled step from its warm start (r_warm, v_free) with each method ALONE, to the
engine's tolerance (1e-5 m/s) or CAP sweep units, and writes units / residual / converged per step.
Existing methods (those of stalled.py, as benchmarks/solver_lab/stalled_steps.py runs them alone):

    turning, momentum, alternating, newton   stalled.py's own resume with the whole cap
    faces                                    faces from momentum's iterate at its 500-sweep stall

New ones (masonrycli/engine/sweep_variants.py; a stall window of STALL sweeps without a new low, then
the step counts as not converged):

    relax-W          plain sweeps under-relaxed by ω = W (forward order)
    relax-W-alt      the same, alternating direction
    mom-relax-W      momentum's extrapolation, then the relaxed visit, projected into the cone
    adapt-W / mom-adapt-W   ω per contact: halved (floor W) when the contact's status flips, else raised
    random / mom-random     a new pseudo-random contact order every sweep (seed 0)
    mom-random-faces        a new pseudo-random order of the faces every sweep
    bodies / bodies-alt     body-wise block Gauss–Seidel (10 inner rounds, drop 1e-6)

``table`` prints per method: steps converged, units (a step not converged counted at CAP), geometric mean
of the per-step ratio to the engine's units (not converged: CAP / engine), steps it beats every existing
method on (fewer units than each, converged), and the same for the steps of ≥ 10 000 engine units.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from benchmarks.solver_lab.problems import DATA
from benchmarks.solver_lab.stalled_steps import _method as existing_method
from masonrycli.engine import sweep_variants as sv

HARD = DATA / "hard"
TOLERANCE, CAP, STALL, BIG = 1e-5, 50_000, 10_000, 10_000
EXISTING = ("turning", "momentum", "alternating", "faces", "newton")


def _variant(**kw):
    def run(z, v, r, status, cap):
        body, pack, count, mu = z["body"], z["pack"], z["body"].shape[0], float(z["mu"])
        return sv.variant_sweeps(body, pack, count, mu, TOLERANCE, cap, v, r, status, stall=STALL, **kw)

    return run


def _bodies(alternate):
    def run(z, v, r, status, cap):
        body, pack, count, mu = z["body"], z["pack"], z["body"].shape[0], float(z["mu"])
        return sv.body_sweeps(body, pack, count, mu, TOLERANCE, cap, v, r, status, alternate=alternate, stall=STALL)

    return run


NEW = {
    "relax-0.5": _variant(omega=0.5),
    "relax-0.7": _variant(omega=0.7),
    "relax-0.9": _variant(omega=0.9),
    "relax-0.7-alt": _variant(omega=0.7, order=sv.ORDER_ALTERNATE),
    "mom-relax-0.7": _variant(omega=0.7, accelerate=True),
    "mom-relax-0.9": _variant(omega=0.9, accelerate=True),
    "mom-relax-0.7-turn": _variant(omega=0.7, accelerate=True, order=sv.ORDER_TURN),
    "adapt-0.25": _variant(omega=0.25, adaptive=True),
    "mom-adapt-0.25": _variant(omega=0.25, adaptive=True, accelerate=True),
    "mom-adapt-0.25-turn": _variant(omega=0.25, adaptive=True, accelerate=True, order=sv.ORDER_TURN),
    "random": _variant(order=sv.ORDER_RANDOM),
    "mom-random": _variant(order=sv.ORDER_RANDOM, accelerate=True),
    "mom-random-faces": _variant(order=sv.ORDER_RANDOM_FACES, accelerate=True),
    "mom-relax-0.7-random": _variant(omega=0.7, order=sv.ORDER_RANDOM, accelerate=True),
    "bodies": _bodies(False),
    "bodies-alt": _bodies(True),
}


def _index() -> dict:
    return {n: e for path in sorted(HARD.glob("index-*.json")) for n, e in json.loads(path.read_text()).items()}


def sample(big_every: int = 3, mid_every: int = 10) -> list[str]:
    """The stratified sample of the module doc (names of data/hard/*.npz)."""
    index = _index()
    names = []
    for case in sorted({e["case"] for e in index.values()}):
        steps = sorted((n for n, e in index.items() if e["case"] == case), key=lambda n: (-index[n]["units"], n))
        big = [n for n in steps if index[n]["units"] >= BIG]
        mid = [n for n in steps if 2500 <= index[n]["units"] < BIG]
        names += big[::big_every] + mid[::mid_every]
    return names


def solve(method: str, name: str, cap: int = CAP) -> dict:
    """One method alone on one kept step from its warm start: units, residual, converged, CPU s."""
    z = dict(np.load(HARD / f"{name}.npz"))
    z["body"] = z["body"].astype(np.int32)
    v, r, status = z["v_free"].copy(), z["r_warm"].copy(), z["status"].copy()
    t = time.process_time()
    if method in NEW:
        units, res = NEW[method](z, v, r, status, cap)
    else:
        units, res = existing_method(method, z, v, r, status, cap)
    cpu = time.process_time() - t
    return {"units": int(units), "residual": float(res), "converged": bool(res <= TOLERANCE), "cpu_s": round(cpu, 3)}


def run(methods: list[str], out: Path, big_every: int, mid_every: int) -> None:
    """Each method over the sample; the JSON is rewritten after every method (module doc)."""
    names = sample(big_every, mid_every)
    index = _index()
    doc = json.loads(out.read_text()) if out.exists() else {"steps": names, "methods": {}}
    doc["engine"] = {n: index[n]["units"] for n in names}
    doc["engine_converged"] = {n: index[n]["residual"] <= TOLERANCE for n in names}
    for method in methods:
        t = time.process_time()
        doc["methods"][method] = {n: solve(method, n) for n in names}
        out.write_text(json.dumps(doc, indent=1))
        print(_line(method, doc["methods"][method], doc["engine"], {}) + f" ({time.process_time() - t:.0f} CPU s)")


def _line(method, res, engine, existing) -> str:
    names = list(res)
    u = np.array([res[n]["units"] if res[n]["converged"] else CAP for n in names], float)
    e = np.array([engine[n] for n in names], float)
    ok = np.array([res[n]["converged"] for n in names])
    big = e >= BIG
    wins = np.array(
        [ok[i] and all(u[i] < existing[m][n] for m in existing if m != method) for i, n in enumerate(names)]
    )
    gm = float(np.exp(np.mean(np.log(u / e))))
    gm_big = float(np.exp(np.mean(np.log(u[big] / e[big])))) if big.any() else float("nan")
    return (
        f"| {method} | {ok.sum()} / {len(u)} | {int(u.sum())} | {gm:.2f} | {int(wins.sum()) if existing else '-'} |"
        f" {ok[big].sum()} / {big.sum()} | {int(u[big].sum())} | {gm_big:.2f} |"
        f" {int(wins[big].sum()) if existing else '-'} |"
    )


def table(paths: list[Path]) -> None:
    """Merge the run files; one row per method (module doc)."""
    doc = {"methods": {}}
    for path in paths:
        d = json.loads(Path(path).read_text())
        doc["engine"] = d["engine"]
        doc["methods"].update(d["methods"])
    engine = doc["engine"]
    existing = {
        m: {n: (s["units"] if s["converged"] else np.inf) for n, s in res.items()}
        for m, res in doc["methods"].items()
        if m in EXISTING
    }
    e = np.array(list(engine.values()))
    print(
        f"{len(e)} steps ({int((e >= BIG).sum())} of ≥ {BIG} engine units), engine total {int(e.sum())};"
        f" not converged counted at {CAP}\n"
        "| method | converged | units | geo-mean ratio to engine | beats every existing |"
        f" converged ≥ {BIG} | units ≥ {BIG} | geo-mean ≥ {BIG} | beats every existing ≥ {BIG} |\n" + "|---" * 9 + "|"
    )
    for method, res in doc["methods"].items():
        print(_line(method, res, engine, existing))


def add_arguments(sub) -> None:
    """The ``hard-methods`` subcommand's parser."""
    p = sub.add_parser("hard-methods", help="new methods alone on a sample of the captured hard steps")
    act = p.add_subparsers(dest="action", required=True)
    r = act.add_parser("run")
    r.add_argument("--methods", nargs="+", required=True, help=f"{', '.join(EXISTING + tuple(NEW))}")
    r.add_argument("--out", type=Path, required=True)
    r.add_argument("--steps-every", type=int, nargs=2, default=(3, 10), metavar=("BIG", "MID"))
    t = act.add_parser("table")
    t.add_argument("files", nargs="+", type=Path)


def main(args) -> None:
    if args.action == "run":
        run(args.methods, args.out, *args.steps_every)
    else:
        table(args.files)
