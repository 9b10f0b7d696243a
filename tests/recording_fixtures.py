"""Synthetic geometry and frames for the recording tests (no engine needed).

A running-bond wall of rectangles (one block of the top course is a pentagon, so the polygons are
ragged), a ground support, a centroid triangulation, and frames with a swaying wall, random contacts
and tensor fields named as in masonrycli.analysis.tensors; reading rows back, and rerun's strict mode.
"""

from __future__ import annotations

import numpy as np
import pytest
import rerun as rr
from scipy.spatial import Delaunay

from masonrycli.outputs.frame import CONTACT_OPEN, CONTACT_SLIP, CONTACT_STICK, Frame
from masonrycli.recording import Recorder, RecordingStatic

BLOCK_W, BLOCK_H = 0.3, 0.2


def _rect(w: float, h: float) -> np.ndarray:
    return np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]])


def _pentagon(w: float, h: float) -> np.ndarray:
    """Rectangle with its top-right corner chamfered, recentred on its centroid."""
    p = np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 4], [w / 4, h / 2], [-w / 2, h / 2]])
    x, y = p[:, 0], p[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = cross.sum() / 2
    c = np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6 * area)
    return p - c


def wall(courses: int = 4, per_course: int = 4, ragged: bool = True) -> tuple[RecordingStatic, np.ndarray]:
    """(static, block_q0 (N, 3)). Odd courses are shifted by half a block; the ground is support 0."""
    polys, cents = [], []
    for k in range(courses):
        shift = 0.5 * BLOCK_W if k % 2 else 0.0
        n = per_course - 1 if k % 2 else per_course
        for j in range(n):
            local = _rect(BLOCK_W, BLOCK_H)
            if ragged and k == courses - 1 and j == 0:
                local = _pentagon(BLOCK_W, BLOCK_H)
            x = shift + (j + 0.5) * BLOCK_W
            y = (k + 0.5) * BLOCK_H
            cents.append([x, y])
            polys.append(local)
    n_blocks = len(polys)
    start = np.r_[0, np.cumsum([len(p) for p in polys])].astype(np.int64)
    width = per_course * BLOCK_W
    ground = _rect(width + 0.4, 0.1)
    q0 = np.zeros((n_blocks, 3))
    q0[:, :2] = cents
    tri = Delaunay(q0[:, :2]).simplices
    edge = np.linalg.norm(q0[tri[:, [1, 2, 0]], :2] - q0[tri, :2], axis=2).max(axis=1)
    static = RecordingStatic(
        block_name=np.array([f"b{i:03d}" for i in range(n_blocks)]),
        block_vert_start=start,
        block_vert_local=np.concatenate(polys),
        support_name=np.array(["ground"]),
        support_vert_start=np.array([0, 4], dtype=np.int64),
        support_vert_local=ground,
        triangles=tri[edge < 1.2 * BLOCK_W].astype(np.int64),
        friction=0.6,
        dt=1e-3,
    )
    return static, q0


GROUND_Q0 = np.array([[2 * BLOCK_W, -0.05, 0.0]])


def tensor_fields(n: int, rng: np.random.Generator, t: float) -> dict[str, np.ndarray]:
    """Per-block fields with the names masonrycli.analysis.tensors produces; block 1 has no triangle (NaN)."""
    p1 = rng.normal(-2e3, 1e3, n)
    p2 = p1 - np.abs(rng.normal(1e3, 500.0, n))
    e1 = rng.normal(0.0, 0.05, n) * (1 + t)
    e2 = e1 - np.abs(rng.normal(0.02, 0.01, n))
    vsr = e1 + e2
    vsr[1] = np.nan
    return {
        "cell_volumetric_strain_rate": vsr,
        "cell_deviatoric_strain": np.abs(rng.normal(1e-4, 5e-5, n)),
        "cell_spherical_stress": (p1 + p2) / 2,
        "cell_deviatoric_stress": (p1 - p2) / 2,
        "cell_principal_stress": np.stack([p1, p2], axis=1),
        "cell_principal_angle": rng.uniform(-np.pi / 2, np.pi / 2, n),
        "cell_principal_strain_rate": np.stack([e1, e2], axis=1),
        "cell_principal_strain_rate_angle": rng.uniform(-np.pi / 2, np.pi / 2, n),
    }


def frame(static: RecordingStatic, q0: np.ndarray, step: int, rng: np.random.Generator, n_contacts: int = 40) -> Frame:
    """One synthetic frame at `step` (t = step·dt): the wall sways, contacts are random."""
    n = len(q0)
    t = step * static.dt
    q = q0.copy()
    q[:, 0] += 0.02 * np.sin(2 * np.pi * 2 * t) * q0[:, 1]
    q[:, 2] += 0.01 * np.sin(2 * np.pi * 2 * t)
    ground_q = GROUND_Q0 + [[0.01 * np.sin(2 * np.pi * 2 * t), 0.0, 0.0]]
    body = np.sort(rng.integers(0, n + 1, size=(n_contacts, 2)), axis=1).astype(np.int32)
    status = rng.choice([CONTACT_OPEN, CONTACT_STICK, CONTACT_SLIP], size=n_contacts).astype(np.int8)
    force = rng.normal(0.0, 500.0, (n_contacts, 2))
    force[:, 1] = np.abs(force[:, 1]) + 100.0
    force[status == CONTACT_OPEN] = 0.0
    normal = np.tile([0.0, 1.0], (n_contacts, 1))
    return Frame(
        step=step,
        time=t,
        block_q=q,
        block_v=np.zeros((n, 3)),
        support_q=ground_q,
        support_v=np.array([[2 * np.pi * 2 * 0.01 * np.cos(2 * np.pi * 2 * t), 0.0]]),
        support_force=np.array([[0.0, 1e4]]),
        contact_body=body,
        contact_point=q[rng.integers(0, n, n_contacts), :2] + rng.normal(0, 0.05, (n_contacts, 2)),
        contact_normal=normal,
        contact_force=force,
        contact_gap=np.zeros(n_contacts),
        contact_status=status,
        contact_mobilised=rng.uniform(0, 1, n_contacts) * (status != CONTACT_OPEN),
        tensors=tensor_fields(n, rng, t),
        energy_kinetic=0.5 * t,
        energy_potential=1e4 - t,
        energy_dissipated=0.1 * t,
        support_work=0.6 * t,
        nlgs_iterations=int(rng.integers(5, 50)),
        nlgs_residual=float(rng.uniform(1e-6, 1e-4)),
        contact_count=int((status != CONTACT_OPEN).sum()),
    )


