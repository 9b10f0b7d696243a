"""Run methods on the captured problems: iterations in sweep units, CPU ms, velocity error, law residual.

For each problem the harness first measures the CPU time of one engine NLGS sweep (``sweep_s``: 200
sweeps from the warm start in one kernel call, minimum of the repeats) so that any method's work can
be read in Gauss–Seidel sweeps; likewise, interleaved with it, that of one accelerated sweep (solver
"nlgs-accel"), whose ratio to the plain one (``accel_cost``) converts accelerated sweeps. Methods run interleaved (``repeat`` rounds over all methods); the
CPU-time minimum of each method's rounds is kept. Accuracy is taken on the impulses the method returns:
v(r) = v_free + M⁻¹ H r is re-derived, and both the velocity error against the reference and the
contact-law residual are measured on (v(r), r); a method whose own v differs from v(r) by more than
1e-9 m/s is flagged ("v≠v(r)").
"""

from __future__ import annotations

import json
import platform
import subprocess
import time
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from benchmarks.solver_lab import law
from benchmarks.solver_lab.methods import gauss_seidel
from benchmarks.solver_lab.outcome import Context
from benchmarks.solver_lab.problems import load_all
from masonrycli.engine import dispatch

METHODS = dict(gauss_seidel.METHODS)
DEFAULT_METHODS = [
    "nlgs",
    "nlgs-oracle",
    "nlgs-law",
    "nlgs-predict",
    "nlgs-predict-half",
    "nlgs-cold",
    "anderson-v",
    "ssn-v",
    "alm-newton",
    "nlgs-cluster",
    "nlgs-linear",
    "nlgs-accel",
]
TARGET = 1e-5
"""m/s: the RMS contact-law residual every method is stopped at (``nlgs``: the engine's own test)."""
RESULTS = Path(__file__).resolve().parent / "results.json"


def _register_optional():
    # Methods in their own modules; imported here so the table runs them by name.
    from benchmarks.solver_lab.methods import (
        accelerated,
        alart_curnier,
        alm_newton,
        anderson,
        cluster,
        cpg,
        galerkin,
        ipm,
        ipm_lcp,
        ipm_shift,
        joint,
        linear,
        lines,
        newton,
        normal_slip,
        schwarz,
        slip,
        tnnmg,
    )

    for module in (
        anderson,
        newton,
        alm_newton,
        cluster,
        linear,
        accelerated,
        tnnmg,
        alart_curnier,
        joint,
        ipm,
        ipm_lcp,
        ipm_shift,
        cpg,
        lines,
        galerkin,
        schwarz,
        slip,
        normal_slip,
    ):
        METHODS.update(module.METHODS)


def sweep_seconds(ctx: Context, repeat: int, n: int = 200) -> dict[str, float]:
    """CPU seconds per sweep of the plain and the accelerated engine sweep ("nlgs", "nlgs-accel"): ``n``
    sweeps from the warm start in one kernel call (fewer if an iterate is exactly a fixed point; the
    count done is used), minimum of ``repeat`` interleaved rounds."""
    p = ctx.p
    best = {"nlgs": np.inf, "nlgs-accel": np.inf}
    for _ in range(repeat):
        for solver in best:
            r, v = p.r_warm.copy(), p.v_free.copy()
            t = time.process_time()
            done, _ = dispatch.solve(
                p.body, ctx.pack, p.count, p.shim(0.0, n, solver), v, r, np.zeros(p.count, np.int8)
            )
            best[solver] = min(best[solver], (time.process_time() - t) / max(done, 1))
    return best


def measure(ctx: Context, method: str, target: float) -> dict:
    t = time.process_time()
    out = METHODS[method](ctx, target)
    cpu = time.process_time() - t if out.cpu_s is None else out.cpu_s
    p = ctx.p
    v_r = law.velocity_from_impulse(p, ctx.H, out.r)
    mismatch = float(np.abs(out.v - v_r).max(initial=0.0))
    return {
        "method": method,
        "problem": p.name,
        "iterations": out.iterations,
        "detail": out.detail,
        "sweeps": out.sweeps,
        "cpu_ms": 1e3 * cpu,
        "phases_ms": {k: 1e3 * s for k, s in out.phases.items()},
        "v_error": law.velocity_error(p, v_r),
        "law_residual": ctx.residual(v_r, out.r),
        "law_residual_max": ctx.residual_max(v_r, out.r),
        "converged": bool(out.converged),
        "v_mismatch": mismatch,
    }


