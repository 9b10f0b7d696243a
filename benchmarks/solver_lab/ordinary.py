"""First-stage variants of the accelerated sweep on a trajectory sample (ordinary steps).

    python -m benchmarks.solver_lab trajectory --case wall-248 --every 5
    python -m benchmarks.solver_lab ordinary --case wall-248 [--variants NAME …] [--repeat 3]

Every kept step of ``data/trajectory/<case>`` is solved again by each variant from its warm start, with
the engine's stopping test (in-sweep RMS residual ≤ 1e-5 m/s) and the momentum's stall window (500
sweeps without a new low: such a step would go to stalled.py; it is counted "stalled" with the sweeps
done). The kernel below is the engine's ``momentum._nlgs_accelerated`` with its constants turned into
arguments (numba freezes globals at compile time, so a variant needs no process or cache of its own), on
the contacts in the engine's interleaved order: with the engine's parameters it is the engine's solve
(sweeps, v and r bit for bit: the "engine" row and tests/test_solver_lab_ordinary.py). Parameters:

    a            β = (j − 1)/(j + a): the engine's a = 2 (Nesterov); larger a, less momentum
    beta_cap     β ≤ beta_cap ("fixed-B": a = −0.999, β = B from the second sweep after a restart)
    omega        the local solution relaxed: r = r_y + ω (r_loc − r_y), clipped into the cone (the
                 residual is still the law's, W (r_loc − r_y))
    plain_first  that many plain sweeps (β = 0) before the momentum starts
    growth       restart when a sweep's residual > growth × the previous one (the engine's 1.1)
    keep         at a restart j ← max(1, keep · j) instead of 1 (0: the engine's full restart)
    jmin         no restart before the j-th sweep since the last one
    local        a contact whose status changed in a sweep carries no momentum into the next (v_prev moved
                 by its share, so v = v(r) still holds)
    probe, mode  once the residual ≤ probe × tolerance, a plain sweep (β = 0) after each accelerated one,
                 the momentum then resumed, restarted, or ended ("off")
    check        once the in-sweep residual ≤ check × tolerance, one pass computes the law residual of the
                 iterate itself (v, r) (no pushes); the step stops when that is ≤ the tolerance. A check is
                 counted as one sweep unit. ("check-low": only at a new lowest in-sweep residual)
    gamma        warm start extrapolated along persistent contacts, r0 = r_{n−1} + γ (r_{n−1} − r_{n−2}),
                 clipped into the cone (γ = 0: the engine's warm start)
    order        the sweep order (sweep_orders.ORDERS)

``skipping.solve_skipping`` measures another idea, leaving contacts open by a margin out of the sweeps.

Reported per variant, over the sample: total sweeps (deterministic; all steps and the ordinary ones,
i.e. those the engine's momentum converged without stalling), the geometric mean of the per-step ratio
to the engine's sweeps and how many steps took fewer / more, steps stalled, CPU s of the whole sample
(kernel calls only; minimum of interleaved rounds), and the velocity error against a tight solve of each
step (momentum to 1e-7 m/s in-sweep RMS, cap 20 000, cached in references.npz; RMS over the blocks'
velocities, mean over the steps) with the mean signed x-velocity error of the blocks (a bias accumulates
into slips). A kept step starts from the engine run's warm start: what a variant's savings become once
its own warm starts follow is measured by ``ordinary_runs.py``.
"""

from __future__ import annotations

import time

import numpy as np

from benchmarks.solver_lab.sweep_orders import ORDERS, sweep_order
from benchmarks.solver_lab.trajectory import TRAJECTORY
from masonrycli.engine import nlgs
from masonrycli.engine._jit import njit
from masonrycli.engine.nlgs import P_WNN, P_WTN, P_WTT, _local_solve, _push, _relative_velocity

TOLERANCE = 1e-5
STALL = 500
CAP = 50_000
REF_TOLERANCE, REF_CAP = 1e-7, 20_000

