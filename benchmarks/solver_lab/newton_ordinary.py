"""Newton-type steps on ordinary steps (issue 10): can one Newton step plus a few sweeps replace momentum?

    python -m benchmarks.solver_lab trajectory --case wall-248 --every 5 --name nwt-wall-248
    python -m benchmarks.solver_lab newton-ordinary --sample nwt-wall-248 [--every 4] [--variants NAME …]

On the ordinary steps of a trajectory sample (``trajectory.py``: the engine's momentum converged them
without stalling), from each step's warm start, every variant ends on the engine's accelerated sweeps
(``dispatch.first_stage``, stall window 500, cap 20 000) until the engine's stopping test (in-sweep RMS
residual ≤ 1e-5 m/s) holds: what a variant adds must make those sweeps fewer than momentum's alone. Units:
sweeps, plus ``newton.NEWTON_UNITS`` (60) per Newton direction; oracle variants count their sweeps only.

    momentum             the engine (ordinary steps: momentum alone; equals the run's units, checked)
    nK-lL[-ls][-xR][-free]  K momentum sweeps, then a Newton direction of :mod:`masonrycli.engine.newton` at
                         the sweeps' iterate (its Alart–Curnier active set) with shift λ = L, the full step
                         (-ls: Armijo's search on ½|F|² as the engine's) projected into the cone; R such
                         rounds; then the sweeps. K = 0: from the warm start. -free: the cone only
                         before the closing sweeps (R undamped semismooth Newton steps, F's own iterate)
    sK-lL                K momentum sweeps, then one Newton direction on the linear piece the sweeps'
                         statuses name (open: r = 0; stick: u = (0, −b); slip in the direction of r_t:
                         u_n = −b, r_t = ±μ r_n), shift L, full step, cone, sweeps: an active set
                         "frozen from the NLGS statuses" (idea (b) of the issue)
    oracle-v             the velocities of a tight solve (momentum to 1e-9 m/s, 20 000 sweeps) reached
                         exactly by the smallest W⁻¹-weighted impulse change dr (H dr = M Δv, a sparse
                         solve of H W⁻¹ Hᵀ over the blocks' dofs), projected into the cone: what idea (a) of
                         the issue, "keep the Newton step's dv, pick another dr", can give at best
    oracle-s             the converse of oracle-v: the tight solve's impulses moved by the smallest
                         W⁻¹-norm change back to the warm start's velocities (its self-stress, the
                         warm start's motion), projected into the cone
    oracle-pieces-lL-nN  N Levenberg–Marquardt Newton steps (shift L) on the linear piece of the
                         Alart–Curnier function the tight solve lies on (its open / stick / slip set, known
                         in advance): what an exact active-set guess can give

Reported per variant: sweep units over the steps (sum, ÷ momentum's, mean, median, geometric mean of the
per-step ratio, steps better / worse), steps whose closing sweeps stalled (unconverged), the mean final
residual, and the CPU ms per step (one run; indicative only). ``--spread`` prints, per step, how far apart
two tight solves are (from the warm start and from r = 0): the solution set of a hyperstatic wall;
``--feasibility`` how far the oracles' impulses are from the cone and what projecting them does.
"""

from __future__ import annotations

import re
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl

from benchmarks.solver_lab.trajectory import TRAJECTORY
from masonrycli.engine import dispatch, newton, nlgs
from masonrycli.engine.nlgs import P_BIAS, P_IIA, P_IIB, P_IMA, P_IMB, P_WNN, P_WTT

TOLERANCE = 1e-5
STALL, CAP = 500, 20_000
TIGHT = 1e-9
VARIANTS = (
    "momentum",
    "n0-l1e-3",
    "n0-l1e-3-ls",
    "n0-l1e-2",
    "n10-l1e-3",
    "n30-l1e-3",
    "n30-l1e-3-ls",
    "n30-l1e-2",
    "n30-l1e-4",
    "n30-l1e-3-x3",
    "n60-l1e-3",
    "n100-l1e-3",
    "n200-l1e-3",
    "n0-l1e-6",
    "n0-l1e-2-x3-free",
    "n0-l1e-1-x3-free",
    "s30-l1e-3",
    "s100-l1e-3",
    "s200-l1e-3",
    "s100-l3e-3",
    "oracle-v",
    "oracle-s",
    "oracle-pieces-l1e-4-n1",
    "oracle-pieces-l1e-4-n4",
)


