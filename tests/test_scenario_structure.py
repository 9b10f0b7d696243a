"""masonrycli.scenario.structure: builder options checked against the spec and the material's defaults, geometry
files read with the material's defaults, validation warnings on one line and errors at their place.
(The TOML spellings of the option errors are in test_scenario_builders.py; these are the module's own rules.)"""

from __future__ import annotations

import dataclasses
import json

import pytest
from shapely.geometry import box

import geometry_library.builders as builders_pkg
from geometry_library.blocks import Assembly, Block, GeometryError, Support
from geometry_library.mass import mass_properties
from masonrycli.errors import InputContext, InputError
from masonrycli.scenario.structure import build_structure, check_finite_tree, read_geometry, structure_warnings

CTX = InputContext("s.toml", ".")


@dataclasses.dataclass(frozen=True)
class TinySpec:
    """Two blocks of ``width`` × ``height`` side by side on a ground; what it was given is kept."""

    width: float = 0.4
    height: float = 0.2
    courses: int = 1
    mortar: bool = False
    top: float | None = None
    density: float = 2500.0
    thickness: float = 1.0

    def build(self):
        if self.width == 9.0:
            raise GeometryError("tiny: width = 9: too wide")
        if self.width == 8.0:
            return "not an assembly"
        if self.width == 7.0:
            raise TypeError("a bug in the builder")
        w, h = self.width, self.height
        blocks = tuple(Block(box(i * w, 0.0, (i + 1) * w, h), f"b{i}", self.density, self.thickness) for i in (0, 1))
        return Assembly(blocks, (Support(box(-1.0, -0.5, 2 * w + 1.0, 0.0), "ground"),))


def _mass(block: Block) -> float:
    return mass_properties(block.vertices, block.density, block.thickness).mass


@pytest.fixture
def tiny(monkeypatch):
    monkeypatch.setattr(builders_pkg, "BUILDERS", {**builders_pkg.BUILDERS, "tiny": TinySpec})


def test_the_material_fills_density_and_thickness_unless_an_option_sets_them(tiny):
    a = build_structure("tiny", {"width": 1, "top": None}, density=2000.0, thickness=0.5)
    # two 1 m × 0.2 m blocks: m = ρ w h t = 2000 · 1 · 0.2 · 0.5 = 200 kg each
    assert [_mass(b) for b in a.blocks] == pytest.approx([200.0, 200.0], rel=1e-12)
    b = build_structure("tiny", {"density": 1800, "thickness": 2.0}, density=2000.0, thickness=0.5)
    assert [_mass(blk) for blk in b.blocks] == pytest.approx([1800 * 0.4 * 0.2 * 2.0] * 2, rel=1e-12)


@pytest.mark.parametrize(
    "options, message",
    [
        ({"mortar": 1}, "mortar = 1: must be true or false"),
        ({"width": [1, 2]}, "width = [1, 2]: must be a number"),  # a TOML list, frozen to a tuple
        ({"courses": 1.0}, "courses = 1.0: must be an integer"),
        ({"zzz": 3}, 'unknown option "zzz" of builder "tiny" (options: width, height, courses, mortar, top'),
        ({"width": 9.0}, 'builder "tiny": width = 9: too wide'),  # the builder's own name not said twice
        ({"width": 8.0}, 'builder "tiny" returned str, not an Assembly'),
    ],
)
def test_option_and_builder_errors_are_one_line(tiny, options, message):
    with pytest.raises(InputError) as info:
        build_structure("tiny", options, density=2500.0, thickness=1.0)
    assert str(info.value).startswith(message), str(info.value)


def test_a_bug_in_a_builder_is_not_hidden_as_bad_input(tiny):
    with pytest.raises(TypeError, match="a bug in the builder"):
        build_structure("tiny", {"width": 7.0}, density=2500.0, thickness=1.0)
    with pytest.raises(InputError, match=r'^builder = "nope": unknown builder \(expected one of .*tiny'):
        build_structure("nope", {}, density=2500.0, thickness=1.0)


def test_finite_check_names_the_place_inside_the_value():
    check_finite_tree("spans", [1.0, {"rise": 2.0}])
    with pytest.raises(InputError, match=r"^spans\[1\]\.rise = nan: must be a finite number$"):
        check_finite_tree("spans", [1.0, {"rise": float("nan")}])
    with pytest.raises(InputError, match=r"^height = inf: must be a finite number$"):
        check_finite_tree("height", float("inf"))


def _geojson(path, *bodies):
    features = [
        {"type": "Feature", "properties": props, "geometry": {"type": "Polygon", "coordinates": [coords]}}
        for props, coords in bodies
    ]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return str(path)


RECT = [[0, 0], [0.4, 0], [0.4, 0.2], [0, 0.2], [0, 0]]
GROUND = [[-1, -0.5], [1, -0.5], [1, 0], [-1, 0], [-1, -0.5]]


def test_a_geometry_file_takes_the_material_where_it_says_nothing(tmp_path):
    path = _geojson(tmp_path / "w.geojson", ({"name": "a"}, RECT), ({"role": "support", "name": "g"}, GROUND))
    a = read_geometry(path, density=2000.0, thickness=0.5, ctx=CTX)
    assert [b.name for b in a.blocks] == ["a"] and [s.name for s in a.supports] == ["g"]
    assert _mass(a.blocks[0]) == pytest.approx(2000.0 * 0.4 * 0.2 * 0.5, rel=1e-12)
    assert structure_warnings(a, CTX) == ()


