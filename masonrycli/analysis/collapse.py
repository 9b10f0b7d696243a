"""Collapse, defined: what happened to the structure, watched step by step.

A run ends in one of three **states**:

``collapsed``
    at some step (the *time of collapse*) one of the following held:

    * a block has fallen by more than ``drop`` × its height — stones on the ground, a voussoir through
      the arch. The fall is counted below the deepest settlement of a support at that step (a block
      riding a settling foundation down has not fallen), and the height is the block's own (its
      bounding box as built) but at least the median block height (the aqueduct's spandrel blocks
      cut along the extrados are down to 3.6 cm: a 4 cm settlement is not their collapse);
    * a block has turned by more than ``turn`` (45° by default) — overturned (a slender block past its
      tipping angle only goes on falling);
    * the top of the structure has drifted, relative to the shaking ground, by more than ``drift`` ×
      its height (the structure leans beyond recovery).
``damaged``
    not collapsed, but at the end the residual drift of the top exceeds ``damage_drift`` × the height,
    or at least ``damage_hinges`` joints are hinged, or a block has slid or opened a joint by more than
    ``damage_opening``.
``intact``
    neither.

The parameters are per structure (:data:`RULES`, keyed by the builder name; scenario files use
``"default"``) and documented in ``docs/collapse.md``. The *top* is the blocks whose centroid lies
within half a median block height of the highest centroid; the height is the blocks' vertical extent.

For threshold studies the monitor also records the first **sliding** (a closed contact whose faces
slide faster than ``SLIDE_SPEED``) and the first **rocking** (a block turning faster than
``ROCK_SPEED``), and the peak drift ratio. The per-step maxima come from one engine kernel
(:func:`masonrycli.engine.watch.watch_step`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from masonrycli.engine.watch import watch_step

SLIDE_SPEED = 1e-5
"""m/s: a closed contact sliding faster than this is sliding (a stuck block stays below 1e-12 m/s; a
block 0.5 % past its sliding threshold reaches ~1e-4 m/s)."""
ROCK_SPEED = 1e-4
"""rad/s: a block turning faster than this is rocking (a block at rest stays below 1e-7 rad/s)."""
ROCK_NOISE = 2.0
"""× tolerance / the narrowest block's smaller side: the rocking threshold's floor for small blocks. The
solver leaves velocities wrong by up to its tolerance (m/s), a turn of about that over a block's width: a
0.05 × 0.2 m block under a ground at 1 mm/s turned at 1.5e-4 rad/s (tolerance 1e-5 m/s: 0.75 × 1e-5 / 0.05),
a 0.25 × 1 m one at 1.9e-5 (0.48 ×), so the small block 'rocked' from the second step on."""
STATES = ("intact", "damaged", "collapsed")
DRIFTED = "the top drifted by more than"
"""The drift rule's reason, up to its threshold (CollapseMonitor adds whether the structure slid or leans)."""
SLID = 0.8
"""A drift whose base (the lowest blocks) moved at least this share of the top's slid on its base; at most
1 − SLID, it leans; between, both (the 51-block wall at 2 m/s, 1 Hz: top 0.3 m, base 0.168 m)."""


@dataclass(frozen=True)
class CollapseRule:
    """Thresholds of the collapse and damage definitions (module docstring)."""

    drop: float = 1.0
    """× block height: a block falling further has collapsed."""
    turn: float = math.pi / 4
    """rad: a block turning further has collapsed."""
    drift: float = 0.25
    """× structure height: a top drift beyond this is collapse."""
    damage_drift: float = 0.002
    """× structure height: residual top drift beyond this is damage."""
    damage_hinges: int = 1
    """hinged joints at the end from which the structure is damaged."""
    damage_opening: float = 0.005
    """m: a joint opened or a block displaced relative to the ground by more than this at the end is damage."""


RULES = {
    "wall": CollapseRule(),
    # The arch and the aqueduct carry their load by thrust: three hinges are how they stand on moved
    # supports, so only a fourth hinge (a mechanism) counts as damage; a leaning pier is damage early.
    "arch": CollapseRule(drift=0.1, damage_hinges=4),
    "aqueduct": CollapseRule(drift=0.1, damage_hinges=4),
    "default": CollapseRule(),
}


def rule_for(scenario) -> CollapseRule:
    return RULES.get(str(scenario.structure.get("builder", "default")), RULES["default"])


