"""The Magnified tab read back: at step 0 the magnified blocks lie on the outline as built, to the bit; later
frames are the as-built pose plus m times the displacement, computed here in float64 from the frames."""

from __future__ import annotations

import numpy as np

from masonrycli.recording import Recorder
from masonrycli.recording.layout import MAGNIFIED, UNDEFORMED

import recording_fixtures as fx
from recording_fixtures import strict_rerun, temporal_rows  # noqa: F401 (strict_rerun: autouse)

M = 600.0  # the bridge's default factor ('masonry simulate arch ... --fill-cover 0.3 --settlement 0.02')


def _wall_far_from_the_origin(tmp_path, shift: float = 4.0):
    """The synthetic wall moved ``shift`` m right (the bridge's voussoirs stand 4 m from its centre), recorded
    × M; returns (path, static, frames)."""
    static, q0 = fx.wall()
    q0[:, 0] += shift
    frames = fx.frames(static, q0, 6)
    path = tmp_path / "far.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=4, magnify=M) as rec:
        for f in frames:
            rec.log_frame(f)
    return path, static, frames


def _posed(static, q: np.ndarray) -> list[np.ndarray]:
    """Each block's closed outline at the poses ``q`` (N, 3), float64."""
    start, local = static.block_vert_start, static.block_vert_local
    out = []
    for i in range(len(start) - 1):
        c, s = np.cos(q[i, 2]), np.sin(q[i, 2])
        xy = local[start[i] : start[i + 1]] @ np.array([[c, s], [-s, c]]) + q[i, :2]
        out.append(np.r_[xy, xy[:1]])
    return out


def test_step_0_of_the_magnified_shape_is_the_outline_as_built(tmp_path):
    """The poses waited for the factor as float32: each coordinate rounded by up to 0.24 µm at 4 m, × 600 =
    0.14 mm off the built outline at step 0 (0.12 mm read back from the bridge's recording). The displacement
    is taken in float64 first: step 0 is the as-built outline exactly."""
    path, static, frames = _wall_far_from_the_origin(tmp_path)
    n = len(frames[0].block_q)
    first = [np.array(s) for s in temporal_rows(path, f"/{MAGNIFIED}", "LineStrips2D:strips")[0]]
    built = [np.array(s) for s in fx.static_value(path, f"/{UNDEFORMED}", "LineStrips2D:strips")]
    assert len(first) == len(built) == n + 1  # the blocks, then the ground
    for drawn, ghost in zip(first, built):
        np.testing.assert_array_equal(drawn, ghost)


def test_a_later_frame_is_the_built_pose_plus_m_times_the_displacement(tmp_path):
    """Relative to the one ground support, which is drawn where it is (magnified.py's module doc)."""
    path, static, frames = _wall_far_from_the_origin(tmp_path)
    rows = temporal_rows(path, f"/{MAGNIFIED}", "LineStrips2D:strips")
    last = frames[-1]
    assert max(rows) == last.step
    q0, g = frames[0].block_q, last.support_q[0] - frames[0].support_q[0]
    expected = _posed(static, q0 + g + M * (last.block_q - q0 - g))
    drawn = [np.array(s) for s in rows[last.step][: len(expected)]]
    assert max(np.abs(d - e).max() for d, e in zip(drawn, expected)) < 1e-6  # float32 vertices (0.24 µm at 4 m)
    assert max(np.abs(d - b).max() for d, b in zip(drawn, _posed(static, q0))) > 0.1  # magnified indeed
