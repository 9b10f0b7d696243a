"""The Rerun recording when a run ends badly: exceptions, interrupts, killed writers, empty frames."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from masonrycli import recording as rec_mod
from masonrycli.recording import Recorder, inspect_recording
from masonrycli.recording import colormap as cm
from masonrycli.recording.layout import FILL
from masonrycli.recording.readback import recording_rows

import recording_fixtures as fx
from cli_helpers import invoke, words
from recording_fixtures import strict_rerun, temporal_rows  # noqa: F401 (strict_rerun: autouse)

BATCH = 10  # frames per flush


@pytest.fixture(scope="module")
def wall():
    return fx.wall()


# ------------------------------------------------------------------------------- closing and errors
@pytest.mark.parametrize("exc, status", [(RuntimeError("boom"), "failed"), (KeyboardInterrupt(), "interrupted")])
def test_recording_is_complete_after_an_exception(wall, tmp_path, exc, status):
    static, q0 = wall
    frames = fx.frames(static, q0, 15)
    path = tmp_path / "crash.rrd"
    with pytest.raises(type(exc)):
        with Recorder(path, static, fx.METADATA, batch_frames=BATCH) as rec:
            for f in frames:
                rec.log_frame(f)
            raise exc
    info = inspect_recording(path)
    assert info["complete"] and info["frames"] == 15  # the partial batch was flushed
    assert f"{status} at t = 0.140 s (step 140)" in info["metadata"]
    if status == "failed":
        assert "RuntimeError: boom" in info["metadata"]
    rerun_cli = os.path.join(os.path.dirname(sys.executable), "rerun")
    verify = subprocess.run(
        [rerun_cli, "rrd", "verify", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "RERUN_ANALYTICS": "0"},
    )
    assert verify.returncode == 0, verify.stderr


def test_close_note_and_idempotence(wall, tmp_path):
    static, q0 = wall
    rec = Recorder(tmp_path / "x.rrd", static, fx.METADATA)
    rec.log_frame(fx.frames(static, q0, 1)[0])
    rec.close("interrupted", "interrupted at t = 0.0000 s (step 0 of 1000)")
    rec.close()  # no-op
    with pytest.raises(RuntimeError):
        rec.log_frame(fx.frames(static, q0, 1)[0])
    doc = inspect_recording(tmp_path / "x.rrd")["metadata"]
    assert "**Status:** interrupted at t = 0.0000 s (step 0 of 1000)" in doc


def test_inspect_a_file_without_footer(wall, tmp_path):
    """A killed writer leaves no footer: inspect still reads what was flushed and says it is incomplete."""
    path = tmp_path / "killed.rrd"
    script = textwrap.dedent(f"""
        import os, signal, sys
        sys.path[:0] = {[os.path.dirname(__file__), os.path.dirname(os.path.dirname(__file__))]!r}
        import recording_fixtures as fx
        from masonrycli.recording import Recorder
        static, q0 = fx.wall()
        rec = Recorder({str(path)!r}, static, fx.METADATA, batch_frames=4, long_batch_frames=4)
        for f in fx.frames(static, q0, 9):  # two batches: the initial frame and 4 more, then 4 (scales fixed)
            rec.log_frame(f)
        rec.rec.flush()
        os.kill(os.getpid(), signal.SIGKILL)
    """)
    subprocess.run([sys.executable, "-c", script], timeout=120, env={**os.environ, "RERUN_ANALYTICS": "0"})
    info = inspect_recording(path)
    assert not info["complete"] and info["truncated"]
    assert info["frames"] == 9 and info["application_id"] == "masonry"
    # QA: the table said "truncated False" under a warning saying "truncated"; now both say it
    result = invoke("inspect", path)
    assert result.exit_code == 0, result.output
    rows = dict(
        [c.strip() for c in line.strip().strip("│").split("│")]
        for line in result.output.splitlines()
        if line.count("│") == 3
    )
    assert rows["truncated"] == "True" and rows["complete"] == "False"
    assert "truncated (its writer did not finish" in words(result.output)


def test_frames_without_tensor_fields_or_contacts(wall, tmp_path):
    static, q0 = wall
    f = fx.frames(static, q0, 2)[1]  # step 10 (a computed frame: the initial one takes the range of the next)
    empty = type(f)(
        **{
            **f.__dict__,
            "tensors": {},
            "contact_body": np.zeros((0, 2), np.int32),
            "contact_point": np.zeros((0, 2)),
            "contact_normal": np.zeros((0, 2)),
            "contact_force": np.zeros((0, 2)),
            "contact_gap": np.zeros(0),
            "contact_status": np.zeros(0, np.int8),
            "contact_mobilised": np.zeros(0),
        }
    )
    path = tmp_path / "empty.rrd"
    with Recorder(path, static, fx.METADATA) as rec:
        rec.log_frame(empty)
    rows = temporal_rows(path, f"/{FILL}", rec_mod.layout.FIELD_BY_KEY["cell_spherical_stress"].colors)
    assert set(rows[10]) == {cm.NAN_RGBA}
    assert temporal_rows(path, "/structure/plane/xy/forces", "Arrows2D:vectors")[10] == []
    assert "scale not fixed yet" in inspect_recording(path)["metadata"]


def test_viewer_safe_text():
    assert rec_mod.viewer_safe_text("σ ≤ 5 kPa, é — ∝ 漢") == "σ ≤ 5 kPa, é — ? ?"


def test_interrupt_in_the_middle_of_a_flush_still_leaves_a_complete_file(wall, tmp_path):
    static, q0 = wall
    path = tmp_path / "mid_flush.rrd"
    with pytest.raises(KeyboardInterrupt):
        # batches of 5 after the scales are fixed too: the second batch is sent at the 11th frame
        with Recorder(path, static, fx.METADATA, batch_frames=5, long_batch_frames=5) as rec:
            send, calls = rec.rec.send_columns, []

            def flaky_send(*args, **kwargs):
                if rec._frames == 11:  # flushing the second batch (the first: the initial frame and 5 more)
                    calls.append(args[0])
                    # part-way through its entities: each colour bar's labels, the fill, the hover points, one more
                    if len(calls) == len(rec_mod.layout.COLOURED) + 3:
                        raise KeyboardInterrupt
                return send(*args, **kwargs)

            rec.rec.send_columns = flaky_send
            for f in fx.frames(static, q0, 12):
                rec.log_frame(f)
    info = inspect_recording(path)
    assert info["complete"] and "interrupted at t = 0.100 s (step 100)" in info["metadata"]
    assert info["frames"] == 11  # the first batch, then as much of the second as was sent: no duplicates
    rows = recording_rows(path)
    assert all(len(set(r)) == len(r) for r in rows.values())  # no row sent twice (the batch again at close)


def _nine_frames(wall, tmp_path):
    """A whole recording of the fixture wall's 9 frames in batches of 4 (the last one's sent at close)."""
    static, q0 = wall
    whole = tmp_path / "whole.rrd"
    with Recorder(whole, static, fx.METADATA, batch_frames=4, long_batch_frames=4) as rec:
        for f in fx.frames(static, q0, 9):
            rec.log_frame(f)
    return whole


def test_the_readback_helpers_read_a_cut_recording_as_inspect_does(wall, tmp_path):
    """A file cut in the middle of a message (a kill -9's .NAME.<pid>.part, a full disk): inspect read it up to
    its last whole message, field_frames, blueprint_views and recording_rows raised "Message payload (start …)
    exceeds file size"."""
    from masonrycli.recording.readback import blueprint_views, field_frames

    whole, cut = _nine_frames(wall, tmp_path), tmp_path / "cut.rrd"
    data = whole.read_bytes()
    for share in (0.8, 0.7, 0.6, 0.5, 0.4, 0.3):  # a cut inside the second batch of frames
        cut.write_bytes(data[: int(len(data) * share)])
        info = inspect_recording(cut)
        if 0 < info["frames"] < 9:
            break
    assert info["truncated"] and 0 < info["frames"] < 9, info
    frames = field_frames(cut)
    assert sorted(frames) == sorted(field_frames(whole))[: info["frames"]]
    assert blueprint_views(cut) and recording_rows(cut)


def test_a_cut_recording_counts_the_frames_whose_blocks_it_holds(wall, tmp_path):
    """Walk-through 2026-11-29: the first tenth of an interrupted aqueduct's recording (its frames sent at
    close, the colour bars' labels before the fill and the blocks) was read as "83 frames up to its last
    complete chunk", steps 0 … 814, with no block drawn past the first. A frame counts once its blocks (their
    hover values, read by field_frames) are in the file."""
    from masonrycli.recording.readback import field_frames

    whole, cut = _nine_frames(wall, tmp_path), tmp_path / "cut.rrd"
    data = whole.read_bytes()
    read, labels_only = 0, 0
    for share in range(1, 101):
        cut.write_bytes(data[: len(data) * share // 100])
        try:
            info = inspect_recording(cut)
        except ValueError:  # not even the recording's first message
            continue
        read += 1
        frames = field_frames(cut)
        drawn = sorted(step for step, row in frames.items() if row["values"])
        assert info["frames"] == len(drawn), (share, info["frames"], drawn, info["entity_paths"])
        assert info["steps"] == ((drawn[0], drawn[-1]) if drawn else None)
        labels_only += len(frames) > len(drawn)
    assert read > 50 and labels_only  # some cuts hold a frame's labels without its blocks
    assert info["frames"] == 9 and info["complete"]


def test_the_colour_bars_stand_right_of_where_the_blocks_went(tmp_path):
    """The bars stood right of the structure as built: 'masonry simulate wall --amp 2 --freq 1
    --stop-at-collapse' shook the wall 0.32 m right and it fell over the bar and its title. At close, the
    bars and their labels move right of the farthest x a block reached and the view widens to hold them."""
    last_static = fx.static_value
    path, static, q0, frames = _drifting_wall(tmp_path / "drift.rrd", 0.1)  # right, 1.1 m by the end
    start = static.block_vert_start
    owner = np.repeat(np.arange(len(q0)), np.diff(start))
    # unrotated outlines: the frames turn the blocks by 0.01 rad at most, under a millimetre here
    reach = max(float((f.block_q[owner, 0] + static.block_vert_local[:, 0]).max()) for f in frames)
    from masonrycli.recording.layout import PLANE
    from masonrycli.recording.static_content import legend_positions

    for f in rec_mod.FIELDS:
        bar = fx.legend_points(path, last_static(path, f"/{f.bar}", "Mesh3D:vertex_positions"))[:, 0]
        assert bar.min() > reach + 0.01, (f.key, bar.min(), reach)
    # the view holds the bar and its tick labels (1 image unit = 1 m; the pinhole's image starts at x0)
    x0 = last_static(path, f"/{PLANE}", "Transform3D:translation")[0][0]
    width = last_static(path, f"/{PLANE}", "Pinhole:resolution")[0][0]
    ticks = legend_positions((bar.min(), 0.0, bar.max(), 1.0))[:5, 0]
    assert x0 + width > ticks.max()


def test_the_view_holds_a_structure_that_went_left(tmp_path):
    """The view was fitted left to the structure as built: a wall drifting or falling left left it. At
    close the view widens left to the smallest x a block reached; the bars stay right of the blocks."""
    last_static = fx.static_value
    path, static, q0, frames = _drifting_wall(tmp_path / "left.rrd", -0.1)  # left, 1.1 m by the end
    start = static.block_vert_start
    owner = np.repeat(np.arange(len(q0)), np.diff(start))
    left = min(float((f.block_q[owner, 0] + static.block_vert_local[:, 0]).min()) for f in frames)
    reach = max(float((f.block_q[owner, 0] + static.block_vert_local[:, 0]).max()) for f in frames)
    from masonrycli.recording.layout import PLANE

    x0 = last_static(path, f"/{PLANE}", "Transform3D:translation")[0][0]
    assert x0 < left - 0.01, (x0, left)
    for f in rec_mod.FIELDS:
        bar = fx.legend_points(path, last_static(path, f"/{f.bar}", "Mesh3D:vertex_positions"))[:, 0]
        assert bar.min() > reach + 0.01, (f.key, bar.min(), reach)


def _drifting_wall(path, step: float):
    """A wall whose frames drift by ``step`` m a frame (12 frames), recorded to ``path``:
    (path, static, q0, frames)."""
    static, q0 = fx.wall()
    frames = fx.frames(static, q0, 12)
    for k, f in enumerate(frames):
        f.block_q[:, 0] += step * k
    with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
        for f in frames:
            rec.log_frame(f)
    return path, static, q0, frames


def test_a_long_low_wall_gets_a_colour_bar_tall_enough_to_read(tmp_path):
    """The bar was as high as the structure: on an 8-course wall 37.5 m long ('masonry simulate wall
    --courses 8 --length 37.5') it was a 1.2 m square beside 37.5 m of wall, and its five tick labels,
    title and count overlapped in a smear at first open. The bar is now at least 12 times as high as it is
    wide (the paper's structures: 15 to 30, unchanged), and the view holds it and its title."""
    from masonrycli.recording.layout import PLANE
    from masonrycli.recording.static_content import TICKS, legend_positions

    static, q0 = fx.wall(courses=2, per_course=40)  # 40 blocks long, 2 courses: 10 times as long as high
    path = tmp_path / "long.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
        for f in fx.frames(static, q0, 3):
            rec.log_frame(f)
    top = fx.static_value(path, f"/{PLANE}", "Transform3D:translation")[0][1]  # the view's upper edge, m
    height = fx.static_value(path, f"/{PLANE}", "Pinhole:resolution")[0][1]
    for f in rec_mod.FIELDS:
        bar = np.array(fx.static_value(path, f"/{f.bar}", "Mesh3D:vertex_positions"))[:, :2]
        (xa, ya), (xb, yb) = bar.min(axis=0), bar.max(axis=0)
        assert yb - ya >= 12.0 * (xb - xa), (f.key, yb - ya, xb - xa)
        anchors = legend_positions((xa, ya, xb, yb))
        assert top - height < anchors[:, 1].min() and anchors[TICKS, 1] < top, (f.key, anchors, top, height)


def test_a_long_low_wall_keeps_its_block_fills(tmp_path):
    """The fills were inset by 0.002 × the structure's size alone: on an 8-course wall 37.5 m long
    ('masonry simulate wall --courses 8 --length 37.5') 0.2 m high blocks lost 7.5 cm a side, the fills were
    5 cm high, about a pixel at first open, and every colour map read as a dark grey strip. The inset is now
    at most 7.5 % of a median block's smaller side: each fill keeps at least 85 % of its block's height."""
    from masonrycli.recording.layout import FILL

    static, q0 = fx.wall(courses=2, per_course=100, ragged=False)  # 30 m long, 0.4 m high
    path = tmp_path / "long.rrd"
    frames = fx.frames(static, q0, 3)
    with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
        for f in frames:
            rec.log_frame(f)
    verts = np.array(fx.temporal_rows(path, f"/{FILL}", "Mesh3D:vertex_positions")[frames[0].step])[:, 1]
    start = static.block_vert_start
    fill_height = np.maximum.reduceat(verts, start[:-1]) - np.minimum.reduceat(verts, start[:-1])
    # the frames turn a block by 0.01 rad at most: its outline's height grows by under 3 mm
    assert fill_height.min() >= 0.85 * fx.BLOCK_H - 0.003, fill_height.min()


def test_centroid_dots_stay_smaller_than_small_blocks(tmp_path):
    """The dots at the blocks' centroids were 2.5 ui points (5 px wide) whatever the blocks: on an 8-course
    wall 37.5 m long the blocks are 4-5 px high at first open and the dots darkened every colour map. As
    drawn at first open (the structure panel of a 1920 x 1080 window, 1150 x 840 px, fitted to the view's
    extent) a dot is now at most a quarter of a block's smaller side wide; a small structure keeps 2.5."""
    from masonrycli.recording.layout import BLOCKS, CENTROID_RADIUS

    def drawn(static, q0, name):  # (dot width, block's smaller side) at first open, px; the radius logged
        return fx.dot_at_first_open(tmp_path / name, static, q0, BLOCKS)

    dot, side, _ = drawn(*fx.wall(courses=2, per_course=100, ragged=False), "long.rrd")  # 30 m x 0.4 m
    assert dot <= 0.25 * side + 1e-6, (dot, side)
    _, _, r = drawn(*fx.wall(), "small.rrd")  # 1.2 m x 0.8 m: blocks ~ 100 px
    assert r == CENTROID_RADIUS


def test_the_closing_document_gives_the_runs_result(tmp_path):
    # a recording handed to a colleague said "completed" and the parameters, not whether the wall stood: the
    # state, its peak drift and the ground motion were in the terminal's summary only
    out = tmp_path / "w.rrd"
    result = invoke("simulate", "wall", "--courses", 4, "--length", 1.2, "--duration", 0.1, "--out", out)
    assert result.exit_code == 0, result.output
    doc = words(inspect_recording(out)["metadata"])
    summary = words(result.output.replace("│", " "))
    for label in ("state", "peak drift", "ground motion (ground)", "hinged joints (end)"):
        row = re.search(rf"\| result\.{re.escape(label)} \| (.*?) \|\n", inspect_recording(out)["metadata"])
        assert row is not None, doc
        assert f"{label} {words(row.group(1).replace(chr(92) + '|', '|'))}" in summary
    assert "| result.state | damaged (residual drift" in doc
