"""Parametric builders: each returns an :class:`~geometry_library.blocks.Assembly`.

Each builder's parameters are one small frozen dataclass (``WallSpec``, ``ArchSpec``, ``AqueductSpec``)
whose ``build()`` makes the assembly; ``build_wall(**options)`` is ``WallSpec(**options).build()``.
``BUILDERS`` maps a builder name (TOML ``[structure] builder = ...``) to its spec class.
"""

from .aqueduct import AqueductSpec, build_aqueduct
from .arch import ArchGeometry, ArchSpec, arch_parts, build_arch
from .wall import WallLayout, WallSpec, build_wall, wall_layout, wall_layouts

BUILDERS = {"wall": WallSpec, "arch": ArchSpec, "aqueduct": AqueductSpec}

__all__ = [
    "BUILDERS",
    "AqueductSpec",
    "ArchGeometry",
    "ArchSpec",
    "WallLayout",
    "WallSpec",
    "arch_parts",
    "build_aqueduct",
    "build_arch",
    "build_wall",
    "wall_layout",
    "wall_layouts",
]
