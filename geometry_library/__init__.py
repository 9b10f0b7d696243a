"""Geometry of dry-stone masonry: blocks, supports, builders, checks, mass properties and I/O.

The only package of masonry that imports shapely. It knows nothing about dynamics.

>>> from geometry_library import build_wall, validate_assembly, mass_properties
>>> wall = build_wall(blocks=51)
>>> validate_assembly(wall)
[]
>>> round(mass_properties(wall.blocks[0].vertices).mass, 6)
150.0
"""

from .assembly_checks import validate_assembly
from .blocks import SUPPORT_ROLES, Assembly, Block, GeometryError, Support, ccw_vertices
from .builders import (
    BUILDERS,
    AqueductSpec,
    ArchGeometry,
    ArchSpec,
    WallLayout,
    WallSpec,
    build_aqueduct,
    build_arch,
    build_wall,
    wall_layout,
    wall_layouts,
)
from .checks import body_label, is_convex, normalise_polygon, polygon_from_coords
from .io import read_geojson, write_geojson
from .mass import MassProperties, mass_properties
from .wkt import read_wkt, write_wkt

__all__ = [
    "BUILDERS",
    "SUPPORT_ROLES",
    "AqueductSpec",
    "ArchGeometry",
    "ArchSpec",
    "Assembly",
    "Block",
    "GeometryError",
    "MassProperties",
    "Support",
    "WallLayout",
    "WallSpec",
    "body_label",
    "build_aqueduct",
    "build_arch",
    "build_wall",
    "ccw_vertices",
    "is_convex",
    "mass_properties",
    "normalise_polygon",
    "polygon_from_coords",
    "read_geojson",
    "read_wkt",
    "validate_assembly",
    "wall_layout",
    "wall_layouts",
    "write_geojson",
    "write_wkt",
]
