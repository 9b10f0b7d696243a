"""masonrycli/cli/build.py as a user drives it: masonry build writes a GeoJSON that counts right, is
convex and non-overlapping, runs directly and from a scenario file; its line says what it wrote."""

from __future__ import annotations

import json

import numpy as np
import pytest

from masonrycli.cli.app import app

from cli_helpers import invoke, runner, words

WIDE = {"COLUMNS": "250"}


def test_build_says_one_block_in_the_singular(tmp_path):
    # "wall: 1 blocks and 1 support → w.geojson"
    # a console wide enough for the path: at 80 columns one longer than the line is cut anywhere ("w.geojs on"),
    # as under pytest-xdist, whose tmp_path is 10 characters longer (popen-gw0/)
    result = runner.invoke(app, ["build", "wall", "--blocks", "1", "--out", str(tmp_path / "w.geojson")], env=WIDE)
    said = words(result.output)  # the console wraps a long path
    assert result.exit_code == 0 and f"wall: 1 block and 1 support → {tmp_path / 'w.geojson'}" in said


@pytest.mark.parametrize(
    "builder, args, blocks, supports",
    [
        ("wall", ["--blocks", "51"], 51, 1),
        ("wall", ["--blocks", "248"], 248, 1),
        ("arch", [], 98, 2),
    ],
)
def test_build_writes_geojson_that_runs(builder, args, blocks, supports, tmp_path):
    """`masonry build` output: the right counts, convex, non-overlapping (checked with shapely), and the
    same format runs directly and from a scenario file that gives its support a motion."""
    from shapely.geometry import shape
    from shapely.strtree import STRtree

    out = tmp_path / f"{builder}.{'json' if supports == 2 else 'geojson'}"  # .json: `run` reads it as GeoJSON
    result = invoke("build", builder, *args, "--out", out)
    assert result.exit_code == 0, result.output
    features = json.loads(out.read_text())["features"]
    polys = [shape(f["geometry"]) for f in features if f["properties"]["role"] == "block"]
    assert len(polys) == blocks
    assert sum(f["properties"]["role"] == "support" for f in features) == supports
    for p in polys:
        assert p.convex_hull.area - p.area < 1e-12
    tree = STRtree(polys)
    for i, p in enumerate(polys):
        for j in tree.query(p):
            if j > i:
                assert p.intersection(polys[j]).area < 1e-9
    if builder == "wall" and blocks == 51:
        npz = tmp_path / "direct.npz"
        result = invoke("run", out, "--duration", 0.01, "--no-recording", "--history", npz)
        assert result.exit_code == 0, result.output
        assert np.load(npz)["block_q"].shape[1] == 51
        scen = tmp_path / "shaken.toml"
        scen.write_text(
            f'[run]\nduration = 0.02\n[structure]\nfile = "{out.name}"\n[[support]]\nname = "ground"\n'
            'motion = { kind = "sine", amplitude = 1.0, frequency = 2.0 }\n'
        )
        result = invoke("run", scen, "--no-recording", "--history", npz, "--force")
        assert result.exit_code == 0, result.output
        assert np.load(npz)["support_v"][-1, 0, 0] == pytest.approx(np.sin(2 * np.pi * 2 * 0.02))
