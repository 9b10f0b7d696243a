"""A fill read back from the masses the blocks carry (geometry_library.fill.level_from_carried): a built-in
bridge written to GeoJSON keeps only carried_mass and carried_at per block; when they are one fill's (one
density, one level over the top surface) its level is found again, and the builder's is the reference. Any
other set of carried masses gives None: nothing says its outline."""

from __future__ import annotations

import dataclasses

import pytest

from geometry_library.builders import build_arch
from geometry_library.builders.arch import ArchSpec, arch_parts, fill_level
from geometry_library.builders.wall import WallSpec
from geometry_library.fill import level_from_carried
from geometry_library.io import read_geojson, write_geojson

BRIDGE = {"span": 8.0, "rise": 2.0, "ring_thickness": 0.5, "pier_width": 3.0, "pier_courses": 5}


@pytest.mark.parametrize(
    "fill", [{"fill_cover": 0.3}, {"fill_cover": 1.0, "fill_density": 1900.0}, {"fill_to": 2.0}, {"fill_to": 4.5}]
)
def test_a_built_in_bridges_level_is_found_from_its_carried_masses(fill, tmp_path):
    """Through a GeoJSON file, as 'masonry build arch ... --fill-cover 0.3 --out b.geojson' writes it; a haunch
    fill under the crown ('fill_to': 2.0 m, the ring standing proud) included."""
    spec = ArchSpec(**BRIDGE, **fill)
    level, half = fill_level(spec, arch_parts(spec)[2]), arch_parts(spec)[2].half_width
    path = write_geojson(spec.build(), tmp_path / "b.geojson")
    found = level_from_carried(read_geojson(path).blocks)
    assert found is not None
    assert found[0] == pytest.approx(level, abs=1e-12) and found[1:] == pytest.approx((-half, half), abs=1e-12)


def _with(blocks, i: int, **change) -> list:
    return [dataclasses.replace(b, **change) if k == i else b for k, b in enumerate(blocks)]


def test_carried_masses_that_are_not_one_fill_give_none():
    blocks = list(build_arch(**BRIDGE, fill_cover=0.3).blocks)
    i = next(k for k, b in enumerate(blocks) if b.carried_mass > 0 and b.name.startswith("v"))
    at = blocks[i].carried_at
    assert level_from_carried(blocks) is not None
    assert level_from_carried(_with(blocks, i, carried_mass=blocks[i].carried_mass * 1.01)) is None  # density
    assert level_from_carried(_with(blocks, i, carried_at=(at[0] + 0.01, at[1]))) is None  # 1 cm aside
    assert level_from_carried(_with(blocks, i, carried_at=(at[0], at[1] + 0.01))) is None  # 1 cm up
    assert level_from_carried(_with(blocks, i, carried_mass=0.0, carried_at=None)) is None  # a block left bare
    assert level_from_carried(list(build_arch(**BRIDGE).blocks)) is None  # nothing carried
    wall = list(WallSpec().build().blocks)
    top = max(range(len(wall)), key=lambda k: wall[k].polygon.bounds[3])
    centre = wall[top].polygon.centroid
    # a point mass on one stone of a wall (a statue): no fill of any level has its centroid there
    assert level_from_carried(_with(wall, top, carried_mass=500.0, carried_at=(centre.x, centre.y + 0.5))) is None
