"""The Rerun recording, read back with rr.chunk.RrdReader (no viewer needed). Its plots (solver health,
energies, displacement, residual, balance error): test_recording_series.py."""

from __future__ import annotations

import numpy as np
import pytest
import rerun as rr

from masonrycli import recording as rec_mod
from masonrycli.analysis.joint_forces import joint_resultants
from masonrycli.recording import ENTITY_PATHS, FIELDS, Recorder, inspect_recording
from masonrycli.recording import colormap as cm
from masonrycli.recording.colour_range import MIN_SPAN, OUTSIDE_SHARE
from masonrycli.recording.layout import FILL, INSET
from masonrycli.recording.readback import field_frames

import recording_fixtures as fx
from recording_fixtures import (  # noqa: F401 (fixtures: strict_rerun autouse, wall, written)
    N_FRAMES,
    strict_rerun,
    temporal_rows,
    wall_fixture,
    written_fixture,
)

static_value = fx.static_value


def world_outline(static, q: np.ndarray, b: int) -> np.ndarray:
    """Block b's polygon in world coordinates, computed independently of the recorder."""
    s, e = static.block_vert_start[b], static.block_vert_start[b + 1]
    c, sn = np.cos(q[b, 2]), np.sin(q[b, 2])
    rot = np.array([[c, -sn], [sn, c]])
    return q[b, :2] + static.block_vert_local[s:e] @ rot.T


# ------------------------------------------------------------------------------------------- the file
def test_application_id_blueprint_and_entity_paths(written):
    path, *_ = written
    reader = rr.chunk.RrdReader(path)
    (recording,) = reader.recordings()
    assert recording.application_id == "masonry"
    # the layout of the start and the one sent at close (the magnified tab names its factor); the last wins
    assert len(reader.blueprints()) == 2
    paths = {chunk.entity_path for chunk in reader.stream()}
    assert {f"/{p}" for p in ENTITY_PATHS} <= paths


def test_recording_id_is_deterministic(wall, tmp_path):
    static, _ = wall
    ids = []
    for name in ("a.rrd", "b.rrd", "c.rrd"):
        meta = fx.METADATA if name != "c.rrd" else {**fx.METADATA, "seed": 1}
        with Recorder(tmp_path / name, static, meta) as rec:
            ids.append(rec.recording_id)
        assert rr.chunk.RrdReader(tmp_path / name).recordings()[0].recording_id == rec.recording_id
    assert ids[0] == ids[1] != ids[2]


def test_frames_on_the_step_and_sim_time_timelines(written):
    path, static, frames, _ = written
    info = inspect_recording(path)
    assert info["frames"] == N_FRAMES
    assert info["steps"] == (frames[0].step, frames[-1].step)
    assert info["time_span"] == pytest.approx((frames[0].time, frames[-1].time))
    assert info["has_blueprint"] and info["complete"]
    assert info["application_id"] == "masonry"
    assert "/structure/plane/xy/blocks" in info["entity_paths"]
    rows = temporal_rows(path, "/structure/plane/xy/blocks", "Points2D:positions")
    assert sorted(rows) == [f.step for f in frames]


# --------------------------------------------------------------------------------------- per frame
def test_block_fills_are_the_world_polygons_inset(written):
    """Fill vertices: the block's world polygon moved inwards by INSET × the structure's size (checked
    with the distance of each vertex to the polygon's two edges at that corner)."""
    path, static, frames, rec = written
    rows = temporal_rows(path, f"/{FILL}", "Mesh3D:vertex_positions")
    d = INSET * rec._size
    for f in frames[::7]:
        verts = np.array(rows[f.step])
        for b in (0, len(static.block_name) - 1):  # the last block is the pentagon
            s, e = static.block_vert_start[b], static.block_vert_start[b + 1]
            poly, fill = world_outline(static, f.block_q, b), verts[s:e, :2]
            assert np.all(verts[s:e, 2] == 0.0)
            for k in range(len(poly)):
                for a_, b_ in ((poly[k - 1], poly[k]), (poly[k], poly[(k + 1) % len(poly)])):
                    edge = b_ - a_
                    inward = np.array([-edge[1], edge[0]]) / np.linalg.norm(edge)
                    assert (fill[k] - a_) @ inward == pytest.approx(d, abs=1e-5)


