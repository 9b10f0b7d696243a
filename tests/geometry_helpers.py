"""Shared by the geometry checks' tests: a one-line GeometryError caught, an assembly of boxes, a ground."""

import pytest
from shapely.geometry import box

from geometry_library import Assembly, Block, GeometryError, Support


def raises_one_line(match: str, fn, *args, **kwargs) -> str:
    with pytest.raises(GeometryError, match=match) as info:
        fn(*args, **kwargs)
    message = str(info.value)
    assert "\n" not in message
    return message


def asm(*polys, supports=(), names=None):
    names = names or [f"b{i}" for i in range(len(polys))]
    return Assembly(tuple(Block(p, n) for p, n in zip(polys, names)), tuple(supports))


GROUND = Support(box(-5, -1, 5, 0), "ground")
