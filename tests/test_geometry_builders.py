"""Builders: exact counts, no overlaps (STRtree), convexity, bond pattern, radial joints, level top."""

import dataclasses
import math

import numpy as np
import pytest
import shapely
from shapely.strtree import STRtree

from geometry_library import (
    BUILDERS,
    AqueductSpec,
    ArchSpec,
    GeometryError,
    WallSpec,
    build_aqueduct,
    build_arch,
    build_wall,
    is_convex,
    validate_assembly,
    wall_layout,
)
from geometry_library.values import DIMENSION_RANGE, check_dimensions

L, H = 0.30, 0.20
# Default arch: span 3.6 m, ring 0.35 m, piers 0.90 m wide × 17 courses of 0.20 m.
R_I, R_E, Y_S, X_OUT = 1.8, 2.15, 3.4, 2.7


@pytest.fixture(scope="module")
def built():
    return {
        "wall51": build_wall(),
        "wall248": build_wall(blocks=248),
        "arch": build_arch(),
        "aqueduct": build_aqueduct(),
    }


def max_pairwise_overlap(assembly) -> float:
    """Largest intersection area between any two bodies (blocks and supports), via an STRtree."""
    geoms = np.array([b.polygon for b in assembly.blocks + assembly.supports], dtype=object)
    left, right = STRtree(geoms).query(geoms, predicate="intersects")
    keep = left < right
    if not keep.any():
        return 0.0
    return float(shapely.area(shapely.intersection(geoms[left[keep]], geoms[right[keep]])).max())


@pytest.mark.parametrize(
    "key, blocks, supports",
    [
        ("wall51", 51, ["ground"]),
        ("wall248", 248, ["ground"]),
        ("arch", 98, ["left-foundation", "right-foundation"]),
        ("aqueduct", 346, ["left-foundation", "right-foundation"]),
    ],
)
def test_counts_overlaps_convexity_and_validation(built, key, blocks, supports):
    a = built[key]
    assert a.block_count == blocks
    assert [s.name for s in a.supports] == supports
    assert max_pairwise_overlap(a) < 1e-9
    assert all(is_convex(b.vertices) for b in a.blocks)
    assert len({b.name for b in a.blocks}) == blocks
    assert validate_assembly(a) == []  # no error, and every block touches something


def test_builders_registry():
    assert BUILDERS == {"wall": WallSpec, "arch": ArchSpec, "aqueduct": AqueductSpec}
    # The aqueduct's parameters are the arch's plus its wall's, declared once.
    arch_fields = [f.name for f in dataclasses.fields(ArchSpec)]
    assert [f.name for f in dataclasses.fields(AqueductSpec)][: len(arch_fields)] == arch_fields
    with pytest.raises(dataclasses.FrozenInstanceError):
        WallSpec().blocks = 3


def test_spec_build_is_the_builder(built):
    wall = WallSpec(blocks=248).build()
    assert [b.name for b in wall.blocks] == [b.name for b in built["wall248"].blocks]
    assert all(np.array_equal(a.vertices, b.vertices) for a, b in zip(wall.blocks, built["wall248"].blocks))
    arch = ArchSpec(voussoirs=21, pier_courses=10).build()
    assert arch.block_count == 21 + 40 and arch.block_count == build_arch(voussoirs=21, pier_courses=10).block_count
    with pytest.raises(TypeError):
        build_wall(voussoirs=3)


# --- wall ------------------------------------------------------------------------------------


def courses_of(assembly):
    """{course number: sorted list of (xmin, xmax)} from the block names cCC-bBB."""
    out: dict[int, list] = {}
    for b in assembly.blocks:
        c = int(b.name.split("-")[0][1:])
        xmin, _, xmax, _ = b.polygon.bounds
        out.setdefault(c, []).append((xmin, xmax))
    return {c: sorted(v) for c, v in out.items()}


