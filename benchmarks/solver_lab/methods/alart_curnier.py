"""Globalised Alart–Curnier semismooth Newton on the full Signorini–Coulomb law: ``ac``, ``ac-gs10`` …

Unknowns: the impulses r (2C: (r_t, r_n) per contact); v(r) = v_free + M⁻¹ Hᵀ r, u = H v(r). Per contact,
with ρ = 1/W_αα (per component: ρ_t = 1/W_tt, ρ_n = 1/W_nn) and the Signorini bias b,

    Φ_n = r_n − max(0, r_n − ρ_n (u_n + b))                      (Signorini: r_n ≥ 0 ⊥ u_n + b ≥ 0)
    Φ_t = r_t − proj_[−s, s](r_t − ρ_t u_t),   s = μ max(r_n, 0)  (Coulomb; ``augmented``: s = μ max(x, 0),
                                                                    x = r_n − ρ_n (u_n + b), AC's original)

Φ = 0 exactly on the lab's contact law (law.py); unlike ``tnnmg`` the threshold s is linearised too. The
residual is used in velocity units, F = W_αα Φ (m/s per component), so ½|F|² weighs contacts like the
lab's law residual. Generalised Jacobian F' = A H M⁻¹ Hᵀ + B, A = ∂F/∂u and B = ∂F/∂r upper-triangular
2×2 per contact (W = the W_αα diagonal entry):

    normal closed (x > 0):                ∂F_n/∂u_n = 1        else ∂F_n/∂r_n = W_nn
    tangent stick (|r_t − ρ_t u_t| < s):  ∂F_t/∂u_t = 1        else ∂F_t/∂r_t = W_tt and, through s,
                                          ∂F_t/∂r_n = −W_tt μ σ  (augmented: also ∂F_t/∂u_n = W_tt/W_nn μ σ),
                                          σ = sign(r_t − ρ_t u_t)

W = H M⁻¹ Hᵀ is singular on a hyperstatic wall (impulses not unique), so the step is Levenberg–Marquardt
shifted: B + λ D, D = diag(W_αα). Three equivalent forms of the Newton system (tested equal): the sparse
saddle point in (dv, dr) over the moving bodies ("saddle"), its Schur complement on dr with the sparse W
formed once ("schur"), and — the default, 5–10× cheaper — dr eliminated (B + λD is invertible, 2×2 per
contact), leaving the 3B_dyn velocity system ("velocity"):

    (M + Hᵀ (B + λD)⁻¹ A H) dv = −Hᵀ (B + λD)⁻¹ F,    dr = (B + λD)⁻¹ (−F − A H dv)

One run (pseudo-code):

    r = r_warm;  PRE engine sweeps of kind KIND (0: plain warm start; 500 momentum: the stalled iterate)
    λ = LAMBDA0
    loop:  if lab law residual RMS(v(r), r) ≤ target: done
           [polish_every = K: every K Newton steps, plain engine sweeps from a COPY of r, in chunks 20, 40,
            … up to POLISH_CAP · 2^min(polishes before, 2) sweeps: if they reach the target, done with their r]
           dr = −(F'(r) + λ D)⁻¹ F(r)                    (one splu of the velocity system)
           α = 1, ½, ¼ … ≥ ALPHA_MIN: accept the first with ½|F(r + α dr)|² ≤ (1 − 2σα) ½|F(r)|²  (Armijo)
           accepted:  r += α dr;  λ = max(λ / 4, LAMBDA_MIN) if α = 1 else λ
           rejected:  λ = min(10 λ, LAMBDA_MAX);  WATCHDOG engine sweeps from r (nonmonotone: the merit
                      is re-taken from wherever they leave r)
           cap NEWTON_CAP Newton steps

Iterations: Newton steps (factorisations). Sweep units: the harness's (all CPU time over one engine
sweep's), numpy/scipy included; phases split pre-sweeps, polish and watchdog sweeps, law checks, assembly,
factor+solve and line search. ``python -m benchmarks.solver_lab.methods.alart_curnier PROBLEM …`` times one
Newton step (assembly; splu + solve) in the three forms. Options tried and kept for the record (benchmarks/JOURNAL.md):
``grow_below`` (λ × 4 after a step shorter than that), ``memory`` (nonmonotone Armijo over the last merits),
``smooth`` (engine sweeps after every accepted step). ``lam_min`` = LAMBDA0 (``ac-l3``, ``ac-aug-l3``) holds the shift at 1e-3: fewer, longer steps (the best
pure-Newton variant with ``augmented``). Measured outcome: benchmarks/JOURNAL.md, "Alart–Curnier".
"""

