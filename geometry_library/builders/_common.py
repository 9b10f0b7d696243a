"""Small helpers shared by the builders (their value checks are in :mod:`geometry_library.values`)."""

from __future__ import annotations

import numpy as np
from shapely.geometry import Polygon

from ..blocks import Block, Support
from ..checks import normalised_polygon


def name_width(count: int) -> int:
    """Digits used to zero-pad indices up to ``count`` in block names (at least 2)."""
    return max(2, len(str(int(count))))


def clean_polygon(coords_or_polygon, name: str) -> Polygon:
    """Normalise a builder's polygon (CCW, no collinear vertices); a failure is a builder bug."""
    if isinstance(coords_or_polygon, Polygon):
        coords = np.asarray(coords_or_polygon.exterior.coords)[:, :2]
    else:
        coords = coords_or_polygon
    return normalised_polygon(coords, f'built block "{name}"')  # validate_assembly will not redo it


def make_block(polygon, name: str, density: float, thickness: float) -> Block:
    """A Block with a normalised polygon."""
    return Block(clean_polygon(polygon, name), name, float(density), float(thickness))


def make_support(polygon, name: str, role: str) -> Support:
    """A Support with a normalised polygon."""
    return Support(clean_polygon(polygon, name), name, role)
