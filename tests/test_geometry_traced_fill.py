"""A bridge's fill traced as an outline in a GeoJSON ("role": "fill") or WKT ('fill NAME: POLYGON') file
(geometry_library/traced_fill.py, fill.traced_fill_over): dead load carried by the blocks under it, from their top
up to the outline's top. A surveyed bridge had no way to carry its fill: a fill polygon was a block (refused, not
convex), and the carried_mass / carried_at columns asked for each stone's column computed by hand. References: the
closed form of a semicircle filled to its crown, the arch builder's fill (itself checked against shapely and that
closed form, tests/test_geometry_fill.py), a cambered fill's trapezoid by hand."""

from __future__ import annotations

import json
import math
import re

import pytest
from shapely.geometry import Point, box

from geometry_library import GeometryError, read_geojson, read_wkt
from geometry_library.builders import build_arch
from geometry_library.fill import level_from_carried

from cli_helpers import assert_one_line_error, invoke

RE, OUTER, CROWN = 2.15, 2.7, 2.15  # the default arch: extrados radius, piers' outer faces, springing → crown
SPRINGING = 3.4  # 17 pier courses of 0.2 m


def _feature(ring, **props) -> dict:
    return {"type": "Feature", "properties": props, "geometry": {"type": "Polygon", "coordinates": [ring]}}


def _ring(polygon) -> list:
    return [[float(x), float(y)] for x, y in polygon.exterior.coords]


def _bridge_file(tmp_path, outline, name="b.geojson", **props):
    """The default bare arch (masonry build arch) as GeoJSON, with a traced fill feature of this outline."""
    features = [_feature(_ring(b.polygon), name=b.name) for b in build_arch().blocks]
    features += [_feature(_ring(s.polygon), role="support", name=s.name) for s in build_arch().supports]
    features.append(_feature(_ring(outline), role="fill", **props))
    path = tmp_path / name
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


def _traced_to(level: float, into: float = 0.01):
    """The fill a surveyor traces: the box between the piers' outer faces from the springing line up to
    ``level``, less a half disc ``into`` m inside the extrados (drawn a little into the ring's stones)."""
    disc = Point(0.0, SPRINGING).buffer(RE - into, 256)
    return box(-OUTER, SPRINGING, OUTER, SPRINGING + level).difference(disc)


def test_a_traced_fill_to_the_crown_is_the_closed_form_and_the_builders(tmp_path):
    """Box 5.4 × 2.15 m less the fan under the 30 extrados chords of 6°, 30 × ½ R_e² sin 6° (the outline drawn 1 cm
    into the ring counts from the stones' top); each block carries what the builder's --fill-to 2.15 gives it."""
    notes = []
    read = read_geojson(_bridge_file(tmp_path, _traced_to(CROWN), density=1800.0), notes=notes)
    area = 2 * OUTER * RE - 30 * 0.5 * RE * RE * math.sin(math.radians(6.0))
    assert sum(b.carried_mass for b in read.blocks) == pytest.approx(1800.0 * area, rel=1e-9)
    built = build_arch(fill_to=CROWN, fill_density=1800.0).blocks
    for got, want in zip(read.blocks, built, strict=True):
        assert got.carried_mass == pytest.approx(want.carried_mass, rel=1e-9, abs=1e-9), got.name
        if want.carried_mass > 0.0:
            assert got.carried_at == pytest.approx(want.carried_at, abs=1e-9), got.name
    assert any('feature 101: fill 1 ("fill-1"): a fill of 1800 kg/m³, read as dead load' in n for n in notes), notes
    level = level_from_carried(read.blocks)  # one fill, so drawn and spread as a built-in's
    assert level is not None and level[0] == pytest.approx(SPRINGING + CROWN, abs=1e-9)


def test_a_haunch_fill_under_the_crown_as_wkt(tmp_path):
    """Fill to 1.5 m over the springing line, below the crown (the ring stands proud of it): the builder's
    --fill-to 1.5 at 1800 kg/m³: two outlines in WKT, each labelled 'fill NAME 1800:' (WKT has no density column:
    it was 2000 kg/m³, always)."""
    outline = _traced_to(1.5)
    assert outline.geom_type == "MultiPolygon" and len(outline.geoms) == 2
    lines = [f"block {b.name}: {b.polygon.wkt}" for b in build_arch().blocks]
    lines += [f"support {s.name}: {s.polygon.wkt}" for s in build_arch().supports]
    lines += [f"fill haunch-{k} 1800: {part.wkt}" for k, part in enumerate(outline.geoms)]  # a line a haunch
    (tmp_path / "b.wkt").write_text("\n".join(lines) + "\n")
    read = read_wkt(tmp_path / "b.wkt")
    for got, want in zip(read.blocks, build_arch(fill_to=1.5, fill_density=1800.0).blocks, strict=True):
        assert got.carried_mass == pytest.approx(want.carried_mass, rel=1e-9, abs=1e-9), got.name
    lines[-1] = lines[-1].replace("haunch-1 1800:", "haunch-1 18OO:")  # a letter O for a zero: one line
    (tmp_path / "bad.wkt").write_text("\n".join(lines) + "\n")
    with pytest.raises(GeometryError, match=r'line 102: fill 2 \("haunch-1"\): the fill.s density .18OO. is not a n'):
        read_wkt(tmp_path / "bad.wkt")