from __future__ import annotations

import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from benchmarks.solver_lab.outcome import Clock, Outcome
from masonrycli.engine import nlgs as N

LAMBDA0 = 1e-3
LAMBDA_MIN = 1e-8
LAMBDA_MAX = 1.0
SIGMA = 1e-4
ALPHA_MIN = 2.0**-10
WATCHDOG = 20
"""Engine sweeps after a rejected Newton step."""
NEWTON_CAP = 100
POLISH_CAP = 1260
"""Plain sweeps the first polish may take (20 + 40 + … + 640); doubled at each further polish, at most
POLISH_DOUBLINGS times (unbounded doubling cost aqueduct-shaken-hard 321 000 polish sweeps in 8 polishes)."""
POLISH_DOUBLINGS = 2
PERMC = "MMD_AT_PLUS_A"
"""splu ordering of the velocity-space matrix, symmetric mode without pivoting (the matrix is nearly
symmetric, only sliding rows break the symmetry): 12.8 ms and 1.9e5 factor nonzeros on wall-64-hard
(992 blocks) against 16.7 ms / 3.5e5 with COLAMD and partial pivoting, 359 ms / 2.4e6 with MMD pivoting."""


class Residual:
    """F(r) and its generalised Jacobian for one problem (built once: H restricted to moving bodies, sparse
    W = H M⁻¹ Hᵀ, W_αα, bias)."""

    def __init__(self, ctx, form: str = "velocity", augmented: bool = False):
        p, pack = ctx.p, ctx.pack
        self.ctx, self.form, self.augmented = ctx, form, augmented
        self.minv = ctx.minv
        self.HT = ctx.H.T.tocsr()
        self.dyn = np.flatnonzero(ctx.minv > 0)
        self.Hd = ctx.H[:, self.dyn].tocsr()
        self.HdT = self.Hd.T.tocsr()
        self.md = 1.0 / ctx.minv[self.dyn]
        self.wdiag = np.stack([pack[:, N.P_WTT], pack[:, N.P_WNN]], axis=1).ravel()
        self.bias = pack[:, N.P_BIAS].copy()
        self.mu = p.mu
        self.vfree = p.v_free.ravel().copy()
        c = p.count
        self.n = 2 * c
        if form == "schur":
            self.W = (self.Hd @ sp.diags(ctx.minv[self.dyn]) @ self.Hd.T).tocsr()
        # sparsity pattern of B: the diagonal and the (t, n) entry of each contact
        self.b_rows = np.concatenate([np.arange(2 * c), 2 * np.arange(c)])
        self.b_cols = np.concatenate([np.arange(2 * c), 2 * np.arange(c) + 1])

    def velocity(self, r: np.ndarray) -> np.ndarray:
        """v(r), flat (3B,)."""
        return self.vfree + self.minv * (self.HT @ r)

    def evaluate(self, r: np.ndarray):
        """(F (2C,) m/s, the Jacobian's pieces) at flat r. Pieces, per contact, of the upper-triangular 2×2
        blocks A = ∂F/∂u = [[a_t, a_tn], [0, a_n]] and B = ∂F/∂r = [[b_t, b_tn], [0, b_n]]."""
        u = self.ctx.H @ self.velocity(r)
        rt, rn = r[0::2], r[1::2]
        ut, un = u[0::2], u[1::2]
        wt, wn = self.wdiag[0::2], self.wdiag[1::2]
        x = rn - (un + self.bias) / wn
        closed = x > 0.0
        # threshold: μ r_n⁺ (default) or μ x⁺ (``augmented``, Alart–Curnier's original: 0 once the normal
        # opens). At r_n = 0 (x = 0) its derivative is taken as 1 where the normal is closed: the step is
        # about to load the contact, and the limit must follow it
        base = x if self.augmented else rn
        s = self.mu * np.maximum(base, 0.0)
        loaded = (base > 0.0) | ((base == 0.0) & closed)
        y = rt - ut / wt
        stick = np.abs(y) < s
        F = np.empty_like(r)
        F[1::2] = wn * (rn - np.maximum(x, 0.0))
        F[0::2] = wt * (rt - np.clip(y, -s, s))
        slide = ~stick & loaded
        sy = np.sign(y)
        a = np.empty(self.n)
        a[1::2] = closed
        a[0::2] = stick
        b = np.empty(self.n)
        b[1::2] = np.where(closed, 0.0, wn)
        b[0::2] = np.where(stick, 0.0, wt)
        btn = np.where(slide, -wt * self.mu * sy, 0.0)  # ∂F_t/∂r_n through s
        # augmented: s also depends on u_n (∂x/∂u_n = −1/W_nn)
        atn = np.where(slide, wt / wn * self.mu * sy, 0.0) if self.augmented else np.zeros_like(btn)
        return F, (a, atn, b, btn)

    def _blocks(self, diag, tn) -> sp.csr_matrix:
        return sp.csr_matrix((np.concatenate([diag, tn]), (self.b_rows, self.b_cols)), shape=(self.n, self.n))

    def jacobian(self, state, lam: float):
        """The Newton matrix for F'(r) + λ D in the form ``self.form`` (module doc), and the pieces
        ``direction`` needs to recover dr."""
        a, atn, b, btn = state
        b = b + lam * self.wdiag
        if self.form == "velocity":
            # per contact B is upper triangular: dr = B⁻¹(−F − A H dv), and M dv = Hᵀ dr gives
            # (M + Hᵀ B⁻¹A H) dv = −Hᵀ B⁻¹ F;  B⁻¹A = [[a_t/b_t, a_tn/b_t − b_tn a_n/(b_t b_n)], [0, a_n/b_n]]
            bt, bn = b[0::2], b[1::2]
            g_tn = atn / bt - btn * a[1::2] / (bt * bn)
            G = self._blocks(a / b, g_tn)
            K = (sp.diags(self.md) + self.HdT @ G @ self.Hd).tocsc()
            return K, (b, btn, a, atn)
        A, B = self._blocks(a, atn), self._blocks(b, btn)
        if self.form == "schur":
            return (A @ self.W + B).tocsc(), None
        return sp.bmat([[sp.diags(self.md), -self.HdT], [A @ self.Hd, B]], format="csc"), None

    @staticmethod
    def _upper_solve(b, btn, x: np.ndarray) -> np.ndarray:
        """B⁻¹ x for the per-contact upper-triangular B (diagonal b, (t, n) entry btn)."""
        out = np.empty_like(x)
        out[1::2] = x[1::2] / b[1::2]
        out[0::2] = (x[0::2] - btn * out[1::2]) / b[0::2]
        return out

    def direction(self, jac, F) -> np.ndarray:
        K, pieces = jac
        if self.form == "velocity":
            b, btn, a, atn = pieces
            lu = spla.splu(K, permc_spec=PERMC, diag_pivot_thresh=0.0, options={"SymmetricMode": True})
            dv = lu.solve(-(self.HdT @ self._upper_solve(b, btn, F)))
            hdv = self.Hd @ dv
            ahdv = a * hdv
            ahdv[0::2] += atn * hdv[1::2]
            return self._upper_solve(b, btn, -F - ahdv)
        lu = spla.splu(K)
        if self.form == "schur":
            return lu.solve(-F)
        rhs = np.concatenate([np.zeros(self.dyn.size), -F])
        return lu.solve(rhs)[self.dyn.size :]