ENGINE = dict(
    a=2.0, beta_cap=1.0, omega=1.0, plain_first=0, growth=1.1, keep=0.0, probe=0.0, probe_mode=0, local=0,
    jmin=0.0, check=0.0, check_new_low=0, gamma=0.0, order="engine",
)  # fmt: skip
VARIANTS: dict[str, dict] = {"engine": {}}
VARIANTS |= {f"gamma-{g:g}": {"gamma": g} for g in (0.25, 0.5, 1.0)}
VARIANTS |= {f"a-{a:g}": {"a": a} for a in (-0.8, -0.5, 0.0, 0.5, 1.0, 1.5, 3.0, 4.0, 5.0)}
VARIANTS |= {f"cap-{c:g}": {"beta_cap": c} for c in (0.8, 0.9, 0.95, 0.98)}
VARIANTS |= {f"fixed-{c:g}": {"a": -0.999, "beta_cap": c} for c in (0.8, 0.9, 0.95)}
VARIANTS |= {f"omega-{w:g}": {"omega": w} for w in (0.9, 1.1, 1.2, 1.3)}
VARIANTS |= {f"plain-{p}": {"plain_first": p} for p in (2, 5, 10)}
VARIANTS |= {f"growth-{g:g}": {"growth": g} for g in (1.02, 1.05, 1.15, 1.2)}
VARIANTS |= {f"keep-{k:g}": {"keep": k} for k in (0.25, 0.5)}
VARIANTS |= {f"jmin-{k}": {"jmin": float(k)} for k in (3, 5, 10)}
VARIANTS |= {"local": {"local": 1}, "local-a-1": {"local": 1, "a": 1.0}}
VARIANTS |= {"local-growth-1.2": {"local": 1, "growth": 1.2}}
VARIANTS |= {
    f"probe-{k:g}-{m}": {"probe": k, "probe_mode": i}
    for k in (1.5, 2.0, 3.0, 5.0)
    for i, m in enumerate(("resume", "restart", "off"))
}
VARIANTS |= {f"check-{k:g}": {"check": k} for k in (1.2, 1.5, 3.0)}
VARIANTS |= {f"check-low-{k:g}": {"check": k, "check_new_low": 1} for k in (1.5, 2.0, 3.0)}
VARIANTS |= {f"a-{a:g}-check-1.2": {"a": a, "check": 1.2} for a in (0.0, -0.5)}
VARIANTS |= {f"a-0-growth-{g:g}": {"a": 0.0, "growth": g} for g in (1.05, 1.15)}
VARIANTS |= {f"a-0-cap-{c:g}": {"a": 0.0, "beta_cap": c} for c in (0.9, 0.95, 0.98)}
VARIANTS |= {"a-1-gamma-0.25": {"a": 1.0, "gamma": 0.25}}
VARIANTS |= {f"order-{o}": {"order": o} for o in ORDERS[1:]}