def test_a_cambered_fill_partly_over_the_ground(tmp_path):
    """A 2 × 1 m stone on a ground; the fill's outline from x = -1 (over the ground) to 2, its top falling from 2.0
    to 1.5 m: over the stone a trapezoid of area 2 (1.0 + 0.5) / 2 = 1.5 m², centroid x = ∫x h / ∫h with
    h = 1 - x/4: (2 - 2/3) / 1.5 = 0.8889 m; the metre over the ground rests on it and is said."""
    stone = _feature([[0, 0], [2, 0], [2, 1], [0, 1], [0, 0]], name="stone")
    ground = _feature([[-2, -0.5], [3, -0.5], [3, 0], [-2, 0], [-2, -0.5]], role="support")
    fill = _feature([[-1, 0], [0, 0], [0, 1], [2, 1], [2, 1.5], [-1, 2.25], [-1, 0]], role="fill", name="road")
    path = tmp_path / "c.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [stone, ground, fill]}))
    notes = []
    block = read_geojson(path, notes=notes).blocks[0]
    assert block.carried_mass == pytest.approx(2000.0 * 1.5, rel=1e-12)
    assert block.carried_at[0] == pytest.approx((2.0 - 2.0 / 3.0) / 1.5, rel=1e-12)
    assert any("2.12 m² over a support rests on it" in n for n in notes), notes  # 1 × (2.0 + 2.25) / 2


@pytest.mark.parametrize(
    ("ring", "geometry", "said"),
    [
        ([[-1, 2], [1, 2], [-1, 3], [1, 3], [-1, 2]], "Polygon", "the fill's outline crosses itself"),
        ([[-9, 0], [-8, 0], [-8, 1], [-9, 1], [-9, 0]], "Polygon", "no block is under this fill"),
        ([[-1, 2], [1, 2]], "LineString", "role must be 'support' (a line is the ground under it)"),
    ],
)
def test_a_bad_fill_is_one_line(tmp_path, ring, geometry, said):
    stone = _feature([[0, 0], [2, 0], [2, 1], [0, 1], [0, 0]], name="stone")
    ground = _feature([[-2, -0.5], [3, -0.5], [3, 0], [-2, 0], [-2, -0.5]], role="support")
    fill = {"type": "Feature", "properties": {"role": "fill"}, "geometry": {"type": geometry, "coordinates": ring}}
    if geometry == "Polygon":
        fill["geometry"]["coordinates"] = [ring]
    path = tmp_path / "bad.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [stone, ground, fill]}))
    with pytest.raises(GeometryError, match=None) as exc:
        read_geojson(path)
    assert said in str(exc.value) and "feature 3" in str(exc.value)
    assert_one_line_error(invoke("check", path), said)


def test_limit_spreads_a_load_through_a_traced_fill(tmp_path):
    """The traced fill to the crown is the builder's, so a load spread through it (--spread) gives the built-in's λ."""
    path = _bridge_file(tmp_path, _traced_to(CROWN + 0.3))
    args = ["--load", "point", "--at", "-0.8", "--spread", "26.6", "--point-force", "10kN", "--json"]
    traced = invoke("limit", path, *args)
    assert traced.exit_code == 0, traced.output
    built = invoke("limit", "arch", "--fill-to", CROWN + 0.3, *args)
    assert json.loads(traced.stdout)["load_factor"] == pytest.approx(json.loads(built.stdout)["load_factor"], rel=1e-6)