def test_array_shapes_per_frame(written):
    path, static, frames, _ = written
    n = len(static.block_name)
    n_vert = len(static.block_vert_local)
    by_step = {f.step: f for f in frames}
    arrows = temporal_rows(path, "/structure/plane/xy/forces", "Arrows2D:vectors")
    force_values = temporal_rows(path, "/structure/plane/xy/forces", "force_kN")
    axes = temporal_rows(path, "/structure/plane/xy/stress_axes", "LineStrips2D:strips")
    hover_p = temporal_rows(path, "/structure/plane/xy/blocks", "p")
    hover_pos = temporal_rows(path, "/structure/plane/xy/blocks", "Points2D:positions")
    verts = temporal_rows(path, f"/{FILL}", "Mesh3D:vertex_positions")
    assert {len(v) for v in verts.values()} == {n_vert} and len(verts) == N_FRAMES
    for f in FIELDS:
        colors = temporal_rows(path, f"/{FILL}", f.colors)
        assert {len(c) for c in colors.values()} == {n_vert} and len(colors) == N_FRAMES
    for step, frame in by_step.items():
        j = joint_resultants(
            frame.contact_body, frame.contact_point, frame.contact_normal, frame.contact_force, frame.contact_status
        )
        assert len(arrows[step]) == len(j.force) == len(force_values[step])
        assert len(axes[step]) == 2 * n
        assert len(hover_p[step]) == n
        np.testing.assert_allclose(hover_p[step], frame.tensors["cell_spherical_stress"], rtol=1e-6)
        np.testing.assert_allclose(hover_pos[step], frame.block_q[:, :2], atol=1e-6)
    assert static_value(path, "/structure/plane/xy/blocks", "name") == list(static.block_name)


def test_joint_arrows_are_resultants_at_their_point_of_application(written):
    """Independent check: per pair, the sum of the forces and the normal-force-weighted mean point; the
    arrow is centred there, along the force on the body above, its length force_scale · |R|."""
    path, static, frames, rec = written
    origins = temporal_rows(path, "/structure/plane/xy/forces", "Arrows2D:origins")
    vectors = temporal_rows(path, "/structure/plane/xy/forces", "Arrows2D:vectors")
    f = frames[3]
    n = len(static.block_name)
    y = np.r_[f.block_q[:, 1], f.support_q[:, 1]]
    expected = {}
    for (a, b), p, nrm, force in zip(f.contact_body, f.contact_point, f.contact_normal, f.contact_force):
        if a == b:
            continue  # not a joint
        key = (min(a, b), max(a, b))
        on_high = force if b > a else -force
        fn = max(force @ nrm, 0.0)
        tot, wp, w = expected.get(key, (np.zeros(2), np.zeros(2), 0.0))
        expected[key] = (tot + on_high, wp + fn * p, w + fn)
    rows = sorted((k, v) for k, v in expected.items() if v[2] > 0)
    got_o, got_v = np.array(origins[f.step]), np.array(vectors[f.step])
    assert len(got_o) == len(rows) and n > 0
    for (key, (tot, wp, w)), o, v in zip(rows, got_o, got_v):
        up = tot if y[key[1]] >= y[key[0]] else -tot
        np.testing.assert_allclose(o + 0.5 * v, wp / w, atol=1e-5)
        np.testing.assert_allclose(v, up * rec.force_scale, rtol=1e-5, atol=1e-6)


def test_principal_axes_follow_eigenvectors_and_sign(written):
    path, static, frames, rec = written
    f = frames[-1]
    strips = np.array(temporal_rows(path, "/structure/plane/xy/stress_axes", "LineStrips2D:strips")[f.step])
    colors = np.array(temporal_rows(path, "/structure/plane/xy/stress_axes", "LineStrips2D:colors")[f.step])
    lam = f.tensors["cell_principal_stress"]
    ang = f.tensors["cell_principal_angle"]
    for b in (0, 5):
        major, minor = strips[2 * b], strips[2 * b + 1]
        np.testing.assert_allclose(major.mean(axis=0), f.block_q[b, :2], atol=1e-5)
        d = major[1] - major[0]
        assert abs(d[0] * np.sin(ang[b]) - d[1] * np.cos(ang[b])) < 1e-5  # parallel to (cos θ, sin θ)
        assert abs((minor[1] - minor[0]) @ d) < 1e-6  # orthogonal
        ratio = np.linalg.norm(d) / np.linalg.norm(minor[1] - minor[0])
        assert ratio == pytest.approx(
            min(abs(lam[b, 0]), rec.axis_scale["stress_axes"]) / min(abs(lam[b, 1]), rec.axis_scale["stress_axes"]),
            rel=1e-4,
        )
        for k in range(2):
            assert colors[2 * b + k] == (rec_mod.COMPRESSION_RGBA if lam[b, k] < 0 else rec_mod.TENSION_RGBA)


