"""What the viewer shows of a run's cells (the recording's hover values: p, q, strain rates, joint states) is
what the history — and so a notebook — reads, frame for frame: a student comparing the paper's stress tensors
in the viewer with her notebook's arrays compares the same numbers (the recording keeps them in float32)."""

from __future__ import annotations

import numpy as np

from masonrycli import api
from masonrycli.recording.layout import HOVER_VALUES
from masonrycli.recording.readback import field_frames


def test_the_recording_s_cell_values_are_the_history_s(tmp_path):
    run = api.simulate("wall", amp=0.5, duration=0.05, recording=tmp_path / "w.rrd", history=tmp_path / "w.npz")
    read = field_frames(tmp_path / "w.rrd")
    assert sorted(read) == [int(s) for s in run["step"]]  # every frame of the history, none more
    steps = list(run["step"])
    checked = 0
    for step, frame in read.items():
        k = steps.index(step)
        for key in HOVER_VALUES.values():
            if key not in frame["values"]:
                continue
            shown, kept = frame["values"][key], run[key][k]
            if key == "cell_volumetric_strain_rate":  # the fill shows the chain's rate where a cell has none
                kept = np.where(np.isnan(kept), run["chain_strain_rate"][k], kept)
            scale = max(np.nanmax(np.abs(kept), initial=0.0), 1e-300)
            assert np.array_equal(np.isnan(shown), np.isnan(kept)), (key, step)
            assert np.nanmax(np.abs(shown - kept), initial=0.0) <= 1e-6 * scale, (key, step)  # float32
            checked += 1
    assert checked >= 6 * 5  # p, q, strain rate, strain, sliding, opening at every frame
