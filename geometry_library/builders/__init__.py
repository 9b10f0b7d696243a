"""Parametric builders: each returns an :class:`~geometry_library.blocks.Assembly`."""

from .aqueduct import build_aqueduct
from .arch import ArchGeometry, arch_parts, build_arch
from .wall import WallLayout, build_wall, wall_layout, wall_layouts

BUILDERS = {"wall": build_wall, "arch": build_arch, "aqueduct": build_aqueduct}

__all__ = [
    "BUILDERS",
    "ArchGeometry",
    "WallLayout",
    "arch_parts",
    "build_aqueduct",
    "build_arch",
    "build_wall",
    "wall_layout",
    "wall_layouts",
]
