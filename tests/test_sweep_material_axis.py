"""A study's density / thickness axis: the history of each run names the material its blocks were built of."""

from __future__ import annotations

import json

import numpy as np

from masonrycli.study.store import read_rows

from sweep_helpers import invoke


def test_a_density_axis_is_the_density_the_history_names(tmp_path):
    # 'sweep wall --param density=2200 --histories h': the blocks weighed 2200 kg/m³ (as simulate --density 2200
    # builds them) but the history's document, and 'masonry inspect', said "density 2500 kg/m³"
    out, histories = tmp_path / "s.csv", tmp_path / "h"
    args = ("--param", "courses=4", "--param", "length=0.6", "--param", "amp=0.2", "--duration", 0.01)
    result = invoke(
        "sweep", "wall", *args, "--param", "density=1800,2200", "--param", "thickness=0.5",
        "--workers", 0, "--no-recording", "--out", out, "--histories", histories,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    assert [r["density"] for r in read_rows(out)] == [1800, 2200]
    for density in (1800, 2200):
        h = np.load(next(histories.glob(f"*density={density}_*.npz")))
        run = json.loads(str(h["run"]))
        assert (run["density_kg_m3"], run["thickness_m"]) == (density, 0.5)
        # the masses are of that density: area (shoelace of the block's outline at rest) × thickness × density
        extent = h["block_extent"]
        areas = (extent[:, 2] - extent[:, 0]) * (extent[:, 3] - extent[:, 1])  # the wall's blocks are rectangles
        np.testing.assert_allclose(h["block_mass"], areas * 0.5 * density, rtol=1e-12)
        shown = invoke("inspect", next(histories.glob(f"*density={density}_*.npz")))
        assert f"density {density} kg/m³, thickness 0.5 m" in shown.output
