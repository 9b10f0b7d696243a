"""records/pga.py's applied peak: the PGA a record's scale is set by, over any run's length in bounded memory.

The reference is the whole run's velocities in one array (what ``--pga`` evaluated before): the chunked peak
must equal it to the bit, and a run far longer than its record must not hold a velocity per step (``masonry
check wall --record q.AT2 --pga 0.25 --duration 100000`` took 12.5 GB and 73 s before it refused the run's
recording)."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli import api
from masonrycli.records import pga
from masonrycli.records.motion import Record
from masonrycli.records.read import G_STANDARD, record_motion

from synthetic_records import band_limited, write_at2


@pytest.fixture
def at2(tmp_path):
    t, u, v, a = band_limited(0.6, 0.005, [2.0, 4.5], [0.004, 0.001], seed=5)
    write_at2(tmp_path / "quake.AT2", a[: len(a) * 3 // 4] / G_STANDARD, 0.005)  # cut short: not at rest at its end
    return tmp_path / "quake.AT2"


def whole_run_peak(record, n_steps: int, dt: float) -> float:
    v = record.velocity_at(np.arange(n_steps + 1, dtype=np.float64) * dt)[:, 0]
    return float(np.abs(np.diff(v)).max()) / dt


@pytest.mark.parametrize("n_steps", [1, 300, 449, 450, 451, 2000])
@pytest.mark.parametrize("chunk", [1, 7, 1 << 20])
def test_the_peak_in_chunks_is_the_whole_runs_to_the_bit(at2, monkeypatch, n_steps, chunk):
    record = record_motion(at2)  # 0.45 s: runs shorter than it, ending at it and past it
    monkeypatch.setattr(pga, "CHUNK_STEPS", chunk)
    assert pga.applied_peak(record, n_steps, 1e-3) == whole_run_peak(record, n_steps, 1e-3)


def test_a_run_far_longer_than_its_record_is_measured_over_the_record(at2, monkeypatch):
    sizes = []
    velocity_at = Record.velocity_at

    def counted(self, t):
        sizes.append(len(t))
        assert len(t) <= 2_000_001, f"{len(t)} velocities at once"  # 16 MB a component
        return velocity_at(self, t)

    monkeypatch.setattr(Record, "velocity_at", counted)
    long = api.scenario("wall", blocks=12, record=at2, pga=0.25, duration=1e5)  # 10⁸ steps
    assert sum(sizes) < 1000
    short = api.scenario("wall", blocks=12, record=at2, pga=0.25, duration=1.0)
    assert long.motions[0].scale == short.motions[0].scale
