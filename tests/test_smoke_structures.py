"""CI smoke runs of each paper structure through the CLI (a few hundred steps), each recording then
opened in the real (headless) viewer: no view may report a visualizer error."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from masonrycli.cli.app import app
from masonrycli.recording import inspect_recording, screenshot_recording
from masonrycli.recording.colormap import BLUES, COOLWARM, unpack_rgba

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
    assert info["frames"] == 21 and info["steps"] == (0, 200)  # the initial state (t = 0), as in the history
    png = tmp_path / f"{name}.png"
    reports = screenshot_recording(rrd, png, at_open=True)  # where the viewer puts the cursor itself
    assert reports == []
    # The structure is drawn at first open: the live tab (p, blues) or the wall's Fig. III.2 tab (pinned to
    # 0.1 s, blue-grey-red). Before, a run without paper tabs (the arch for 0.2 s) opened on the start of
    # the time line, before its first frame: the colour bar alone.
    assert fill_share(png) > 0.03


def fill_share(png) -> float:
    """Share of the structure panel's pixels (left of the colour bar, above the legend) in a fill colour."""
    import PIL.Image as image_module

    rgb = np.asarray(image_module.open(png).convert("RGB"))[60:870, :850].astype(np.int32)
    lut = np.concatenate([unpack_rgba(BLUES), unpack_rgba(COOLWARM)])[::4, :3].astype(np.int32)
    mask = np.zeros(rgb.shape[:2], dtype=bool)
    for c in lut:
        mask |= np.abs(rgb - c).sum(axis=-1) < 8
    return float(mask.mean())
