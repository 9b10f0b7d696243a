"""``masonry inspect study.csv`` of a record study: the collapsed fraction per level (pga_g or scale), one column a
value of the other swept parameters, read back from the table (masonrycli/study/levels.py). The sweep printed the
counts once, at its end; from the table nothing gave them. Checked against the rows counted here one by one."""

from __future__ import annotations

import csv
import itertools

import numpy as np

from masonrycli.study.inspect_table import level_table

from cli_helpers import invoke, words

HEAD = "record,pga_g,friction,state,peak_drift,status,error,study,source,command\n"


def _table(path, seed: int = 3):
    """A study's table of 3 records x 4 PGAs x 2 frictions, states drawn at random (collapse likelier at larger
    PGA), and two error rows (no state)."""
    rng = np.random.default_rng(seed)
    lines = []
    for record, pga, friction in itertools.product(("a.AT2", "b.AT2", "c.AT2"), (0.25, 0.5, 0.75, 1.0), (0.5, 0.7)):
        state = "collapsed" if rng.random() < pga * 0.8 else rng.choice(["damaged", "intact"])
        lines.append(f"{record},{pga},{friction},{state},0.01,completed,,abc,def,masonry sweep …")
    lines[5] = "b.AT2,0.75,0.7,,nan,error,KilledWorker: …,abc,def,masonry sweep …"  # replaces row 5
    lines[-1] = "c.AT2,1.0,0.7,,nan,error,KilledWorker: …,abc,def,masonry sweep …"
    path.write_text(HEAD + "\n".join(lines) + "\n")
    return path


def test_the_collapsed_fraction_per_level_is_the_rows_counted_one_by_one(tmp_path):
    path = _table(tmp_path / "s.csv")
    title, heads, cells, note = level_table(path)
    assert title == "collapsed / runs per pga_g (rows) and friction (columns)"
    assert heads == ["pga_g (g)", "0.5", "0.7"]
    rows = list(csv.DictReader(open(path)))
    for line in cells:  # by hand: each level's rows of each friction that have a state, those collapsed
        for friction, cell in zip(("0.5", "0.7"), line[1:]):
            runs = fell = 0
            for r in rows:
                if float(r["pga_g"]) == float(line[0]) and r["friction"] == friction and r["state"]:
                    runs += 1
                    fell += r["state"] == "collapsed"
            assert cell == f"{fell}/{runs}  {100 * fell / runs:.0f} %", (line, friction)
    assert [line[0] for line in cells] == ["0.25", "0.5", "0.75", "1"]
    assert note == "2 rows without a state (error rows) left out"
    assert sum(int(c.split("/")[1].split()[0]) for line in cells for c in line[1:]) == 22  # 24 rows, 2 errors


def test_inspect_prints_it_and_a_grid_study_has_none(tmp_path):
    path = _table(tmp_path / "s.csv")
    result = invoke("inspect", path)
    assert result.exit_code == 0, result.output
    said = words(result.output)
    assert "collapsed / runs per pga_g (rows) and friction (columns)" in said, said
    assert "2 rows without a state (error rows) left out" in said
    grid = tmp_path / "g.csv"
    grid.write_text("amp,freq,state,status,study,source\n0.1,2,intact,completed,abc,def\n")
    assert level_table(grid) is None
    assert "collapsed / runs per" not in words(invoke("inspect", grid).output)
    one = tmp_path / "one.csv"  # one friction: one column, named for what it counts
    one.write_text(
        HEAD + "a.AT2,0.5,0.6,collapsed,0.3,completed,,abc,def,\na.AT2,1.0,0.6,intact,0,completed,,abc,def,\n"
    )
    assert level_table(one)[:3] == (
        "collapsed / runs per pga_g",
        ["pga_g (g)", "collapsed"],
        [["0.5", "1/1  100 %"], ["1", "0/1  0 %"]],
    )
    two = tmp_path / "two.csv"  # two other parameters: a column a pair, each named
    two.write_text(
        "record,scale,friction,blocks,state,status,study,source\n"
        "a.AT2,1,0.5,12,collapsed,completed,abc,def\n"
        "a.AT2,1,0.7,24,intact,completed,abc,def\n"
    )
    assert level_table(two)[:3] == (
        "collapsed / runs per scale",
        ["scale", "friction = 0.5, blocks = 12", "friction = 0.7, blocks = 24"],
        [["1", "1/1  100 %", "0/1  0 %"]],
    )
