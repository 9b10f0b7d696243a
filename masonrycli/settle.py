"""Settling a structure under its own weight before it is analysed or shaken (``--settle SECONDS`` of
``masonry limit``, ``run``, ``check`` and ``sweep``).

Why. Limit analysis takes the joints of the configuration it is given: faces within the engine's contact
distance (1 mm, :mod:`masonrycli.limit.joints`). A wall traced by hand on a photograph has stones whose faces
stand a millimetre or two apart where the tracing slipped; there the LP finds no joint, and a stone held only
by such faces gives way at no load ("no equilibrium"). Taking joints across wider gaps made joints of faces
that do not meet: on a traced wall the LP then found mechanisms the engine did not follow (it stood at 1.05 λ).
The stones of the real wall rest on each other, so the wall is first let down onto its own joints by the
engine: gravity alone, every support fixed, for SECONDS, and analysed where it came to rest. Shaken as drawn,
the same wall was reported "damaged" with no shaking at all (31 hinges, 3.5 mm openings in 1 s at rest: the
tracing's gaps closing); ``run --settle`` shakes it from where it came to rest, its damage measured from there.

    run the engine from the wall as drawn, gravity alone, supports fixed, the tolerance of --verify
    refuse if a block moved more than COLLAPSE_SHARE × the median block radius (it does not stand as drawn)
    each block ← its polygon moved by its rigid motion: R(θ − θ0) (v − c0) + c

What moved is said (largest displacement, which block, the end speed): a few millimetres are the tracing's
gaps closing; the analysis is of the settled wall.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from geometry_library.checks import normalised_polygon
from masonrycli.errors import InputError
from masonrycli.limit.verify import COLLAPSE_SHARE, MAX_ITERATIONS, TOLERANCE
from masonrycli.scenario.motion import Fixed
from masonrycli.scenario.values import option_text

MAX_SETTLE = 10.0
"""s: the longest settling asked for (a wall that has not come to rest in 10 s does not stand)."""


@dataclass(frozen=True)
class Settling:
    """What the engine's settling run did."""

    duration: float
    """s simulated."""
    largest_move: float
    """m: the largest block displacement (centroid plus rotation × radius)."""
    block: str
    """The block that moved most."""
    end_speed: float
    """m/s: the fastest block point at the end (a settled wall is at rest again)."""

    def describe(self) -> str:
        return (
            f"{self.duration:g} s under its own weight (--settle): blocks moved up to {self.largest_move * 1e3:.3g} mm "
            f"({self.block}), {self.end_speed * 1e3:.2g} mm/s at the end"
        )

    def summary(self) -> dict:
        return dataclasses.asdict(self)


def check_settle(duration) -> None:
    """Refuse a settling time out of (0, ``MAX_SETTLE``] s (as ``check`` does, without running it)."""
    if not (math.isfinite(duration) and 0.0 < duration <= MAX_SETTLE):
        raise InputError(
            f"--settle {option_text(duration)}: must be in (0, {MAX_SETTLE:g}] s (0.5 lets a traced wall's gaps close)"
        )


def settled_scenario(scenario, duration: float | None):
    """``scenario`` settled for ``duration`` s (:func:`settle`) with a warning line saying so; as it is for None."""
    if duration is None:
        return scenario
    settled, settling = settle(scenario, duration)
    said = f"settled {settling.describe()} before the run: it starts there, at rest"
    reading = {**settled.reading, "settle_s": float(duration)}  # the run's parameters say it (execute.run_metadata)
    return dataclasses.replace(settled, warnings=(*settled.warnings, said), reading=reading)


def settle(scenario, duration: float):
    """``scenario`` with its blocks where the engine brings them to rest under gravity alone in ``duration``
    s (module docstring), and the :class:`Settling`. Raises :class:`InputError` for a bad duration or a wall
    that does not stand (a block moved more than the collapse threshold of ``--verify``)."""
    from masonrycli.run import Simulation

    check_settle(duration)
    steps = max(1, round(duration / scenario.run.dt))
    run = dataclasses.replace(
        scenario.run,
        duration=steps * scenario.run.dt,
        record_every=10**6,
        tolerance=min(TOLERANCE, scenario.run.tolerance),
        max_iterations=max(MAX_ITERATIONS, scenario.run.max_iterations),
    )
    sim = Simulation(dataclasses.replace(scenario, run=run, motions=tuple(Fixed() for _ in scenario.motions)))
    m = sim.model
    n = m.block_count
    for _ in range(steps):
        sim.step()
        if sim.diverged():
            break
    q0, q = m.body_q0[:n], sim.state.body_q[:n]
    radius = m.body_radius[:n]
    moved = np.hypot(q[:, 0] - q0[:, 0], q[:, 1] - q0[:, 1]) + np.abs(q[:, 2] - q0[:, 2]) * radius
    v = sim.state.body_v[:n]
    speed = np.hypot(v[:, 0], v[:, 1]) + np.abs(v[:, 2]) * radius
    worst = int(np.argmax(moved))
    blocks = scenario.assembly.blocks
    settling = Settling(steps * scenario.run.dt, float(moved[worst]), blocks[worst].name, float(speed.max()))
    threshold = COLLAPSE_SHARE * float(np.median(radius))
    if not moved[worst] <= threshold or not np.all(np.isfinite(q)):
        falling = [blocks[i].name for i in np.argsort(-moved) if moved[i] > threshold][:5]
        raise InputError(
            f"the wall does not stand as drawn: under its own weight, settling {settling.duration:g} s, "
            f"{', '.join(falling)} moved more than {threshold * 1e3:.3g} mm (the collapse threshold of --verify; "
            f"{blocks[worst].name}: {moved[worst] * 1e3:.3g} mm): a stone traced out of place, or a support missing"
        )
    moved_blocks = []
    for i, block in enumerate(blocks):
        local = m.vert_local[m.body_vert_start[i] : m.body_vert_start[i + 1]]
        turn = q[i, 2] - q0[i, 2]
        c, s = math.cos(turn), math.sin(turn)
        # vert_local is the body frame at q0 (θ0 = the initial angle): turn it by θ − θ0 and place it at q
        turned = np.array([[c, s], [-s, c]])
        xy = local @ turned + q[i, :2]
        polygon = normalised_polygon(xy, f'block {i + 1} ("{block.name}")')
        moved = {"polygon": polygon}
        if block.carried_at is not None:  # a carried fill rides with its block: it moves as the polygon does
            at = (np.asarray(block.carried_at, dtype=np.float64) - q0[i, :2]) @ turned + q[i, :2]
            moved["carried_at"] = (float(at[0]), float(at[1]))
        moved_blocks.append(dataclasses.replace(block, **moved))
    assembly = dataclasses.replace(scenario.assembly, blocks=tuple(moved_blocks))
    # "touches nothing … it will fall freely" was of the wall as drawn: settled, it rests (or was refused above)
    warnings = tuple(w for w in scenario.warnings if " touches nothing " not in w)
    return dataclasses.replace(scenario, assembly=assembly, warnings=warnings), settling
