"""One Moreau–Jean time step: launchers only, every loop lives in a kernel.

1. q_m = q_n + (1 − θ) dt v_n, top speed               integrate.begin_step
2. contacts at q_m within alert + 2·dt·(top speed)     collision.detect_contacts
3. r_α ← r of the previous step with the same key      warmstart.WarmStart.start
4. v_free = v_n + dt g ; supports get v(t_n+1)         integrate.free_velocity
5. lever arms, W_αα, Signorini bias                    nlgs.prepare_contacts
   no contact warm-started (first step): static guess  warmstart.static_guess
6. NLGS → r, v_n+1                                     dispatch.solve
   a structure at rest: the solve continued to a tighter tolerance   Solver._settle
7. contact forces, dissipation, support work           power.contact_power
8. q_n+1 = q_n + dt (θ v_n+1 + (1 − θ) v_n)            integrate.update_q
9. keep the keys and impulses for step 3 next time    warmstart.WarmStart.remember

Steps 1–4 run as one call (fused.before_solve), and 8–9 with the step's largest penetration as
another (fused.after_solve): the same kernels, without a launcher call around each. The first step,
and any step whose detection needs larger buffers, goes through 1–4 one by one.

At rest. An exact solve keeps a structure at rest where it stands: every sticking contact ends the step
with u = 0, whatever velocity error the step began with. A solve stopped at the tolerance (an RMS of the
contact-law violation, nlgs) leaves block velocities of up to ~200× it on the 98-block arch under gravity
alone: each joint's error adds up along the load path, and the residual hardly sees a velocity error
spread over many joints. Nothing pulls the blocks back, so the arch wanders in its hinge mechanism:
0.14 mm in 2 s and 1.3 mm in 48 s at the default 1e-5 m/s, mostly joints opening (slips ≤ 1.3 µm),
with momentum or plain sweeps, θ = ½ or 1 (benchmarks/JOURNAL.md, "A structure at rest"). A step
at rest (every block slower than REST_SPEED at the end of the previous step, supports still) is
therefore solved on from its solution to REST_TIGHTEN × the tolerance, for at most REST_BUDGET sweep
units and below the run's sweep cap (the result with the lower residual is kept; the step's iterations
count these sweeps too). At rest that is cheap (the arch's steps take 2.6
sweeps on average at 1e-7 m/s against 4.4 at 1e-5: a structure that stays put converges from its warm
start), and a moving structure never pays it. A step at rest is solved in double precision whatever the
solver: "nlgs-accel32"'s float32 sweeps left a wall at rest creeping (_in_float64).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from masonrycli.engine import dispatch, fused, integrate, nlgs, power, warmstart
from masonrycli.engine.collision import ContactBuffers, detect_contacts
from masonrycli.engine.tuning import TUNING, Tuning

REST_SPEED = 1e-3
"""m/s: a step is at rest when every block ended the previous step slower than this and no support moves.
The stopping tolerance leaves a structure at rest with block speeds of up to ~200× itself (2e-3 m/s on
the 98-block arch at 1e-5 m/s), so this is the speed of an error, not of a motion (module doc, "At rest")."""
REST_TIGHTEN = 0.01
"""A step at rest is solved on to this fraction of the run's tolerance (module doc, "At rest")."""
REST_BUDGET = 1000
"""Sweep units at most that a step at rest spends beyond its ordinary solve (and never so many that the
step's total reaches the run's sweep cap, max_iterations)."""


@dataclass(frozen=True)
class StepStats:
    """What one step did, for the run's tally, its progress bar and its divergence test."""

    contact_count: int
    """C, contacts detected at the step's configuration."""
    iterations: int
    """Sweep units the contact solver spent (masonrycli.engine.dispatch.solve)."""
    residual: float
    """m/s: RMS contact-law violation of the last sweep, the quantity compared with the tolerance."""
    dissipated: float
    """Energy dissipated at the contacts during the step, J."""
    support_work: float
    """Work of the supports on the blocks during the step, J."""
    max_penetration: float
    """Largest penetration among the step's contacts at detection, m (0 if none)."""
    max_block_speed: float
    """Top block speed |v| at the end of the step, m/s; NaN if a block's q or v is not finite."""
    converged: bool
    """The solver met its stopping test: residual ≤ tolerance before the sweep cap (dispatch.solve)."""