class Step:
    """One kept step of a trajectory sample, with the helpers the variants share."""

    def __init__(self, path):
        z = np.load(path)
        self.step, self.recorded, self.stalled = int(z["step"]), int(z["sweeps"]), bool(z["stalled"])
        self.body, self.pack, self.v_free, self.r_warm = z["body"].astype(np.int64), z["pack"], z["v_free"], z["r_warm"]
        self.mu = float(z["mu"])
        self.count = self.body.shape[0]
        self._tight = None

    def sweeps(self, r0, cap=CAP, stall=STALL, tolerance=TOLERANCE):
        """The engine's accelerated sweeps from impulses r0: (sweeps, residual, v, r, status)."""
        v, r, status = self.v_free.copy(), r0.copy(), np.zeros(self.count, np.int8)
        its, res = dispatch.first_stage(self.body, self.pack, self.count, self.mu, tolerance, cap, v, r, status, stall)
        return its, res, v, r, status

    def velocity(self, r):
        v = np.empty_like(self.v_free)
        newton._velocity(self.body, self.pack, self.count, self.v_free, r, v)
        return v

    @property
    def tight(self):
        """(v, r) of momentum to TIGHT m/s from the warm start (cap CAP, no stall window)."""
        if self._tight is None:
            self._tight = self.sweeps(self.r_warm, CAP, CAP, TIGHT)[2:4]
        return self._tight

    def rows(self):
        """H (3B × 2C, columns 2c: t, 2c + 1: n of contact c) and the inverse masses of the 3B dofs."""
        rows, cols, vals = [], [], []
        for c in range(self.count):
            ht, hn = newton._rows(self.pack, c)
            a, b = self.body[c]
            for k in range(6):
                d = 3 * a + k if k < 3 else 3 * b + k - 3
                rows += [d, d]
                cols += [2 * c, 2 * c + 1]
                vals += [ht[k], hn[k]]
        n = self.v_free.shape[0]
        h = sp.csr_matrix((vals, (rows, cols)), shape=(3 * n, 2 * self.count))
        im, ii = np.zeros(n), np.zeros(n)
        for side, (cm, ci) in enumerate(((P_IMA, P_IIA), (P_IMB, P_IIB))):
            im[self.body[:, side]] = self.pack[:, cm]
            ii[self.body[:, side]] = self.pack[:, ci]
        return h, np.stack([im, im, ii], 1).ravel()


def cone(r, mu):
    """r projected into the friction cone: r_n ≥ 0, |r_t| ≤ μ r_n."""
    out = r.copy()
    out[:, 1] = np.maximum(out[:, 1], 0.0)
    lim = mu * out[:, 1]
    out[:, 0] = np.clip(out[:, 0], -lim, lim)
    return out


def _newton_rounds(s: Step, k, lam, search, rounds, free=False):
    units, r = 0, s.r_warm.copy()
    for _ in range(rounds):
        if k > 0:
            its, res, _, r, _ = s.sweeps(r, cap=k)
            units += its
            if res <= TOLERANCE:
                return units, res
        f, jac, merit = newton.phi(s.body, s.pack, s.count, s.mu, s.v_free, r)
        dr = newton.newton_direction(s.body, s.pack, s.count, s.v_free, f, jac, lam)
        units += newton.NEWTON_UNITS
        if dr is None:
            continue
        t = 1.0
        while search and t >= newton.ALPHA_MIN:
            if newton.phi(s.body, s.pack, s.count, s.mu, s.v_free, r + t * dr)[2] <= (1 - 2 * newton.SIGMA * t) * merit:
                break
            t /= 2
        if t >= newton.ALPHA_MIN:
            r = r + t * dr if free else cone(r + t * dr, s.mu)
    its, res = s.sweeps(cone(r, s.mu))[:2]
    return units + its, res


def min_norm_change(s: Step, dv):
    """The impulse change dr (C, 2) of smallest W⁻¹-weighted norm that moves the blocks' velocities by
    ``dv`` (B, 3): H dr = M dv on the blocks' dofs (a sparse solve of H W⁻¹ Hᵀ)."""
    h, minv = s.rows()
    dyn = minv > 0
    w = sp.diags(np.stack([1 / s.pack[:, P_WTT], 1 / s.pack[:, P_WNN]], 1).ravel())
    hd = h[dyn]
    y = spl.spsolve((hd @ w @ hd.T).tocsc(), dv.ravel()[dyn] / minv[dyn])
    return (w @ (hd.T @ y)).reshape(-1, 2)


