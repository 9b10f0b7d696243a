"""The four paper runs' recordings, read back as an engineer would open them (no viewer needed).

At every recorded frame at most 2 % of a field's defined cells lie outside the colour range logged for
that frame; at the paper's instant each of the four fields spans at least 40 % of its range; p is on a
one-sided map; solver health is logged once per step; the paper-figure tabs are pinned to the paper's
instant. Arch: cell strain on the springing voussoirs and every pier block, a strain rate along the ring
on every voussoir. Aqueduct: at most 7 MB per simulated second at default settings. The walls run to
0.2 s (their instant is 0.1 s), the arch and the aqueduct to their default 5 s.
"""

from __future__ import annotations

import numpy as np
import pytest
import rerun as rr
from typer.testing import CliRunner

from masonrycli.cli.app import app
from masonrycli.recording import FIELDS
from masonrycli.recording.layout import FIELD_BY_KEY, PAPER_FIELDS
from masonrycli.recording.readback import blueprint_views, field_frames

pytestmark = pytest.mark.slow

RUNS = {  # name -> (CLI arguments, the paper's instant s, blocks)
    "wall-51": (["simulate", "wall", "--freq", "2", "--amp", "1", "--duration", "0.2"], 0.1, 51),
    "wall-248": (["simulate", "wall", "--blocks", "248", "--freq", "2", "--amp", "1", "--duration", "0.2"], 0.1, 248),
    "arch": (["simulate", "arch", "--settlement", "0.01"], 5.0, 98),
    "aqueduct": (["simulate", "aqueduct"], 5.0, 346),
}


_DONE: dict[str, tuple] = {}


def _record(name: str, tmp_path_factory) -> tuple:
    """Run ``name`` once per test session through the CLI and read its recording back."""
    if name not in _DONE:
        args, instant, blocks = RUNS[name]
        rrd = tmp_path_factory.mktemp(name) / f"{name}.rrd"
        result = CliRunner().invoke(app, [*args, "--out", str(rrd)])
        assert result.exit_code == 0, result.output
        _DONE[name] = (name, rrd, instant, blocks, field_frames(rrd))
    return _DONE[name]


@pytest.fixture(scope="module", params=list(RUNS))
def recording(request, tmp_path_factory):
    return _record(request.param, tmp_path_factory)


def test_fields_inside_their_range_at_every_frame_and_spread_at_the_paper_instant(recording):
    name, _, instant, blocks, frames = recording
    assert len(frames) >= 19
    for step, row in frames.items():
        for f in FIELDS:
            values = row["values"][f.key]
            lo, hi = row["ranges"][f.key]
            defined = values[np.isfinite(values)]
            outside = int(((defined < lo) | (defined > hi)).sum())
            assert outside <= np.floor(0.02 * defined.size), (name, step, f.key, outside, defined.size)
    (at,) = [row for row in frames.values() if abs(row["time"] - instant) < 1e-9]
    for f in PAPER_FIELDS:
        values = at["values"][f.key]
        lo, hi = at["ranges"][f.key]
        v = np.clip(values[np.isfinite(values)], lo, hi)
        assert (v.max() - v.min()) / (hi - lo) >= 0.40, (name, f.key, v.min(), v.max(), lo, hi)


def test_p_is_one_sided_and_the_paper_tabs_are_pinned(recording):
    name, rrd, instant, _, frames = recording
    assert FIELD_BY_KEY["cell_spherical_stress"].kind == "negative"
    assert all(row["ranges"]["cell_spherical_stress"][1] == 0.0 for row in frames.values())
    pinned = {n: v["pinned"] for n, v in blueprint_views(rrd).items() if v["pinned"]}
    assert len(pinned) == 4 and set(pinned.values()) == {("sim_time", instant, instant)}, pinned


def test_solver_health_is_logged_once_per_step(recording):
    name, rrd, _, _, frames = recording
    counts: dict[int, int] = {}
    for chunk in rr.chunk.RrdReader(str(rrd)).stream():
        if chunk.entity_path == "/series/solver/iterations" and not chunk.is_static:
            for step in chunk.to_record_batch().column("step").to_pylist():
                counts[step] = counts.get(step, 0) + 1
    last = max(frames)
    assert sorted(counts) == list(range(1, last + 1)) and set(counts.values()) == {1}


def test_arch_cells_and_ring_strain_rate(tmp_path_factory):
    name, _, instant, blocks, frames = _record("arch", tmp_path_factory)
    (at,) = [row for row in frames.values() if abs(row["time"] - instant) < 1e-9]
    from geometry_library.builders import build_arch

    names = [b.name for b in build_arch().blocks]
    voussoirs = [k for k, n in enumerate(names) if n.startswith("v")]
    piers = [k for k, n in enumerate(names) if "pier" in n]
    assert len(voussoirs) == 30 and len(piers) == 68
    strain = at["values"]["cell_deviatoric_strain"]
    assert np.isfinite(strain[piers]).all() and np.isfinite(strain[[voussoirs[0], voussoirs[-1]]]).all()
    assert np.isfinite(at["values"]["chain_strain_rate"][voussoirs]).all()


def test_aqueduct_file_size(tmp_path_factory):
    name, rrd, *_ = _record("aqueduct", tmp_path_factory)
    assert rrd.stat().st_size / 5.0 <= 7e6  # bytes per simulated second, default 5 s run
