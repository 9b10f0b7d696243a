"""The body-order stage's hand-over: record its residual histories on captured hard steps, replay hand-over rules.

    python -m benchmarks.solver_lab handover record --cases wall-248 [--min-units 2500] [--max-units N] [--dir DIR] --out H.npz
    python -m benchmarks.solver_lab handover table H.npz [H2.npz …] [--rules …]

A stalled step goes to ``stalled.continue_stalled``: momentum in body order (``bodies.body_order_sweeps``,
"the stage") from the warm start, then, if it does not converge, the round-robin of the other methods. The
round-robin starts from the warm start and momentum's stalled iterate, not from the stage's, so what it
costs does not depend on when the stage stopped. So a step's units under any hand-over rule are

    momentum's units + the stage's units until the rule stops it (or it converges) + the round-robin's units
    (if the stage did not converge)

and a rule that decides from the stage's residual history alone can be judged offline from three
recordings a step: ``record`` replays each kept step (``hard_steps``' capture, ``data/hard``) through
``dispatch.solve`` and, at the hand-over, runs the stage alone for up to RECORD_UNITS sweep units with no stall
window, keeping every sweep's residual, and then the round-robin alone (``Tuning.bodies_units = 0``). Per
step: momentum's units and its residual at the stall, the stage's units a sweep (body-order visits / C),
its history, the round-robin's units and residual. ``table`` evaluates rules (``RULES``) on the
recordings, the cap ignored (100 000: only a step that already fails reaches it). The stage's re-entry
(``Tuning.bodies_reenter``) is not modelled: the units are those of the engine with it 0.
"""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from benchmarks.solver_lab.hard_steps import HARD
from masonrycli.engine import bodies, dispatch, stalled
from masonrycli.engine.tuning import TUNING, Tuning

RECORD_UNITS = 32_000
"""Sweep units the stage gets in a recording: twice the engine's Tuning.bodies_units, to see what more would buy."""


def _names(cases, min_units, max_units, directory=None) -> list[str]:
    directory = directory or HARD
    index = {n: e for path in sorted(directory.glob("index-*.json")) for n, e in json.loads(path.read_text()).items()}
    return sorted(
        n
        for n, e in index.items()
        if e["units"] >= min_units and (max_units is None or e["units"] < max_units) and e["case"] in cases
    )


def record_step(name: str, directory=None, tuning: Tuning = TUNING) -> dict | None:
    """One kept step (of ``directory``, default data/hard): momentum until its stall, then the stage alone
    (history) and the round-robin alone, the engine's ``tuning`` otherwise. None if momentum converges the step
    (no hand-over)."""
    z = np.load((directory or HARD) / f"{name}.npz")
    body, pack, count = z["body"].astype(np.int32), z["pack"], z["body"].shape[0]
    v, r, status = z["v_free"].copy(), z["r_warm"].copy(), z["status"].copy()
    model = SimpleNamespace(
        friction=float(z["mu"]), tolerance=float(z["tolerance"]), max_iterations=int(z["cap"]), solver="nlgs-accel"
    )
    out: dict = {}
    finish = stalled.continue_stalled

    def entered(
        contact_body, pack, count, mu, tolerance, cap, v, r, status, v_free, r_warm, iterations, residual, tuning=TUNING
    ):
        out["momentum_units"], out["momentum_residual"] = int(iterations), float(residual)
        start, members = bodies._body_lists(contact_body, pack, count, v.shape[0])
        out["units_per_sweep"] = members.shape[0] / count
        history = np.full(int(RECORD_UNITS / out["units_per_sweep"]) + 2, np.nan)
        v_b, r_b, status_b = v_free.copy(), r_warm[:count].copy(), status[:count].copy()
        t = time.process_time()
        done, res = bodies.body_order_sweeps(
            contact_body, pack, count, mu, tolerance, RECORD_UNITS, v_b, r_b, status_b, 10**9, history=history
        )
        out["stage_cpu_s"] = time.process_time() - t
        out["history"] = history[~np.isnan(history)]
        out["stage_units"], out["stage_residual"] = int(done), float(res)
        robin = replace(tuning, bodies_units=0)  # the round-robin alone
        total, res = finish(
            contact_body, pack, count, mu, tolerance, cap, v, r, status, v_free, r_warm, iterations, residual, robin
        )
        out["robin_units"], out["robin_residual"] = int(total - iterations), float(res)
        return total, res

    stalled.continue_stalled = entered
    try:
        dispatch.solve(body, pack, count, model, v, r, status, tuning)
    finally:
        stalled.continue_stalled = finish
    if not out:
        return None
    out["tolerance"] = model.tolerance
    return out