@pytest.mark.parametrize("key, courses, per_odd", [("wall51", 6, 8), ("wall248", 16, 15)])
def test_wall_layout_and_running_bond(built, key, courses, per_odd):
    a = built[key]
    rows = courses_of(a)
    assert len(rows) == courses
    for c, row in rows.items():
        widths = [x1 - x0 for x0, x1 in row]
        if c % 2 == 1:
            assert widths == pytest.approx([L] * per_odd)
        else:
            assert widths == pytest.approx([L / 2] + [L] * (per_odd - 1) + [L / 2])
        assert row[0][0] == pytest.approx(-per_odd * L / 2) and row[-1][1] == pytest.approx(per_odd * L / 2)
    for b in a.blocks:
        _, y0, _, y1 = b.polygon.bounds
        assert y1 - y0 == pytest.approx(H)
    # Bond: every vertical joint is half a block from the nearest joint of the course below/above.
    for c in range(1, courses):
        lower = np.array([x1 for _, x1 in rows[c][:-1]])
        upper = np.array([x1 for _, x1 in rows[c + 1][:-1]])
        for joints, other in ((lower, upper), (upper, lower)):
            gaps = np.abs(joints[:, None] - other[None, :]).min(axis=1)
            assert gaps == pytest.approx(np.full(len(joints), L / 2))


def test_wall_sits_on_ground(built):
    a = built["wall51"]
    assert min(b.polygon.bounds[1] for b in a.blocks) == 0.0
    xmin, ymin, xmax, ymax = a.supports[0].polygon.bounds
    assert (ymax, ymin) == (0.0, -0.5) and xmin == pytest.approx(-1.2 - 2.0) and xmax == pytest.approx(3.2)


def test_wall_layout_table():
    lay = wall_layout(51)
    assert (lay.courses, lay.full_per_course, lay.length, lay.height) == (6, 8, pytest.approx(2.4), pytest.approx(1.2))
    assert [r[3] for r in lay.rows()] == [8, 9, 8, 9, 8, 9]
    assert "51 blocks = 6 courses" in lay.table()
    lay = wall_layout(248)
    assert (lay.courses, lay.full_per_course) == (16, 15)


def test_wall_courses_and_length_options():
    a = build_wall(blocks=None, courses=4, length=2.4)
    assert a.block_count == 4 * 8 + 2
    assert build_wall(blocks=51, courses=2).block_count == 51  # 2 × 25
    assert build_wall(blocks=51, length=2.4).block_count == 51


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(blocks=51, courses=4), "51 blocks cannot be laid in running bond with 4 courses"),
        # the lengths that fit beside it are named (it said only "not a whole number of 0.3 m blocks")
        (dict(blocks=51, length=1.0), r"length 1 m is not a whole number of 0.3 m blocks \(0.9 m is 3, 1.2 m is 4\)"),
        (dict(blocks=51, length=0.1), r"length 0.1 m is not a whole number of 0.3 m blocks \(0.3 m is 1\)$"),
        (dict(blocks=51, courses=5, length=2.4), "cannot be laid"),
        (dict(blocks=0), "positive integer"),
        (dict(block_length=-0.3), "block_length must be a positive"),
    ],
)
def test_wall_errors_are_one_line(kwargs, match):
    with pytest.raises(GeometryError, match=match) as info:
        build_wall(**kwargs)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    "build, kwargs, match",
    [
        (
            build_wall,
            dict(block_length=1e-9),
            r"wall: block_length 1e-09 m is absurd \(a likely typo: 0.001 to 1000 m\)",
        ),
        (build_wall, dict(block_height=1e5), "wall: block_height 100000 m is absurd"),
        (build_wall, dict(ground_depth=1e4), "wall: ground_depth 10000 m is absurd"),
        (build_arch, dict(span=1e-6), "arch: span 1e-06 m is absurd"),
        (build_arch, dict(span=1e5), "arch: span 100000 m is absurd"),
        (build_arch, dict(pier_course_height=1e-4), "arch: pier_course_height 0.0001 m is absurd"),
        (build_aqueduct, dict(block_height=5e3), "aqueduct: block_height 5000 m is absurd"),
    ],
)
def test_absurd_dimensions_are_refused(build, kwargs, match):
    # Were built and run without a word: --block-height 1e5 a 600 km wall, --block-length 1e-9 blocks of 1 nm,
    # --span 1e-6 an arch of 1 µm reported "intact".
    with pytest.raises(GeometryError, match=match) as info:
        build(**kwargs)
    assert "\n" not in str(info.value)
    check_dimensions("x", lo=DIMENSION_RANGE[0], hi=DIMENSION_RANGE[1])  # the bounds themselves are accepted