def _fmt_phases(ph: dict) -> str:
    return ", ".join(f"{k} {v:.2f}" for k, v in ph.items())


def run_table(methods: list[str] | None, problems: list[str] | None, repeat: int, target: float = TARGET):
    _register_optional()
    methods = methods or DEFAULT_METHODS
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise SystemExit(f"unknown method {', '.join(unknown)} (have: {', '.join(METHODS)})")
    rows = []
    head = (
        "| problem | blocks | contacts | method | iterations | sweep units | CPU ms (phases) | velocity error m/s"
        " | law residual RMS / max m/s |\n|---|---|---|---|---|---|---|---|---|"
    )
    print(head, flush=True)
    for prob in load_all(problems):
        ctx = Context(prob)
        per_sweep = sweep_seconds(ctx, repeat)
        ctx.sweep_s = per_sweep["nlgs"]
        ctx.accel_cost = per_sweep["nlgs-accel"] / per_sweep["nlgs"]
        best: dict[str, dict] = {}
        for _ in range(repeat):
            for m in methods:
                with np.errstate(all="ignore"):  # diverging methods overflow; their rows say so
                    row = measure(ctx, m, target)
                if m not in best or row["cpu_ms"] < best[m]["cpu_ms"]:
                    best[m] = row
        for m in methods:
            row = best[m]
            row.update(
                blocks=prob.blocks,
                contacts=prob.count,
                sweep_ns=1e9 * ctx.sweep_s,
                accel_cost=ctx.accel_cost,
                step=prob.step,
                ref_sweeps=prob.ref_sweeps,
                ref_residual=prob.ref_residual,
                v_scale=law.velocity_scale(prob),
            )
            if m != "nlgs" and not m.startswith("nlgs-"):
                row["sweeps"] = row["cpu_ms"] * 1e-3 / ctx.sweep_s
            rows.append(row)
            flag = "" if row["converged"] else " (not converged)"
            flag += " v≠v(r)" if row["v_mismatch"] > 1e-9 else ""
            print(
                f"| {prob.name} | {prob.blocks} | {prob.count} | {m}{flag} | {row['iterations']}{' (' + row['detail'] + ')' if row['detail'] else ''} | {row['sweeps']:.0f} |"
                f" {row['cpu_ms']:.2f} ({_fmt_phases(row['phases_ms'])}) | {row['v_error']:.1e} |"
                f" {row['law_residual']:.1e} / {row['law_residual_max']:.1e} |",
                flush=True,
            )
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    meta = {
        "date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "commit": commit,
        "machine": platform.processor() or platform.machine(),
        "target_m_s": target,
        "repeat": repeat,
    }
    RESULTS.write_text(json.dumps({"meta": meta, "rows": rows}, indent=1))
    print(f"\n{meta['date']}, commit {commit}, target {target:g} m/s, CPU-time minimum of {repeat} interleaved runs")
    print_growth(rows)


def print_growth(rows: list[dict]) -> None:
    """Sweep units per method on the wall series (8 → 64 courses), cold, typical and hard steps (also those
    of a capture with another solver, ``typical-nlgs`` …), and the ratio."""
    heights = [8, 16, 32, 64]
    by = {(r["method"], r["problem"]): r for r in rows}
    methods = list(dict.fromkeys(r["method"] for r in rows))
    kinds = list(dict.fromkeys(r["problem"].split("-", 2)[2] for r in rows if r["problem"].startswith("wall-")))
    print("\n| method | step | " + " | ".join(f"{h} courses" for h in heights) + " | 64 / 8 |")
    print("|---|---|" + "---|" * (len(heights) + 1))
    for m in methods:
        for kind in kinds:
            cells = [by.get((m, f"wall-{h}-{kind}")) for h in heights]
            if not any(cells):
                continue
            text = ["–" if c is None else f"{c['sweeps']:.0f}{'' if c['converged'] else '*'}" for c in cells]
            ratio = f"{cells[-1]['sweeps'] / cells[0]['sweeps']:.1f}" if cells[0] and cells[-1] else "–"
            print(f"| {m} | {kind} | " + " | ".join(text) + f" | {ratio} |")
    print("(* not converged within the method's cap)")
