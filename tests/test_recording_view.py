"""What the structure views frame, read back from recordings: every frame's content inside the view."""

from __future__ import annotations

import numpy as np

from masonrycli.outputs.frame import CONTACT_STICK
from masonrycli.recording import Recorder
from masonrycli.recording.layout import FIELDS, FORCES, LEGEND, PLANE, RESULTANT_CAP

import recording_fixtures as fx
from recording_fixtures import strict_rerun, temporal_rows  # noqa: F401 (strict_rerun: autouse)


def _view(path) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax), m, of the structure views (1 image unit = 1 m; the image starts at x0, y0)."""
    x0, y0, _ = fx.static_value(path, f"/{PLANE}", "Transform3D:translation")[0]
    width, height = fx.static_value(path, f"/{PLANE}", "Pinhole:resolution")[0]
    return x0, y0 - height, x0 + width, y0


def test_the_view_holds_every_frames_joint_arrows(tmp_path):
    """'masonry simulate wall --courses 64 --length 4.5' (the lab's h64): the wall rocks on its toes, whose
    joint carries the weight of the wall (1.6 MN against 67 kN a block height at the run's fixed scale); the
    arrow, centred on its point, ran 4 m below the view in 70 frames of 100 (Live, Sliding and Opening tabs).
    The scale stays fixed for the run (the arrows compare across time); the view holds every frame's arrows,
    and an arrow is at most RESULTANT_CAP x the structure's size long (an impact's one-frame spike: 12 m on
    the 12.8 m wall), its force on hover."""
    static, q0 = fx.wall()
    n = len(q0)
    frames = fx.frames(static, q0, 12)
    toe = np.array([0.0, 0.05])  # the wall's left toe, on the ground (its top at y = 0)
    force = 300.0 * (1.0 + np.arange(12.0))
    force[-1] = 1e6  # the last frame: a spike
    for f, fy in zip(frames, force):  # one joint (block 0 on the ground) carrying more and more
        f.contact_body[(f.contact_body[:, 0] == 0) & (f.contact_body[:, 1] == n)] = (1, 2)
        f.contact_body[0], f.contact_point[0], f.contact_normal[0] = (0, n), toe, (0.0, 1.0)
        f.contact_status[0], f.contact_force[0] = CONTACT_STICK, (0.0, fy)
    path = tmp_path / "toe.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
        for f in frames:
            rec.log_frame(f)
    origins = temporal_rows(path, f"/{FORCES}", "Arrows2D:origins")
    vectors = temporal_rows(path, f"/{FORCES}", "Arrows2D:vectors")
    xmin, ymin, xmax, ymax = _view(path)
    cap = RESULTANT_CAP * 4 * fx.BLOCK_W  # the structure's size: the wall is 1.2 m long, 0.8 m high
    toe_lengths, lowest = [], np.inf
    for f in frames:
        o, v = np.array(origins[f.step]).reshape(-1, 2), np.array(vectors[f.step]).reshape(-1, 2)
        ends = np.concatenate([o, o + v])
        assert (ends[:, 0] > xmin).all() and (ends[:, 0] < xmax).all(), (f.step, ends[:, 0].min(), xmin, xmax)
        assert (ends[:, 1] > ymin).all() and (ends[:, 1] < ymax).all(), (f.step, ends[:, 1].min(), ymin, ymax)
        assert np.hypot(*v.T).max() <= cap * (1 + 1e-6)
        at_toe = np.argmin(np.hypot(*(o + 0.5 * v - toe).T))
        toe_lengths.append(np.hypot(*v[at_toe]))
        lowest = min(lowest, ends[:, 1].min())
    # the fixed scale: the toe arrow grows with its force until the cap (the spike)
    np.testing.assert_allclose(toe_lengths, np.minimum(rec.force_scale * force, cap), rtol=1e-5)
    # uncapped, the arrow before the spike reaches below the ground's underside (y = -0.1 m) by more than
    # the margin of a view fitted to the structure (0.05 x its size)
    assert rec.force_scale * force[-2] < cap and lowest < -0.1 - 0.05 * 1.2, (rec.force_scale, lowest)
    # the Magnified tab (no arrows) shows the structure, not the room below it for the arrows
    from masonrycli.recording.layout import MAGNIFIED_TAB
    from masonrycli.recording.readback import blueprint_views

    _, (v0, v1) = blueprint_views(path)[MAGNIFIED_TAB]["bounds"]
    assert ymax - v1 > -0.1 - 0.05 * 1.2 - 0.01 > lowest, (ymax - v1, lowest)  # image v runs down from ymax
    legend = fx.static_value(path, f"/{LEGEND}", "TextDocument:text")[0]
    assert f"at most {cap:.3g} m ({cap / rec.force_scale / 1e3:.4g} kN and up)" in legend, legend


def test_the_magnified_tab_is_framed_on_the_structure_and_holds_the_magnified_shape(tmp_path):
    """The magnified shape's tab has no colour bar, yet showed the view the other tabs share: the structure
    in its left two thirds, the right third kept for a bar. It is framed on the view left of the bars. And
    the view holds the magnified shape (blocks; supports in y): the arch's right foundation, settled 1 cm in
    'masonry simulate arch --duration 1' and drawn x 25, touched the bottom edge (0.03 m from it)."""
    from masonrycli.recording.layout import MAGNIFIED, MAGNIFIED_TAB
    from masonrycli.recording.readback import blueprint_views

    static, q0 = fx.wall()
    frames = fx.frames(static, q0, 12)
    for k, f in enumerate(frames):  # the blocks rise 5 mm a frame, drawn x 40: 2.2 m above the wall at the end
        f.block_q[:, 1] += 0.005 * k
    path = tmp_path / "magnified.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=4, magnify=40.0) as rec:
        for f in frames:
            rec.log_frame(f)
    xmin, ymin, xmax, ymax = _view(path)
    strips = temporal_rows(path, f"/{MAGNIFIED}", "LineStrips2D:strips")
    n = len(q0)
    for step, rows in strips.items():
        blocks = np.concatenate([np.array(r) for r in rows[:n]])
        assert (blocks >= (xmin, ymin)).all() and (blocks <= (xmax, ymax)).all(), (step, blocks.max(axis=0), ymax)
    (x_range, y_range) = blueprint_views(path)[MAGNIFIED_TAB]["bounds"]
    bar_left = min(
        fx.legend_points(path, fx.static_value(path, f"/{f.bar}", "Mesh3D:vertex_positions"))[:, 0].min()
        for f in FIELDS
    )
    owner = np.repeat(np.arange(n), np.diff(static.block_vert_start))
    right = max(float((f.block_q[owner, 0] + static.block_vert_local[:, 0]).max()) for f in frames)
    assert 0.0 <= x_range[0] and right - xmin < x_range[1] < bar_left - xmin, (x_range, right, bar_left)
    top = max(np.concatenate([np.array(r) for r in rows[:n]])[:, 1].max() for rows in strips.values())
    assert 0.0 <= y_range[0] < ymax - top and y_range[1] <= ymax - ymin + 1e-6, (y_range, top, ymax)


def test_hinge_dots_stay_smaller_than_small_blocks(tmp_path):
    """'masonry simulate wall --courses 64 --length 4.5': 729 hinge dots 4 ui points (8 px wide) on blocks
    9 px high covered the Sliding and Opening tabs in yellow, the colour of a sliding ratio of 1 there. As
    drawn at first open (the 1150 x 840 px structure panel fitted to the view) a hinge dot is now at most half
    a block's smaller side wide, and grows with the blocks when zoomed; a small structure keeps 4 points."""
    from masonrycli.recording.layout import HINGE_RADIUS, HINGES

    def drawn(static, q0, name):  # (dot width, block's smaller side) at first open, px; the radius logged
        return fx.dot_at_first_open(tmp_path / name, static, q0, HINGES)

    dot, side, _ = drawn(*fx.wall(courses=64, per_course=15, ragged=False), "tall.rrd")  # 4.5 m x 12.8 m
    assert dot <= 0.5 * side + 1e-6, (dot, side)
    _, _, r = drawn(*fx.wall(), "small.rrd")  # 1.2 m x 0.8 m: blocks ~ 100 px
    assert r == HINGE_RADIUS


def test_lines_over_the_blocks_stay_thinner_than_small_blocks(tmp_path):
    """'masonry simulate wall --courses 8 --length 37.5': blocks 5.6 px high at first open, joint arrows
    1.5 ui points (3 px thick), glyphs 1.25: every colour hidden under orange and green. At first open an
    arrow is now at most a quarter of a block's smaller side thick, a glyph or magnified outline a fifth;
    they thicken with the blocks when zoomed; a small structure keeps its ui points."""
    from masonrycli.recording.layout import FORCES, MAGNIFIED, STRESS_AXES
    from masonrycli.recording.static_content import LINE_POINTS

    columns = {FORCES: "Arrows2D:radii", STRESS_AXES: "LineStrips2D:radii", MAGNIFIED: "LineStrips2D:radii"}
    for static, q0, name, small in (
        (*fx.wall(courses=2, per_course=100, ragged=False), "long.rrd", False),  # 30 m x 0.4 m
        (*fx.wall(), "small.rrd", True),  # 1.2 m x 0.8 m: blocks ~ 100 px
    ):
        path = tmp_path / name
        px_per_m = fx.px_per_metre_at_first_open(path, static, q0)
        side = min(fx.BLOCK_W, fx.BLOCK_H) * px_per_m
        for entity, column in columns.items():
            (r,) = fx.static_value(path, f"/{entity}", column)
            points, share = LINE_POINTS[entity]
            if small:
                assert r == -points, (entity, r)
            else:
                assert 0 < r * px_per_m <= share * side + 1e-6, (entity, r, side)
        assert small or side < 8.0  # the long wall's blocks are small at first open


def test_a_block_falling_for_ever_does_not_shrink_the_structure_to_a_dot(tmp_path):
    """A collapsed aqueduct run on after its collapse: blocks off the foundations' edge fell ~120 m in 5 s (nothing
    under them), the view widened to hold them and the 7 m structure was a dot at its top. The view holds the
    structure and what the run drew within CONTENT_REACH × its size of it: a block 1000 m down leaves it, the top
    course moved one wall height aside stays in."""
    from masonrycli.recording.static_content import CONTENT_REACH

    static, q0 = fx.wall()
    frames = fx.frames(static, q0, 8)
    size = 4 * fx.BLOCK_W  # the wall is 1.2 m long, 0.8 m high
    top = q0[:, 1] > q0[:, 1].max() - 0.5 * fx.BLOCK_H
    for k, f in enumerate(frames):
        f.block_q[top, 0] += 0.8 * k / 7  # the top course slides off by the wall's height
        f.block_q[0, 1] -= 1000.0 * (k / 7) ** 2  # block 0 falls 1000 m
    path = tmp_path / "falling.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
        for f in frames:
            rec.log_frame(f)
    xmin, ymin, xmax, ymax = _view(path)
    assert ymin > -(CONTENT_REACH + 0.2) * size and ymax - ymin < (CONTENT_REACH + 3) * size, (ymin, ymax)
    owner = np.repeat(np.arange(len(q0)), np.diff(static.block_vert_start))
    slid = frames[-1].block_q[owner, 0] + static.block_vert_local[:, 0]
    assert slid[top[owner]].max() < xmax  # the slid course is in the view


def test_a_block_fallen_off_the_supports_leaves_the_view_to_the_structure(tmp_path):
    """'masonry simulate wall --amp 3 --freq 0.8 --duration 3': two end blocks fell off the shaken ground and
    kept falling; the view was widened and deepened to their last (magnified x 1) pose, metres under the
    ground, and the wall and its colour bar filled the top third of the panel. A block below the supports'
    lowest point is in free fall off them: the view holds the rest, as a run without the fall (the block
    leaves it through the bottom edge)."""
    static, q0 = fx.wall()
    frames = fx.frames(static, q0, 12)
    for f in frames:  # the joint arrows stay on the wall: its contacts between its blocks as built
        f.contact_point[:] = np.clip(f.contact_point, (0.0, 0.0), (1.2, 0.8))
    fallen = [type(f)(**{**f.__dict__, "block_q": f.block_q.copy()}) for f in frames]
    for k, f in enumerate(fallen[8:]):  # block 3 (the first course's right end) thrown right, falling
        f.block_q[3, :2] = q0[3, :2] + (1.0 + k, -1.0 - 2.0 * k**2)
    views = {}
    for name, run in (("stood", frames), ("fell", fallen)):
        with Recorder(tmp_path / f"{name}.rrd", static, fx.METADATA, batch_frames=4) as rec:
            for f in run:
                rec.log_frame(f)
        views[name] = np.array(_view(tmp_path / f"{name}.rrd"))
    # the ground's underside is at y = -0.1 m; the block ends 19 m under it and 4 m right of the wall
    np.testing.assert_allclose(views["fell"], views["stood"], atol=1e-9)
    assert views["fell"][1] > -0.1 - 0.1 * 1.2 and views["fell"][2] < 1.2 + 1.5, views["fell"]


def test_the_bar_s_title_has_room_right_of_the_bar_on_a_wide_view(tmp_path):
    """The bar's title is centred on the bar and says the frame's time ("Spherical stress p, t = 3.000 s",
    ~180 px at 1920 x 1080). A wall strewn 2 m to the right of its 1.2 m (its reach widens the view, its size
    does not) left the title ~80 px right of the bar's centre, its end cut by the panel's edge; at first open
    (the 1150 x 840 px structure panel fitted to the view) 125 px are kept."""
    from masonrycli.recording.static_content import _PANEL_PX, _TITLE_HALF_PX

    static, q0 = fx.wall()
    frames = fx.frames(static, q0, 8)
    for k, f in enumerate(frames):  # the wall slides 0.3 m a frame along its ground, 2.1 m in all
        f.block_q[:, 0] += 0.3 * k
        f.contact_point[:] = np.clip(f.contact_point, (0.0, 0.0), (1.2, 0.8))
    path = tmp_path / "wide.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
        for f in frames:
            rec.log_frame(f)
    xmin, ymin, xmax, ymax = _view(path)
    px_per_m = min(_PANEL_PX[0] / (xmax - xmin), _PANEL_PX[1] / (ymax - ymin))
    bar = fx.legend_points(path, fx.static_value(path, f"/{FIELDS[0].bar}", "Mesh3D:vertex_positions"))[:, 0]
    centre = 0.5 * (bar.min() + bar.max())
    assert xmax - xmin > 3.0  # the view widened for the slide
    assert (xmax - centre) * px_per_m >= _TITLE_HALF_PX - 1e-6, ((xmax - centre) * px_per_m, xmax, centre)


def test_the_colour_bar_keeps_its_size_and_its_ticks_clear_of_it_on_a_wide_view(tmp_path):
    """'masonry simulate wall --amp 3 --freq 0.8 --duration 3': the bar was sized and its tick labels placed at
    the first frame, on the wall as built; the view widened at close to hold the collapse strewn along its ground
    and the bar opened ~7 px wide, its tick labels (~50-80 px wide, centred 3 bar widths right of it) over it.
    At close the bar is sized to the view that holds the run: as wide on screen as on a wall that stood, its
    ticks' labels clear of it."""
    from masonrycli.recording.layout import LEGEND_LABELS
    from masonrycli.recording.static_content import _PANEL_PX, TICKS

    static, q0 = fx.wall()
    frames = fx.frames(static, q0, 8)
    for f in frames:
        f.contact_point[:] = np.clip(f.contact_point, (0.0, 0.0), (1.2, 0.8))
    strewn = [type(f)(**{**f.__dict__, "block_q": f.block_q.copy()}) for f in frames]
    for k, f in enumerate(strewn):  # the wall slides 0.6 m a frame along its ground, 4.2 m in all
        f.block_q[:, 0] += 0.6 * k
    shown = {}
    for name, run in (("stood", frames), ("strewn", strewn)):
        path = tmp_path / f"{name}.rrd"
        with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
            for f in run:
                rec.log_frame(f)
        xmin, ymin, xmax, ymax = _view(path)
        px_per_m = min(_PANEL_PX[0] / (xmax - xmin), _PANEL_PX[1] / (ymax - ymin))
        bar = fx.legend_points(path, fx.static_value(path, f"/{FIELDS[0].bar}", "Mesh3D:vertex_positions"))
        anchors = fx.legend_points(
            path, temporal_rows(path, f"/{FIELDS[0].labels}", "Points2D:positions")[frames[-1].step]
        )
        ticks = anchors[:TICKS, 0]
        shown[name] = (px_per_m * (bar[:, 0].max() - bar[:, 0].min()), px_per_m * (ticks.min() - bar[:, 0].max()))
        assert xmax - xmin > (4.0 if name == "strewn" else 0.0)
        assert (ticks < xmax).all() and bar[:, 1].max() < ymax, (name, ticks, xmax)
        assert fx.static_value(path, f"/{LEGEND_LABELS}", "Transform3D:translation") is not None
    stood_width, _ = shown["stood"]
    width, gap = shown["strewn"]
    assert width >= 0.7 * stood_width and width >= 15.0, shown  # px
    assert gap >= 40.0, shown  # a label's half width: clear of the bar


def test_the_bar_s_title_has_room_left_of_the_bar_on_a_tall_structure(tmp_path):
    """The aqueduct, 7 m high and narrower, opens with the view fitted to its height: the bar stood 2 pads
    (0.1 x its size) right of the structure, ~78 px at first open, and its title, centred on the bar
    ("Volumetric strain rate, t = 5.000 s", ~210 px), covered the wall's top right blocks. The bar's centre now
    stands at least half a title (125 px) right of every block and support as built at the title's height."""
    from masonrycli.recording.layout import UNDEFORMED
    from masonrycli.recording.static_content import _PANEL_PX, _TITLE_HALF_PX, TICKS

    from cli_helpers import invoke

    path = tmp_path / "aqueduct.rrd"
    result = invoke("simulate", "aqueduct", "--duration", 0.02, "--out", path)
    assert result.exit_code == 0, result.output
    xmin, ymin, xmax, ymax = _view(path)
    px_per_m = min(_PANEL_PX[0] / (xmax - xmin), _PANEL_PX[1] / (ymax - ymin))
    strips = [np.array(s) for s in fx.static_value(path, f"/{UNDEFORMED}", "LineStrips2D:strips")]
    for f in FIELDS:
        rows = temporal_rows(path, f"/{f.labels}", "Points2D:positions")
        title_x, title_y = fx.legend_points(path, rows[max(rows)])[TICKS]
        band = 10.0 / px_per_m  # half a title's box, ~20 px high
        beside = [s[:, 0].max() for s in strips if s[:, 1].max() >= title_y - band and s[:, 1].min() <= title_y + band]
        assert beside, (title_y, f.key)  # the title stands beside the wall's top
        assert (title_x - max(beside)) * px_per_m >= _TITLE_HALF_PX, (f.key, (title_x - max(beside)) * px_per_m)
        assert (xmax - title_x) * px_per_m >= _TITLE_HALF_PX - 1e-6, (f.key, (xmax - title_x) * px_per_m)