def alart_curnier(
    ctx,
    target,
    pre=0,
    pre_kind="nlgs-accel",
    form="velocity",
    cap=NEWTON_CAP,
    watchdog=WATCHDOG,
    lam0=LAMBDA0,
    lam_min=LAMBDA_MIN,
    grow_below=0.0,
    memory=1,
    smooth=0,
    augmented=False,
    polish_every=0,
    polish_cap=POLISH_CAP,
) -> Outcome:
    """The method of the module doc from r_warm after ``pre`` engine sweeps of ``pre_kind``."""
    p = ctx.p
    clock = Clock()
    with clock("setup"):
        res = Residual(ctx, form, augmented)
    r = p.r_warm.copy()
    sweeps = 0
    if pre:
        with clock("pre-sweeps"):
            ctx.sweep(r, pre, pre_kind)
        sweeps += pre
    flat = r.ravel().copy()
    lam = lam0
    recent: list[float] = []
    newton = rejected = 0
    ok = False
    stats = {"alpha": [], "law": [], "merit": [], "lambda": [], "polish": []}
    while True:
        with clock("check"):
            v = res.velocity(flat).reshape(-1, 3)
            law_rms = ctx.residual(v, flat.reshape(-1, 2))
        stats["law"].append(law_rms)
        if law_rms <= target:
            ok = True
            break
        if newton >= cap:
            break
        if polish_every and newton and newton % polish_every == 0:
            with clock("polish sweeps"):
                r, done, hit = _polish(ctx, flat, target, polish_cap << min(len(stats["polish"]), POLISH_DOUBLINGS))
            sweeps += done
            stats["polish"].append(done)
            if hit:
                flat = r.ravel().copy()
                ok = True
                break
        with clock("assemble"):
            F, state = res.evaluate(flat)
            f0 = 0.5 * float(F @ F)
            recent = (recent + [f0])[-memory:]  # nonmonotone (Grippo–Lampariello–Lucidi) for memory > 1
            J = res.jacobian(state, lam)
        with clock("factor+solve"):
            dr = res.direction(J, F)
        newton += 1
        alpha = 1.0
        accepted = False
        with clock("line search"):
            while alpha >= ALPHA_MIN:
                trial = flat + alpha * dr
                Ft, _ = res.evaluate(trial)
                if 0.5 * float(Ft @ Ft) <= max(recent) - 2.0 * SIGMA * alpha * f0:
                    accepted = True
                    break
                alpha *= 0.5
        stats["alpha"].append(alpha if accepted else 0.0)
        stats["merit"].append(f0)
        stats["lambda"].append(lam)
        if accepted:
            flat = trial
            if smooth:  # hybrid: Gauss–Seidel repairs the local kinks the step crossed
                r = flat.reshape(-1, 2).copy()
                with clock("smoothing sweeps"):
                    ctx.sweep(r, smooth)
                sweeps += smooth
                flat = r.ravel().copy()
                recent = []
            if alpha == 1.0:
                lam = max(lam / 4.0, lam_min)
            elif alpha < grow_below:  # a short step: the model is poor, shift more (LM trust-region rule)
                lam = min(4.0 * lam, LAMBDA_MAX)
        else:
            rejected += 1
            lam = min(10.0 * lam, LAMBDA_MAX)
            recent = []
            if watchdog:
                r = flat.reshape(-1, 2).copy()
                with clock("watchdog sweeps"):
                    ctx.sweep(r, watchdog)
                sweeps += watchdog
                flat = r.ravel().copy()
    r = flat.reshape(-1, 2)
    v = res.velocity(flat).reshape(-1, 3)
    out = Outcome(v, r, newton, float(sweeps), clock.phases, converged=ok)
    out.rejected, out.engine_sweeps, out.stats = rejected, sweeps, stats
    return out


