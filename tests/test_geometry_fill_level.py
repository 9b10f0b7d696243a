"""A fill read back from the masses the blocks carry (geometry_library.fill.level_from_carried): a built-in
bridge written to GeoJSON keeps only carried_mass and carried_at per block; when they are one fill's (one
density, one level over the top surface) its level is found again, and the builder's is the reference. Any
other set of carried masses gives None: nothing says its outline."""

from __future__ import annotations

import dataclasses

import pytest
from shapely.affinity import translate
from shapely.geometry import box

from geometry_library.blocks import Block, GeometryError
from geometry_library.builders import build_arch
from geometry_library.builders.arch import ArchSpec, arch_parts, fill_level
from geometry_library.builders.wall import WallSpec
from geometry_library.fill import fill_over, level_from_carried
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


def test_a_fill_level_at_the_skewbacks_top_is_no_fill_and_says_so():
    """'masonry build arch --span 8 --rise 2 ... --fill-to 0.3' levels the fill with the skewbacks' top, which the
    builder computes as 1.2999999999999994 m: each skewback carried a column 6e-16 m high (3.5e-12 kg), a file of
    it was no fill ('--spread: no fill to spread through') and the run's table said a 7e-12 kg fill. The skewbacks'
    top is 0.3 m above the springing line (R = 5 m, the springing joint's normal at 53.13° from the vertical, a
    0.5 m ring: 0.5 cos 53.13° = 0.3) and the ring rises from there, so that level carries no fill at all: refused,
    naming that height. Just above it the skewbacks carry their columns (a 2.6 m wide top under 1 cm: 52 kg)."""
    with pytest.raises(GeometryError, match=r"fill_to 0.3 m .*lowest top .* is 0.3 m above the springing line"):
        ArchSpec(**BRIDGE, fill_to=0.3).build()
    blocks = ArchSpec(**BRIDGE, fill_to=0.31).build().blocks
    skewback = next(b for b in blocks if b.name == "left-skewback")
    assert skewback.carried_mass == pytest.approx(2000.0 * 2.6 * 0.01, rel=1e-9)
    assert min(b.carried_mass for b in blocks if b.carried_mass > 0.0) > 1e-3  # kg: no round-off columns


def test_a_top_at_the_level_but_for_round_off_carries_nothing():
    """A block whose top is the fill's level less 6e-16 m (as the builder's skewbacks were) carries no column."""
    low = Block(box(0.0, 0.0, 1.0, 1.2999999999999994), "low")
    high = Block(box(1.0, 0.0, 2.0, 1.0), "high")
    fill = fill_over([low, high], 1.3, 0.0, 2.0)
    assert fill.area[0] == 0.0 and fill.area[1] == pytest.approx(0.3, rel=1e-12)


def test_a_sliver_of_a_bare_blocks_top_still_reads_one_fill():
    """A traced bridge settled first (--settle) had its stones moved by nanometres: L-c3-s2, under the course above,
    showed a sliver of its top (8e-10 m², 24 blocks under the fill, 23 carrying) and the fill was no fill, so not
    drawn. The builder's right skewback moved 1 µm inwards bares 1 µm of the pier's outer top stone under ~3 m of
    fill (a sliver of 3e-6 m² of the fill's ~45 m²): still one fill. Moved 0.1 m, a real column (0.3 m²) over a
    stone carrying nothing: none."""
    blocks = list(build_arch(**BRIDGE, fill_cover=0.3).blocks)
    k = next(i for i, b in enumerate(blocks) if b.name == "right-skewback")
    outer = next(b for b in blocks if b.name == "right-pier-c05-b2")
    assert outer.carried_mass == 0.0 and outer.polygon.bounds[2] == blocks[k].polygon.bounds[2]  # flush outside
    for shift, one in ((1e-6, True), (0.1, False)):
        moved = dataclasses.replace(blocks[k], polygon=translate(blocks[k].polygon, -shift, 0.0))
        found = level_from_carried([moved if i == k else b for i, b in enumerate(blocks)])
        assert (found is not None) == one, shift