@pytest.mark.parametrize(
    "build, kwargs, match",
    [
        (build_wall, dict(blocks=10**8), "wall: 100000000 blocks, more than 100000"),
        (build_wall, dict(blocks=None, courses=10**5, length=3.0), "100000 courses of length 3 m makes 1050000 blocks"),
        (build_arch, dict(voussoirs=10**8), "100000000 voussoirs and 17 pier courses makes 100000068 blocks"),
        (build_aqueduct, dict(wall_courses=10**5), "100000 wall courses .* makes up to 2100098 blocks"),
    ],
)
def test_absurd_block_counts_are_refused_before_building(build, kwargs, match):
    # Each used to build for minutes (the aqueduct's for hours) and fill the memory; now refused at once.
    with pytest.raises(GeometryError, match=match):
        build(**kwargs)


# --- arch ------------------------------------------------------------------------------------


def test_arch_voussoirs_have_radial_joints_and_circle_vertices(built):
    a = built["arch"]
    ring = [b for b in a.blocks if b.name.startswith("v")]
    assert len(ring) == 30
    centre = np.array([0.0, Y_S])
    for b in ring:
        xy = b.vertices
        assert len(xy) == 4
        r = np.hypot(*(xy - centre).T)
        assert sorted(np.round(r, 12)) == [R_I, R_I, R_E, R_E]
        # Joints: the two edges joining an intrados vertex to an extrados vertex pass through the centre.
        for i in range(4):
            p, q = xy[i], xy[(i + 1) % 4]
            if abs(np.hypot(*(p - centre)) - np.hypot(*(q - centre))) > 0.1:
                d = q - p
                cross = d[0] * (centre - p)[1] - d[1] * (centre - p)[0]
                assert abs(cross) / np.hypot(*d) < 1e-12  # distance from the centre to the joint line
        # Each voussoir spans 6°.
        ang = np.degrees(np.arctan2(*(xy - centre).T[::-1]))
        assert ang.max() - ang.min() == pytest.approx(6.0)


def test_arch_piers_bond_and_springing_support(built):
    a = built["arch"]
    for side, sign in (("left", -1), ("right", 1)):
        pier = [b for b in a.blocks if b.name.startswith(f"{side}-pier")]
        assert len(pier) == 34
        joints = {}
        for b in pier:
            c = int(b.name.split("-c")[1][:2])
            xmin, y0, xmax, y1 = b.polygon.bounds
            assert y1 - y0 == pytest.approx(0.2)
            assert xmax - xmin == pytest.approx(0.6) or xmax - xmin == pytest.approx(0.3)
            joints.setdefault(c, set()).update({round(xmin, 9), round(xmax, 9)})
        inner = {c: sorted(j - {round(sign * R_I, 9), round(sign * X_OUT, 9)}) for c, j in joints.items()}
        for c in range(1, 17):
            assert abs(inner[c][0] - inner[c + 1][0]) == pytest.approx(0.3)  # half of the full block
        # The springing voussoir rests entirely on the pier's top course.
        spring = a.blocks[34] if side == "left" else a.blocks[63]
        top = shapely.union_all([b.polygon for b in pier if "-c17-" in b.name])
        base = shapely.intersection(spring.polygon.boundary, top.boundary)
        assert base.length == pytest.approx(0.35)
    foundations = {s.name: s.polygon.bounds for s in a.supports}
    assert foundations["left-foundation"][3] == 0.0 and foundations["right-foundation"][3] == 0.0


def test_arch_options_and_errors():
    assert build_arch(voussoirs=21, pier_courses=10).block_count == 21 + 40
    with pytest.raises(GeometryError, match="ring_thickness .* wider than the pier"):
        build_arch(ring_thickness=1.0, pier_width=0.9)
    with pytest.raises(GeometryError, match="voussoirs must be an integer"):
        build_arch(voussoirs=1)


