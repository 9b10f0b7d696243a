"""Record files: CSV formats, error messages naming file and line, the Record motion they make."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from masonrycli.errors import InputError
from masonrycli.records.read import load_at2, load_record_csv, record_motion

from synthetic_records import band_limited, write_at2

DATA = Path(__file__).parent / "data"


SCENARIO = """
[run]
duration = 0.05
[[block]]
polygon = [[-0.2, 0.0], [0.2, 0.0], [0.2, 0.2], [-0.2, 0.2]]
[[support]]
name = "ground"
polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]
motion = MOTION
"""
"""A scenario whose ground moves by MOTION (replaced by each test)."""


def one_line(exc_info) -> str:
    msg = str(exc_info.value)
    assert "\n" not in msg and msg.strip() == msg and msg
    return msg


def test_load_record_csv_formats(tmp_path):
    t, v = load_record_csv(DATA / "quake_velocity.csv")
    np.testing.assert_array_equal(t, [0.0, 0.1, 0.2, 0.3, 0.4])
    np.testing.assert_array_equal(v, [0.0, 0.2, -0.1, 0.05, 0.0])
    f = tmp_path / "semi.csv"
    f.write_text("\ufefftime;vx;vy\n\n# comment\n0;1;2\n  1 ;  3 ; 4  \n2\t5\t6\n")
    t, v = load_record_csv(f)
    np.testing.assert_array_equal(t, [0, 1, 2])
    np.testing.assert_array_equal(v, [[1, 2], [3, 4], [5, 6]])


def test_semicolon_csv_has_decimal_commas(tmp_path):
    # a European spreadsheet's CSV: "0;0,5" was split on the comma too and read as (time, x, y) = (0, 0, 5)
    f = tmp_path / "eu.csv"
    f.write_text("time;velocity\n0;0,0\n1;0,5\n2;1,0\n3,5;-0,25\n")
    t, v = load_record_csv(f)
    np.testing.assert_array_equal(t, [0.0, 1.0, 2.0, 3.5])
    np.testing.assert_array_equal(v, [0.0, 0.5, 1.0, -0.25])
    f.write_text("t;v\n0;1,234.5\n1;2\n")  # a thousands separator is not a decimal comma
    with pytest.raises(InputError, match=r'eu.csv:2: not a number: "1,234.5"'):
        load_record_csv(f, display="eu.csv")


def test_tab_separated_csv_has_decimal_commas(tmp_path):
    # Excel's "Text (Tab delimited)" in a European locale: "0\t0,5" was split on the comma too and read as a
    # (time, x, y) record (0, 0, 5): a vertical ground velocity of 5 m/s, without a word
    f = tmp_path / "eu.txt.csv"
    f.write_text("time\tvelocity\n0\t0,0\n1\t0,5\n2\t1,0\n3\t-0,25\n")
    t, v = load_record_csv(f)
    np.testing.assert_array_equal(t, [0.0, 1.0, 2.0, 3.0])
    np.testing.assert_array_equal(v, [0.0, 0.5, 1.0, -0.25])
    f.write_text("0.0\t1.5\n0.5\t2.5\n")  # points stay points
    np.testing.assert_array_equal(load_record_csv(f)[1], [1.5, 2.5])


def test_comma_separated_csv_aligned_with_tabs(tmp_path):
    # "0.01,<TAB>0.5": the comma separates (a CSV whose columns are aligned with tabs), as before the
    # tab-delimited rule: split on tabs alone it read '"0.01,": not a number'
    f = tmp_path / "aligned.csv"
    f.write_text("time,\tvel\n0.00,\t0.0\n0.01,\t0.5\n0.02 ,\t-0.25\n")
    t, v = load_record_csv(f)
    np.testing.assert_array_equal(t, [0.0, 0.01, 0.02])
    np.testing.assert_array_equal(v, [0.0, 0.5, -0.25])


def test_record_motion_source_is_absolute():
    m = record_motion(DATA / "quake_velocity.csv", scale=2.0)
    assert Path(m.source).is_absolute() and Path(m.source).name == "quake_velocity.csv"
    assert m.describe().startswith("record of velocity (quake_velocity.csv, 5 samples")
    assert m.velocity_at([0.1])[0, 0] == pytest.approx(0.4)


@pytest.mark.parametrize(
    "text, expected",
    [
        ("0,1\n0.1,abc\n", 'bad.csv:2: not a number: "abc"'),
        ("# c\n0,1,2,3\n", "bad.csv:2: expected 2 columns (time, value) or 3 (time, x, y), got 4"),
        ("0,1\n1,2,3\n", "bad.csv:2: expected 2 columns like the first sample, got 3"),
        ("0,1\n0.5,2\n0.5,3\n", "bad.csv:3: time 0.5 is not after the previous sample's 0.5"),
        ("0,1\n1,nan\n", "bad.csv:2: values must be finite"),
        ("time,value\n0,1\n", "bad.csv: a record needs at least 2 samples, found 1"),
        ("", "bad.csv: a record needs at least 2 samples, found 0"),
        ("t,v\nx,y\n0,1\n", 'bad.csv:2: not a number: "x"'),
    ],
)
def test_load_record_csv_errors_name_file_and_line(tmp_path, text, expected):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(InputError) as exc:
        load_record_csv(f, display="bad.csv")
    assert expected in one_line(exc)


def test_load_record_csv_unreadable(tmp_path):
    with pytest.raises(InputError) as exc:
        load_record_csv(tmp_path / "missing.csv")
    assert "missing.csv: cannot read record" in one_line(exc)
    with pytest.raises(InputError) as exc:
        load_record_csv(tmp_path)
    assert "is a directory" in one_line(exc)
    f = tmp_path / "latin1.csv"  # not UTF-8: read in the Windows code page, where the line shows what it holds
    f.write_bytes(b"0,1\n1,\xe9\n")
    with pytest.raises(InputError) as exc:
        load_record_csv(f)
    assert one_line(exc).endswith('latin1.csv:2: not a number: "é"')
    f.write_bytes(b"0,1\n1,\x00\xe9\n")  # a NUL byte: no text file
    with pytest.raises(InputError) as exc:
        load_record_csv(f)
    assert one_line(exc) == f"{f}: not a text file (it holds NUL bytes: a binary file)"


def test_a_spreadsheet_csv_in_the_windows_code_page_is_read(tmp_path):
    # Excel's "CSV (comma delimited)" and many accelerograms' headers are not UTF-8: "(m/s²)", "données" and
    # a station's "é" made the file "not a UTF-8 text file (byte 28)"; the samples are ASCII in any code page
    body = "".join(f"{0.01 * i:.2f};{0.1 * (i % 3):.1f}\n".replace(".", ",") for i in range(5))
    f = tmp_path / "excel.csv"
    f.write_bytes(("temps (s);vitesse (m/s) données\n" + body).encode("cp1252"))
    reference = tmp_path / "utf8.csv"
    reference.write_text("temps (s);vitesse (m/s) données\n" + body, encoding="utf-8")
    for got, want in zip(load_record_csv(f), load_record_csv(reference)):
        assert np.array_equal(got, want)
    # the header's units read in the code page: "m/s²" is an acceleration, refused when read as velocity
    f.write_bytes(("t (s);a (m/s²)\n" + body).encode("cp1252"))
    with pytest.raises(InputError, match=r"excel\.csv:1: the header says acceleration"):
        record_motion(f, quantity="velocity")
    assert record_motion(f, quantity="acceleration").quantity == "acceleration"
    at2 = tmp_path / "station.AT2"  # an .AT2 file naming its station in Latin-1
    at2.write_bytes(
        b"PEER NGA\nSt\xe9 Baume 1909, 0\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS= 3, DT= .01 SEC\n0 1 0\n"
    )
    assert load_at2(at2)[1].tolist() == [0.0, 1.0, 0.0]


def test_a_peer_record_named_txt_is_named_so(tmp_path):
    # a PEER record saved as .txt was read as a CSV: 'q.txt:2: not a number: "IMPERIAL"', nothing about why
    f = tmp_path / "RSN6.txt"
    f.write_text(
        "PEER NGA\nIMPERIAL VALLEY 1940, EL CENTRO, 180\nACCELERATION TIME SERIES IN UNITS OF G\n"
        "NPTS=  3, DT=   .0100 SEC\n 0.0 0.1 0.0\n"
    )
    with pytest.raises(InputError) as exc:
        load_record_csv(f)
    assert one_line(exc) == (
        f"{f}: a PEER .AT2 record (its line 4 gives NPTS and DT) read as a CSV: the file's suffix chooses the "
        "format, name it RSN6.AT2"
    )


@pytest.mark.parametrize(("suffix", "what"), [(".VT2", "velocity (.VT2, cm/s)"), (".dt2", "displacement (.DT2, cm)")])
def test_a_peer_velocity_or_displacement_file_names_the_at2(tmp_path, suffix, what):
    # A PEER .VT2 was read as a CSV: 'x.VT2:2: not a number: "Imperial Valley..."', nothing about the format.
    f = tmp_path / f"RSN6_IMPVALL.I_I-ELC180{suffix}"
    f.write_text(
        "PEER NGA STRONG MOTION DATABASE RECORD\nImperial Valley, 5/19/1940, El Centro Array #9, 180\n"
        "VELOCITY TIME SERIES IN UNITS OF CM/S\nNPTS=  3, DT=   .0100 SEC\n 0.1 0.2 0.3\n"
    )
    with pytest.raises(InputError) as exc:
        record_motion(f)
    assert one_line(exc) == (
        f"{f}: a PEER {what} record; give the same component's acceleration record (.AT2, in g), "
        "which masonry integrates, or a CSV of velocity"
    )


@pytest.mark.parametrize(
    ("name", "said"),
    [
        (
            "wall.geojson",
            "a geometry file (GeoJSON), not a ground-motion record (a PEER .AT2 file, an ESM .ASC file, a K-NET file or a CSV); masonry run runs it",
        ),
        (
            "quake.xlsx",
            "a spreadsheet (.xlsx), not a ground-motion record (a PEER .AT2 file, an ESM .ASC file, a K-NET file or a CSV); save the sheet as CSV",
        ),
        ("run.rrd", "a Rerun recording (.rrd), not a ground-motion record"),
        ("wall.toml", "a scenario file (TOML), not a ground-motion record"),
    ],
)
def test_another_kind_of_file_as_a_record_is_named(tmp_path, name, said):
    # A GeoJSON was read as a CSV: 'wall.geojson:2: not a number: "\"type\":"'; a workbook "not a UTF-8 text file".
    f = tmp_path / name
    f.write_text('{\n "type": "FeatureCollection"\n}\n')
    with pytest.raises(InputError) as exc:
        record_motion(f)
    assert one_line(exc).startswith(f"{f}: {said}")
    with pytest.raises(InputError, match="cannot read record: No such file"):  # a missing one: said so first
        record_motion(tmp_path / f"missing-{name}")


def test_a_utf16_record_is_named_as_such(tmp_path):
    # Excel's "Unicode Text" export is UTF-16 with a byte-order mark: "not a UTF-8 text file (byte 0)" left the
    # user to guess what byte 0 was.
    f = tmp_path / "excel.csv"
    f.write_bytes("time\tv\n0\t0\n0.1\t0.1\n".encode("utf-16"))
    with pytest.raises(InputError) as exc:
        load_record_csv(f)
    assert one_line(exc) == f"{f}: a UTF-16 text file (it starts with UTF-16's byte-order mark); save it as UTF-8"


def test_a_pipe_or_a_device_is_refused_without_reading_it(tmp_path):
    # "--record /dev/zero" read for ever (memory growing) and a named pipe blocked in open() waiting for a
    # writer: the command hung before its first line. The read runs in a thread so that the old hang fails
    # the test instead of stopping the suite.
    import os

    from cli_helpers import refusals_within

    pipe = tmp_path / "pipe.csv"
    os.mkfifo(pipe)
    for path in (pipe, Path("/dev/zero")):
        said = refusals_within(load_record_csv, path)
        assert said == [f"{path}: cannot read record: not a regular file (a device, a pipe or a socket)"]


# ------------------------------------------------------------------------------------ one value per line


def one_and_two_columns(folder: Path, values, dt: float, name: str = "a") -> tuple[Path, Path]:
    """A one-column file of ``values`` (with a header) and the 2-column file the user means by it: the
    same values at times i·dt, written out here (Python's own i * dt), not by the reader."""
    one, two = folder / f"{name}1.csv", folder / f"{name}2.csv"
    one.write_text("samples\n" + "".join(f"{v!r}\n" for v in values))
    two.write_text("time,samples\n" + "".join(f"{i * dt!r},{v!r}\n" for i, v in enumerate(values)))
    return one, two


def same_samples(a, b) -> None:
    for x, y in [(a.time, b.time), (a.value, b.value), *zip(a._arrays, b._arrays)]:
        assert x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes()


ONE_COLUMN_SETTINGS = [
    dict(quantity="acceleration"),
    dict(quantity="acceleration", scale=0.5, window=(0.3, 1.2), baseline="none", direction=(3.0, 4.0)),
    dict(quantity="velocity", scale=2.0, window=(0.05, 0.5)),
]


@pytest.mark.parametrize("settings", ONE_COLUMN_SETTINGS)
def test_a_one_column_file_is_its_two_column_file_with_times_i_dt(tmp_path, settings):
    t, u, v, a = band_limited(1.5, 0.005, [1.5, 3.0], [0.01, 0.004], seed=2)
    one, two = one_and_two_columns(tmp_path, a.tolist(), 0.005)
    got = record_motion(one, time_step=0.005, **settings)
    ref = record_motion(two, **settings)
    same_samples(got, ref)
    assert got.time_step == 0.005 and ref.time_step is None and got.quantity == settings["quantity"]
    probe = np.linspace(-0.1, 2.0, 777)
    assert got.velocity_at(probe).tobytes() == ref.velocity_at(probe).tobytes()
    assert got.baseline_correction == ref.baseline_correction
    # the same record but for where it came from and how its times were given
    assert got == dataclasses.replace(ref, source=str(one), time_step=0.005)


def test_one_column_files_with_a_vertical_component(tmp_path):
    rng = np.random.default_rng(5)
    h, v = rng.normal(size=50).tolist(), rng.normal(size=40).tolist()
    h1, h2 = one_and_two_columns(tmp_path, h, 0.01, "h")
    v1, v2 = one_and_two_columns(tmp_path, v, 0.01, "v")
    got = record_motion(h1, vertical=v1, time_step=0.01, quantity="acceleration", window=(0.05, 0.3))
    ref = record_motion(h2, vertical=v2, quantity="acceleration", window=(0.05, 0.3))
    same_samples(got, ref)
    assert got.is_vector and got.time.size == 40  # the shorter component sets the length


def test_a_one_column_file_in_a_scenario_reads_and_writes_back(tmp_path):
    from masonrycli.scenario.toml_file import dump_scenario, loads_scenario

    values = np.random.default_rng(6).normal(scale=0.1, size=300).tolist()
    one, two = one_and_two_columns(tmp_path, values, 0.01, "q")
    motion = '{ kind = "record", file = "FILE", TIME_STEP quantity = "acceleration", scale = 2.0, window = [0.5, 2.5] }'
    got = loads_scenario(
        SCENARIO.replace("MOTION", motion.replace("FILE", one.name).replace("TIME_STEP", "time_step = 0.01,")),
        base_dir=tmp_path,
    )
    ref = loads_scenario(
        SCENARIO.replace("MOTION", motion.replace("FILE", two.name).replace("TIME_STEP", "")), base_dir=tmp_path
    )
    same_samples(got.motions[0], ref.motions[0])
    assert got.motions[0] == record_motion(one, time_step=0.01, quantity="acceleration", scale=2.0, window=(0.5, 2.5))
    text = dump_scenario(got)
    assert "time_step = 0.01" in text
    assert loads_scenario(text, base_dir="/").motions == got.motions
    inline = loads_scenario(dump_scenario(got, inline_records=True)).motions[0]  # times written, no time_step
    assert inline.time_step is None
    same_samples(inline, ref.motions[0])


@pytest.mark.parametrize(
    "motion, expected",
    [
        (
            '{ kind = "record", file = "one.csv" }',
            # --record-dt goes with --record: of the scenario's own file, the table's key is the way
            "motion.file: one.csv:1: one value per line, no times: give the time between samples: time_step = "
            "SECONDS in the record table",
        ),
        (
            '{ kind = "record", file = "two.csv", time_step = 0.01 }',
            "motion.file: two.csv:1: 2 columns, but a time step was given: it is for a file of one value per line "
            "(this one has a time column: leave out time_step)",
        ),
        (
            '{ kind = "record", file = "three.csv", time_step = 0.01 }',
            "motion.file: three.csv:2: 3 columns, but a time step was given",
        ),
        (
            '{ kind = "record", file = "h.AT2", time_step = 0.01 }',
            "motion.file: h.AT2: an .AT2 file gives its own time step (DT in its header): time_step goes with a "
            "CSV of one value per line",
        ),
        (
            '{ kind = "record", time = [0.0, 1.0], value = [1.0, 2.0], time_step = 1.0 }',
            "motion.time_step: goes with file, a CSV of one value per line (inline samples give time)",
        ),
        ('{ kind = "record", file = "one.csv", time_step = 0.0 }', "motion.time_step = 0.0: must be > 0"),
        ('{ kind = "record", file = "one.csv", time_step = -0.01 }', "motion.time_step = -0.01: must be > 0"),
        ('{ kind = "record", file = "one.csv", time_step = nan }', "motion.time_step = nan: must be a finite number"),
        ('{ kind = "record", file = "one.csv", time_step = inf }', "motion.time_step = inf: must be a finite number"),
        ('{ kind = "record", file = "one.csv", time_step = "0.01" }', 'motion.time_step = "0.01": must be a number'),
        ('{ kind = "record", file = "one.csv", time_step = true }', "motion.time_step = true: must be a number"),
        (
            '{ kind = "record", file = "one.csv", time_step = 10 }',
            "motion.time_step = 10: must be within 1e-06–1 s, likely a typo (accelerographs sample every 1–20 ms; "
            "10 for 10 ms would stretch the record 1000-fold)",
        ),
        ('{ kind = "record", file = "one.csv", time_step = 1e-9 }', "motion.time_step = 1e-09: must be within"),
        # acceleration one a line 0.5 s apart (the header says acc): as an .AT2 of DT = 0.5, refused
        (
            '{ kind = "record", file = "acc.csv", time_step = 0.5 }',
            "motion.file: acc.csv: acceleration samples 0.5 s apart (the time step given) hold nothing above 1 Hz, "
            "where earthquakes shake and walls rock (accelerographs sample every 5–20 ms): an acceleration record's "
            "time step is at most 0.1 s",
        ),
    ],
)
def test_one_column_errors_in_a_scenario(tmp_path, motion, expected):
    from masonrycli.scenario.toml_file import loads_scenario

    write_at2(tmp_path / "h.AT2", [0.0, 0.1, 0.2], 0.01)
    (tmp_path / "one.csv").write_text("0.1\n0.2\n0.3\n")
    (tmp_path / "two.csv").write_text("0,0.1\n0.01,0.2\n")
    (tmp_path / "three.csv").write_text("t,x,y\n0,0.1,0.2\n")
    (tmp_path / "acc.csv").write_text("acc (g)\n0\n0.1\n0\n")
    with pytest.raises(InputError) as exc:
        loads_scenario(SCENARIO.replace("MOTION", motion), source="s.toml", base_dir=tmp_path)
    message = one_line(exc)
    # the line of the motion (SCENARIO's 9th: its motion = { … } inline table, tests/test_scenario_toml_lines.py)
    assert message.startswith('s.toml:9: [[support]] #1 ("ground"): ' + expected), message


def test_a_binary_file_under_a_text_suffix_is_not_named_by_its_suffix(tmp_path):
    """A binary file named bin.toml was "a scenario file (TOML)" for --record and inspect (check and run said
    "not a text file"): its bytes are looked at before its suffix names it."""
    from masonrycli.recording.readback import recording_path_problem

    binary = tmp_path / "bin.toml"
    binary.write_bytes(b"ab\x00cd\x01\x02")
    with pytest.raises(InputError, match=r"bin\.toml: not a text file \(it holds NUL bytes: a binary file\), not a"):
        record_motion(binary)
    assert "not a text file (it holds NUL bytes" in recording_path_problem(binary)
    text = tmp_path / "s.toml"
    text.write_text('name = "s"\n')
    with pytest.raises(InputError, match=r"s\.toml: a scenario file \(TOML\), not a ground-motion record"):
        record_motion(text)


def test_one_column_acceleration_takes_a_time_step_up_to_0_1_s_and_velocity_up_to_1_s(tmp_path):
    # the bound of an accelerogram's header (motion.MAX_ACCELEROGRAM_STEP) holds for acceleration given one value a
    # line; a velocity so given keeps the one-column bound, 1 s (a shake table's smooth input)
    from masonrycli.records.read import record_motion

    (tmp_path / "acc.csv").write_text("acc (g)\n0\n0.1\n0\n")
    (tmp_path / "vel.csv").write_text("0\n0.1\n0\n")
    assert record_motion(tmp_path / "acc.csv", time_step=0.1).time[-1] == pytest.approx(0.2)
    with pytest.raises(InputError, match=r"acc.csv: acceleration samples 0.2 s apart \(the time step given\)"):
        record_motion(tmp_path / "acc.csv", time_step=0.2, display="acc.csv")
    assert record_motion(tmp_path / "vel.csv", time_step=0.5).quantity == "velocity"
