"""A record study's summary gives the fraction collapsed at each level (scale or pga_g), per curve: the
fragility plot's diamonds as numbers, which only the PNG showed."""

from __future__ import annotations

import numpy as np

from masonrycli.records.read import G_STANDARD
from masonrycli.study.store import read_rows

from cli_helpers import invoke, words
from synthetic_records import band_limited, write_at2


def test_the_summary_counts_the_collapses_at_each_pga_of_each_curve(tmp_path):
    recs = tmp_path / "recs"
    recs.mkdir()
    for seed in (1, 2):
        a = band_limited(1.0, 0.005, [1.5, 3.0], [0.02, 0.004], seed=seed)[3]
        write_at2(recs / f"q{seed}.AT2", a / G_STANDARD, 0.005)
    out = tmp_path / "s.csv"
    args = ["--param", "courses=4", "--param", "length=0.6", "--records", recs, "--param", "pga_g=0.1,0.9,2.5"]
    args += ["--param", "friction=0.3,0.8", "--duration", 1.0, "--workers", 0, "--no-recording", "--out", out]
    result = invoke("sweep", "wall", *args)
    assert result.exit_code == 0, result.output
    rows = read_rows(out)
    said = words(result.output)
    states = {r["state"] for r in rows}
    assert "collapsed" in states and states - {"collapsed"}, states  # the counts are not all 0 or all 2
    for friction in (0.3, 0.8):
        counts = []
        for pga in (0.1, 0.9, 2.5):  # counted from the table, independently of the line
            at = [r for r in rows if r["friction"] == friction and r["pga_g"] == pga]
            counts.append(f"{pga:g} {sum(r['state'] == 'collapsed' for r in at)}/{len(at)}")
        assert f"friction = {friction:g}: collapsed per pga_g (g): {', '.join(counts)}" in said, said
    assert np.isfinite([r["pga"] for r in rows]).all()
