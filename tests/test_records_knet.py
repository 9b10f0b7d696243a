"""K-NET / KiK-net ASCII records (``….NS``, ``.EW``, ``.UD``, ``.NS1`` …): the reader against a hand-made file
(tests/data/knet.NS: NIED's 17-line header, 100 Hz, scale factor 3920(gal)/6182761, the counts of
a(t) = 50 sin(2π·2·t) gal rounded, plus an offset of 1000 counts), errors naming file and line, and the file
through ``check``, ``run``'s ``--record`` and a ``sweep --records`` folder."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from masonrycli.errors import InputError
from masonrycli.records.read import read_record, record_motion
from masonrycli.study.store import read_rows

from cli_helpers import assert_one_line_error, invoke, words
from synthetic_records import edited_copy

DATA = Path(__file__).parent / "data"
KNET = DATA / "knet.NS"
BLOCK = DATA / "block_on_ground.toml"  # a block on a sine-shaken ground, 1 s
COUNT = 0.01 * 3920 / 6182761  # m/s² a count


def _edited(tmp_path: Path, old: str, new: str, name: str = "q.NS") -> Path:
    return edited_copy(KNET, tmp_path / name, old, new)


def test_the_reader_scales_the_counts_and_removes_the_offset():
    time, acc, quantity = read_record(KNET)
    assert quantity == "acceleration" and acc.shape == (100,)
    np.testing.assert_array_equal(time, np.arange(100) * 0.01)
    # the counts rounded to 1 (0.63 mgal); the offset of 1000 counts is the record's mean (whole periods)
    expected = 0.5 * np.sin(2 * np.pi * 2 * time)
    np.testing.assert_allclose(acc, expected, rtol=0, atol=0.6 * COUNT)


def test_the_record_integrates_to_the_velocity_of_its_sine():
    # a(t) = A sin(ωt) from rest: v(t) = (A/ω)(1 - cos ωt); the trapezoid rule's error at 100 Hz and 2 Hz is
    # (ω dt)²/12 = 0.13 % of the amplitude 2A/ω
    m = record_motion(KNET, baseline="none")
    omega = 2 * np.pi * 2
    t = np.arange(99) * 0.01
    v = m.velocity_at(t)[:, 0]
    np.testing.assert_allclose(v, 0.5 * (1 - np.cos(omega * t)) / omega, rtol=0, atol=2e-3 * 2 * 0.5 / omega)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("Memo.\n", "", "q.NS: not a K-NET / KiK-net record: no 'Memo.' line"),
        ("Sampling Freq(Hz) 100Hz", "Sampling Freq(Hz) fast", "q.NS:11: Sampling Freq(Hz): not a frequency"),
        (
            "Sampling Freq(Hz) 100Hz",
            "Sampling Freq(Hz) 0.1Hz",
            'q.NS:11: Sampling Freq(Hz) = "0.1Hz": a time step of 10 s: must be within',
        ),
        (
            "Sampling Freq(Hz) 100Hz",
            "Sampling Freq(Hz) 5Hz",
            'q.NS:11: Sampling Freq(Hz) = "5Hz": a time step of 0.2 s: an acceleration record sampled every 0.2 s holds '
            "nothing above 2.5 Hz",
        ),
        ("Sampling Freq(Hz) 100Hz", "Sampling Rate     100Hz", "q.NS: the K-NET header has no 'Sampling Freq' line"),
        ("3920(gal)/6182761", "3920/6182761", 'q.NS:14: Scale Factor: "3920/6182761": expected A(gal)/B'),
        ("3920(gal)/6182761", "3920(gal)/0", 'q.NS:14: Scale Factor: "3920(gal)/0": expected A(gal)/B'),
        ("   10884", "   1O884", 'q.NS:18: not a number: "1O884"'),
    ],
)
def test_errors_name_the_file_the_line_and_the_key(tmp_path, old, new, message):
    path = _edited(tmp_path, old, new)
    with pytest.raises(InputError) as info:
        read_record(path, display="q.NS")
    assert message in str(info.value) and "\n" not in str(info.value)


def test_check_run_and_sweep_take_a_knet_file(tmp_path):
    # before: read as a CSV, 'knet.NS:2: not a number: "Lat."'
    result = invoke("check", BLOCK, "--record", KNET)
    assert result.exit_code == 0, result.output
    assert "record of acceleration (knet.NS, 100 samples" in words(result.output)
    result = invoke("check", BLOCK, "--record", KNET, "--record-dt", 0.01)
    assert_one_line_error(result, "knet.NS", "a K-NET file gives its own time step", "--record-dt")
    folder = tmp_path / "recs"
    folder.mkdir()
    (folder / "MYG0041103111446.NS").write_text(KNET.read_text())
    (folder / "MYG0041103111446.UD").write_text(KNET.read_text().replace("N-S", "U-D"))
    out = tmp_path / "s.csv"
    args = ["sweep", BLOCK, "--records", folder, "--scale", 1, "--duration", 0.5, "--workers", 0, "--out", out]
    result = invoke(*args, "--no-recording")
    assert result.exit_code == 0, result.output
    assert sorted(r["record"] for r in read_rows(out)) == ["MYG0041103111446.NS", "MYG0041103111446.UD"]
    assert "MYG0041103111446.UD is a vertical component (PEER's UP / DWN, ESM's Z, K-NET's UD)" in words(result.output)


def test_a_records_folder_of_a_kiknet_download_takes_the_surface_files(tmp_path):
    # a KiK-net download holds each station's borehole (….NS1, .EW1, .UD1) and surface (….NS2 …) files: read
    # all, the folder ran the borehole motion (at the sensor's depth) as a second record of the same shaking
    folder = tmp_path / "recs"
    folder.mkdir()
    for suffix in ("NS1", "EW1", "NS2", "EW2"):
        (folder / f"FKSH100304091446.{suffix}").write_text(KNET.read_text())
    out = tmp_path / "s.csv"
    args = ["sweep", BLOCK, "--records", folder, "--scale", 1, "--duration", 0.2, "--workers", 0, "--out", out]
    result = invoke(*args, "--no-recording")
    assert result.exit_code == 0, result.output
    assert sorted(r["record"] for r in read_rows(out)) == ["FKSH100304091446.EW2", "FKSH100304091446.NS2"]
    said = words(result.output)
    assert (
        f"--records {folder}: 2 KiK-net borehole files left out (FKSH100304091446.EW1, FKSH100304091446.NS1): the "
        "motion at the sensor's depth" in said
    )
    assert "not read as records" not in said  # named once, by the line that says why
    # a folder of borehole files alone says why none is read
    for p in folder.glob("*2"):
        p.unlink()
    assert_one_line_error(
        invoke(*args, "--no-recording", "--force"),
        f"--records {folder}: no .AT2, .ASC, K-NET or .csv record in it; 2 KiK-net borehole files left out",
    )
    # given by name, a borehole file runs
    result = invoke("check", BLOCK, "--record", folder / "FKSH100304091446.NS1")
    assert result.exit_code == 0 and "record of acceleration (FKSH100304091446.NS1" in words(result.output)
