"""The mechanism recording of ``masonry limit --out``: what it draws of a :class:`LimitResult` (blocks, mechanism,
hinges, line of thrust, the live load's arrow, a bridge's fill) and the words of its side panel. The drawing
itself is :mod:`masonrycli.recording.limit`'s (Rerun lives in the recording package)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from geometry_library.mass import mass_properties
from masonrycli.limit.analysis import LimitResult, parts_text
from masonrycli.limit.command import depth_text, lambda_reading
from masonrycli.limit.problem import DIRECTIONS

THRUST_SHOWN = 0.02
"""The recording's line of thrust shows joints carrying at least this share of the largest joint force."""


def mechanism_document(result: LimitResult, fill_drawn: bool = True, magnified: str = "magnified") -> str:
    """Markdown for the recording's side panel; ``fill_drawn``: the fill's columns are drawn (a carried fill's);
    ``magnified``: how much the mechanism is magnified (``recording.limit.magnified_words``)."""
    reading = lambda_reading(result)
    lines = [
        f"# masonry limit: {result.scenario_name}",
        f"**load factor λ = {result.load_factor:.4f}**" + (f" ({reading})" if reading else ""),
        "",
        f"live load: {result.load.describe()}; friction {result.model.friction:g}",
        "",
        *_fill_lines(result, fill_drawn),
        "Left: the structure as built; red dots: the line of thrust (centre of pressure of each loaded joint).",
        f"Right: the collapse mechanism, {magnified}; blocks coloured by their speed in it (grey: still);",
        "yellow: hinges; orange: sliding joints. Play the timeline to grow the mechanism.",
        "",
        f"Blue arrow (left): the live load at collapse, {result.load_factor * result.reference_force:.4g} N"
        + depth_text(result)
        + (" (the resultant of the body forces, at the centre of mass)." if result.load.kind != "point" else "."),
        "",
        f"hinges ({len(result.hinges)}, the fastest first): " + _document_names(result.hinges_largest_first()),
        "",
        f"sliding joints ({len(result.sliding_joints)}, the fastest first): "
        + _document_names(result.sliding_largest_first()),
    ]
    opening = result.opening_largest_first()
    if opening:  # turning as they part all along: the table's 'joints opening' row, listed as hinges before
        lines += ["", f"joints opening ({len(opening)}, the fastest first): " + _document_names(opening)]
    moving = len(result.moving_blocks)
    parts = parts_text(result.model.block_name, result.part_indices)
    lines += ["", f"blocks in the mechanism: {moving} of {result.model.block_count}{parts}"]
    return "\n".join(lines)


def _fill_lines(result: LimitResult, drawn: bool) -> list[str]:
    """The panel's word on a fill: a filled bridge's recording showed a bare ring (the view draws its columns
    now, a file's too when its carried masses are one fill's: ``scenario.fill``; other masses are not drawn)."""
    fill = result.summary()["fill_load_N"]
    if not fill:
        return []
    said = f"dead load: the blocks' weight and {fill:.4g} N of fill{depth_text(result)}, borne by the blocks under it"
    how = (
        " (sand: each column over its block, carried along the mechanism)"
        if drawn
        else " (not drawn: the carried masses are not those of one fill up to one level)"
    )
    return [said + how, ""]


DOCUMENT_NAMES = 12
"""Joint names the recording's side panel lists (each kind): the aqueduct's point load ('masonry limit
aqueduct --load point --block v15 --direction -y') listed 40 of 363 hinges and 40 of 500 sliding joints,
a 30-line wall of names beside the view, with no word that there were more."""


def _document_names(names: list[str]) -> str:
    shown = ", ".join(names[:DOCUMENT_NAMES])
    more = len(names) - DOCUMENT_NAMES
    return shown + (f" … and {more} more (all in --json)" if more > 0 else "")


def load_arrow(result: LimitResult) -> tuple[np.ndarray, np.ndarray]:
    """(point, unit direction), m: where the live load acts (``--at``'s place on the loaded block's top, the
    loaded block's centroid, or the blocks' centre of mass for body forces: their resultant) and which way."""
    m = result.model
    n = m.block_count
    direction = np.asarray(DIRECTIONS[result.load.direction], dtype=np.float64)
    if result.load.kind == "point" and result.load.top is not None:
        return np.array([result.load.at, result.load.top]), direction
    if result.load.kind == "point":  # at the block's own centroid: a carried fill moved the body's centre of mass
        i = list(m.block_name).index(result.load.block)
        own = mass_properties(m.vert_local[m.body_vert_start[i] : m.body_vert_start[i + 1]]).centroid
        return m.body_q0[i, :2] + own, direction
    mass = m.body_mass[:n]
    return (mass[:, None] * m.body_q0[:n, :2]).sum(axis=0) / mass.sum(), direction


