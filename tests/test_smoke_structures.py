"""CI smoke runs of each paper structure through the CLI (a few hundred steps), each recording then
opened in the real (headless) viewer: no view may report a visualizer error."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from masonrycli.cli import app
from masonrycli.recording import inspect_recording, screenshot_recording

pytestmark = pytest.mark.slow

STRUCTURES = {
    "wall-51": ["simulate", "wall", "--freq", "2", "--amp", "1"],
    "wall-248": ["simulate", "wall", "--blocks", "248", "--freq", "2", "--amp", "1"],
    "arch": ["simulate", "arch", "--settlement", "0.01"],
    "aqueduct": ["simulate", "aqueduct"],
}
BLOCKS = {"wall-51": 51, "wall-248": 248, "arch": 98, "aqueduct": 346}


@pytest.mark.parametrize("name", list(STRUCTURES))
def test_structure_runs_and_opens_in_viewer(name, tmp_path):
    rrd, npz = tmp_path / f"{name}.rrd", tmp_path / f"{name}.npz"
    args = STRUCTURES[name] + ["--duration", "0.2", "--out", str(rrd), "--history", str(npz)]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    h = np.load(npz)
    assert h["block_q"].shape == (21, BLOCKS[name], 3)
    info = inspect_recording(rrd)
    assert info["application_id"] == "masonry" and info["has_blueprint"] and info["complete"]
    assert info["frames"] == 20  # the initial state (no force yet) is in the history only
    reports = screenshot_recording(rrd, tmp_path / f"{name}.png", time_s=0.1)
    assert reports == []
    assert (tmp_path / f"{name}.png").stat().st_size > 10_000