@njit(cache=False)  # the engine's flags (masonrycli/engine/_jit.py); not cached: a lab copy
def _accelerated(
    body,
    pack,
    count,
    mu,
    tolerance,
    max_iterations,
    v,
    r,
    status,
    stall_after,
    a,
    beta_cap,
    omega,
    plain_first,
    growth,
    keep,
    probe,
    probe_mode,
    local,
    jmin,
    check,
    check_new_low,
    history,
    norm_count=0,
):
    # momentum._nlgs_accelerated (flip=False) with its constants as arguments, plus ω, plain_first, keep.
    for c in range(count):
        _push(v, body[c, 0], body[c, 1], pack, c, r[c, 0], r[c, 1])
    iterations = 0
    residual = 0.0
    if count == 0:
        return iterations, residual
    v_prev = v.copy()
    v_flat = v.reshape(v.size)
    v_prev_flat = v_prev.reshape(v.size)
    rr = np.empty((count, 4))
    for c in range(count):
        rr[c, 0] = rr[c, 2] = r[c, 0]
        rr[c, 1] = rr[c, 3] = r[c, 1]
    best = np.inf
    best_at = 0
    last = np.inf
    st_prev = np.full(count, -1, dtype=np.int64)
    j = 1.0
    beta = 0.0
    probing = False
    off = False
    checks = 0
    for it in range(max_iterations):
        iterations = it + 1
        for i in range(v_flat.shape[0]):
            x = v_flat[i]
            v_flat[i] = x + beta * (x - v_prev_flat[i])
            v_prev_flat[i] = x
        sum_e2 = 0.0
        for c in range(count):
            ba = body[c, 0]
            bb = body[c, 1]
            ut, un = _relative_velocity(v, ba, bb, pack, c)
            xt = rr[c, 0]
            xn = rr[c, 1]
            rt0 = xt + beta * (xt - rr[c, 2])
            rn0 = xn + beta * (xn - rr[c, 3])
            rr[c, 2] = xt
            rr[c, 3] = xn
            wtt = pack[c, P_WTT]
            wtn = pack[c, P_WTN]
            wnn = pack[c, P_WNN]
            ut -= wtt * rt0 + wtn * rn0
            un -= wtn * rt0 + wnn * rn0
            lt, ln, st = _local_solve(ut, un, pack, c, mu)
            status[c] = st
            rt, rn = lt, ln
            if omega != 1.0:
                rn = rn0 + omega * (ln - rn0)
                if rn < 0.0:
                    rn = 0.0
                rt = rt0 + omega * (lt - rt0)
                lim = mu * rn
                if rt > lim:
                    rt = lim
                elif rt < -lim:
                    rt = -lim
            rr[c, 0] = rt
            rr[c, 1] = rn
            if local and st != st_prev[c]:
                # local restart: this contact carries no momentum into the next sweep; v_prev moved by
                # its share of v − v_prev keeps v_prev = v(r_prev) (the extrapolation stays consistent)
                _push(v_prev, ba, bb, pack, c, rt - rr[c, 2], rn - rr[c, 3])
                rr[c, 2] = rt
                rr[c, 3] = rn
            st_prev[c] = st
            drt = rt - rt0
            drn = rn - rn0
            if drt != 0.0 or drn != 0.0:
                _push(v, ba, bb, pack, c, drt, drn)
                dlt = lt - rt0
                dln = ln - rn0
                et = wtt * dlt + wtn * dln
                en = wtn * dlt + wnn * dln
                sum_e2 += et * et + en * en
        residual = np.sqrt(sum_e2 / (norm_count if norm_count > 0 else count))
        if it < history.shape[0]:
            history[it] = residual
        if residual <= tolerance:
            break
        if check > 0.0 and residual <= check * tolerance and (check_new_low == 0 or residual < best):
            # the law residual of the iterate itself (v, r): one pass without pushes
            s2 = 0.0
            for c in range(count):
                ut, un = _relative_velocity(v, body[c, 0], body[c, 1], pack, c)
                xt = rr[c, 0]
                xn = rr[c, 1]
                wtt = pack[c, P_WTT]
                wtn = pack[c, P_WTN]
                wnn = pack[c, P_WNN]
                lt, ln, _ = _local_solve(ut - wtt * xt - wtn * xn, un - wtn * xt - wnn * xn, pack, c, mu)
                dlt = lt - xt
                dln = ln - xn
                et = wtt * dlt + wtn * dln
                en = wtn * dlt + wnn * dln
                s2 += et * et + en * en
            checks += 1
            if np.sqrt(s2 / count) <= tolerance:
                residual = np.sqrt(s2 / count)
                break
        if residual < best:
            best = residual
            best_at = it
        elif tolerance > 0.0 and it - best_at >= stall_after:
            break
        if residual > growth * last and not probing and j >= jmin:
            j = max(1.0, np.floor(keep * j))
        last = residual
        beta = 0.0 if it + 1 < plain_first else min(beta_cap, (j - 1.0) / (j + a))
        if it + 1 >= plain_first:
            j += 1.0
        # probe: near the tolerance, a plain sweep measures the iterate's own violation (not the
        # extrapolated point's); mode 0 resumes the momentum after it, 1 restarts it, 2 ends it
        if off:
            beta = 0.0
        elif probe > 0.0 and residual <= probe * tolerance and not probing:
            beta = 0.0
            probing = True
            if probe_mode == 1:
                j = 2.0
            elif probe_mode == 2:
                off = True
        else:
            probing = False
    for c in range(count):
        r[c, 0] = rr[c, 0]
        r[c, 1] = rr[c, 1]
    if history.shape[0] > 0:
        history[-1] = checks
    return iterations + checks, residual  # a check counted as one sweep unit (it reads what a sweep reads)


KERNEL_PARAMETERS = (
    "a",
    "beta_cap",
    "omega",
    "plain_first",
    "growth",
    "keep",
    "probe",
    "probe_mode",
    "local",
    "jmin",
    "check",
    "check_new_low",
)
"""The variant parameters in the order _accelerated takes them (after stall_after)."""


def kernel_args(params: dict) -> tuple:
    q = ENGINE | params
    return tuple(q[k] for k in KERNEL_PARAMETERS)


class Step:
    """One kept step; its contacts in a given sweep order (``arrays``)."""

    def __init__(self, path):
        z = np.load(path)
        self.raw = {k: z[k] for k in ("body", "pack", "r_warm", "r_prev2", "has_prev2", "point")}
        self.step, self.engine_sweeps, self.stalled = int(z["step"]), int(z["sweeps"]), bool(z["stalled"])
        self.v_free = z["v_free"]
        self.mu = float(z["mu"])
        self.v_ref = None
        self._by_order = {}

    @property
    def count(self) -> int:
        return self.raw["body"].shape[0]

    def arrays(self, order: str):
        if order not in self._by_order:
            o = sweep_order(order, self.raw["point"], self.raw["body"])
            d = {k: np.ascontiguousarray(a[o]) for k, a in self.raw.items()}
            d["body"] = d["body"].astype(np.uint32)
            self._by_order[order] = d
        return self._by_order[order]

    def start(self, d: dict, gamma: float) -> np.ndarray:
        r = d["r_warm"].copy()
        if gamma:
            h = d["has_prev2"]
            r[h] += gamma * (d["r_warm"][h] - d["r_prev2"][h])
            r[:, 1] = np.maximum(r[:, 1], 0.0)
            lim = self.mu * r[:, 1]
            r[:, 0] = np.clip(r[:, 0], -lim, lim)
        return r

    def solve(self, p: dict, tolerance=TOLERANCE, cap=CAP, stall=STALL, history=None):
        q = ENGINE | p
        d = self.arrays(q["order"])
        r = self.start(d, q["gamma"])
        v = self.v_free.copy()
        status = np.zeros(self.count, dtype=np.int8)
        its, res = _accelerated(
            d["body"],
            d["pack"],
            self.count,
            self.mu,
            tolerance,
            cap,
            v,
            r,
            status,
            stall,
            *kernel_args(p),
            np.zeros(0) if history is None else history,
        )
        return its, res, v, r


