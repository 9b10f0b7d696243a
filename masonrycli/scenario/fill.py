"""The fill a built-in bridge carries: its level and its columns, for whatever draws or loads it.

A block knows only the mass it carries and where (``Block.carried_mass`` at ``carried_at``); the fill's level
and extent are the builder's (``ArchSpec``: ``--fill-to`` / ``--fill-cover`` between the piers' outer faces).
They are read again from the scenario's structure options, and the columns recomputed over the scenario's own
blocks (``geometry_library.fill.fill_columns``, the pieces ``with_fill`` weighed). A GeoJSON or a scenario
file has only the carried masses: their columns are drawn when the masses are one fill's, of one density up to
one level (a built-in bridge's written to a file: ``geometry_library.fill.level_from_carried`` finds that
level and checks every block against it); other carried masses have no outline to draw (the recording says
the mass and that it is not drawn). A load spread through the fill (``limit --spread``) takes the same
level (:func:`fill_surface`): a file's fill was drawn, and the spread refused as "no fill".
"""

from __future__ import annotations

import numpy as np

from geometry_library.fill import FillColumns, fill_columns, level_from_carried


def _fill_of(scenario) -> tuple[float, float, float] | None:
    """(level, x_lo, x_hi), m, of an arch built with a fill; None otherwise."""
    from geometry_library.builders.arch import ArchSpec, arch_parts, fill_level

    if scenario.structure.get("builder") != "arch":
        return None
    spec = ArchSpec(**{k: v for k, v in scenario.structure.items() if k != "builder"})
    geometry = arch_parts(spec)[2]
    level = fill_level(spec, geometry)
    return None if level is None else (level, -geometry.half_width, geometry.half_width)


def _fill(scenario) -> tuple[float, float, float] | None:
    """(level, x_lo, x_hi), m, of the scenario's fill: the builder's for the arch built-in, else the one fill
    its blocks' carried masses are (a file's, :func:`level_from_carried`); None when there is none."""
    if scenario.structure.get("builder") == "arch":
        return _fill_of(scenario)
    return level_from_carried(scenario.assembly.blocks)


def fill_surface(scenario) -> float | None:
    """m: the level of the scenario's fill (:func:`_fill`: an arch built with ``--fill-to`` / ``--fill-cover``,
    or a file whose carried masses are one fill's), else None."""
    fill = _fill(scenario)
    return None if fill is None else fill[0]


def carried_columns(scenario) -> FillColumns | None:
    """The fill's columns over the scenario's blocks (world coordinates as built), None without a fill or when
    a file's carried masses are not one fill's (module doc)."""
    fill = _fill(scenario)
    return None if fill is None else fill_columns(scenario.assembly.blocks, *fill)


def columns_on_blocks(scenario, centre: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """(block (P,), start (P+1,), vertices (V, 2) m relative to their block's ``centre`` (N, 2)) of the fill's
    columns (:func:`carried_columns`): as the recording poses them, on their blocks; None without a fill."""
    columns = carried_columns(scenario)
    if columns is None or not len(columns.block):
        return None
    owner = np.repeat(columns.block, np.diff(columns.start))
    return columns.block, columns.start, columns.vertices - np.asarray(centre)[owner]