class Solver:
    """Owns the per-step work buffers of one model. ``step(state)`` advances ``state`` in place. ``tuning``:
    the contact solve's numbers (:class:`~masonrycli.engine.tuning.Tuning`; the shipped ones by default).

    After a step, the ``contact_*`` properties hold the step's contacts (views of length C).
    """

    def __init__(self, model, tuning: Tuning = TUNING):
        self.model = model
        self.tuning = tuning
        """The contact solve's first-stage and stalled-step numbers (engine/tuning.py), handed to dispatch.solve
        every step: the shipped ones, or the solver lab's (a frozen value, set at construction)."""
        b = model.body_count
        self.buffers = ContactBuffers(model.body_vert_start)
        self.body_q_m = np.empty((b, 3))
        """(B, 3) configuration at which the last step detected its contacts."""
        self.body_v_n = np.empty((b, 3))
        """(B, 3) m/s, rad/s: v_n, the velocities the last step began with (θ-method update, contact power);
        written at the start of a step, so during the contact solve it holds that step's v_n (the solver
        lab's capture reads it there)."""
        self._warm = warmstart.WarmStart(self.buffers.contact_capacity)
        self._count = 0
        """C: contacts of the last step (rows [:C] of the contact arrays are valid)."""
        self._alloc(self.buffers.contact_capacity)
        self._v_free = np.empty((b, 3))
        """(B, 3) m/s, rad/s: a step at rest's free velocities, from which _settle solves on."""
        self._top_speed = None
        """m/s: top block speed at the end of the last step (None before the first)."""

    def _alloc(self, capacity: int) -> None:
        # Capacity rows (the contact buffers' capacity), rows [:C] valid after a step.
        self._pack = np.zeros((capacity, nlgs.PACK_WIDTH))
        """(C_cap, PACK_WIDTH) the contacts' packed constants (nlgs.prepare_contacts; units per column)."""
        self._r = np.zeros((capacity, 2))
        """(C_cap, 2) N·s: impulses (r_t, r_n) on body b; the warm start in, the solution out."""
        self._status = np.zeros(capacity, dtype=np.int8)
        """(C_cap,) int8: ContactStatus of each contact after the solve."""
        self._force = np.zeros((capacity, 2))
        """(C_cap, 2) N: world force on body b of each contact, r / dt (power.contact_power)."""
        self.support_force = np.zeros((self.model.support_count, 2))
        """(S, 2) N: total force the blocks exert on each support during the last step."""

    # Views of the last step's contacts -------------------------------------------------------
    @property
    def contact_body(self) -> np.ndarray:
        """(C, 2) int32: bodies a, b of each contact (the normal points from a to b)."""
        return self.buffers.contact_body[: self._count]

    @property
    def contact_point(self) -> np.ndarray:
        """(C, 2) m: contact points, world coordinates, at the detection configuration."""
        return self.buffers.contact_point[: self._count]

    @property
    def contact_normal(self) -> np.ndarray:
        """(C, 2) unit normals [-] from body a to body b."""
        return self.buffers.contact_normal[: self._count]

    @property
    def contact_gap(self) -> np.ndarray:
        """(C,) m: gaps at detection (negative: penetration)."""
        return self.buffers.contact_gap[: self._count]

    @property
    def contact_r(self) -> np.ndarray:
        """(C, 2) local impulses (r_t, r_n), N·s, on body b."""
        return self._r[: self._count]

    @property
    def contact_force(self) -> np.ndarray:
        """(C, 2) world force on body b, N."""
        return self._force[: self._count]

    @property
    def contact_pack(self) -> np.ndarray:
        """(C, PACK_WIDTH) the contacts' packed constants at the step's detection configuration (nlgs.py's
        columns: frame, lever arms m, W_αα 1/kg, Signorini bias m/s, inverse masses)."""
        return self._pack[: self._count]

    @property
    def contact_status(self) -> np.ndarray:
        """(C,) int8: 0 open, 1 stick, 2 slip."""
        return self._status[: self._count]

    def contact_tangential_velocity(self, body_v: np.ndarray) -> np.ndarray:
        """(C,) m/s: u_t of the last step's contacts for velocities ``body_v`` (B, 3), with the step's
        lever arms (called for recorded frames only)."""
        return power.tangential_velocity(self.buffers.contact_body, self._pack, self._count, body_v)

    def detect(self, body_q: np.ndarray, alert: float | None = None) -> int:
        """Contacts of configuration ``body_q`` within ``alert`` (default: the model's alert distance)
        into the buffers (no solve); returns the count."""
        m = self.model
        alert = m.alert_distance if alert is None else alert
        count = detect_contacts(body_q, m.body_vert_start, m.vert_local, m.body_dynamic, alert, self.buffers)
        if self.buffers.contact_capacity > self._r.shape[0]:
            self._alloc(self.buffers.contact_capacity)
        self._count = count
        return count

    def detection_distance(self, top_speed: float) -> float:
        """m: the alert distance plus how far two bodies can approach each other within a step.

        A pair farther apart than the alert distance but closing fast (a falling block, a collapsing
        arch) would otherwise be found only once it has penetrated, and a penetration is never pushed
        out. Found in time, its Signorini condition u_n + g/dt ≥ 0 stops it at contact instead.
        Points move at most ``top_speed`` = max |v| + |ω|·radius; two bodies approach at most twice that.
        """
        return self.model.alert_distance + 2.0 * self.model.dt * top_speed

    def step(self, state) -> StepStats:
        m = self.model
        k = state.step
        support_v_next = m.support_velocity[k + 1]
        bf = self.buffers
        begun = fused.before_solve(  # steps 1–4 in one call
            m, bf, self._warm, state, support_v_next, self.body_q_m, self.body_v_n, self._r
        )
        if begun is None:  # first detection, capacities exceeded, a pose not finite: one by one
            top_speed = integrate.begin_step(m, state.body_q, state.body_v, self.body_q_m, self.body_v_n)
            count = self.detect(self.body_q_m, self.detection_distance(top_speed))
            warm = self._warm.start(bf.contact_key, count, self._r)
            integrate.free_velocity(m, self.body_v_n, support_v_next, state.body_v, state.body_q)
        else:
            count, warm, _ = begun
            self._count = count
        body = bf.contact_body
        nlgs.prepare_contacts(
            body, bf.contact_point, bf.contact_normal, bf.contact_gap, count, self.body_q_m, m, self._pack
        )
        if warm == 0:  # nothing to warm-start from (first step): start from the static load path
            warmstart.static_guess(body, self._pack, count, self.body_q_m, m, self._r)
        rest = self._at_rest(state, support_v_next)
        if rest:
            np.copyto(self._v_free, state.body_v)
            m = _in_float64(m)
        iterations, residual = dispatch.solve(
            body, self._pack, count, m, state.body_v, self._r, self._status, self.tuning
        )
        # The continuation stays below the run's sweep cap: a step whose ordinary solve met the tolerance
        # must not be reported capped or unconverged for the extra sweeps (nor spend more than the cap).
        budget = min(REST_BUDGET, m.max_iterations - 1 - iterations)
        if rest and budget > 0 and m.tolerance * REST_TIGHTEN < residual <= m.tolerance:
            more, residual = self._settle(state, count, residual, budget)
            iterations += more
        dissipated, work = power.contact_power(
            body, self._pack, self._r, count, self.body_v_n, state.body_v, m, self._force, self.support_force
        )
        block_speed, penetration = fused.after_solve(  # steps 8–9
            self.model, bf, self._warm, state, count, self.body_v_n, self._r
        )
        self._top_speed = block_speed
        state.step = k + 1
        state.time = state.step * m.dt
        converged = residual <= m.tolerance and iterations < m.max_iterations
        return StepStats(
            count,
            int(iterations),
            float(residual),
            float(dissipated),
            float(work),
            penetration,
            float(block_speed),
            bool(converged),
        )

    def _at_rest(self, state, support_v_next) -> bool:
        """Whether this step is at rest (module doc, "At rest"): every block ended the last step slower
        than REST_SPEED (NaN is not) and every support stands still at t_n and t_n+1. Called after v_free
        is written; a moving structure is told apart by one comparison."""
        m = self.model
        if m.tolerance <= 0.0:
            return False
        n = m.block_count
        top = self._top_speed
        if top is None:  # first step: the initial velocities
            top = float(np.hypot(self.body_v_n[:n, 0], self.body_v_n[:n, 1]).max()) if n else 0.0
        if not top < REST_SPEED:
            return False
        return not (np.any(support_v_next) or np.any(self.body_v_n[n:]))

    def _settle(self, state, count: int, residual: float, budget: int) -> tuple[int, float]:
        """Solve a step at rest on from its solution (r, status of the ordinary solve; v from v_free) to
        REST_TIGHTEN × the tolerance, for at most ``budget`` (≤ REST_BUDGET) sweep units; keep whichever of
        the two results has the lower residual. Returns (sweep units spent here, residual kept)."""
        m = _in_float64(self.model)
        # The model with the tighter tolerance and the budget for a cap, made here (~4 µs; the sweeps cost
        # far more): the model is frozen, so nothing kept between steps could go stale.
        tight = dataclasses.replace(m, tolerance=m.tolerance * REST_TIGHTEN, max_iterations=budget)
        v, r, status = state.body_v, self._r[:count], self._status[:count]
        kept = v.copy(), r.copy(), status.copy()
        np.copyto(v, self._v_free)
        bf = self.buffers
        more, settled = dispatch.solve(bf.contact_body, self._pack, count, tight, v, self._r, self._status, self.tuning)
        if settled > residual:  # the continuation ended worse: back to the ordinary solve's result
            np.copyto(v, kept[0])
            np.copyto(r, kept[1])
            np.copyto(status, kept[2])
            return int(more), residual
        return int(more), float(settled)


def _in_float64(model):
    """``model`` with "nlgs-accel32" solved as "nlgs-accel": a step at rest is solved in double precision.
    The float32 sweeps' rounding (~1e-8 m/s a sweep) left a wall standing on a fixed ground creeping, with
    1.8e-4 J dissipated in 50 steps where the float64 solve keeps it exactly still (test_engine_warmstart).
    Made per step at rest (~4 µs, as _settle's model): the model is frozen."""
    return dataclasses.replace(model, solver="nlgs-accel") if model.solver == "nlgs-accel32" else model