def record(
    cases: list[str], min_units: int, max_units: int | None, out: Path, directory=None, tuning: Tuning = TUNING
) -> None:
    """Record every kept step of ``cases`` (module doc; of the captured set ``directory``, default data/hard)
    into ``out`` (.npz: one array per field and step)."""
    names = _names(cases, min_units, max_units, directory)
    arrays: dict[str, np.ndarray] = {}
    t = time.process_time()
    for i, name in enumerate(names):
        rec = record_step(name, directory, tuning)
        if rec is None:
            continue
        for key, value in rec.items():
            arrays[f"{name}/{key}"] = np.asarray(value)
        if i % 20 == 0:
            print(f"{i + 1} / {len(names)} ({time.process_time() - t:.0f} CPU s)", flush=True)
    np.savez_compressed(out, **arrays)
    print(f"{len(names)} steps recorded to {out} ({time.process_time() - t:.0f} CPU s)")


def load(path: Path) -> dict[str, dict]:
    """A recording: step name → its fields (module doc)."""
    z = np.load(path)
    steps: dict[str, dict] = {}
    for key in z.files:
        name, field = key.rsplit("/", 1)
        value = z[key]
        steps.setdefault(name, {})[field] = value if value.ndim else value.item()
    return steps


def stage_end(history, ups: float, tolerance: float, budget: int, rule) -> tuple[int, bool]:
    """Sweeps the stage does under a hand-over rule within ``budget`` sweep units, and whether it converged.
    ``rule(history)`` → (S,) bool: hand over after sweep s + 1 (a rule sees only the sweeps up to s). As the
    engine's kernel: the tolerance is tested first, the budget is in units."""
    n = len(history)
    sweeps = np.arange(1, n + 1)
    end = (history <= tolerance) | rule(history) | (sweeps * ups >= budget)
    s = int(np.argmax(end)) + 1 if end.any() else n
    return s, bool(history[s - 1] <= tolerance)


def stall_rule(window: int):
    """The engine's rule before this module: ``window`` sweeps without a new lowest residual."""

    def rule(history):
        n = len(history)
        best = np.minimum.accumulate(history)
        lowered = np.ones(n, dtype=bool)
        lowered[1:] = history[1:] < best[:-1]
        best_at = np.maximum.accumulate(np.where(lowered, np.arange(1, n + 1), 0))
        return np.arange(1, n + 1) - best_at >= window

    return rule


def level_rule(window: int, level: float, cycling: int):
    """The engine's hand-over (bodies._cycling_windows): ``cycling`` windows of ``window`` sweeps in a row
    whose geometric mean is above ``level`` × the lowest residual so far."""

    def rule(history):
        n = len(history)
        out = np.zeros(n, dtype=bool)
        if cycling <= 0:
            return out
        best = np.minimum.accumulate(history)
        log_sum = np.concatenate([[0.0], np.cumsum(np.log(history))])
        run = 0
        for s in range(window, n + 1, window):
            run = run + 1 if np.exp((log_sum[s] - log_sum[s - window]) / window) > level * best[s - 1] else 0
            if run >= cycling:
                out[s - 1] = True
                break
        return out

    return rule