def test_a_glyph_stays_inside_a_thin_block(wall, tmp_path):
    """Block 0 squashed to a quarter of its height (as the aqueduct's thin cut spandrel blocks): its stress
    glyphs are at most 0.45 × its smaller side long, while the others keep the common length."""
    import dataclasses

    static, q0 = wall
    local = static.block_vert_local.copy()
    s0, e0 = static.block_vert_start[0], static.block_vert_start[1]
    local[s0:e0, 1] *= 0.25
    thin = dataclasses.replace(static, block_vert_local=local)
    frames = fx.frames(thin, q0, 12)
    for f in frames:
        f.tensors["cell_principal_stress"][0] = f.tensors["cell_principal_stress"][1:].min() * 10  # long glyphs
    path = tmp_path / "thin.rrd"
    with Recorder(path, thin, fx.METADATA, batch_frames=5) as rec:
        for f in frames:
            rec.log_frame(f)
    strips = temporal_rows(path, "/structure/plane/xy/stress_axes", "LineStrips2D:strips")[frames[-1].step]
    half = [0.5 * np.linalg.norm(np.subtract(*strips[k])) for k in range(len(strips))]
    lam, scale = frames[-1].tensors["cell_principal_stress"], rec.axis_scale["stress_axes"]
    smaller = 0.25 * fx.BLOCK_H
    assert rec._glyph_length > 0.45 * smaller  # the common length would stick out of block 0
    for b, full in ((0, 0.45 * smaller), (3, rec._glyph_length), (7, rec._glyph_length)):
        for k in range(2):
            expected = min(abs(lam[b, k]) / scale, 1.0) * full
            assert half[2 * b + k] == pytest.approx(expected, rel=1e-4, abs=1e-7)


# ------------------------------------------------------------------------------------------- colours
def ramp_frames(static, q0, count: int) -> list:
    """Frames whose fields are ramps over the blocks growing 20× over the run, with one outlier per end."""
    rng = np.random.default_rng(3)
    out = []
    for k in range(count):
        f = fx.frame(static, q0, 10 * k, rng)
        n = len(q0)
        grow = 1.2**k
        ramp = -np.linspace(0.0, 1.0, n) * 1e3 * grow
        ramp[0] = -1e6  # far beyond any robust range
        f.tensors["cell_spherical_stress"] = ramp
        dev = np.linspace(0.0, 1.0, n) * 50.0 * grow
        dev[-1] = 1e6
        f.tensors["cell_deviatoric_stress"] = dev
        out.append(f)
    return out


def test_fill_colours_follow_the_field_with_ranges_that_follow_the_data(tmp_path):
    static, q0 = fx.wall(8, 8)  # 60 blocks: one cell (under 2 %) may lie outside the range
    frames = ramp_frames(static, q0, 18)
    path = tmp_path / "ramp.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=5) as rec:
        for f in frames:
            rec.log_frame(f)
    owner = np.repeat(np.arange(len(q0)), np.diff(static.block_vert_start))
    first_vertex = np.r_[0, np.cumsum(np.diff(static.block_vert_start))[:-1]]
    read = field_frames(path)
    for key, lut in (("cell_spherical_stress", cm.BLUES), ("cell_deviatoric_stress", cm.VIRIDIS)):
        spec = rec_mod.layout.FIELD_BY_KEY[key]
        rows = temporal_rows(path, f"/{FILL}", spec.colors)
        ranges = []
        for f in frames:
            lo, hi = read[f.step]["ranges"][key]
            ranges.append((lo, hi))
            values = f.tensors[key]
            if key == "cell_spherical_stress":
                assert hi == 0.0 and lo < 0.0  # p: one-sided, ends at zero
            outside = (values < lo) | (values > hi)
            assert outside.mean() <= OUTSIDE_SHARE + 1e-12
            inside = values[~outside]
            assert (inside.max() - inside.min()) / (hi - lo) >= MIN_SPAN
            colors = np.array(rows[f.step], dtype=np.uint32)
            assert np.all(colors == colors[first_vertex][owner])  # one colour per block
            block_colors = colors[first_vertex]
            t = (values - lo) / (hi - lo)  # an independent linear map (both are one-sided here)
            expected = np.where(
                t < 0, cm.UNDER_RGBA, np.where(t > 1, cm.OVER_RGBA, lut[np.rint(np.clip(t, 0, 1) * 255).astype(int)])
            )
            np.testing.assert_array_equal(block_colors, expected)
        assert len(set(ranges)) >= 2  # the data grew 20×: the range followed


def test_colour_bar_end_caps_stand_apart_from_the_bar(written):
    """Each field's bar as recorded: the below / above caps (the last 6 vertices) are far from every colour
    of the bar (the spherical-stress bar's top, 0 kPa, and its white "above" cap read as one)."""
    from test_recording_colormap import min_distances

    path = written[0]
    for f in FIELDS:
        colours = np.array(static_value(path, f"/{f.bar}", "Mesh3D:vertex_colors"), dtype=np.uint32)
        bar, caps = colours[:-6], colours[-6:]
        for cap in set(caps.tolist()):
            delta_e, rgb = min_distances(cap, bar)
            assert delta_e > 40.0 and rgb > 100.0, (f.key, hex(cap), delta_e, rgb)


