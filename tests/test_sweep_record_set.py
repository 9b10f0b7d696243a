"""A record set with damaged files: one line naming the first and why, and every other file that cannot be read."""

from __future__ import annotations

import numpy as np

from cli_helpers import assert_one_line_error, invoke
from synthetic_records import band_limited, edited_copy, write_at2


def test_every_damaged_file_of_a_set_is_named_in_the_one_line(tmp_path):
    # the first damaged file alone was named: mended, the same command refused the next one, and so on
    recs = tmp_path / "recs"
    recs.mkdir()
    a = band_limited(1.0, 0.01, [2.0, 4.0], [0.004, 0.001], seed=3)[3]
    write_at2(tmp_path / "good.AT2", a / 9.80665, 0.01)
    edited_copy(tmp_path / "good.AT2", recs / "a_good.AT2", "PEER", "PEER")
    edited_copy(tmp_path / "good.AT2", recs / "b_units.AT2", "UNITS OF G", "UNITS OF CM/S/S")
    edited_copy(tmp_path / "good.AT2", recs / "c_npts.AT2", "NPTS=    101", "NPTS=    102")
    edited_copy(tmp_path / "good.AT2", recs / "d_nan.AT2", f"{a[7] / 9.80665:15.7E}", "            NaN")
    out = tmp_path / "s.csv"
    result = invoke("sweep", "wall", "--records", recs, "--param", "pga_g=0.3", "--workers", 0, "--out", out)
    assert_one_line_error(
        result,
        f"{recs / 'b_units.AT2'}:3: the header says units of CM/S/S; an .AT2 record holds acceleration in g (convert "
        "the samples, or give them as a CSV with quantity and scale) (and 2 more files of --records cannot be read: "
        f"{recs / 'c_npts.AT2'}, {recs / 'd_nan.AT2'})",
    )
    assert not out.exists() and np.isfinite(a).all()