def _parameters(scenario, result: LimitResult) -> dict:
    """The Parameters table's rows from the source simulate's recording takes them from (execute.run_metadata),
    ``settle_s`` in its ``reading`` as run's: settle() leaves it to settled_scenario, which limit does not call.
    Every support is said fixed, as the analysis holds it: a built-in's rows carried the loading simulate would
    apply ('masonry limit arch --fill-cover 0.3': right-foundation, constant velocity (0, -0.01) m/s)."""
    from masonrycli.execute import command_line, run_metadata

    if result.settled is not None:
        scenario = replace(scenario, reading={**scenario.reading, "settle_s": float(result.settled.duration)})
    parameters = {k: v for k, v in run_metadata(scenario, result.model).items() if k not in TIME_LOOP}
    return {**parameters, "supports": dict.fromkeys(parameters["supports"], "fixed")} | command_line()


TIME_LOOP = (
    "duration_s",
    "dt_s",
    "theta",
    "nlgs_tolerance",
    "nlgs_max_iterations",
    "solver",
    "record_every",
    "baseline_corrections",
)
"""run_metadata's keys of the time loop, left out of a limit recording's Parameters table: one LP runs no time
step, no Gauss–Seidel, records no frame and applies no record ('masonry limit arch --out' said dt 0.001, duration
5 s, solver nlgs-accel32, a tolerance; --settle and --verify run the engine at their own settings, said apart)."""


def write_recording(result: LimitResult, out: Path, scenario=None) -> None:
    """The mechanism recording (``masonrycli.recording.limit``) of ``result``; ``scenario``'s fill drawn."""
    from masonrycli.recording.carried_fill import ColumnArrays
    from masonrycli.recording.limit import MechanismDrawing, magnification, magnified_words, write_limit_recording
    from masonrycli.scenario.fill import columns_on_blocks

    m, j, mo = result.model, result.joints, result.motion
    n = m.block_count
    start = m.body_vert_start
    first, last = j.joint_start[:-1], j.joint_start[1:] - 1
    # The block that carries a joint marker into the mechanism copy: b unless b is a support.
    carrier = np.where(j.joint_body[:, 1] < n, j.joint_body[:, 1], j.joint_body[:, 0])
    middle = 0.5 * (j.contact_point[first] + j.contact_point[last])
    # Centres of pressure of the joints that carry load (lightly loaded head joints only clutter the line).
    normal = result.thrust.joint_normal_force
    thrust = result.thrust.joint_point[normal >= THRUST_SHOWN * normal.max(initial=0.0)]
    cols = columns_on_blocks(scenario, m.body_q0[:n, :2]) if scenario else None
    _, size = magnification(start[: n + 1], m.vert_local[: start[n]], m.body_q0[:n], result.solution.block_velocity)
    drawing = MechanismDrawing(
        block_vert_start=start[: n + 1].copy(),
        block_vert_local=m.vert_local[: start[n]].copy(),
        block_q0=m.body_q0[:n].copy(),
        block_velocity=result.solution.block_velocity,
        block_moving=mo.block_moving,
        support_vert_start=start[n:] - start[n],
        support_vert_local=m.vert_local[start[n] :].copy(),
        support_q0=m.body_q0[n:].copy(),
        hinge_point=mo.hinge_point,
        hinge_block=carrier[mo.joint_hinged],
        sliding_point=middle[mo.joint_sliding],
        sliding_block=carrier[mo.joint_sliding],
        thrust_point=thrust[np.isfinite(thrust).all(axis=1)],
        document=mechanism_document(result, fill_drawn=cols is not None, magnified=magnified_words(size)),
        load=load_arrow(result),
        fill=None if cols is None else ColumnArrays(*cols),
        parameters=None if scenario is None else _parameters(scenario, result),
    )
    out.parent.mkdir(parents=True, exist_ok=True)
    write_limit_recording(out, drawing)