def test_geojson_properties_not_used_give_one_warning_with_near_misses(tmp_path):
    # the reader used the material's density for a block whose "densty" said 2000, and no per-block friction
    block = {"name": "a", "densty": 2000, "friction": 0.7, "fid": 1, "colour": "red"}
    path = _geojson(tmp_path / "w.geojson", (block, RECT), ({"role": "support", "name": "g"}, GROUND))
    notes: list[str] = []
    read_geometry(path, 2500.0, 1.0, CTX, notes=notes)
    (note,) = notes
    assert note == (
        f"{path}: properties not used, ignored (used: role, name, density, thickness, velocity, support_role, carried_mass, carried_at): "
        '"densty" (did you mean "density"?) first on feature 1, block 1 ("a"); '
        '"friction" (friction is the scenario file\'s [material] friction, one for every contact) first on '
        'feature 1, block 1 ("a"); "colour" first on feature 1, block 1 ("a")'
    )
    clean = _geojson(tmp_path / "c.geojson", ({"name": "a", "density": 2000, "id": 4}, RECT))
    read_geometry(clean, 2500.0, 1.0, CTX, notes=notes)
    assert len(notes) == 1


def test_a_property_of_the_other_role_is_warned_about_with_why(tmp_path):
    # the user gave the ground a velocity to shake it: it stayed fixed, the run "intact", and nothing said why
    ground = {"role": "support", "name": "g", "velocity": [0.5, 0, 0], "thickness": 1.0}
    path = _geojson(tmp_path / "w.geojson", ({"name": "a", "support_role": "fixed"}, RECT), (ground, GROUND))
    notes: list[str] = []
    read_geometry(path, 2500.0, 1.0, CTX, notes=notes)
    assert notes == [
        f"{path}: properties not used, ignored (used: role, name, density, thickness, velocity, support_role, carried_mass, carried_at): "
        '"support_role" (read on supports only) first on feature 1, block 1 ("a"); "velocity" (read on blocks '
        'only: a support moves by a scenario file\'s [[support]] motion) first on feature 2, support 1 ("g"); '
        '"thickness" (read on blocks only: a support has no mass) first on feature 2, support 1 ("g")'
    ]


def test_geometry_file_errors_name_the_table_or_only_the_file(tmp_path):
    with pytest.raises(InputError, match=r'^s\.toml: \[structure\] file = "w\.dxf": unknown geometry format'):
        read_geometry("w.dxf", 2500.0, 1.0, CTX)
    missing = str(tmp_path / "none.wkt")
    with pytest.raises(InputError, match=r"\[structure\] file = .*none\.wkt\": no such file$"):
        read_geometry(missing, 2500.0, 1.0, CTX)
    folder = tmp_path / "d.geojson"
    folder.mkdir()
    with pytest.raises(InputError) as info:
        read_geometry(str(folder), 2500.0, 1.0, CTX, where="")
    assert str(info.value) == "s.toml: is a directory"  # it said NOT_A_FILE: "a device, a pipe or a socket"
    bad = tmp_path / "bad.geojson"
    bad.write_text("{")
    with pytest.raises(InputError) as info:  # the scenario is the file itself: the reader's message as is
        read_geometry(str(bad), 2500.0, 1.0, CTX, where="")
    assert str(info.value).startswith(f"{bad}: invalid JSON")
    with pytest.raises(InputError) as info:
        read_geometry(str(bad), 2500.0, 1.0, CTX)
    assert str(info.value).startswith(f"s.toml: [structure] {bad}: invalid JSON")


def test_validation_warnings_are_lines_and_its_errors_are_placed():
    ground = Support(box(-1.0, -0.5, 1.0, 0.0), "ground")
    floating = Assembly((Block(box(0, 0, 0.4, 0.2), "a"), Block(box(0, 5, 0.4, 5.2), "up")), (ground,))
    (warning,) = structure_warnings(floating, CTX)
    assert warning.startswith('block 2 ("up") touches nothing (nearest body 4.8 m away') and "\n" not in warning
    overlapping = Assembly((Block(box(0, 0, 0.4, 0.2), "a"), Block(box(0.2, 0, 0.6, 0.2), "b")), (ground,))
    with pytest.raises(InputError, match=r'^s\.toml: blocks 1 \("a"\) and 2 \("b"\) overlap by 0\.04 m²'):
        structure_warnings(overlapping, CTX)


@pytest.mark.parametrize(
    "options, given, message",
    [
        ({"ring_thickness": 0.0001}, None, "--ring-thickness 0.0001 m is absurd (a likely typo: 0.001 to 1000 m)"),
        ({"ring_thickness": 0.9, "pier_width": 0.5}, None, "--ring-thickness and --pier-width: --ring-thickness 0.9 m"),
        ({"ring_thickness": 0.9, "pier_width": 0.5}, {"pier_width": 0.5}, "--pier-width: --ring-thickness 0.9 m"),
        ({"voussoirs": 1}, {}, 'builder "arch": voussoirs must be an integer ≥ 2, got 1'),  # not given: as it was
    ],
)
def test_a_builder_check_names_the_command_line_options_it_is_about(options, given, message):
    import pickle

    from masonrycli.scenario.structure import BuilderError, as_options

    with pytest.raises(BuilderError) as info:
        build_structure("arch", options, 2500.0, 1.0)
    again = pickle.loads(pickle.dumps(info.value))  # a sweep's worker sends it back whole
    assert (again.keys, again.problem, str(again)) == (info.value.keys, info.value.problem, str(info.value))
    assert str(as_options(info.value, options if given is None else given)).startswith(message)