# --- aqueduct --------------------------------------------------------------------------------


def test_aqueduct_has_arch_first_then_248_wall_blocks(built):
    a = built["aqueduct"]
    arch = built["arch"]
    assert [b.name for b in a.blocks[:98]] == [b.name for b in arch.blocks]
    for x, y in zip(a.blocks[:98], arch.blocks):
        np.testing.assert_array_equal(x.vertices, y.vertices)
    wall = a.blocks[98:]
    assert len(wall) == 248 and all(b.name.startswith("wall-c") for b in wall)


def test_aqueduct_wall_blocks_are_not_slivers(built):
    wall = built["aqueduct"].blocks[98:]
    smallest = min(b.polygon.area for b in wall)
    assert smallest >= 0.05 * L * H
    assert max(b.polygon.area for b in wall) <= 2.0 * L * H


def test_aqueduct_level_top_and_no_gaps(built):
    a = built["aqueduct"]
    wall = a.blocks[98:]
    top = max(b.polygon.bounds[3] for b in wall)
    half_width = X_OUT
    # Level top: the blocks reaching the top cover its whole width with their top edges.
    top_edges = shapely.union_all(
        [shapely.intersection(b.polygon.boundary, shapely.box(-9, top - 1e-12, 9, top + 1e-12)) for b in wall]
    )
    assert top_edges.length == pytest.approx(2 * half_width, abs=1e-9)
    # No gaps and no overlaps: the blocks tile exactly the envelope minus the arch opening, whose
    # area is the rectangle under the springing line plus the half polygon under the intrados.
    opening = 2 * R_I * Y_S + 0.5 * 30 * R_I**2 * math.sin(math.pi / 30)
    total = sum(b.polygon.area for b in a.blocks)
    assert total == pytest.approx(2 * half_width * top - opening, abs=1e-9)
    union = shapely.union_all([b.polygon for b in a.blocks]).buffer(1e-7, join_style="mitre")
    assert union.geom_type == "Polygon" and len(union.interiors) == 0


def test_aqueduct_is_mirror_symmetric(built):
    wall = built["aqueduct"].blocks[98:]
    shapes = {tuple(np.round(np.sort(b.vertices, axis=0).ravel(), 9)) for b in wall}
    for b in wall:
        mirrored = b.vertices * [-1.0, 1.0]
        assert tuple(np.round(np.sort(mirrored, axis=0).ravel(), 9)) in shapes


@pytest.mark.parametrize(
    "span",
    [
        0.5,  # a voussoir corner at x = -0.6 cos 60° = -0.30000000000000004, on the joint at -0.3
        2.4176914536,  # a voussoir corner 1e-11 m to the right of the joint at -1.35
    ],
)
def test_aqueduct_builds_when_an_extrados_vertex_falls_on_a_joint(span):
    # Both failed with "spandrel: could not split a wall piece into convex blocks (builder bug)": the
    # piece beside the joint had a 6e-17 / 2e-11 m edge whose round-off angle looked reflex.
    a = build_aqueduct(span=span)
    assert max_pairwise_overlap(a) < 1e-9
    assert all(is_convex(b.vertices) for b in a.blocks)
    assert validate_assembly(a) == []
    # The blocks tile the envelope minus the opening (rectangle under the springing + half polygon).
    r_i, n = 0.5 * span, 30
    half_width, top = r_i + 0.9, Y_S + 18 * H
    opening = 2 * r_i * Y_S + 0.5 * n * r_i**2 * math.sin(math.pi / n)
    assert sum(b.polygon.area for b in a.blocks) == pytest.approx(2 * half_width * top - opening, abs=1e-9)


def test_aqueduct_too_few_wall_courses_names_the_option():
    # The message is read by CLI users (--wall-courses) and scenario-file users (wall_courses) alike.
    with pytest.raises(
        GeometryError, match=r"below the crown .* \(--wall-courses, or wall_courses in a scenario file\)"
    ):
        build_aqueduct(wall_courses=2)
