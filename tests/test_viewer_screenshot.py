"""Open a recording in the headless Rerun viewer, as a user would, and look at it.

Needs a Vulkan driver (Debian: mesa-vulkan-drivers libvulkan1; .ci/run installs it). About 10 s.
"""

from __future__ import annotations

import ctypes.util

import numpy as np
import pytest

from masonrycli.recording import Recorder, screenshot_recording
from masonrycli.recording.colormap import BLUES, unpack_rgba
from masonrycli.recording.layout import SUPPORT_FILL_RGBA
from masonrycli.recording.readback import _viewer_executable
from masonrycli.scenario.builtin import paper_loading

import recording_fixtures as fx

pytestmark = pytest.mark.slow  # starts the viewer: ~20 s on the CI machine


def test_viewer_prerequisites_are_installed():
    """Not a skip: without them the screenshot tests below would prove nothing (.ci/run installs them)."""
    assert ctypes.util.find_library("vulkan") is not None, "apt-get install mesa-vulkan-drivers libvulkan1"
    assert _viewer_executable() is not None, "the rerun executable of rerun-sdk is missing"


def png_size(path) -> tuple[int, int]:
    with open(path, "rb") as fh:
        head = fh.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


def near(image: np.ndarray, colors: np.ndarray, tol: float = 8.0) -> np.ndarray:
    """(H, W) mask of pixels within `tol` (RGB distance) of any of `colors` (K, 3)."""
    rgb = image[..., :3].astype(np.int32)
    mask = np.zeros(rgb.shape[:2], dtype=bool)
    for c in np.asarray(colors, dtype=np.int32)[::4]:  # every 4th LUT entry is dense enough
        mask |= np.abs(rgb - c).sum(axis=-1) < tol
    return mask