def test_nan_field_values_are_grey(written):
    path, static, frames, _ = written
    spec = rec_mod.layout.FIELD_BY_KEY["cell_volumetric_strain_rate"]
    rows = temporal_rows(path, f"/{FILL}", spec.colors)
    s, e = static.block_vert_start[1], static.block_vert_start[2]  # block 1 has no triangle (NaN)
    for f in frames[::5]:
        assert np.isnan(f.tensors["cell_volumetric_strain_rate"][1])
        assert set(rows[f.step][s:e]) == {cm.NAN_RGBA}


def test_legend_labels_per_frame_and_run_document(written):
    path, static, frames, rec = written
    info = inspect_recording(path)
    doc = info["metadata"]
    assert doc.startswith("# masonry — synthetic wall")
    assert "completed, last frame t = 0.240 s (step 240)" in doc
    for needle in ("parameters.freq | 2.0", "Run time", "| masonry |", "| rerun-sdk | 0.41", "| numba |", "kN"):
        assert needle in doc, needle
    assert "Wall time" not in doc  # in a recording of the wall, a class read it as a time of the wall
    read = field_frames(path)
    for f in FIELDS:
        lo, hi = rec.field_ranges[f.key]
        assert f"{lo:.4g} … {hi:.4g}" in doc
        labels = temporal_rows(path, f"/{f.labels}", "Points2D:labels")
        last = labels[frames[-1].step]
        # five ticks, the title with the frame's instant, then the below / above counts there are
        assert last[5] == f"{f.title}, t = {frames[-1].time:.3f} s"
        # an empty count is no label at all: its point drew an empty box beside the bar
        for frame in frames:
            assert all(labels[frame.step])
            if f.key not in frame.tensors:  # the joint states: made by the recorder from the contacts
                continue
            values, (lo_f, hi_f) = frame.tensors[f.key], read[frame.step]["ranges"][f.key]
            counts = [f"{n} {way}" for n, way in (((values < lo_f).sum(), "below"), ((values > hi_f).sum(), "above"))]
            assert labels[frame.step][6:] == [c for c in counts if not c.startswith("0 ")], (f.key, frame.step)
        assert read[frames[-1].step]["ranges"][f.key] == (lo, hi)
    legend = static_value(path, "/run/legend", "TextDocument:text")
    assert "Joint forces" in legend[0] and "Magnified" in legend[0]


def test_magnified_shape(written):
    """The blocks' displacement relative to the one shaken ground is magnified, drawn on the ground where it
    is (the ground's travel was magnified too: the view slid by m × the ground's displacement)."""
    path, static, frames, rec = written
    rows = temporal_rows(path, "/structure/plane/xy/magnified", "LineStrips2D:strips")
    m = rec.magnify
    assert m >= 1.0
    f = frames[-1]
    g = np.append(f.support_q[0, :2] - frames[0].support_q[0, :2], 0.0)
    assert abs(g[0]) > 1e-3  # the fixture's ground has moved
    q = frames[0].block_q + g + m * (f.block_q - frames[0].block_q - g)
    np.testing.assert_allclose(np.array(rows[f.step][0])[:-1], world_outline(static, q, 0), atol=1e-4)
    assert len(rows[f.step]) == len(static.block_name) + 1  # blocks and the ground
    ground = np.array(rows[f.step][-1])[:-1]
    np.testing.assert_allclose(ground.min(axis=0) - g[:2], np.array(rows[0][-1])[:-1].min(axis=0), atol=1e-4)


def test_recording_path_problem_names_a_folders_recordings(tmp_path):
    """A folder is said to be one (``inspect recordings`` said "no such recording"): its .rrd files are
    named, the first three by name and the rest counted, and the newest is the one suggested."""
    import os

    from masonrycli.recording import recording_path_problem

    folder = tmp_path / "recs"
    folder.mkdir()
    assert recording_path_problem(folder) == f"{folder}: a folder, not a recording (it holds no .rrd file)"
    for age, name in enumerate(["e.rrd", "a.rrd", "c.rrd", "b.rrd", "d.rrd"]):
        (folder / name).write_bytes(b"")
        os.utime(folder / name, ns=(10**18, 10**18 - age * 10**9))  # e.rrd the newest
    (folder / "sub.rrd").mkdir()  # a folder named like a recording is not one
    assert recording_path_problem(folder) == (
        f"{folder}: a folder, not a recording; it holds 5 recordings (a.rrd, b.rrd, c.rrd and 2 more): "
        f"give one, e.g. masonry inspect {folder / 'e.rrd'} (the newest)"
    )
    assert recording_path_problem(folder / "a.rrd") is None
    assert recording_path_problem(folder / "missing.rrd") == f"{folder / 'missing.rrd'}: no such recording"
