"""masonry export --times LAB.csv: a history's columns at a lab's sample times, beside the lab's columns, and
--compare's measures of agreement. The resampling against linear interpolation written from its definition
(a loop over the samples, not np.interp) on a synthetic history; the measures against closed forms; a real
run (an accelerogram in g at 200 Hz, as a shake table's CSV) resampled at its own frame times giving back the
plain export bit for bit; bad lab files as one line, exit 2, nothing written."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from test_outputs_export import TIMES, floats, hand_history, read_csv

from masonrycli.outputs.agreement import agreement, column_unit
from masonrycli.outputs.export import export_table

from cli_helpers import assert_one_line_error, invoke

RNG = np.random.default_rng(7)


def random_history(path):
    """The hand-built history with random block positions and velocities (a motion no straight line fits) and
    a hinge count that changes between frames."""
    q = np.zeros((len(TIMES), 3, 3))
    q[:, :, 0] = RNG.normal(size=(len(TIMES), 3))
    q[:, :, 1] = [0.1, 0.1, 0.3] + 0.01 * RNG.normal(size=(len(TIMES), 3))
    q[:, :, 2] = 0.1 * RNG.normal(size=(len(TIMES), 3))
    v = RNG.normal(size=(len(TIMES), 3, 3))
    return hand_history(path, block_q=q, block_v=v, hinge_count=np.array([0, 3, 1, 4, 2]))


def by_definition(time, values, at):
    """Linear interpolation, sample by sample: the frames j, j+1 around t, value_j + (value_{j+1} − value_j) ×
    (t − t_j) / (t_{j+1} − t_j); on a frame, its value."""
    out = []
    for t in at:
        j = max(i for i in range(len(time)) if time[i] <= t)
        if time[j] == t:
            out.append(values[j])
        else:
            out.append(values[j] + (values[j + 1] - values[j]) * (t - time[j]) / (time[j + 1] - time[j]))
    return np.array(out)


def write_lab(path, times, extra="LVDT top (mm)", header="time (s)", sep=","):
    lines = [f"{header}{sep}{extra}{sep}comment"] + [f"{t!r}{sep}{i * 0.5}{sep}row {i}" for i, t in enumerate(times)]
    path.write_text("\n".join(lines) + "\n")
    return path


# lab times: the first frame, between frames (uneven: 0.035 is a short last interval), on a frame, the last frame
LAB_TIMES = [0.0, 0.0037, 0.01, 0.0149, 0.02, 0.0312, 0.0333, 0.035]


def test_every_column_is_linearly_interpolated_at_the_lab_times(tmp_path):
    h = random_history(tmp_path / "h.npz")
    lab = write_lab(tmp_path / "lab.csv", LAB_TIMES)
    result = invoke("export", h, "--times", lab, "--blocks", "a,c", "--top", "--out", tmp_path / "s.csv")
    assert result.exit_code == 0, result.output
    cols = read_csv(tmp_path / "s.csv")
    plain = export_table(h, blocks=["a", "c"], top=True)
    # the lab's columns first, as written, then masonry's without its own time
    assert list(cols)[:3] == ["time (s)", "LVDT top (mm)", "comment"] and cols["comment"][3] == "row 3"
    assert cols["time (s)"] == [repr(t) for t in LAB_TIMES]
    assert list(cols)[3:] == plain.names[1:]
    at = np.array(LAB_TIMES)
    for name, value in zip(plain.names[1:], plain.values[1:]):
        got = floats(cols[name])
        if name == "hinges (-)":  # a count: the frame at or before the sample
            held = [value[max(i for i in range(len(TIMES)) if TIMES[i] <= t)] for t in at]
            assert cols[name] == [str(k) for k in held], name
            continue
        assert np.allclose(got, by_definition(TIMES, value, at), rtol=1e-13, atol=1e-15, equal_nan=True), name
    # and from the raw arrays: block a's x relative to the ground, interpolated
    raw = np.load(h)
    ux = raw["block_q"][:, 0, 0] - raw["block_q"][0, 0, 0] - (raw["support_q"][:, 0, 0] - raw["support_q"][0, 0, 0])
    assert np.allclose(floats(cols["a ux rel (m)"]), by_definition(TIMES, ux, at), rtol=1e-13, atol=1e-15)
    # step 0 has no base shear: empty up to the next frame, a number from it on
    assert cols["base shear (N)"][:3] == ["", "", cols["base shear (N)"][2]] and cols["base shear (N)"][2]


def test_lab_files_as_spreadsheets_write_them(tmp_path):
    h = random_history(tmp_path / "h.npz")
    plain = dict(zip(*(lambda t: (t.names, t.values))(export_table(h))))
    at = np.array([0.0, 0.012, 0.03])
    expected = by_definition(TIMES, plain["top ux rel (m)"], at)
    # times in ms, a semicolon CSV with decimal commas, a '#' comment, a time column named by --time-column
    cases = [
        ("ms.csv", "t (ms),x (mm)\n0,1\n12,2\n30,3\n", ()),
        ("eu.csv", "# test 12\nTime [s];x (mm)\n0;1\n0,012;2\n0,03;3\n", ()),
        ("named.csv", "Zeit,x (mm)\n0,1\n0.012,2\n0.03,3\n", ("--time-column", "Zeit")),
        ("tab.csv", "time_s\tx (mm)\n0\t1\n0.012\t2\n0.03\t3\n", ()),
        # Excel's "Text (tab-delimited)" in a decimal-comma locale: "time 0,012 is not a number"
        ("eutab.csv", "time (s)\tx (mm)\n0\t1\n0,012\t2\n0,03\t3\n", ()),
    ]
    for name, text, extra in cases:
        (tmp_path / name).write_text(text)
        out = tmp_path / f"out-{name}"
        result = invoke("export", h, "--times", tmp_path / name, "--out", out, *extra)
        assert result.exit_code == 0, (name, result.output)
        cols = read_csv(out)
        assert np.allclose(floats(cols["top ux rel (m)"]), expected, rtol=1e-13), name
        assert cols["x (mm)"] == ["1", "2", "3"], name


def test_bad_lab_files_are_one_line_and_write_nothing(tmp_path):
    h = random_history(tmp_path / "h.npz")
    files = {
        "notime.csv": ("a (s),b (mm)\n0,1\n", "notime.csv:1: no time column"),
        "back.csv": (
            "time (s),x\n0,1\n0.02,2\n0.01,3\n",
            "back.csv:4: time 0.01 is not after the previous sample's 0.02",
        ),
        "same.csv": ("time (s),x\n0,1\n0.01,2\n0.01,3\n", "same.csv:4: time 0.01 is not after"),
        "word.csv": ("time (s),x\n0,1\nabc,2\n", "word.csv:3: time abc is not a number"),
        "nan.csv": ("time (s),x\n0,1\nnan,2\n", "nan.csv:3: time nan is not a finite number"),
        "blank.csv": ("time (s),x\n0,1\n,2\n", "blank.csv:3: an empty time cell"),
        "wide.csv": ("time (s),x\n0,1,2\n", "wide.csv:2: 3 cells, the header names 2 columns"),
        "noheader.csv": ("0,1\n0.01,2\n", "noheader.csv:1: no header row"),
        "empty.csv": ("", "empty.csv: an empty file"),
        "headonly.csv": ("time (s),x\n", "headonly.csv: a header and no sample"),
        "minutes.csv": ("time (min),x\n0,1\n", "its unit min is not s or ms"),
        "two.csv": ("time (s),t (ms)\n0,0\n", "2 time columns (time (s), t (ms)): name one with --time-column"),
        "late.csv": (
            "time (s),x\n0.01,1\n0.03,1\n0.04,1\n0.05,1\n",
            "late.csv:4: time 0.04 is after the run's last frame",
        ),
        "early.csv": ("time (s),x\n-0.01,1\n0.03,1\n", "early.csv:2: time -0.01 is before the run's first frame"),
    }
    for name, (text, fragment) in files.items():
        (tmp_path / name).write_text(text)
        assert_one_line_error(invoke("export", h, "--times", tmp_path / name), fragment)
    assert_one_line_error(invoke("export", h, "--times", tmp_path / "late.csv"), "(2 samples outside it")
    (tmp_path / "book.xlsx").write_bytes(b"PK\x03\x04" + bytes(100))
    assert_one_line_error(invoke("export", h, "--times", tmp_path / "book.xlsx"), "book.xlsx: a zip file (an Excel")
    assert_one_line_error(invoke("export", h, "--times", h), "h.npz: an .npz archive (a history?), not a CSV")
    # Excel's "Unicode Text" is UTF-16: it was called "not a text file"; now named, with the fix, as a record is
    (tmp_path / "u16.csv").write_bytes("time (s)\tx\n0\t1\n".encode("utf-16"))
    assert_one_line_error(invoke("export", h, "--times", tmp_path / "u16.csv"), "u16.csv: a UTF-16 text file", "UTF-8")
    (tmp_path / "bin.csv").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00")
    assert_one_line_error(invoke("export", h, "--times", tmp_path / "bin.csv"), "bin.csv: not a text file")
    assert_one_line_error(invoke("export", h, "--times", tmp_path / "none.csv"), "none.csv: cannot read: No such file")
    assert_one_line_error(invoke("export", h, "--times", tmp_path), "is a folder, not a CSV")
    lab = write_lab(tmp_path / "lab.csv", LAB_TIMES)
    assert_one_line_error(invoke("export", h, "--times", lab, "--time-column", "x"), "--time-column x: no such column")
    assert_one_line_error(invoke("export", h, "--times", lab, "--every", 2), "--every 2 and --times")
    assert_one_line_error(invoke("export", h, "--compare", "x (mm)"), "--compare: a column of the --times file")
    assert_one_line_error(invoke("export", h, "--times", lab, "--compare", "y (mm)"), "no column 'y (mm)' among")
    assert_one_line_error(invoke("export", h, "--times", lab, "--compare", "comment"), "'comment' names no unit")
    assert_one_line_error(
        invoke("export", h, "--times", lab, "--compare", "LVDT top (mm)=hinges (-)"), "'LVDT top (mm)' is a length"
    )
    assert_one_line_error(
        invoke("export", h, "--times", lab, "--compare", "LVDT top (mm)=ground ax (m/s2)"),
        "'LVDT top (mm)' is a length, 'ground ax (m/s2)' an acceleration",  # it said 'a acceleration'
    )
    assert_one_line_error(
        invoke("export", h, "--times", lab, "--compare", "LVDT top (mm)=LVDT top (mm)"), "among masonry's columns"
    )
    # --force never replaces the lab's own file with the export of it
    assert_one_line_error(invoke("export", h, "--times", lab, "--out", lab, "--force"), "is the --times file")
    assert not list(tmp_path.glob("h.csv")) and not list(tmp_path.glob(".*part*"))
    assert lab.read_text().startswith("time (s),LVDT top (mm),comment\n0.0,0.0,row 0")


def test_measures_of_agreement_against_their_closed_forms():
    t = np.linspace(0, 2, 2001)  # two whole periods of a 1 Hz sine
    m = np.sin(2 * np.pi * t)
    same = agreement(t, m, m)
    assert (same.magnitude, same.phase, same.combined, same.rms_error) == (0, 0, 0, 0) and same.correlation == 1
    double = agreement(t, m, 2 * m)
    # M = sqrt(∫4m²/∫m²) − 1 = 1; in phase; RMS error = RMS of m = 1/√2
    assert double.magnitude == pytest.approx(1, abs=1e-12) and double.phase == pytest.approx(0, abs=1e-7)
    assert double.rms_error == pytest.approx(math.sqrt(np.mean(m**2)), rel=1e-12)
    assert double.relative_rms_error == pytest.approx(1, rel=1e-12) and double.peak_ratio == pytest.approx(2)
    # a quarter period late: orthogonal over whole periods, P = 1/2, the same magnitude
    late = agreement(t, m, np.cos(2 * np.pi * t))
    assert late.phase == pytest.approx(0.5, abs=1e-6) and late.magnitude == pytest.approx(0, abs=1e-6)
    assert late.combined == pytest.approx(0.5, abs=1e-6) and late.correlation == pytest.approx(0, abs=1e-3)
    # opposite sign: P = 1, r = −1; peaks and their times, the last samples, NaN samples left out
    flip = agreement(t, m, -m)
    assert flip.phase == pytest.approx(1) and flip.correlation == pytest.approx(-1)
    assert (double.peak_measured, double.peak_measured_time) == (pytest.approx(1), pytest.approx(0.25))
    gap = agreement(t, np.where(t > 1, np.nan, m), 2 * m)
    assert gap.samples == 1001 and gap.final_measured == pytest.approx(0, abs=1e-12)
    assert agreement(t[:1], m[:1], m[:1]) is None
    assert column_unit("LVDT top (mm)")[1:] == ("length", 1e-3) and column_unit("acc [g]")[2] == 9.80665
    assert column_unit("comment") is None


@pytest.mark.parametrize(
    "name, quantity, factor",
    [  # the spellings --record reads in the same lab file's header (records/units.py), --compare did not
        ("acc (cm/sec^2)", "acceleration", 0.01),
        ("acc (m/s/s)", "acceleration", 1.0),
        ("a (m s-2)", "acceleration", 1.0),
        ("acc (ft/s2)", "acceleration", 0.3048),
        ("v (in/s)", "velocity", 0.0254),
        ("v (cm/sec)", "velocity", 0.01),
        ("acc (G)", "acceleration", 9.80665),
        ("t (ms)", None, None),  # milliseconds, not m/s
    ],
)
def test_compare_reads_the_units_a_record_header_is_read_in(name, quantity, factor):
    found = column_unit(name)
    assert (found[1:] if found else (None, None)) == (quantity, factor)


def test_compare_converts_the_lab_unit(tmp_path):
    h = hand_history(tmp_path / "h.npz")
    at = TIMES  # on the frames: masonry's columns exactly the formula
    # the lab's LVDT, in mm: masonry's top x relative to the ground (0.5 C t² − D t) × 1.1 — 10 % larger
    lvdt = 1.1e3 * (0.5 * 2.0 * at**2 - 0.5 * at)
    text = "time (s),LVDT top (mm)\n" + "".join(f"{float(t)!r},{float(x)!r}\n" for t, x in zip(at, lvdt))
    (tmp_path / "lab.csv").write_text(text)
    result = invoke("export", h, "--times", tmp_path / "lab.csv", "--compare", "LVDT top (mm)")
    assert result.exit_code == 0, result.output
    out = " ".join(result.output.split())
    assert "top ux rel (m) (masonry) against LVDT top (mm) (lab), 5 samples, in mm:" in out
    # masonry's is the lab's / 1.1: M = 1/1.1 − 1 = −0.091, in phase, peak ratio 0.909
    assert "M = -0.091 (magnitude), P = 0.000 (phase), C = 0.091" in out and "ratio 0.909" in out
    final = re.search(r"final lab (\S+), masonry (\S+)\s", out)
    assert float(final[1]) == pytest.approx(lvdt[-1], rel=1e-3) and float(final[2]) == pytest.approx(
        lvdt[-1] / 1.1, rel=1e-3
    )


@pytest.mark.slow
def test_a_real_table_run_at_its_own_frame_times_is_the_plain_export(tmp_path):
    """A 200 Hz accelerogram in g (a shake table's input as its CSV gives it) run on the wall; the lab's times
    are some of the run's frame times and some between: on a frame the resampled top displacement is the
    plain export's, bit for bit; between frames, the straight line between them."""
    t = np.arange(0, 0.1 + 1e-9, 0.005)
    table = "time (s),acc (g)\n" + "".join(f"{x:.3f},{0.4 * math.sin(2 * math.pi * 5 * x)!r}\n" for x in t)
    (tmp_path / "table.csv").write_text(table)
    h = tmp_path / "h.npz"
    run = ("simulate", "wall", "--record", tmp_path / "table.csv", "--record-every", 5, "--no-recording")
    result = invoke(*run, "--history", h)
    assert result.exit_code == 0, result.output
    frames = np.load(h)["time"]
    assert len(frames) == 21 and frames[-1] == pytest.approx(0.1)
    at = np.array([frames[0], frames[3], 0.0171, frames[8], 0.0512, 0.0777, frames[-1]])
    (tmp_path / "lab.csv").write_text("time (s),lab\n" + "".join(f"{float(x)!r},\n" for x in at))
    assert invoke("export", h, "--out", tmp_path / "plain.csv").exit_code == 0
    result = invoke("export", h, "--times", tmp_path / "lab.csv", "--out", tmp_path / "lab-out.csv")
    assert result.exit_code == 0, result.output
    plain, lab = read_csv(tmp_path / "plain.csv"), read_csv(tmp_path / "lab-out.csv")
    top, base = floats(plain["top ux rel (m)"]), floats(lab["top ux rel (m)"])
    assert np.abs(top).max() > 1e-6  # the table moves the top course
    on = [0, 1, 3, 6]
    assert [lab["top ux rel (m)"][i] for i in on] == [plain["top ux rel (m)"][k] for k in (0, 3, 8, 20)]
    assert np.allclose(base, by_definition(frames, top, at), rtol=1e-12, atol=1e-18)


def test_a_pipe_as_the_lab_file_is_refused_not_waited_on(tmp_path):
    """A named pipe (or /dev/zero) given as --times: reading it never ended, as a record's did before it was
    refused (records.read and lab_file now read an input file alike: records.units.input_text)."""
    import os

    from masonrycli.outputs.lab_file import read_lab_file

    from cli_helpers import refusals_within

    pipe = tmp_path / "lab.csv"
    os.mkfifo(pipe)
    said = refusals_within(read_lab_file, pipe)
    assert said == [f"{pipe}: cannot read: not a regular file (a device, a pipe or a socket)"]


def test_a_list_cut_at_a_space_is_said_not_taken_for_a_history(tmp_path):
    """`--blocks a, c`: the shell hands `c` over as a second history; it said only 'c: no such history'."""
    h = hand_history(tmp_path / "h.npz")
    result = invoke("export", h, "--blocks", "a,", "c", "--out", tmp_path / "o.csv")
    assert_one_line_error(result, "--blocks a, c: a list goes without spaces after its commas: --blocks a,c")
    assert not (tmp_path / "o.csv").exists()