def test_a_point_load_placed_by_its_map_abscissa(tmp_path):
    """A bridge traced in Lambert-93 is read moved by whole km (by -650 000 m: x = 651 001.9 is 1001.9); its
    researcher gives --at on the map: it said 'no block over x = 651002 m (the blocks span x = 997.1 … 1002.5 m)'.
    A map abscissa is moved as the file was, with a note, and loads the same voussoir with the same λ."""
    east, north = 651000.0, 6861000.0
    features = [_feature(_ring(b.polygon), name=b.name) for b in build_arch().blocks]
    features += [_feature(_ring(s.polygon), role="support", name=s.name) for s in build_arch().supports]
    for f in features:  # the crown at x = 651 001.8 m
        f["geometry"]["coordinates"] = [[[x + east + 1.8, y + north] for x, y in f["geometry"]["coordinates"][0]]]
    path = tmp_path / "l93.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    local = invoke("limit", path, "--load", "point", "--at", 1001.9, "--json")
    mapped = invoke("limit", path, "--load", "point", "--at", east + 1.9, "--json")
    assert local.exit_code == 0 and mapped.exit_code == 0, mapped.stderr
    said = " ".join(mapped.stderr.split())
    assert "--at 651001.9 is the map's abscissa: x = 1001.9 m in the file as read (moved by -650000 m)" in said
    a, b = json.loads(local.stdout), json.loads(mapped.stdout)
    assert a["load"]["block"] == b["load"]["block"] == "v16"
    assert b["load_factor"] == pytest.approx(a["load_factor"], rel=1e-9)
    assert b["map_origin_m"] == [650000.0, 6860000.0]
    # and the worst place is said on the map too (it was the file's 1001.8 m alone)
    worst = " ".join(invoke("limit", path, "--load", "point", "--worst").stdout.split())
    x, on_map = re.search(r"x = (\S+) m \((\S+) on the map\)", worst).groups()
    assert float(on_map) - 650000.0 == pytest.approx(float(x), abs=0.05)  # x said to 4 digits


def test_a_fills_unused_property_is_said_as_a_fills(tmp_path):
    """A fill's 'velocity' was reported '(read on blocks only: a support moves by a scenario file's [[support]]
    motion)', a support's reason."""
    stone = _feature([[0, 0], [2, 0], [2, 1], [0, 1], [0, 0]], name="stone")
    ground = _feature([[-2, -0.5], [3, -0.5], [3, 0], [-2, 0], [-2, -0.5]], role="support")
    fill = _feature([[0, 1], [2, 1], [2, 2], [0, 2], [0, 1]], role="fill", velocity=[0, 0, 0])
    path = tmp_path / "v.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [stone, ground, fill]}))
    said = " ".join(invoke("check", path).stderr.split())
    assert '"velocity" (a fill takes role, name and density only) first on feature 3, fill 1' in said, said


STONE_ON_GROUND = (
    "block a: POLYGON ((0 0, 2 0, 2 1, 0 1, 0 0))\nsupport g: POLYGON ((-2 -0.5, 3 -0.5, 3 0, -2 0, -2 -0.5))\n"
)


@pytest.mark.parametrize(
    ("label", "said"),
    [
        # 'fill 1800:' was a fill named "1800" at 2000 kg/m³, without a word: 11 % more dead load than meant
        ("fill 1800", "line 3: 'fill 1800:' reads 1800 as the fill's name; its density goes after a name: 'fill NAME"),
        # the builder's --fill-density 1e9 is refused as a typo; a traced fill of 1e9 kg/m³ ran (2e9 kg on a stone)
        ("fill road 1e9", 'line 3: fill 1 ("road"): density 1e+09 kg/m³ is absurd (a likely typo: 0.001 to 100000'),
        # a label that is none listed every form but the fill's
        (
            "road 1800",
            "expected 'NAME: POLYGON ((…))', 'block NAME: …', 'support [NAME] [fixed|driven]: …', 'fill NAME",
        ),
    ],
)
def test_a_wkt_fill_s_density_is_read_as_meant_or_refused(tmp_path, label, said):
    path = tmp_path / "f.wkt"
    path.write_text(STONE_ON_GROUND + f"{label}: POLYGON ((0 1, 2 1, 2 2, 0 2, 0 1))\n")
    assert_one_line_error(invoke("check", path), said)


def test_a_geojson_fill_s_absurd_density_is_refused(tmp_path):
    stone = _feature([[0, 0], [2, 0], [2, 1], [0, 1], [0, 0]], name="stone")
    ground = _feature([[-2, -0.5], [3, -0.5], [3, 0], [-2, 0], [-2, -0.5]], role="support")
    fill = _feature([[0, 1], [2, 1], [2, 2], [0, 2], [0, 1]], role="fill", density=1e9)
    path = tmp_path / "f.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [stone, ground, fill]}))
    assert_one_line_error(invoke("check", path), 'feature 3: fill 1 ("fill-1"): density 1e+09 kg/m³ is absurd')