@pytest.fixture(scope="module")
def screenshot(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("viewer")
    static, q0 = fx.wall(5, 6)
    frames = fx.frames(static, q0, 20)
    rrd = tmp / "wall.rrd"
    # Characters the viewer's font lacks would kill the viewer: the recorder must replace them.
    with Recorder(rrd, static, {**fx.METADATA, "scenario": "aqueduct 水道 ∝"}, batch_frames=8) as rec:
        for f in frames:
            rec.log_frame(f)
    png = tmp / "viewer.png"
    reports = screenshot_recording(rrd, png, time_s=frames[-1].time, timeout=120, tabs_dir=tmp / "tabs")
    return png, reports, tmp


def test_no_view_reports_visualizer_errors(screenshot):
    png, reports, tmp = screenshot
    assert reports == []
    assert png_size(png) == (1920, 1080)
    # every tab was shown and checked: 9 structure tabs (p √ too). Both rows open on their first tab (the
    # live view; the ground moves, so the plots open on the supports' velocity since 6057731), which the
    # screenshot itself shows: the other eight are brought to the front in turn
    assert sorted(p.name for p in (tmp / "tabs").glob("tab*.png")) == [f"tab{i}.png" for i in range(1, 9)]


def test_blocks_are_drawn_y_up_with_field_colours(screenshot):
    import PIL.Image as image_module  # pillow comes with rerun-sdk

    png, _, _ = screenshot
    image = np.asarray(image_module.open(png).convert("RGB"))
    main = image[60:1000, :1100]  # the structure view (left of the plots, above the time panel)
    blocks = near(main, unpack_rgba(BLUES)[:, :3])
    ground = near(main, unpack_rgba(np.array([SUPPORT_FILL_RGBA]))[:, :3].repeat(4, axis=0), tol=12)
    assert blocks.mean() > 0.05 and ground.mean() > 0.01  # filled blocks and the ground are visible
    block_rows, ground_rows = np.nonzero(blocks)[0], np.nonzero(ground)[0]
    # y up: the ground is below the wall on screen (larger row index); the legend bar is above it too.
    assert np.median(ground_rows) > np.percentile(block_rows, 97)


def test_a_run_ended_before_the_paper_instant_opens_on_its_structure(tmp_path):
    """Interrupted at 0.04 s, before the paper's 0.1 s: the recording opened on the tab pinned to 0.1 s,
    where no frame is — the colour bar and the triangulation on black. It opens on the live tab."""
    import PIL.Image as image_module

    static, q0 = fx.wall(5, 6)
    rrd, png = tmp_path / "wall.rrd", tmp_path / "open.png"
    paper = {**fx.METADATA, "scenario": "wall", "duration_s": 1.0, "supports": paper_loading("wall")}
    with pytest.raises(KeyboardInterrupt):
        with Recorder(rrd, static, paper, batch_frames=8) as rec:
            for f in fx.frames(static, q0, 5):
                rec.log_frame(f)
            raise KeyboardInterrupt
    assert screenshot_recording(rrd, png, timeout=120, at_open=True) == []
    main = np.asarray(image_module.open(png).convert("RGB"))[60:1000, :850]
    assert near(main, unpack_rgba(BLUES)[:, :3]).mean() > 0.05  # the blocks, filled by p (blues)


def longest_runs(mask: np.ndarray) -> np.ndarray:
    """(W,) the longest vertical run of True in each column of an (H, W) mask."""
    best, cur = np.zeros(mask.shape[1], int), np.zeros(mask.shape[1], int)
    for row in mask:
        cur = np.where(row, cur + 1, 0)
        best = np.maximum(best, cur)
    return best


def test_the_colour_bar_is_not_covered_by_its_labels(screenshot):
    """The tick labels (centred on their anchors, 0.6 bar widths right of the bar) hid a band of the bar
    at every tick, and "1 above" covered the top tick: the bar's longest uncovered run was 104 of its
    ~250 px in the 51-block wall's Fig. III.2 tab. The labels now stand clear: the bar is whole."""
    import PIL.Image as image_module

    png, _, _ = screenshot
    rgb = np.asarray(image_module.open(png).convert("RGB"))[60:1000, :1150].astype(np.int32)
    lut = unpack_rgba(BLUES)[:, :3].astype(np.int32)  # the live tab shows p
    mask = np.min([np.abs(rgb - c).sum(axis=-1) for c in lut], axis=0) < 24
    runs = longest_runs(mask)
    bar = np.nonzero(runs >= 0.6 * runs.max())[0]  # the bar's columns: the longest unbroken colours
    rows = np.nonzero(mask[:, bar].any(axis=1))[0]
    # a bar, not the blocks (with the labels over it, no run of the bar outgrew the blocks' own)
    assert bar.max() - bar.min() < 40 and rows.max() - rows.min() > 150
    assert runs.max() >= 0.95 * (rows.max() - rows.min() + 1)


def test_the_block_hover_targets_are_small_dots(screenshot):
    """The hover targets (a point per block carrying its values) were 0.15 block sizes wide, "in the
    block's colour, so they do not show": rerun shades points and ignores their alpha over the fill mesh,
    so each showed as a grey ring: 10 177 px changed over this wall's 28 blocks. They are dots of 2.5 ui
    points at the centroids now, which the legend names: 200 px changed (about 7 a block)."""
    import PIL.Image as image_module

    from masonrycli.recording.layout import BLOCKS

    _, _, tmp = screenshot
    rrd, n_blocks = tmp / "wall.rrd", len(fx.wall(5, 6)[0].block_name)
    with_dots, without = tmp / "with.png", tmp / "without.png"
    assert screenshot_recording(rrd, with_dots, time_s=None, timeout=120) == []
    assert screenshot_recording(rrd, without, time_s=None, timeout=120, without=(f"/{BLOCKS}",)) == []
    a, b = (np.asarray(image_module.open(p).convert("RGB"))[60:1000, :1150].astype(int) for p in (with_dots, without))
    changed = int((np.abs(a - b).sum(axis=-1) > 24).sum())
    assert 0 < changed <= 30 * n_blocks


def test_a_recording_of_static_data_alone_is_shown(tmp_path):
    """A study's state map is all static: no time line. The screenshot waited for one until its timeout
    (TimeoutError after 300 s on `masonry sweep wall --param freq=1,2,3 --param amp=0.5,1`)."""
    import time
    from types import SimpleNamespace

    from masonrycli.recording.study import record_study

    rows = [
        {"freq": f, "amp": a, "state": s, "status": "completed"}
        for (f, a), s in zip([(1, 0.5), (1, 1.0), (2, 0.5), (2, 1.0)], ["intact", "damaged", "damaged", "collapsed"])
    ]
    axes = [SimpleNamespace(name="freq", values=(1, 2)), SimpleNamespace(name="amp", values=(0.5, 1.0))]
    rrd = record_study(tmp_path / "map.rrd", "s", rows, SimpleNamespace(axes=axes, find=None), None, "pga", None)
    start = time.monotonic()
    assert screenshot_recording(rrd, tmp_path / "map.png", timeout=60, at_open=True) == []
    assert time.monotonic() - start < 45 and png_size(tmp_path / "map.png") == (1920, 1080)


def test_every_tab_of_a_paper_run_is_shown_the_live_one_too(tmp_path):
    """A paper run opens on its second tab (Fig. III.2); the tabs were shown from the second on, so the
    live tab (joint forces, principal stress: the one a user reaches first) was never drawn nor checked:
    tab1..tab11 of its 12 tabs (13 since the p √ tab). Now every tab not on screen at open is shown."""
    static, q0 = fx.wall(5, 6)
    rrd = tmp_path / "wall.rrd"
    paper = {**fx.METADATA, "scenario": "wall", "duration_s": 0.14, "supports": paper_loading("wall")}
    with Recorder(rrd, static, paper, batch_frames=8) as rec:
        for f in fx.frames(static, q0, 15):  # to t = 0.14 s, past the paper's 0.1 s
            rec.log_frame(f)
    tabs = tmp_path / "tabs"
    assert screenshot_recording(rrd, tmp_path / "open.png", timeout=120, at_open=True, tabs_dir=tabs) == []
    assert sorted(p.name for p in tabs.glob("tab*.png")) == sorted(f"tab{i}.png" for i in range(13))


def test_a_limit_recording_is_shown_at_its_last_step(tmp_path):
    """A limit analysis records the mechanism on a `step` time line alone: the screenshot at the last
    frame asked for `sim_time` and failed (ConnectionError: no timeline "sim_time")."""
    from masonrycli.limit import LiveLoad, analyse
    from masonrycli.limit.drawing import write_recording

    from limit_helpers import column

    rrd = tmp_path / "mechanism.rrd"
    write_recording(analyse(column(2, 0.4, 0.8, 0.9), LiveLoad("horizontal")), rrd)
    assert screenshot_recording(rrd, tmp_path / "last.png", timeout=120) == []


def test_a_fragility_legend_of_five_groups_shows_the_runs_entries(tmp_path):
    # 'masonry sweep … --records recs --param friction=0.4:0.8:5': the plot's legend lost "runs: intact" and
    # "runs: damaged" (13 entries, 5 of them two lines long, ran off the view's bottom); their dots are the only
    # green and orange right of the runs themselves (intact at pga 3-4 m/s², damaged up to 43 of a 74 m/s² axis)
    import PIL.Image as image_module

    from masonrycli.records.read import G_STANDARD
    from masonrycli.study.curves import STATE_COLOURS, rgb

    from sweep_helpers import invoke, write_block
    from synthetic_records import band_limited, write_at2

    folder = tmp_path / "records"
    folder.mkdir()
    for seed in range(3):
        t, u, v, a = band_limited(1.0, 0.01, [1.0 + 0.4 * seed, 2.5], [0.03, 0.01], seed=seed)
        write_at2(folder / f"syn{seed}.AT2", a / G_STANDARD, 0.01)
    rrd = tmp_path / "s.rrd"
    args = ["--records", folder, "--scale", "5:80:4", "--param", "friction=0.4:0.8:5", "--duration", 0.2]
    result = invoke(
        "sweep", write_block(tmp_path), *args, "--workers", 0, "--out", tmp_path / "s.csv", "--recording", rrd
    )
    assert result.exit_code == 0, result.output
    png = tmp_path / "s.png.shot.png"
    assert screenshot_recording(rrd, png, at_open=True, timeout=120) == []
    image = np.asarray(image_module.open(png).convert("RGB"))
    width, height = png_size(png)
    legend_side = image[
        int(0.05 * height) : int(0.97 * height), int(0.18 * width) : width // 3
    ]  # the plot's right half
    for state in ("intact", "damaged", "collapsed"):
        assert near(legend_side, np.array([rgb(STATE_COLOURS[state])] * 4), tol=40).sum() > 20, state


def test_the_picture_of_a_one_point_search_is_drawn_at_open(tmp_path):
    # A class's first threshold search, `masonry sweep block.toml --param amp=0.05:1.0:3 --find amp`: its
    # recording opened with the picture's view empty ("No data available"): the cursor at the time line's
    # start, -1, and Rerun 0.41 draws no static image below 0. The picture is the middle third of the window.
    import PIL.Image as image_module

    from sweep_helpers import invoke, write_block

    rrd = tmp_path / "find.rrd"
    args = ["-p", "amp=0.02:0.4:3", "--find", "amp", "--outcome", "sliding", "--duration", 0.3, "--workers", 0]
    result = invoke("sweep", write_block(tmp_path), *args, "--out", tmp_path / "find.csv", "--recording", rrd)
    assert result.exit_code == 0, result.output
    png = tmp_path / "open.png"
    assert screenshot_recording(rrd, png, at_open=True, timeout=120) == []
    image = np.asarray(image_module.open(png).convert("RGB")).astype(np.int32)
    width, height = png_size(png)
    middle = image[height // 10 : 9 * height // 10, width // 3 + 20 : 2 * width // 3 - 20]
    assert (middle.sum(axis=-1) > 600).mean() > 0.1  # the PNG's white background (was 0.0002)
