"""ESM / ITACA ASCII records (``….ACC.ASC``): the reader's header keys and units against a hand-made file
(tests/data/esm_acc.ASC: an ESM header, then a(t) = 100 sin(2π·2·t) cm/s² every 5 ms, 200 samples), errors
naming file and line, and the file through ``check``, ``run``'s ``--record`` and a ``sweep --records`` folder."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from masonrycli.errors import InputError, RecordWarning
from masonrycli.records.read import load_esm, record_motion
from masonrycli.study.store import read_rows

from cli_helpers import assert_one_line_error, invoke, words
from synthetic_records import edited_copy

DATA = Path(__file__).parent / "data"
ESM = DATA / "esm_acc.ASC"
BLOCK = DATA / "block_on_ground.toml"  # a block on a sine-shaken ground, 1 s
FIRST_SAMPLE_LINE = 61  # the header's 60 lines, then the samples


def _edited(tmp_path: Path, old: str, new: str, name: str = "q.ASC") -> Path:
    return edited_copy(ESM, tmp_path / name, old, new)


def test_the_reader_takes_interval_count_and_cm_s2_from_the_header():
    dt, values, quantity = load_esm(ESM)
    t = np.arange(200) * 0.005
    assert dt == 0.005 and quantity == "acceleration" and values.shape == (200,)
    # cm/s² -> m/s²: the file's 7 significant digits of 100 sin(2π·2·t) (within 5e-5 cm/s²), times 0.01
    np.testing.assert_allclose(values, np.sin(2 * np.pi * 2 * t), rtol=0, atol=6e-7)


def test_the_record_integrates_to_the_velocity_of_its_sine():
    # a(t) = A sin(ωt) from rest integrates to v(t) = (A/ω)(1 - cos ωt): at the samples the trapezoid rule's
    # error is (ω dt)²/12 of the amplitude, 0.08 % at 2 Hz and 5 ms
    m = record_motion(ESM, baseline="none")
    omega = 2 * np.pi * 2
    t = np.arange(199) * 0.005
    v = m.velocity_at(t)[:, 0]
    np.testing.assert_allclose(v, (1 - np.cos(omega * t)) / omega, rtol=0, atol=2e-3 * (2 / omega))
    assert m.quantity == "acceleration" and m.source == str(ESM.resolve())


def test_a_velocity_file_is_read_as_velocity_in_m_s(tmp_path):
    path = _edited(tmp_path, "UNITS: cm/s^2", "UNITS: cm/s")
    path.write_text(path.read_text().replace("DATA_TYPE: ACCELERATION", "DATA_TYPE: VELOCITY"))
    m = record_motion(path)
    assert m.quantity == "velocity"
    assert m.value[50] == pytest.approx(0.01 * 100 * math.sin(2 * math.pi * 2 * 50 * 0.005), abs=1e-8)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            "UNITS: cm/s^2",
            "UNITS: cm",
            "q.ASC:35: UNITS: cm: a displacement series: give the same component's acceleration",
        ),
        (
            "DATA_TYPE: ACCELERATION",
            "DATA_TYPE: DISPLACEMENT",
            'q.ASC:52: DATA_TYPE: "DISPLACEMENT": a displacement series',
        ),
        (
            "DATA_TYPE: ACCELERATION",
            "DATA_TYPE: ACCELERATION RESPONSE SPECTRUM",
            'q.ASC:52: DATA_TYPE: "ACCELERATION RESPONSE SPECTRUM": not an acceleration or velocity time series',
        ),
        ("UNITS: cm/s^2", "UNITS: counts", 'q.ASC:35: UNITS: "counts": not a unit masonry reads'),
        (
            "UNITS: cm/s^2",
            "UNITS: cm/s",
            "q.ASC:35: UNITS: cm/s is velocity, but DATA_TYPE (line 52) says ACCELERATION",
        ),
        (
            "SAMPLING_INTERVAL_S: 0.005000",
            "SAMPLING_INTERVAL: 0.005",
            "q.ASC: not an ESM record: its header has no SAMPLING_INTERVAL_S",
        ),
        (
            "SAMPLING_INTERVAL_S: 0.005000",
            "SAMPLING_INTERVAL_S: 5",
            'q.ASC:29: SAMPLING_INTERVAL_S = "5": must be within',
        ),
        (
            "SAMPLING_INTERVAL_S: 0.005000",
            "SAMPLING_INTERVAL_S: 0.5",
            'q.ASC:29: SAMPLING_INTERVAL_S = "0.5": an acceleration record sampled every 0.5 s holds nothing above 1 Hz',
        ),
        ("SAMPLING_INTERVAL_S: 0.005000", "SAMPLING_INTERVAL_S: 5 ms", "q.ASC:29: SAMPLING_INTERVAL_S: not a number"),
        ("NDATA: 200", "NDATA: 300", "q.ASC: header says NDATA = 300 but the file holds 200 samples"),
        ("NDATA: 200", "NDATA: two hundred", "q.ASC:30: NDATA: not a whole number"),
        ("6.279052e+00\n", "6.279052e+00\n1.2O3e+01\n", f'q.ASC:{FIRST_SAMPLE_LINE + 2}: not a number: "1.2O3e+01"'),
        ("6.279052e+00\n", "6.279052e+00\nnan\n", f"q.ASC:{FIRST_SAMPLE_LINE + 2}: values must be finite"),
    ],
)
def test_errors_name_the_file_the_line_and_the_key(tmp_path, old, new, message):
    path = _edited(tmp_path, old, new)
    with pytest.raises(InputError) as info:
        load_esm(path, display="q.ASC")
    assert message in str(info.value) and "\n" not in str(info.value)


def test_more_samples_than_ndata_keeps_ndata_with_a_warning(tmp_path):
    path = _edited(tmp_path, "NDATA: 200", "NDATA: 150")
    with pytest.warns(RecordWarning, match="NDATA = 150 but the file holds 200 samples; the 50 after"):
        dt, values, _ = load_esm(path)
    assert values.size == 150


def test_check_and_run_take_an_esm_file_as_record(tmp_path):
    # before: 'esm_acc.ASC:2: not a number: "EVENT_ID:"' (read as a CSV), exit 2
    result = invoke("check", BLOCK, "--record", ESM)
    assert result.exit_code == 0, result.output
    assert "record of acceleration (esm_acc.ASC, 200 samples" in words(result.output)
    result = invoke("run", BLOCK, "--record", ESM, "--scale", 2, "--duration", 0.5, "--no-recording")
    assert result.exit_code == 0, result.output
    assert "completed" in result.output and "ground motion (ground) │ PGA" in words(result.output)


def test_an_esm_file_refuses_a_time_step_and_is_named_under_another_suffix(tmp_path):
    result = invoke("check", BLOCK, "--record", ESM, "--record-dt", 0.01)
    assert_one_line_error(result, "esm_acc.ASC", "an ESM .ASC file gives its own time step", "--record-dt")
    renamed = tmp_path / "norcia.txt"
    renamed.write_text(ESM.read_text())
    result = invoke("check", BLOCK, "--record", renamed)
    assert_one_line_error(result, "norcia.txt: an ESM record", "name it norcia.ASC")


def test_a_vertical_component_shaking_horizontally_is_warned(tmp_path):
    path = _edited(tmp_path, "CHANNEL: HNE", "CHANNEL: HNZ", name="IT.NRC..HNZ.D.ACC.ASC")
    path.write_text(path.read_text().replace("COMPONENT: E", "COMPONENT: Z"))
    result = invoke("check", BLOCK, "--record", path)
    assert result.exit_code == 0, result.output
    assert "IT.NRC..HNZ.D.ACC.ASC is a vertical component" in words(result.output)


def test_a_records_folder_sweeps_its_esm_files(tmp_path):
    # before: the .ASC file of the folder was left out without a word (1 row, the CSV's)
    folder = tmp_path / "recs"
    folder.mkdir()
    (folder / "IT.NRC..HNE.D.20161030.064017.C.ACC.ASC").write_text(ESM.read_text())
    # the same samples in m/s², with their times
    _, acc, _ = load_esm(ESM)
    (folder / "same.csv").write_text(
        "time (s),acc (m/s2)\n" + "".join(f"{i * 0.005!r},{float(a)!r}\n" for i, a in enumerate(acc))
    )
    out = tmp_path / "s.csv"
    result = invoke(
        "sweep", BLOCK, "--records", folder, "--scale", 1, "--duration", 0.5, "--workers", 0, "--out", out,
        "--no-recording",
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    rows = {r["record"]: r for r in read_rows(out)}
    assert sorted(rows) == ["IT.NRC..HNE.D.20161030.064017.C.ACC.ASC", "same.csv"]
    esm, csv = rows["IT.NRC..HNE.D.20161030.064017.C.ACC.ASC"], rows["same.csv"]
    for column in ("state", "pga", "pgv", "arias", "energy_dissipated", "peak_drift"):
        assert repr(esm[column]) == repr(csv[column]), column  # the same record, read from either file


def test_a_records_folder_of_an_esm_download_takes_the_acceleration_files(tmp_path):
    # an ESM zip holds each component's ACC, VEL and DIS files (and spectra): read all, a folder stopped at the
    # DIS file, or ran the VEL file beside its ACC as a second record of the same shaking
    folder = tmp_path / "recs"
    folder.mkdir()
    stem = "IT.NRC..HNE.D.20161030.064017.C"
    (folder / f"{stem}.ACC.ASC").write_text(ESM.read_text())
    velocity = (
        ESM.read_text()
        .replace("UNITS: cm/s^2", "UNITS: cm/s")
        .replace("DATA_TYPE: ACCELERATION", "DATA_TYPE: VELOCITY")
    )
    (folder / f"{stem}.VEL.ASC").write_text(velocity)
    (folder / f"{stem}.DIS.ASC").write_text(
        velocity.replace("UNITS: cm/s", "UNITS: cm").replace("VELOCITY", "DISPLACEMENT")
    )
    spectrum = ESM.read_text().replace("DATA_TYPE: ACCELERATION", "DATA_TYPE: ACCELERATION RESPONSE SPECTRUM")
    (folder / f"{stem}.SA.ASC").write_text(spectrum)
    out = tmp_path / "s.csv"
    args = ["sweep", BLOCK, "--records", folder, "--scale", 1, "--duration", 0.2, "--workers", 0, "--out", out]
    result = invoke(*args, "--no-recording")
    assert result.exit_code == 0, result.output
    assert [r["record"] for r in read_rows(out)] == [f"{stem}.ACC.ASC"]
    said = words(result.output)
    assert (
        f"--records {folder}: 3 ESM files of another series than acceleration left out ({stem}.DIS.ASC, "
        f"{stem}.SA.ASC, {stem}.VEL.ASC): a set folder takes each component's acceleration" in said
    )
    assert "not read as records" not in said  # named once, by the line that says why
    # a folder of the other series alone says why none is read ("no .ASC record in it" before)
    (folder / f"{stem}.ACC.ASC").unlink()
    assert_one_line_error(
        invoke(*args, "--no-recording", "--force"),
        f"--records {folder}: no .AT2, .ASC, K-NET or .csv record in it; 3 ESM files of another series",
    )
    # given by name, the velocity file runs (as velocity, m/s)
    result = invoke("check", BLOCK, "--record", folder / f"{stem}.VEL.ASC")
    assert result.exit_code == 0 and "record of velocity" in words(result.output), result.output


@pytest.mark.parametrize("record, unit, peak", [(ESM, "cm/s^2", "0.01"), (DATA / "knet.NS", "gal", "0.00499")])
def test_a_scale_of_0_01_converting_cm_again_is_warned(record, unit, peak):
    # the file is converted from cm/s² (gal) on reading: a scale of 0.01, meant as that conversion, ran the
    # record 100 times too weak, "intact", without a word
    result = invoke("check", BLOCK, "--record", record, "--scale", 0.01)
    assert result.exit_code == 0, result.output
    said = words(result.output)
    assert (
        f"the record {record.name} is read in its header's unit ({unit}) and converted to m/s² already; scale 0.01 "
        f"converts it again ({peak} m/s² as applied, 100 times too weak" in said
    )
    assert "converts it again" not in words(invoke("check", BLOCK, "--record", record, "--scale", 0.5).output)


def test_the_scale_of_0_01_warning_names_a_velocity_files_own_unit(tmp_path):
    # an ESM VEL file is in cm/s: the warning said "(cm/s², gal) and converted to m/s²" of it, and gave its
    # peak as an acceleration; the samples are 100 sin(2π·2·t) cm/s, 1 m/s at their peak, 0.01 m/s scaled
    velocity = tmp_path / "IT.NRC..HNE.D.20161030.064017.C.VEL.ASC"
    velocity.write_text(
        ESM.read_text()
        .replace("UNITS: cm/s^2", "UNITS: cm/s")
        .replace("DATA_TYPE: ACCELERATION", "DATA_TYPE: VELOCITY")
    )
    result = invoke("check", BLOCK, "--record", velocity, "--scale", 0.01)
    assert result.exit_code == 0, result.output
    said = words(result.output)
    assert (
        f"the record {velocity.name} is read in its header's unit (cm/s) and converted to m/s already; scale 0.01 "
        "converts it again (0.01 m/s as applied, 100 times too weak" in said
    ), said
    assert "cm/s²" not in said and "gal" not in said
    # an ESM file in m/s² is not converted from centimetres: a scale of 0.01 converts nothing twice
    metres = tmp_path / "m.ASC"
    metres.write_text(ESM.read_text().replace("UNITS: cm/s^2", "UNITS: m/s^2"))
    result = invoke("check", BLOCK, "--record", metres, "--scale", 0.01)
    assert result.exit_code == 0 and "converts it again" not in words(result.output), result.output


def test_a_plain_table_named_asc_is_read_as_a_csv(tmp_path):
    # .asc is a common name for a table of samples: read as a CSV before the ESM reader, then refused ('not an
    # ESM record: its header has no SAMPLING_INTERVAL_S line'), its one-column form refusing --record-dt
    _, acc, _ = load_esm(ESM)
    two = tmp_path / "table.asc"
    two.write_text("".join(f"{i * 0.005!r} {float(a)!r}\n" for i, a in enumerate(acc)))
    m = record_motion(two, quantity="acceleration", baseline="none")
    np.testing.assert_array_equal(m.time, np.arange(200) * 0.005)
    np.testing.assert_array_equal(m.value, acc)
    one = tmp_path / "column.asc"
    one.write_text("".join(f"{float(a)!r}\n" for a in acc))
    result = invoke("check", BLOCK, "--record", one, "--record-dt", 0.005)
    assert result.exit_code == 0 and "record of velocity (column.asc, 200 samples" in words(result.output)
    # an ESM file saved again with a byte-order mark is still one
    bom = tmp_path / "bom.ASC"
    bom.write_text("\ufeff" + ESM.read_text(), encoding="utf-8")
    assert record_motion(bom).quantity == "acceleration"
    # in cm/s², converted by a scale of 0.01 as a CSV's: not an ESM file's "converts it again"
    result = invoke("check", BLOCK, "--record", two, "--scale", 0.01)
    assert result.exit_code == 0 and "converts it again" not in words(result.output), result.output


# the spellings the ESM reader's own table held, with their factors from the units' definitions
ESM_SPELLINGS = {
    **dict.fromkeys(("cm/s^2", "cm/s2", "cm/s/s", "cm/s²", "cm/sec^2", "gal"), ("acceleration", 0.01)),
    **dict.fromkeys(("m/s^2", "m/s2", "m/s/s", "m/s²"), ("acceleration", 1.0)),
    **dict.fromkeys(("mm/s^2", "mm/s2"), ("acceleration", 0.001)),
    "g": ("acceleration", 9.80665),
    **dict.fromkeys(("cm/s", "cm/sec"), ("velocity", 0.01)),
    "m/s": ("velocity", 1.0),
    "mm/s": ("velocity", 0.001),
}


@pytest.mark.parametrize("unit", sorted(ESM_SPELLINGS))
def test_an_esm_file_reads_every_unit_it_read_before(tmp_path, unit):
    # the reader's unit table was a copy of records/units.py's; it reads through that one now, unchanged
    quantity, factor = ESM_SPELLINGS[unit]
    path = _edited(tmp_path, "UNITS: cm/s^2", f"UNITS: {unit.upper() if unit != 'g' else unit}")
    path.write_text(path.read_text().replace("DATA_TYPE: ACCELERATION", f"DATA_TYPE: {quantity.upper()}"))
    dt, values, read_as = load_esm(path)
    raw = np.loadtxt(ESM, skiprows=FIRST_SAMPLE_LINE - 1)  # the file's numbers as written
    assert read_as == quantity and np.array_equal(values, raw * factor)


@pytest.mark.parametrize("unit", ["cm s-2", "cm/s**2", "in/s2", "ft/s2", "in/s", "gal", "g", "mm/s"])
def test_an_esm_header_and_a_csv_header_read_a_unit_alike(tmp_path, unit):
    # one table: an ESM file named "cm s-2" or "in/s2" was refused ("not a unit masonry reads") where a CSV
    # header giving the same unit was read in it
    from masonrycli.records.units import header_factor

    quantity = "velocity" if unit in ("in/s", "mm/s") else "acceleration"
    csv_file = tmp_path / "q.csv"
    csv_file.write_text(f"time (s),{'vel' if quantity == 'velocity' else 'acc'} ({unit})\n0,0\n0.01,1\n")
    path = _edited(tmp_path, "UNITS: cm/s^2", f"UNITS: {unit}")
    path.write_text(path.read_text().replace("DATA_TYPE: ACCELERATION", f"DATA_TYPE: {quantity.upper()}"))
    _, values, read_as = load_esm(path)
    factor = header_factor(csv_file, quantity)[1]
    raw = np.loadtxt(ESM, skiprows=FIRST_SAMPLE_LINE - 1)
    assert read_as == quantity and np.array_equal(values, raw * factor)
