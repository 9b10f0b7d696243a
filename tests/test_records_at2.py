"""PEER NGA .AT2 records: the reader's formats and units, errors naming file and line, the vertical component and
its window, and .AT2 files in scenario files (tests/test_records_read.py holds the CSV formats and one-column files)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_records_read import SCENARIO, one_line

from masonrycli.errors import InputError, RecordWarning
from masonrycli.records.read import G_STANDARD, load_at2, record_fields, record_motion

from synthetic_records import band_limited, closed_form, write_at2

DATA = Path(__file__).parent / "data"


FREQS, AMPS = [0.7, 1.3, 2.1, 2.9], [0.02, 0.015, 0.01, 0.006]  # band 0.7–2.9 Hz, displacement amplitudes m


@pytest.mark.parametrize("offset_g", [0.0, 0.002])
def test_at2_round_trip_velocity_and_baseline(tmp_path, offset_g):
    # a synthetic accelerogram with a known integral, written in PEER's format (7 significant digits);
    # offset_g adds a constant baseline error, which integrates to a linear velocity drift
    duration, dt = 10.0, 0.01
    t, u, v, a = band_limited(duration, dt, FREQS, AMPS)
    write_at2(tmp_path / "syn.AT2", a / G_STANDARD + offset_g, dt)
    m = record_motion(tmp_path / "syn.AT2")
    assert m.quantity == "acceleration" and m.baseline == "quadratic" and m.time[0] == 0.0
    fine = np.linspace(0.0, duration + 1.0, 110_001)
    v_true = closed_form(np.clip(fine, 0, duration), duration, FREQS, AMPS, _phases())[1]
    got = m.velocity_at(fine)
    assert np.abs(got[:, 0] - v_true).max() < 0.01 * np.abs(v_true).max()
    assert np.all(got[:, 1] == 0.0)
    # the ground ends where it started (independent quadrature of the imposed velocity) and at rest
    assert abs(np.trapezoid(got[:, 0], fine)) < 1e-3
    assert abs(got[-1, 0]) < 1e-9
    # without the correction the baseline error leaves the ground far away
    raw = record_motion(tmp_path / "syn.AT2", baseline="none").velocity_at(fine)[:, 0]
    if offset_g:
        assert abs(np.trapezoid(raw, fine)) > 0.5 * offset_g * G_STANDARD * duration**2 / 2
    corr = m.baseline_correction
    assert corr["baseline"] == "quadratic" and corr["length"] == pytest.approx(duration)
    assert corr["c1"][0] == pytest.approx(offset_g * G_STANDARD * duration, rel=1e-3, abs=1e-6)


def _phases():
    return np.random.default_rng(0).uniform(0.0, 2.0 * np.pi, len(FREQS))


def test_at2_reader_formats_and_units(tmp_path):
    write_at2(tmp_path / "a.at2", [0.1, -0.2, 0.3, 0.0, 0.5, 0.25, 9.0], 0.005)
    # an older NGA header: "NPTS, DT" after the numbers; more values than NPTS are ignored, with a warning
    (tmp_path / "b.AT2").write_text("title\nstation\nunits of g\n   3   0.0200   NPTS, DT\n 0.1 0.2\n 0.3 0.4\n")
    # NGA's older header, "UNITS OF G." followed by the filter corners, is g
    (tmp_path / "c.AT2").write_text(
        "PEER\nIMPERIAL VALLEY\nACCELERATION TIME HISTORY IN UNITS OF G. FILTER POINTS: HP=0.1 Hz\n"
        "   2   0.0100   NPTS, DT\n 0.1 0.2\n"
    )
    assert load_at2(tmp_path / "c.AT2")[1].tolist() == [0.1, 0.2]
    dt, acc = load_at2(tmp_path / "a.at2")
    assert dt == 0.005 and acc.tolist() == [0.1, -0.2, 0.3, 0.0, 0.5, 0.25, 9.0]
    with pytest.warns(RecordWarning, match=r"b.AT2: header says NPTS = 3 but the file holds 4 samples; the 1 after"):
        dt, acc = load_at2(tmp_path / "b.AT2")
    assert dt == 0.02 and acc.tolist() == [0.1, 0.2, 0.3]
    with pytest.warns(RecordWarning):
        m = record_motion(tmp_path / "b.AT2", scale=0.5, baseline="none")
    assert m.time.tolist() == [0.0, 0.02, 0.04]
    np.testing.assert_allclose(m.value, [0.1 * G_STANDARD, 0.2 * G_STANDARD, 0.3 * G_STANDARD], rtol=1e-15)
    # velocity at the 2nd sample: scale · trapezoid = 0.5 · 0.02 · (0.1 + 0.2) g / 2
    assert m.velocity_at([0.02])[0, 0] == pytest.approx(0.5 * 0.02 * 0.15 * G_STANDARD, rel=1e-12)


@pytest.mark.parametrize(
    "text, expected",
    [
        ("a\nb\nc\nNPTS=3\n0.1 0.2 0.3\n", "bad.AT2:4: expected NPTS and DT"),
        ("a\nb\nc\nNPTS= 3, DT= 0.01 SEC\n0.1 x 0.3\n", 'bad.AT2:5: not a number: "x"'),
        ("a\nb\nc\nNPTS= 4, DT= 0.01 SEC\n0.1 0.2 0.3\n", "bad.AT2: header says NPTS = 4 but the file holds 3"),
        ("a\nb\nc\nNPTS= 3, DT= 0 SEC\n0.1 0.2 0.3\n", "bad.AT2:4: DT must be > 0"),
        # an absurd DT was read as given: DT = 10 made 3 samples a record of 20 s, with no word on its time step
        ("a\nb\nc\nNPTS= 3, DT= 10 SEC\n0.1 0.2 0.3\n", "bad.AT2:4: DT = 10: must be within 1e-06–1 s, likely a typo"),
        (
            "a\nb\nc\nNPTS= 3, DT= 0.2 SEC\n0.1 0.2 0.3\n",
            "bad.AT2:4: DT = 0.2: an acceleration record sampled every 0.2 s holds nothing above 2.5 Hz, where "
            "earthquakes shake and walls rock (accelerographs sample every 5–20 ms): at most 0.1 s, so a typo or a "
            "damaged header",
        ),
        ("a\nb\n", "bad.AT2: not a PEER .AT2 file"),
        # the header's own word on units and quantity (samples would be read as g: 100-1000x off)
        (
            "PEER\nx\nACCELERATION TIME SERIES IN UNITS OF CM/S/S\nNPTS= 3, DT= 0.01 SEC\n0.1 0.2 0.3\n",
            "bad.AT2:3: the header says units of CM/S/S; an .AT2 record holds acceleration in g",
        ),
        (
            "PEER\nx\nVELOCITY TIME SERIES IN UNITS OF CM/S\nNPTS= 3, DT= 0.01 SEC\n0.1 0.2 0.3\n",
            'bad.AT2:3: the header says velocity ("VELOCITY TIME SERIES IN UNITS OF CM/S")',
        ),
        (
            "PEER\nx\nDISPLACEMENT TIME SERIES IN UNITS OF CM\nNPTS= 3, DT= 0.01 SEC\n0.1 0.2 0.3\n",
            "bad.AT2:3: the header says displacement",
        ),
        ("PEER\nx\nUNITS OF GAL\nNPTS= 3, DT= 0.01 SEC\n0.1 0.2 0.3\n", "bad.AT2:3: the header says units of GAL"),
        # cm/s² samples under a header that names no unit (or says g): 294 "g"
        ("a\nb\nc\nNPTS= 3, DT= 0.01 SEC\n0.1 0.2\n-294.2\n", "bad.AT2:6: sample -294.2 g is beyond 10 g"),
    ],
)
def test_at2_errors_name_file_and_line(tmp_path, text, expected):
    (tmp_path / "bad.AT2").write_text(text)
    with pytest.raises(InputError) as exc:
        load_at2(tmp_path / "bad.AT2", display="bad.AT2")
    assert expected in one_line(exc)


def test_an_at2_sampled_at_0_1_s_or_finer_is_read(tmp_path):
    # the bound is above the coarsest accelerogram (old digitised films: 0.04 s), not a real record's DT
    for dt in (0.1, 0.04, 0.005):
        write_at2(tmp_path / "ok.AT2", [0.0, 0.1, 0.0], dt)
        assert load_at2(tmp_path / "ok.AT2")[0] == dt


def test_vertical_component_and_window(tmp_path):
    write_at2(tmp_path / "h.AT2", [0.0, 0.1, 0.2, 0.3, 0.4, 0.5], 0.01)
    write_at2(tmp_path / "v.AT2", [0.0, -0.1, -0.2, -0.3, -0.4], 0.01)
    m = record_motion(tmp_path / "h.AT2", vertical=tmp_path / "v.AT2", window=(0.02, 0.035), baseline="none")
    assert m.is_vector and len(m.time) == 5  # the shorter component sets the length
    # window: samples 0.02 and 0.03 only, moved to t = 0: a = (0.2, -0.2) g then (0.3, -0.3) g
    v = m.velocity_at([0.0, 0.01, 1.0])
    expected = 0.01 * 0.25 * G_STANDARD
    np.testing.assert_allclose(v[1], [expected, -expected], rtol=1e-12)
    np.testing.assert_allclose(v[2], v[1], rtol=0)  # after the window the acceleration is zero
    assert "vertical v.AT2" in m.describe() and "window 0.02–0.035 s" in m.describe()
    write_at2(tmp_path / "v2.AT2", [0.0, 0.1], 0.02)
    with pytest.raises(InputError, match="not sampled like"):
        record_motion(tmp_path / "h.AT2", vertical=tmp_path / "v2.AT2")
    with pytest.raises(InputError, match="an .AT2 file holds acceleration, not velocity"):
        record_motion(tmp_path / "h.AT2", quantity="velocity")


def test_a_scenario_record_file_under_the_home_folder(tmp_path, monkeypatch):
    # file = "~/records/q.AT2" was looked for as <scenario folder>/~/records/q.AT2, "no such file"
    from masonrycli.scenario.toml_file import loads_scenario

    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    (tmp_path / "home" / "records").mkdir(parents=True)
    write_at2(tmp_path / "home" / "records" / "q.AT2", [0.0, 0.1, 0.0], 0.01)
    motion = '{ kind = "record", file = "~/records/q.AT2" }'
    s = loads_scenario(SCENARIO.replace("MOTION", motion), base_dir=tmp_path / "elsewhere")
    assert s.motions[0].source == str(tmp_path / "home" / "records" / "q.AT2")


def test_scenario_record_with_at2_vertical_window_and_round_trip(tmp_path):
    from masonrycli.scenario.toml_file import dump_scenario, loads_scenario

    write_at2(tmp_path / "h.AT2", [0.0, 0.1, 0.2, 0.3, 0.4, 0.5], 0.01)
    write_at2(tmp_path / "v.AT2", [0.0, -0.1, -0.2, -0.3, -0.4, -0.5], 0.01)
    motion = '{ kind = "record", file = "h.AT2", vertical = "v.AT2", scale = 0.5, window = [0.01, 0.04] }'
    s = loads_scenario(SCENARIO.replace("MOTION", motion), base_dir=tmp_path)
    m = s.motions[0]
    assert m.quantity == "acceleration" and m.is_vector and m.window == (0.01, 0.04) and m.baseline == "quadratic"
    assert m.vertical_source == str(tmp_path / "v.AT2")
    again = loads_scenario(dump_scenario(s), base_dir="/")
    assert again.motions == s.motions
    inline = loads_scenario(dump_scenario(s, inline_records=True))
    np.testing.assert_array_equal(
        inline.motions[0].velocity_at(np.linspace(0, 0.1, 11)), m.velocity_at(np.linspace(0, 0.1, 11))
    )


@pytest.mark.parametrize(
    "motion, expected",
    [
        ('{ kind = "record", file = "h.AT2", quantity = "velocity" }', "motion.quantity: h.AT2 holds acceleration"),
        ('{ kind = "record", file = "h.AT2", vertical = "q.csv" }', "motion.vertical: must be in the same format"),
        ('{ kind = "record", time = [0, 1], value = [0, 1], vertical = "v.AT2" }', "motion.vertical: goes with file"),
        (
            '{ kind = "record", file = "h.AT2", vertical = "h.AT2", direction = [1.0, 0.0] }',
            "motion.direction: not used with a vertical component",
        ),
        ('{ kind = "record", file = "h.AT2", baseline = "yes" }', 'motion.baseline = "yes": must be "quadratic"'),
        ('{ kind = "record", file = "h.AT2", window = [5.0, 6.0] }', "motion.window = [5.0, 6.0]: holds 0 samples"),
    ],
)
def test_scenario_record_errors(tmp_path, motion, expected):
    from masonrycli.scenario.toml_file import loads_scenario

    write_at2(tmp_path / "h.AT2", [0.0, 0.1, 0.2], 0.01)
    (tmp_path / "q.csv").write_text("0,0\n1,1\n")
    with pytest.raises(InputError) as exc:
        loads_scenario(SCENARIO.replace("MOTION", motion), source="s.toml", base_dir=tmp_path)
    assert expected in one_line(exc)


def test_csv_header_units_reach_record_motion_and_scenario_files(tmp_path):
    f = tmp_path / "q.csv"
    f.write_text("time,v (cm/s)\n0,0\n0.1,5\n")
    # read in cm/s, converted to m/s, by --record and a scenario's record table alike; the scale of 0.01 that
    # converted it before (read in m/s) would convert it twice: refused
    assert record_motion(f, display="q.csv").velocity_at([0.1])[0, 0] == pytest.approx(0.05)
    assert record_motion(f, scale=2.0).velocity_at([0.1])[0, 0] == pytest.approx(0.1)
    with pytest.raises(InputError, match=r"^q.csv:1: the header gives velocity in cm/s .* scale 0.01 would convert"):
        record_motion(f, display="q.csv", scale=0.01)
    assert record_fields({"file": "q.csv"}, str(tmp_path))["value"].tolist() == [0.0, 0.05]
    with pytest.raises(InputError, match=r"^motion.file: q.csv:1: the header gives velocity in cm/s .* drop the sc"):
        record_fields({"file": "q.csv", "scale": 0.01}, str(tmp_path))