def _oracle_v(s: Step):
    v_ref, _ = s.tight
    dr = min_norm_change(s, v_ref - s.velocity(s.r_warm))
    return s.sweeps(cone(s.r_warm + dr, s.mu))[:2]


def _oracle_s(s: Step):
    v_ref, r_ref = s.tight
    dr = min_norm_change(s, s.velocity(s.r_warm) - v_ref)
    return s.sweeps(cone(r_ref + dr, s.mu))[:2]


def _oracle_pieces(s: Step, lam, n):
    # F on the tight solve's linear piece: F_piece(r) = F(r_ref) + A Hᵀ (v(r) − v_ref) + B (r − r_ref).
    v_ref, r_ref = s.tight
    f_ref, jac, _ = newton.phi(s.body, s.pack, s.count, s.mu, s.v_free, r_ref)
    j = newton

    def piece(r):
        du = np.array(
            [
                nlgs._relative_velocity(s.velocity(r) - v_ref, s.body[c, 0], s.body[c, 1], s.pack, c)
                for c in range(s.count)
            ]
        )
        d = r - r_ref
        f = np.empty((s.count, 2))
        f[:, 0] = f_ref[:, 0] + jac[:, j.J_AT] * du[:, 0] + jac[:, j.J_ATN] * du[:, 1] + jac[:, j.J_BT] * d[:, 0]
        f[:, 0] += jac[:, j.J_BTN] * d[:, 1]
        f[:, 1] = f_ref[:, 1] + jac[:, j.J_AN] * du[:, 1] + jac[:, j.J_BN] * d[:, 1]
        return f

    r = s.r_warm.copy()
    for _ in range(n):
        r = r + newton.newton_direction(s.body, s.pack, s.count, s.v_free, piece(r), jac, lam)
    return s.sweeps(cone(r, s.mu))[:2]


def _piece(s: Step, status, r):
    # Jacobian pieces (newton.J_*) of the linear piece the statuses name; slip's σ = sign(r_t).
    wt, wn, mu, j = s.pack[:, P_WTT], s.pack[:, P_WNN], s.mu, newton
    jac = np.zeros((s.count, 6))
    op, sk, sl = (status == nlgs.STATUS_OPEN), (status == nlgs.STATUS_STICK), (status == nlgs.STATUS_SLIP)
    sig = np.sign(r[:, 0])
    jac[op, j.J_BT], jac[op, j.J_BN] = wt[op], wn[op]
    jac[sk, j.J_AT], jac[sk, j.J_AN] = 1.0, 1.0
    jac[sl, j.J_AN], jac[sl, j.J_BT] = 1.0, wt[sl]
    jac[sl, j.J_ATN], jac[sl, j.J_BTN] = (wt / wn * mu * sig)[sl], (-wt * mu * sig)[sl]
    return jac


def _piece_value(s: Step, jac, r):
    # F on that piece: A (u + (0, b)) + B r (the Alart–Curnier function where the piece is the active one).
    j = newton
    v = s.velocity(r)
    u = np.array([nlgs._relative_velocity(v, s.body[c, 0], s.body[c, 1], s.pack, c) for c in range(s.count)])
    un = u[:, 1] + s.pack[:, P_BIAS]
    f = np.empty((s.count, 2))
    f[:, 0] = jac[:, j.J_AT] * u[:, 0] + jac[:, j.J_ATN] * un + jac[:, j.J_BT] * r[:, 0] + jac[:, j.J_BTN] * r[:, 1]
    f[:, 1] = jac[:, j.J_AN] * un + jac[:, j.J_BN] * r[:, 1]
    return f


def _status_piece(s: Step, k, lam):
    its, res, _, r, status = s.sweeps(s.r_warm, cap=k)
    if res <= TOLERANCE:
        return its, res
    jac = _piece(s, status, r)
    dr = newton.newton_direction(s.body, s.pack, s.count, s.v_free, _piece_value(s, jac, r), jac, lam)
    if dr is not None:
        r = cone(r + dr, s.mu)
    n, res = s.sweeps(r)[:2]
    return its + newton.NEWTON_UNITS + n, res


