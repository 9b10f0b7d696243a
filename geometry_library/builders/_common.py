"""Small helpers shared by the builders."""

from __future__ import annotations

import math

import numpy as np
from shapely.geometry import Polygon

from ..blocks import Block, GeometryError, Support
from ..checks import normalise_coords


def check_positive(builder: str, **values: float) -> None:
    """Raise a one-line GeometryError unless every value is a finite positive number."""
    for key, value in values.items():
        try:
            ok = math.isfinite(float(value)) and float(value) > 0.0
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise GeometryError(f"{builder}: {key} must be a positive number, got {value!r}")


def check_count(builder: str, minimum: int = 1, **values: int) -> None:
    """Raise a one-line GeometryError unless every value is an integer ≥ ``minimum``."""
    for key, value in values.items():
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
            raise GeometryError(f"{builder}: {key} must be an integer ≥ {minimum}, got {value!r}")


def name_width(count: int) -> int:
    """Digits used to zero-pad indices up to ``count`` in block names (at least 2)."""
    return max(2, len(str(int(count))))


def clean_polygon(coords_or_polygon, name: str) -> Polygon:
    """Normalise a builder's polygon (CCW, no collinear vertices); a failure is a builder bug."""
    if isinstance(coords_or_polygon, Polygon):
        coords = np.asarray(coords_or_polygon.exterior.coords)[:, :2]
    else:
        coords = coords_or_polygon
    return Polygon(normalise_coords(coords, f'built block "{name}"'))


def make_block(polygon, name: str, density: float, thickness: float) -> Block:
    """A Block with a normalised polygon."""
    return Block(clean_polygon(polygon, name), name, float(density), float(thickness))


def make_support(polygon, name: str, role: str) -> Support:
    """A Support with a normalised polygon."""
    return Support(clean_polygon(polygon, name), name, role)
