"""A study of the wall sized by ``courses`` and ``length``: the block count follows, as ``simulate`` builds it."""

from __future__ import annotations

import numpy as np

from masonrycli.scenario.builtin import builtin
from masonrycli.study.store import read_rows

from sweep_helpers import invoke


def extents(assembly) -> np.ndarray:
    return np.array([[*b.vertices.min(axis=0), *b.vertices.max(axis=0)] for b in assembly.blocks])


def test_a_wall_of_courses_and_length_is_swept_as_simulate_builds_it(tmp_path):
    # 'sweep wall --param courses=15 --param length=0.6' was refused: "51 blocks cannot be laid in running bond
    # with 15 courses and length 0.6 m" (the study's wall kept the built-in's 51 blocks), where 'simulate wall
    # --courses 15 --length 0.6' builds its 37 blocks
    out, histories = tmp_path / "s.csv", tmp_path / "h"
    args = ("--param", "length=0.6,0.9", "--param", "amp=0.5", "--duration", 0.01, "--workers", 0)
    result = invoke(
        "sweep", "wall", "--param", "courses=15", *args, "--no-recording", "--out", out, "--histories", histories
    )
    assert result.exit_code == 0, result.output
    assert [(r["courses"], r["length"], r["state"] != "") for r in read_rows(out)] == [(15, 0.6, True), (15, 0.9, True)]
    for length in (0.6, 0.9):
        h = np.load(next(histories.glob(f"*length={length}*.npz")))
        built = builtin("wall", courses=15, length=length).assembly
        assert list(h["block_name"]) == [b.name for b in built.blocks]
        np.testing.assert_allclose(h["block_extent"], extents(built), rtol=0, atol=1e-12)
    # blocks given with them is the count asked for: a count that does not fit is refused, as simulate refuses it
    result = invoke("sweep", "wall", "--param", "blocks=51", "--param", "courses=15", *args, "--out", out, "--force")
    assert result.exit_code == 2 and "51 blocks cannot be laid in running bond" in result.output
