"""The structures of the solver benchmark (issue 9) and the accuracy measure shared by every engine.

Cases (dt = 1e-3, θ = 0.5, μ = 0.6, ρ = 2500 kg/m³, blocks 0.30 × 0.20 m):

* ``wall-51``, ``wall-248``: the paper's walls; ``wall-52``: 8 courses × 6 blocks (1.8 m long);
  ``h8``, ``h16``, ``h32``, ``h64``: 8–64 courses of a 4.5 m wall (15 blocks per course; h16 is the
  248-block wall); ``l500`` … ``l4000``: 8-course walls long enough for about that many blocks.
  Walls are shaken by their ground at 1 m/s · sin(2π · 2 Hz · t), as ``masonry simulate wall``.
* ``arch``, ``aqueduct``: the paper's arch and aqueduct, the right foundation settling at 1 cm/s, as
  ``masonry simulate arch`` / ``aqueduct``.

Accuracy ("slip"): the horizontal displacement of a block relative to the ground, x(t) − x(0) −
x_ground(t); the top-course slip is its mean over the top course, the mean slip its mean over all
blocks. Compared at 0.1 and 0.2 s with a tight solve of the same engine (or, for another engine, with
masonry's tight solve).
"""

from __future__ import annotations

import numpy as np

from masonrycli.scenario.motion import Constant, Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder

SINE = Sine(amplitude=1.0, frequency=2.0)
SETTLE = {"right-foundation": Constant(velocity=(0.0, -0.01))}
WALL_LENGTH = 4.5
LENGTH_SERIES = {500: 18.6, 1000: 37.5, 2000: 74.7, 4000: 149.7}
"""Block count → length (m) of an 8-course wall with about that many blocks."""

CASES: dict[str, tuple[str, dict, float, dict]] = {
    "wall-51": ("wall", {"blocks": 51}, 1.0, {"ground": SINE}),
    "wall-52": ("wall", {"blocks": None, "courses": 8, "length": 1.8}, 1.0, {"ground": SINE}),
    "wall-248": ("wall", {"blocks": 248}, 1.0, {"ground": SINE}),
    "arch": ("arch", {}, 5.0, SETTLE),
    "aqueduct": ("aqueduct", {}, 5.0, SETTLE),
}
for _courses in (8, 16, 32, 64):
    CASES[f"h{_courses}"] = (
        "wall",
        {"blocks": None, "courses": _courses, "length": WALL_LENGTH},
        1.0,
        {"ground": SINE},
    )
for _blocks, _length in LENGTH_SERIES.items():
    CASES[f"l{_blocks}"] = ("wall", {"blocks": None, "courses": 8, "length": _length}, 1.0, {"ground": SINE})


FLOAT64 = "nlgs-accel"
"""The accelerated solver in double precision: the tools that time or instrument the float64 first stage
(``dispatch.first_stage``, the lane sweeps) run it by name since the default, "nlgs-accel32", starts in
float32."""


def make_scenario(case: str, duration: float | None = None, **run_options):
    """The scenario of ``case``; ``run_options`` override RunConfig fields (tolerance, max_iterations…)."""
    builder, options, default_duration, motions = CASES[case]
    run = RunConfig(duration=duration or default_duration, **run_options)
    return scenario_from_builder(builder, options, run, Material(), motions)


def is_wall(case: str) -> bool:
    return CASES[case][0] == "wall"


def course_of(block_names) -> np.ndarray:
    """Course number of each wall block from its name ``cCC-bBB``."""
    return np.array([int(name.split("-")[0][1:]) for name in block_names])


def slips(x0: np.ndarray, x: np.ndarray, ground_dx: float, course: np.ndarray) -> tuple[float, float]:
    """(top-course slip, mean slip) in m: block x displacement relative to the ground's."""
    slip = x - x0 - ground_dx
    return float(slip[course == course.max()].mean()), float(slip.mean())