def _polish(ctx, flat, target, cap):
    """Plain engine sweeps from a copy of the Newton iterate in growing chunks (20, 40, 80 … sweeps, the law
    residual checked after each) until ≤ target or ``cap`` sweeps: (r, sweeps done, reached)."""
    r = flat.reshape(-1, 2).copy()
    done, chunk = 0, 20
    while done < cap:
        n = min(chunk, cap - done)
        v, _ = ctx.sweep(r, n)
        done += n
        if ctx.residual(v, r) <= target:
            return r, done, True
        chunk *= 2
    return r, done, False


def newton_step_ms(ctx, repeat: int = 3, form: str = "velocity") -> dict:
    """CPU ms of one Newton step (assembly; splu + solve) from the warm start, minimum of ``repeat``; the
    matrix's size and nonzeros."""
    res = Residual(ctx, form)
    flat = ctx.p.r_warm.ravel().copy()
    best = {"assemble": np.inf, "factor+solve": np.inf}
    for _ in range(repeat):
        t = time.process_time()
        F, state = res.evaluate(flat)
        jac = res.jacobian(state, LAMBDA0)
        t1 = time.process_time()
        res.direction(jac, F)
        t2 = time.process_time()
        best["assemble"] = min(best["assemble"], 1e3 * (t1 - t))
        best["factor+solve"] = min(best["factor+solve"], 1e3 * (t2 - t1))
    best["size"], best["nnz"] = jac[0].shape[0], jac[0].nnz
    return best