def _blocks(step: Step) -> np.ndarray:
    """Rows of v that are blocks (a support has inverse mass 0 in every contact it is in)."""
    n = step.v_free.shape[0]
    dyn = np.zeros(n, dtype=bool)
    for side, col in ((0, nlgs.P_IMA), (1, nlgs.P_IMB)):
        dyn[step.raw["body"][:, side]] |= step.raw["pack"][:, col] > 0
    return dyn


def references(case: str, steps: list[Step]) -> None:
    """Give each step ``v_ref`` (the tight solve's velocities: momentum to REF_TOLERANCE, cap REF_CAP, cached
    in the sample's references.npz), ``ref_ok`` (it reached REF_TOLERANCE) and ``blocks`` (rows of v that are
    blocks)."""
    cached = TRAJECTORY / case / "references.npz"
    refs = dict(np.load(cached)) if cached.exists() else {}
    for s in steps:
        if f"v{s.step}" not in refs:
            _, res, v, _ = s.solve({}, REF_TOLERANCE, REF_CAP, REF_CAP)
            refs[f"v{s.step}"], refs[f"res{s.step}"] = v, res
        s.v_ref, s.ref_ok = refs[f"v{s.step}"], refs[f"res{s.step}"] <= REF_TOLERANCE
        s.blocks = _blocks(s)
    np.savez(cached, **refs)


def table(case: str, names: list[str] | None, repeat: int) -> None:
    steps = [Step(p) for p in sorted((TRAJECTORY / case).glob("step-*.npz"))]
    names = names or list(VARIANTS)
    t = time.process_time()
    references(case, steps)
    print(
        f"{len(steps)} steps of {case}; references in {time.process_time() - t:.1f} s CPU,"
        f" {sum(not s.ref_ok for s in steps)} above {REF_TOLERANCE:g} m/s at {REF_CAP} sweeps",
        flush=True,
    )
    rows = {}
    for name in names:
        its = np.zeros(len(steps), dtype=np.int64)
        stalled = np.zeros(len(steps), dtype=bool)
        err = np.zeros(len(steps))
        bias = np.zeros(len(steps))
        for i, s in enumerate(steps):
            n, res, v, _ = s.solve(VARIANTS[name])
            its[i], stalled[i] = n, res > TOLERANCE
            d = (v - s.v_ref)[s.blocks]
            err[i] = np.sqrt((d[:, 0] ** 2 + d[:, 1] ** 2).mean())
            bias[i] = d[:, 0].mean()
        rows[name] = dict(its=its, stalled=stalled, err=err, bias=bias, cpu=np.inf)
    engine = rows.get("engine")
    ordinary = np.array([not s.stalled for s in steps])
    if engine is not None:
        mismatch = [s.step for s, n in zip(steps, engine["its"]) if not s.stalled and n != s.engine_sweeps]
        print(f"engine variant vs the run's sweep counts on ordinary steps: {len(mismatch)} differ {mismatch[:10]}")
    for _ in range(repeat):
        for name in names:
            t = time.process_time()
            for s in steps:
                s.solve(VARIANTS[name])
            rows[name]["cpu"] = min(rows[name]["cpu"], time.process_time() - t)
    base = engine["its"][ordinary].sum() if engine is not None else np.nan
    base_cpu = engine["cpu"] if engine is not None else np.nan
    print(
        "| variant | sweeps, all steps | ordinary steps | ÷ engine | per step ÷ engine (geo. mean) |"
        " steps fewer / more | stalled | CPU s | ÷ engine | velocity error RMS m/s (mean) | vx bias m/s (mean) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name in names:
        row = rows[name]
        o = row["its"][ordinary].sum()
        ratio = row["its"][ordinary] / engine["its"][ordinary]
        paired = f"{np.exp(np.log(ratio).mean()):.3f} | {(ratio < 1).sum()} / {(ratio > 1).sum()}"
        print(
            f"| {name} | {row['its'].sum()} | {o} | {o / base:.3f} | {paired} | {row['stalled'].sum()} |"
            f" {row['cpu']:.3f} | {row['cpu'] / base_cpu:.3f} | {row['err'].mean():.2e} |"
            f" {row['bias'].mean():+.2e} |",
            flush=True,
        )