def frames(
    static: RecordingStatic, q0: np.ndarray, count: int, every: int = 10, seed: int = 0, n_contacts: int = 40
) -> list[Frame]:
    rng = np.random.default_rng(seed)
    return [frame(static, q0, k * every, rng, n_contacts) for k in range(count)]


METADATA = {"scenario": "synthetic wall", "parameters": {"freq": 2.0, "amp": 1.0, "dt": 1e-3}, "seed": 0}


@pytest.fixture(autouse=True)
def strict_rerun():
    """Any logging error raises instead of becoming a warning."""
    before = rr.strict_mode()
    rr.set_strict_mode(True)
    yield
    rr.set_strict_mode(before)


def temporal_rows(path, entity: str, column: str) -> dict[int, list]:
    """step -> the row's value (Python list) of `column` on `entity` (temporal chunks only)."""
    out: dict[int, list] = {}
    for chunk in rr.chunk.RrdReader(path).stream():
        if chunk.entity_path != entity or chunk.is_static:
            continue
        batch = chunk.to_record_batch()
        if column not in batch.schema.names:
            continue
        for step, value in zip(batch.column("step").to_pylist(), batch.column(column).to_pylist()):
            out[step] = value
    return out


def static_value(path, entity: str, column: str):
    """The last static value of ``column`` logged at ``entity`` in the recording at ``path`` (None: none):
    the one of the latest row id, which the viewer shows (the chunks are not stored in the order logged)."""
    import rerun as rr

    value, latest = None, b""
    for chunk in rr.chunk.RrdReader(str(path)).stream():
        if chunk.entity_path == entity and chunk.is_static:
            batch = chunk.to_record_batch()
            if column in batch.schema.names:
                for row_id, v in zip(
                    batch.column("rerun.controls.RowId").to_pylist(), batch.column(column).to_pylist()
                ):
                    if v is not None and row_id > latest:  # row ids: big-endian, time first
                        value, latest = v, row_id
    return value


def px_per_metre_at_first_open(path, static: RecordingStatic, q0: np.ndarray, count: int = 3) -> float:
    """Record ``count`` frames of ``static`` at ``path``; the structure panel's pixels per metre as the recording
    opens: the 1150 x 840 px panel of a 1920 x 1080 window fitted to the view's logged extent."""
    from masonrycli.recording.layout import PLANE

    with Recorder(path, static, METADATA, batch_frames=4) as rec:
        for f in frames(static, q0, count):
            rec.log_frame(f)
    w, h = static_value(path, f"/{PLANE}", "Pinhole:resolution")[0]
    return min(1150.0 / w, 840.0 / h)


def dot_at_first_open(path, static: RecordingStatic, q0: np.ndarray, entity: str) -> tuple[float, float, float]:
    """(a dot's width, a block's smaller side) in px as the recording at ``path`` opens, and the radius logged
    for the points at ``entity`` (negative: ui points, a fixed size on screen)."""
    px_per_m = px_per_metre_at_first_open(path, static, q0)
    (r,) = static_value(path, f"/{entity}", "Points2D:radii")
    return (-2.0 * r if r < 0 else 2.0 * r * px_per_m), min(BLOCK_W, BLOCK_H) * px_per_m, r


N_FRAMES, BATCH = 25, 10  # the written recording's frames: three flushes, the last one partial


@pytest.fixture(scope="module", name="wall")
def wall_fixture():
    """The synthetic wall (:func:`wall`): (static, q0)."""
    return wall()


@pytest.fixture(scope="module", name="written")
def written_fixture(wall, tmp_path_factory):
    """``N_FRAMES`` frames of the wall recorded, ``BATCH`` a batch, in rerun's strict mode: (path, static,
    frames, the closed recorder)."""
    static, q0 = wall
    frames_ = frames(static, q0, N_FRAMES)
    path = tmp_path_factory.mktemp("rec") / "run.rrd"
    before = rr.strict_mode()
    rr.set_strict_mode(True)
    with Recorder(path, static, METADATA, batch_frames=BATCH) as rec:
        for f in frames_:
            rec.log_frame(f)
    rr.set_strict_mode(before)
    return path, static, frames_, rec


def legend_points(path, points) -> np.ndarray:
    """(K, 2) ``points`` (x, y, m) of the colour bars or their labels as drawn: moved and stretched by their
    parent's transform at close (static_content.legend_move: translation after scale; none: as logged)."""
    from masonrycli.recording.layout import LEGEND_BARS

    p = np.array(points, dtype=np.float64).reshape(-1, np.shape(points)[-1])[:, :2]
    t = static_value(path, f"/{LEGEND_BARS}", "Transform3D:translation")
    s = static_value(path, f"/{LEGEND_BARS}", "Transform3D:scale")
    scale = np.ones(2) if s is None else np.array(s[0][:2])
    shift = np.zeros(2) if t is None else np.array(t[0][:2])
    return p * scale + shift