def evaluate(steps: dict[str, dict], rule, budget: int = 16_000) -> dict:
    """Units and outcome of every recorded step under a hand-over rule (module doc)."""
    out = {}
    for name, d in steps.items():
        s, finished = stage_end(d["history"], d["units_per_sweep"], d["tolerance"], budget, rule)
        stage = int(np.ceil(s * d["units_per_sweep"] - 1e-9))
        units = d["momentum_units"] + stage
        converged = finished
        if not finished:
            units += d["robin_units"]
            converged = d["robin_residual"] <= d["tolerance"]
        out[name] = {"units": units, "converged": converged, "stage": stage, "finished": finished}
    return out


RULES: dict[str, tuple] = {
    "as shipped (stall 8000)": ("stall", 8000, 16_000),
    "stall 500": ("stall", 500, 16_000),
    "stall 1000": ("stall", 1000, 16_000),
    "stall 2000": ("stall", 2000, 16_000),
    "units 4000": ("stall", 8000, 4000),
    "no stage": ("stall", 8000, 0),
    **{
        f"level {w} × {lv} × {k}": ("level", (w, lv, k), 16_000)
        for w, lv, k in [(500, 1.6, 4), (500, 1.7, 4), (500, 1.8, 3), (500, 1.8, 4), (500, 1.8, 5), (500, 2.0, 4)]
        + [(400, 1.8, 4), (400, 1.8, 5), (250, 1.7, 4), (1000, 1.8, 2)]
    },
}
"""Rules ``table`` replays: the engine's stall window or budget, and level rules (window, level, cycling)."""


def _rule(kind, arg):
    return stall_rule(arg) if kind == "stall" else level_rule(*arg)


def table(paths: list[Path], rules: list[str] | None = None) -> None:
    """Per rule and recording: units (× the first rule's), converged, steps the stage finished, and steps it
    would have finished but handed over ("early": their trajectory changes in a whole run)."""
    sets = {Path(p).stem: load(Path(p)) for p in paths}
    names = rules or list(RULES)
    ref = {k: evaluate(st, _rule(*RULES[names[0]][:2]), RULES[names[0]][2]) for k, st in sets.items()}
    head = " | ".join(f"{k}: units (×) | conv. | finished | early" for k in sets)
    print(f"| rule | {head} |\n|---|" + "---|" * (4 * len(sets)))
    for name in names:
        kind, arg, budget = RULES[name]
        cells = []
        for k, st in sets.items():
            ev = evaluate(st, _rule(kind, arg), budget)
            units = sum(e["units"] for e in ev.values())
            base = sum(e["units"] for e in ref[k].values())
            early = sum(ref[k][n]["finished"] and not ev[n]["finished"] for n in st)
            conv = sum(e["converged"] for e in ev.values())
            fin = sum(e["finished"] for e in ev.values())
            cells.append(f"{units:,} ({units / base:.3f}) | {conv} / {len(ev)} | {fin} | {early}".replace(",", " "))
        print(f"| {name} | " + " | ".join(cells) + " |")


def add_arguments(sub) -> None:
    """The ``handover`` subcommand's parser."""
    p = sub.add_parser("handover", help="the body-order stage's residual histories on hard steps; hand-over rules")
    act = p.add_subparsers(dest="action", required=True)
    r = act.add_parser("record")
    r.add_argument("--cases", nargs="+", default=["wall-248"])
    r.add_argument("--min-units", type=int, default=2500)
    r.add_argument("--max-units", type=int, default=None)
    r.add_argument("--out", type=Path, required=True)
    r.add_argument("--dir", type=Path, default=None, help="the captured set (default data/hard)")
    t = act.add_parser("table")
    t.add_argument("files", nargs="+", type=Path)
    t.add_argument("--rules", nargs="+", default=None, help=f"of: {', '.join(RULES)}")


def main(args) -> None:
    if args.action == "record":
        record(args.cases, args.min_units, args.max_units, args.out, args.dir)
    else:
        table(args.files, args.rules)
