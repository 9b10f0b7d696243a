"""A small captured problem for the solver lab's tests."""

from __future__ import annotations

import numpy as np

from benchmarks.solver_lab.capture import SINE, capture_run, reference
from masonrycli.run import Simulation
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder


def tiny_cold_problem(courses: int = 2, name: str = "tiny-cold"):
    """The cold start (step 1, every impulse 0) of a 7-block shaken wall of ``courses`` courses, with its
    tight reference (contact-law residual ≤ 1e-9 m/s): small enough for dense references."""
    sc = scenario_from_builder(
        "wall", {"blocks": 7, "courses": courses}, RunConfig(duration=0.002), Material(), {"ground": SINE}
    )
    p = capture_run(Simulation(sc), typical_step=1)[0]["cold"]
    p.name = name
    reference(p)
    assert p.ref_residual <= 1e-9
    return p


def frozen_shift_qp(ht, hn, u_sup, m, x_free, bias, mu, s):
    """The frozen-shift step solved independently by scipy's SLSQP: min ½ (x − x_free)ᵀ M (x − x_free)
    subject to u_n + bias + s ± μ u_t ≥ 0 (u = H x + the supports' part ``u_sup``), M = diag(m). Strictly
    convex, so its x (the free bodies' velocities) is the unique answer any solver of that step must give."""
    from scipy.optimize import minimize

    c = bias + s + u_sup[:, 1]
    A = np.vstack([hn + mu * ht, hn - mu * ht])
    b = np.concatenate([c + mu * u_sup[:, 0], c - mu * u_sup[:, 0]])
    res = minimize(
        lambda x: 0.5 * (x - x_free) @ (m * (x - x_free)),
        x_free,
        jac=lambda x: m * (x - x_free),
        constraints=[{"type": "ineq", "fun": lambda x: A @ x + b, "jac": lambda x: A}],
        method="SLSQP",
        options={"ftol": 1e-15, "maxiter": 500},
    )
    assert res.success
    return res.x