METHODS = {
    "ac": alart_curnier,
    "ac-s20": lambda ctx, target: alart_curnier(ctx, target, pre=20, pre_kind="nlgs"),
    "ac-m500": lambda ctx, target: alart_curnier(ctx, target, pre=500),
    "ac-gs5": lambda ctx, target: alart_curnier(ctx, target, polish_every=5),
    "ac-gs10": lambda ctx, target: alart_curnier(ctx, target, polish_every=10),
    "ac-aug-gs10": lambda ctx, target: alart_curnier(ctx, target, polish_every=10, augmented=True),
    "ac-l3": lambda ctx, target: alart_curnier(ctx, target, lam_min=LAMBDA0),
    "ac-aug-l3": lambda ctx, target: alart_curnier(ctx, target, lam_min=LAMBDA0, augmented=True),
    "ac-aug": lambda ctx, target: alart_curnier(ctx, target, augmented=True),
    "ac-aug-m500": lambda ctx, target: alart_curnier(ctx, target, pre=500, augmented=True),
    "ac-saddle": lambda ctx, target: alart_curnier(ctx, target, form="saddle"),
    "ac-schur": lambda ctx, target: alart_curnier(ctx, target, form="schur"),
}


if __name__ == "__main__":
    # python -m benchmarks.solver_lab.methods.alart_curnier PROBLEM …: one Newton step's cost, both forms
    from benchmarks.solver_lab.harness import sweep_seconds
    from benchmarks.solver_lab.outcome import Context
    from benchmarks.solver_lab.problems import load_all

    print("| problem | blocks | contacts | form | size | nnz | assemble ms | factor+solve ms | sweep units |")
    print("|---|---|---|---|---|---|---|---|---|")
    for prob in load_all(sys.argv[1:]):
        ctx = Context(prob)
        sweep_ms = 1e3 * sweep_seconds(ctx, 3)["nlgs"]
        for form in ("velocity", "saddle", "schur"):
            t = newton_step_ms(ctx, 3, form)
            units = (t["assemble"] + t["factor+solve"]) / sweep_ms
            print(
                f"| {prob.name} | {prob.blocks} | {prob.count} | {form} | {t['size']} |"
                f" {t['nnz']} | {t['assemble']:.1f} | {t['factor+solve']:.1f} | {units:.0f} |",
                flush=True,
            )