class CollapseMonitor:
    """Running maxima of the collapse indicators of one run, updated after every step.

    model : the run's :class:`~masonrycli.model.Model`; ground : index of the shaking support or None.
    """

    def __init__(
        self, model, vertices_by_block: list[np.ndarray], ground: int | None, rule: CollapseRule, tolerance: float = 0.0
    ):
        n = model.block_count
        self.rule = rule
        self.n = n
        self.ground = None if ground is None else n + ground
        q0 = model.body_q0
        self.q0 = q0.copy()
        heights = np.array([np.ptp(v[:, 1]) for v in vertices_by_block]) if n else np.zeros(0)
        # The fall is measured in units of at least a median block: a sliver's own height is no scale.
        self.block_height = np.maximum(heights, float(np.median(heights))) if n else heights
        ys = np.concatenate([v[:, 1] for v in vertices_by_block]) if n else np.zeros(1)
        self.height = float(np.ptp(ys)) or 1.0
        top_y = q0[:n, 1].max() if n else 0.0
        half = 0.5 * float(np.median(heights) if n else 0.0)
        self.top = np.flatnonzero(q0[:n, 1] >= top_y - half).astype(np.int64)
        base_y = q0[:n, 1].min() if n else 0.0
        self.base = np.flatnonzero(q0[:n, 1] <= base_y + half).astype(np.int64)
        """The lowest blocks (centroid within half a median block height of the lowest): what a drift is told by."""
        self.collapse_time: float | None = None
        self.collapse_reason = ""
        self.slide_time: float | None = None
        self.rock_time: float | None = None
        sides = [min(np.ptp(v[:, 0]), np.ptp(v[:, 1])) for v in vertices_by_block]
        self.rock_speed = max(ROCK_SPEED, ROCK_NOISE * tolerance / min(sides)) if sides else ROCK_SPEED
        """rad/s: turning faster than this is rocking (ROCK_SPEED, or above the solver's noise on a small block)."""
        self.peak_drift = 0.0
        self.max_slide_speed = 0.0
        self.max_rock_speed = 0.0

    def drift(self, body_q: np.ndarray) -> float:
        """m: mean horizontal displacement of the top blocks relative to the shaking ground."""
        if not self.top.size:
            return 0.0
        return float(np.mean(body_q[self.top, 0] - self.q0[self.top, 0])) - self._ground_dx(body_q)

    def update(self, time: float, solver, body_q: np.ndarray, body_v: np.ndarray) -> None:
        """One step: ``body_q``/``body_v`` (B, 3) after ``solver``'s step."""
        if not self.n:
            return
        # the fall below the supports' settlement: watch_step's (a block riding a settling support has not fallen)
        rock, slide, fall, turn, top_dx = watch_step(solver, body_q, body_v, self.q0, self.block_height, self.top)
        before, drift = self.collapse_time, top_dx - self._ground_dx(body_q)
        self.observe(time, rock, slide, fall, turn, drift)
        if before is None and self.collapse_time is not None and self.collapse_reason.startswith(DRIFTED):
            self.collapse_reason += self._how_it_drifted(body_q, drift)

    def observe(self, time: float, rock: float, slide: float, fall: float, turn: float, drift: float) -> None:
        """Fold one step's indicators in: max |ω| (rad/s), max closed-contact |u_t| (m/s), max fall ×
        block height, max |θ| (rad), top drift relative to the ground (m)."""
        rule = self.rule
        self.max_rock_speed = max(self.max_rock_speed, rock)
        self.max_slide_speed = max(self.max_slide_speed, slide)
        if self.rock_time is None and rock > self.rock_speed:
            self.rock_time = time
        if self.slide_time is None and slide > SLIDE_SPEED:
            self.slide_time = time
        ratio = abs(drift) / self.height
        self.peak_drift = max(self.peak_drift, ratio)
        if self.collapse_time is not None:
            return
        reason = ""
        if fall > rule.drop:
            reason = f"a block fell by more than {rule.drop:g} × its height"
        elif turn > rule.turn:
            reason = f"a block turned by more than {math.degrees(rule.turn):g}°"
        elif ratio > rule.drift:
            reason = f"{DRIFTED} {rule.drift:g} × the height"
        if reason:
            self.collapse_time, self.collapse_reason = time, reason

    def _how_it_drifted(self, body_q: np.ndarray, drift: float) -> str:
        """Told once, at the step the drift rule fires: whether the structure slid on its base (its lowest
        blocks moved with the top: a single block sliding on the ground "drifts" so) or leans (they did not)."""
        base = float(np.mean(body_q[self.base, 0] - self.q0[self.base, 0])) - self._ground_dx(body_q)
        share = abs(base) / abs(drift) if drift else 0.0
        how = "it slid on its base" if share >= SLID else "it leans" if share <= 1.0 - SLID else "it slid and leans"
        return f": {how}, the top {abs(drift):.3g} m, the base {abs(base):.3g} m"

    def _ground_dx(self, body_q: np.ndarray) -> float:
        return 0.0 if self.ground is None else float(body_q[self.ground, 0] - self.q0[self.ground, 0])

    def state(self, body_q: np.ndarray, hinges: int, max_opening: float) -> str:
        """``collapsed``, ``damaged`` or ``intact`` at the end of the run (module docstring)."""
        if self.collapse_time is not None:
            return "collapsed"
        rule = self.rule
        displaced = self.max_block_displacement(body_q)
        if (
            abs(self.drift(body_q)) / self.height > rule.damage_drift
            or hinges >= rule.damage_hinges
            or max(max_opening, displaced) > rule.damage_opening
        ):
            return "damaged"
        return "intact"

    def max_block_displacement(self, body_q: np.ndarray) -> float:
        """m: largest distance a block has moved relative to the shaking ground."""
        if not self.n:
            return 0.0
        d = body_q[: self.n, :2] - self.q0[: self.n, :2]
        if self.ground is not None:
            d = d - (body_q[self.ground, :2] - self.q0[self.ground, :2])
        return float(np.hypot(d[:, 0], d[:, 1]).max())