def run_variant(s: Step, name: str):
    """(units, final residual) of variant ``name`` on step ``s`` (module doc)."""
    if name == "momentum":
        return s.sweeps(s.r_warm)[:2]
    if name == "oracle-v":
        return _oracle_v(s)
    if name == "oracle-s":
        return _oracle_s(s)
    m = re.fullmatch(r"oracle-pieces-l([0-9.e-]+)-n(\d+)", name)
    if m:
        return _oracle_pieces(s, float(m[1]), int(m[2]))
    m = re.fullmatch(r"s(\d+)-l([0-9.e-]+)", name)
    if m:
        return _status_piece(s, int(m[1]), float(m[2]))
    m = re.fullmatch(r"n(\d+)-l([0-9.e-]+?)(-ls)?(?:-x(\d+))?(-free)?", name)
    if not m:
        raise SystemExit(f"unknown variant {name}")
    return _newton_rounds(s, int(m[1]), float(m[2]), bool(m[3]), int(m[4] or 1), bool(m[5]))


def spread(steps) -> None:
    for s in steps:
        v_a, r_a = s.tight
        _, res0, v_0, r_0, _ = s.sweeps(np.zeros_like(s.r_warm), CAP, CAP, TIGHT)
        print(
            f"step {s.step}: two tight solves (from the warm start / from 0, residuals"
            f" {max(res0, TIGHT):.1e} m/s at most): |Δv| max {np.abs(v_a - v_0).max():.1e} m/s (rad/s),"
            f" |Δr| max {np.abs(r_a - r_0).max():.1e} N·s",
            flush=True,
        )


def feasibility(steps, lam=1e-4, n=4) -> None:
    """Why the oracles do not finish a step: how far their impulses are from the cone, and what the cone
    projection then does to the velocities (max over the dofs, m/s or rad/s)."""
    for s in steps:
        v_ref, r_ref = s.tight
        r = s.r_warm + min_norm_change(s, v_ref - s.velocity(s.r_warm))
        rc = cone(r, s.mu)
        line = (
            f"step {s.step}: oracle-v: the cone moves r by {np.abs(rc - r).max():.1e} N·s, v by"
            f" {np.abs(s.velocity(rc) - v_ref).max():.1e};"
        )
        jac = _piece(s, s.sweeps(r_ref, cap=1)[4], r_ref)
        r = s.r_warm.copy()
        for _ in range(n):
            r = r + newton.newton_direction(s.body, s.pack, s.count, s.v_free, _piece_value(s, jac, r), jac, lam)
        rc = cone(r, s.mu)
        print(
            f"{line} oracle-pieces-l{lam:g}-n{n}: |F_piece| {np.abs(_piece_value(s, jac, r)).max():.1e} m/s,"
            f" r_n < 0 at {(r[:, 1] < -1e-9).sum()} and |r_t| > μ r_n at"
            f" {(np.abs(r[:, 0]) > s.mu * r[:, 1] + 1e-9).sum()} of {s.count} contacts, the cone moves r by"
            f" {np.abs(rc - r).max():.1e} N·s, v by {np.abs(s.velocity(rc) - s.velocity(r)).max():.1e}",
            flush=True,
        )


def table(sample: str, every: int, names: list[str] | None, show_spread: bool, show_feasibility=False) -> None:
    paths = sorted((TRAJECTORY / sample).glob("step-*.npz"))
    steps = [s for s in (Step(p) for p in paths) if not s.stalled][::every]
    names = names or list(VARIANTS)
    base = None
    print(f"{sample}: {len(steps)} ordinary steps (every {every}-th of {len(paths)} kept)", flush=True)
    print("| variant | units (sum) | ÷ momentum | mean | median | per step ÷ (geo. mean) | better / worse |"
          " unconverged | residual (mean) m/s | CPU ms / step |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name in names:
        t = time.process_time()
        out = np.array([run_variant(s, name) for s in steps])
        ms = (time.process_time() - t) / len(steps) * 1e3
        units, res = out[:, 0], out[:, 1]
        if base is None:
            base = units
            recorded = np.array([s.recorded for s in steps])
            assert name != "momentum" or (units == recorded).all(), "the sample is not this engine's"
        ratio = units / base
        print(
            f"| {name} | {units.sum():.0f} | {units.sum() / base.sum():.3f} | {units.mean():.0f} |"
            f" {np.median(units):.0f} | {np.exp(np.log(ratio).mean()):.3f} | {(ratio < 1).sum()} /"
            f" {(ratio > 1).sum()} | {(res > TOLERANCE).sum()} | {res.mean():.1e} | {ms:.1f} |",
            flush=True,
        )
    if show_spread:
        spread(steps[:: max(1, len(steps) // 6)])
    if show_feasibility:
        feasibility(steps[:: max(1, len(steps) // 8)])
