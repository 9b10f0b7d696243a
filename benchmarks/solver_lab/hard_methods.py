"""New methods on hard steps: each method alone on a stratified sample of the captured hard steps.

    python -m benchmarks.solver_lab hard-methods run --methods NAME … --out FILE.json [--steps-every 3 10]
    python -m benchmarks.solver_lab hard-methods table FILE.json [FILE.json …]

The hard steps are those the hard capture kept (``data/hard``, benchmarks/solver_lab/hard_steps.py on the
``hard`` branch: dispatch.solve's input at every step of ≥ 1000 sweep units of 12 + 12 ensemble runs of the
32- and 64-course walls, with the engine's units in ``index-<case>-c<copy>.json``). The sample
(:func:`sample`): per case, the steps of ≥ 10 000 engine units sorted by units (largest first), every
``big_every``-th from the first; and of those with 2500–10 000, every ``mid_every``-th. Deterministic.

``run`` solves each sampled step from its warm start (r_warm, v_free) with each method ALONE, to the
engine's tolerance (1e-5 m/s) or CAP sweep units, and writes units / residual / converged per step.
Existing methods (those of stalled.py, as benchmarks/solver_lab/stalled_steps.py runs them alone):

    turning, momentum, alternating, newton   stalled.py's own resume with the whole cap
    faces                                    faces from momentum's iterate at its 500-sweep stall

New ones (benchmarks/solver_lab/sweep_variants.py; a stall window of STALL sweeps without a new low, then
the step counts as not converged):

    relax-W          plain sweeps under-relaxed by ω = W (forward order)
    relax-W-alt      the same, alternating direction
    mom              momentum in detection order (the engine's "momentum" without its interleaving)
    mom-relax-W      momentum's extrapolation, then the relaxed visit, projected into the cone
    adapt-W / mom-adapt-W   ω per contact: halved (floor W) when the contact's status flips, else raised
    random / mom-random     a new pseudo-random contact order every sweep (seed 0)
    mom-random-faces        a new pseudo-random order of the faces every sweep
    bodies / bodies-alt     body-wise block Gauss–Seidel (10 inner rounds, drop 1e-6; -alt: bodies in
                            reverse order every second sweep)
    bodies-5                the same, at most 5 inner rounds, drop 1e-2
    bodies-1 / bodies-1-alt one inner round: point sweeps in body order, each contact visited once from
                            each of its bodies with mass (twice per sweep but at the supports)

``table`` prints per method: steps converged, units (a step not converged counted at CAP), geometric mean
of the per-step ratio to the engine's units (not converged: CAP / engine), steps it beats every existing
method on (fewer units than each, converged), and the same for the steps of ≥ 10 000 engine units.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from benchmarks.solver_lab import sweep_variants as sv
from benchmarks.solver_lab.problems import DATA
from benchmarks.solver_lab.stalled_steps import _method as existing_method
from masonrycli.engine import dispatch, stalled
from masonrycli.engine.tuning import TUNING

HARD = DATA / "hard"
TOLERANCE, CAP, STALL, BIG = 1e-5, 50_000, 10_000, 10_000
EXISTING = ("turning", "momentum", "alternating", "faces", "newton")


def _variant(**kw):
    def run(z, v, r, status, cap):
        body, pack, count, mu = z["body"], z["pack"], z["body"].shape[0], float(z["mu"])
        return sv.variant_sweeps(body, pack, count, mu, TOLERANCE, cap, v, r, status, stall=STALL, **kw)

    return run


def _bodies(alternate, rounds=10, drop=1e-6, accelerate=False):
    def run(z, v, r, status, cap):
        body, pack, count, mu = z["body"], z["pack"], z["body"].shape[0], float(z["mu"])
        return sv.body_sweeps(
            body, pack, count, mu, TOLERANCE, cap, v, r, status, rounds, drop, alternate, STALL, accelerate
        )

    return run


NEW = {
    "relax-0.5": _variant(omega=0.5),
    "relax-0.7": _variant(omega=0.7),
    "relax-0.9": _variant(omega=0.9),
    "relax-0.7-alt": _variant(omega=0.7, order=sv.ORDER_ALTERNATE),
    "mom": _variant(accelerate=True),
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
    "bodies-1": _bodies(False, rounds=1),
    "bodies-1-alt": _bodies(True, rounds=1),
    "bodies-5": _bodies(False, rounds=5, drop=1e-2),
    "bodies-1-mom": _bodies(False, rounds=1, accelerate=True),
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
    p = act.add_parser("replay")
    p.add_argument("--variants", nargs="+", required=True, help=", ".join(REPLAYS))
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--min-units", type=int, default=None, help="every kept step with this many engine units or more")
    p.add_argument("--steps-every", type=int, nargs=2, default=(3, 10), metavar=("BIG", "MID"))


def main(args) -> None:
    if args.action == "run":
        run(args.methods, args.out, *args.steps_every)
    elif args.action == "replay":
        index = _index()
        if args.min_units is None:
            names = sample(*args.steps_every)
        else:
            names = sorted(n for n, e in index.items() if e["units"] >= args.min_units)
        replay(args.variants, names, args.out)
    else:
        table(args.files)


# Replay: the round-robin of stalled.py with body-wise sweeps as one more method, through dispatch.solve.


def _round_robin(
    methods,
    rounds,
    factor,
    last,
    accelerate,
    ahead,
    contact_body,
    pack,
    count,
    mu,
    tolerance,
    cap,
    v,
    r,
    status,
    v_free,
    r_warm,
    its,
    res,
    tuning=TUNING,
):
    # stalled.continue_stalled with ``methods`` in its order, where "bodies" is body_sweeps with ``rounds``
    # inner rounds from the warm start (v rebuilt from v_free at each resume, its budget as stall window),
    # ``factor`` × the others' budget, in rounds 0 … ``last`` only; the others stalled.py's own resumes;
    # the same budgets and drop rules. ``ahead`` > 0: before the round-robin, bodies alone from the warm
    # start for at most ``ahead`` units, stall window ``ahead[1]`` sweeps; its r then goes on in the round-robin.
    if ahead:
        vb, rb, sb = v_free.copy(), r_warm[:count].copy(), status[:count].copy()
        done, got = sv.body_sweeps(
            contact_body, pack, count, mu, tolerance, ahead[0], vb, rb, sb, rounds, 1e-2, False, ahead[1], accelerate
        )
        its += done
        if got <= tolerance:
            v[:] = vb
            r[:count] = rb
            status[:count] = sb
            return its, got
        r_warm = r_warm.copy()  # the others start from the warm start as before
    states = {
        "newton": stalled._State(None, r_warm[:count].copy(), status[:count].copy(), np.inf),
        "turning": stalled._State(None, r_warm[:count].copy(), status[:count].copy(), np.inf),
        "alternating": stalled._State(None, r_warm[:count].copy(), status[:count].copy(), np.inf),
        "bodies": stalled._State(None, r_warm[:count].copy(), status[:count].copy(), np.inf),
        "momentum": stalled._State(v.copy(), r[:count].copy(), status[:count].copy(), res),
        "faces": stalled._State(v.copy(), r[:count].copy(), status[:count].copy(), res),
    }
    active = list(methods)
    budget, round_ = TUNING.first_budget, 0
    while its < cap and active:
        for name in list(active):
            if (name == "newton" and round_ > TUNING.newton_last_round) or (name == "bodies" and round_ > last):
                active.remove(name)
                continue
            share = TUNING.newton_budget if name == "newton" else factor if name == "bodies" else 1
            units = min(budget * share, cap - its)
            if units <= 0:
                break
            state = states[name]
            if name == "bodies":
                state.v = v_free.copy()
                done, state.residual = sv.body_sweeps(
                    contact_body,
                    pack,
                    count,
                    mu,
                    tolerance,
                    units,
                    state.v,
                    state.r,
                    state.status,
                    rounds,
                    1e-2,
                    False,
                    units,
                    accelerate,
                )
            else:
                done = stalled._resume(
                    name, state, contact_body, pack, count, mu, tolerance, units, v_free, cap - its, tuning
                )
            its += done
            if state.residual <= tolerance:
                stalled._adopt(state, v, r, status, count)
                return its, state.residual
            if name != "newton" and (done < units or state.residual >= state.low):
                active.remove(name)
            state.low = min(state.low, state.residual)
        budget *= 2
        round_ += 1
    best = min((s for s in states.values() if s.v is not None), key=lambda s: s.residual)
    stalled._adopt(best, v, r, status, count)
    return its, best.residual


_FIRST = ("bodies",) + TUNING.methods
_SECOND = TUNING.methods[:1] + ("bodies",) + TUNING.methods[1:]
REPLAYS = {
    "main": None,
    "bodies-first": (_FIRST, 1, 1, 99, False, None),
    "bodies-second": (_SECOND, 1, 1, 99, False, None),
    "mom-bodies-first": (_FIRST, 1, 1, 99, True, None),
    "mom-bodies-first-x2": (_FIRST, 1, 2, 99, True, None),
    "mom-bodies-first-x4": (_FIRST, 1, 4, 99, True, None),
    "mom-bodies-second": (_SECOND, 1, 1, 99, True, None),
    "mom-bodies-ahead-16k-s2000": (TUNING.methods, 1, 1, 99, True, (16000, 2000)),
    "mom-bodies-ahead-30k-s2000": (TUNING.methods, 1, 1, 99, True, (30000, 2000)),
    "mom-bodies-ahead-16k-s1000": (TUNING.methods, 1, 1, 99, True, (16000, 1000)),
    "mom-bodies-ahead-16k-s8000": (TUNING.methods, 1, 1, 99, True, (16000, 8000)),
    "mom-bodies-ahead-25k-s10000": (TUNING.methods, 1, 1, 99, True, (25000, 10000)),
}
"""Replay variants: None is stalled.py as it is; else (the round-robin's methods in order, bodies' inner rounds,
bodies' budget in units of the others', the last round (0-based) bodies takes part in, bodies with momentum,
(units, stall sweeps) of bodies alone ahead of the round-robin or None)."""


def replay(variants: list[str], names: list[str], out: Path) -> None:
    """Each step of ``names`` through dispatch.solve from its warm start, stalled.continue_stalled replaced by
    the variant's round-robin; units, residual per step to ``out``."""
    from types import SimpleNamespace

    index = _index()
    doc = json.loads(out.read_text()) if out.exists() else {"replays": {}}
    doc["engine"] = {n: index[n]["units"] for n in names}
    finish = stalled.continue_stalled
    for variant in variants:
        spec = REPLAYS[variant]
        if spec is not None:
            stalled.continue_stalled = lambda *a, spec=spec: _round_robin(*spec, *a)
        try:
            t = time.process_time()
            res = {}
            for name in names:
                z = np.load(HARD / f"{name}.npz")
                body, pack, count = z["body"].astype(np.int32), z["pack"], z["body"].shape[0]
                v, r, status = z["v_free"].copy(), z["r_warm"].copy(), z["status"].copy()
                model = SimpleNamespace(
                    friction=float(z["mu"]),
                    tolerance=float(z["tolerance"]),
                    max_iterations=int(z["cap"]),
                    solver="nlgs-accel",
                )
                units, residual = dispatch.solve(body, pack, count, model, v, r, status)
                res[name] = {
                    "units": int(units),
                    "residual": float(residual),
                    "converged": bool(residual <= model.tolerance),
                }
        finally:
            stalled.continue_stalled = finish
        doc["replays"][variant] = res
        out.write_text(json.dumps(doc, indent=1))
        u = np.array([s["units"] for s in res.values()])
        e = np.array([doc["engine"][n] for n in res])
        print(
            f"| {variant} | {u.sum()} | {u.sum() / e.sum():.3f} | {sum(not s['converged'] for s in res.values())} |"
            f" {int((u > BIG).sum())} | {int(u.max())} | ({time.process_time() - t:.0f} CPU s)",
            flush=True,
        )
