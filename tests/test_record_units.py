"""A record header's own word on its units: refused where it disagrees with how the samples are read."""

from __future__ import annotations

import pytest

from masonrycli.errors import InputError
from masonrycli.record_units import check_at2_header, check_csv_header, csv_header, header_factor, header_quantity


def check(tmp_path, text, quantity="velocity", scale=1.0):
    f = tmp_path / "q.csv"
    f.write_text(text)
    check_csv_header(f, "q.csv", quantity, scale)


SAMPLES = "0,0\n0.01,0.5\n0.02,0.1\n"


@pytest.mark.parametrize(
    "header, quantity, scale, expected",
    [
        ("time_ms,vel", "velocity", 1.0, 'q.csv:1: the header gives times in ms ("time_ms,vel"); record times'),
        ("t [msec], v", "velocity", 1.0, "q.csv:1: the header gives times in ms"),
        ("time (s),acc (g)", "velocity", 1.0, 'q.csv:1: the header says acceleration ("time (s),acc (g)") but the'),
        ("Time,Ground acceleration [m/s^2]", "velocity", 9.81, "the header says acceleration"),
        ("time,velocity", "acceleration", 1.0, "the header says velocity"),
        ("time,velocity (cm/s)", "velocity", 1.0, "q.csv:1: the header gives velocity in cm/s"),
        ("time,v_mm/s", "velocity", 1.0, 'in mm/s ("time,v_mm/s") but the samples are read in m/s (a scale of 0.001'),
        ("time,acc (g)", "acceleration", 1.0, 'acceleration in g ("time,acc (g)") but the samples are read in m/s²'),
        ("time,a [gal]", "acceleration", 1.0, "acceleration in gal"),
        ("time,a [cm/s2]", "acceleration", 1.0, "acceleration in cm/s2"),
        # US units were read as SI without a word: in/s 39x, ft/s 3.3x too large
        (
            "time,vel (in/s)",
            "velocity",
            1.0,
            'velocity in in/s ("time,vel (in/s)") but the samples are read in m/s (a scale of 0.0254',
        ),
        ("time,v [ft/s]", "velocity", 1.0, "velocity in ft/s"),
        ("time,acc (in/s^2)", "acceleration", 1.0, "acceleration in in/s^2"),
        ("time,a (ft/s2)", "acceleration", 1.0, "(a scale of 0.3048 converts them)"),
        ("time,acc (in/s2)", "velocity", 1.0, "the header says acceleration"),
        # were read as velocity in cm/s / in/s ("/s/s"), or as m/s² without a word (², mm, sec)
        ("time,a (cm/s/s)", "acceleration", 1.0, "acceleration in cm/s/s"),
        ("time,a (cm/s/s)", "velocity", 1.0, "the header says acceleration"),
        ("time,acc (in/s/s)", "acceleration", 1.0, "(a scale of 0.0254 converts them)"),
        ("time,acc (cm/s²)", "acceleration", 1.0, "acceleration in cm/s² ("),
        ("time,acc (mm/s2)", "acceleration", 1.0, "(a scale of 0.001 converts them)"),
        ("time,acc (cm/sec^2)", "acceleration", 1.0, "acceleration in cm/sec^2"),
        ("time,v (cm/sec)", "velocity", 1.0, "velocity in cm/sec"),
    ],
)
def test_header_disagreeing_with_the_reading_is_one_line(tmp_path, header, quantity, scale, expected):
    with pytest.raises(InputError) as exc:
        check(tmp_path, header + "\n" + SAMPLES, quantity, scale)
    msg = str(exc.value)
    assert expected in msg and "\n" not in msg


@pytest.mark.parametrize(
    "header, quantity, scale",
    [
        ("time,velocity", "velocity", 1.0),
        ("t [s]; v [m/s]", "velocity", 1.0),
        ("time,vx,vy", "velocity", 1.0),
        ("time,rms,ground", "velocity", 1.0),  # words that merely contain "ms" or "g"
        ("time,velocity (cm/s)", "velocity", 0.01),  # the scale converts it
        ("time,acc (g)", "acceleration", 9.80665),
        ("time, acc [m/s^2]", "acceleration", 1.0),
        ("time,items", "acceleration", 1.0),
        ("time,vel (in/s)", "velocity", 0.0254),
        ("time (s), position in s-curve", "velocity", 1.0),
        ("time, a (m/s/s)", "acceleration", 1.0),
        ("time,a (cm/s/s)", "acceleration", 0.01),
        # a_g, v_g: the ground's acceleration and velocity, not a unit of g
        ("time,a_g", "acceleration", 1.0),
        ("time,v_g", "velocity", 1.0),
    ],
)
def test_header_that_agrees_or_names_nothing_is_read(tmp_path, header, quantity, scale):
    check(tmp_path, header + "\n" + SAMPLES, quantity, scale)


@pytest.mark.parametrize(
    "header, quantity, factor",
    [
        ("time (s),a (cm/s/s)", "acceleration", 0.01),
        ("time (s),acceleration (in/s/s)", "acceleration", 0.0254),
        ("time (s),acc (cm/s²)", "acceleration", 0.01),
        ("time (s),acc (mm/s2)", "acceleration", 0.001),
        ("time (s),acc (CM/SEC^2)", "acceleration", 0.01),
        ("time (s),v (cm/sec)", "velocity", 0.01),
        ("time (s),acc (cm/s**2)", "acceleration", 0.01),
        ("time (s),acc (cm s-2)", "acceleration", 0.01),
        ("time (s),acc (mm s^-2)", "acceleration", 0.001),
        ("time (s),acc (m s-2)", "acceleration", None),
        ("time (s),vel (cm s-1)", "velocity", 0.01),
        ("time (s),acc*", "acceleration", None),  # a footnote's star
        ("time (s),a (m/s/s)", "acceleration", None),
        ("time (s),v_g", "velocity", None),  # the ground's velocity (read as acceleration in g before)
        ("time (s),a_g", "acceleration", None),
        ("time (s),a_g (g)", "acceleration", 9.80665),
        ("time (s),acc_g", "acceleration", 9.80665),
    ],
)
def test_how_a_sets_csv_reads_its_headers_unit(tmp_path, header, quantity, factor):
    # how a sweep --records set reads a CSV: the quantity and the factor to SI its header names
    f = tmp_path / "q.csv"
    f.write_text(header + "\n" + SAMPLES)
    assert header_quantity(f) == quantity
    found = header_factor(f, quantity)
    assert (found and found[1]) == factor


def test_csv_header_is_the_line_before_the_samples(tmp_path):
    f = tmp_path / "q.csv"
    f.write_text("\ufeff# a comment\n\ntime,v\n0,0\n1,1\n")
    assert csv_header(f) == (3, "time,v")
    f.write_text("0,0\ntime_ms,v\n")  # no header: the loader reports the stray line
    assert csv_header(f) is None


def test_at2_header_units():
    check_at2_header(["PEER", "x", "ACCELERATION TIME SERIES IN UNITS OF G"], "a.AT2")
    check_at2_header(["title", "station", "units of g"], "a.AT2")
    check_at2_header(["a", "b", "c"], "a.AT2")  # no unit named: PEER's g
    with pytest.raises(InputError, match=r"^a.AT2:3: the header says units of CM/S/S; an .AT2 record holds"):
        check_at2_header(["PEER", "x", "ACCELERATION TIME SERIES IN UNITS OF CM/S/S"], "a.AT2")
    with pytest.raises(InputError, match=r"^a.AT2:3: the header says velocity"):
        check_at2_header(["PEER", "x", "VELOCITY TIME SERIES IN UNITS OF CM/S"], "a.AT2")


def test_at2_samples_beyond_ten_g_are_not_g():
    from masonrycli.record_units import MAX_AT2_G, check_at2_sample

    check_at2_sample(-MAX_AT2_G, "a.AT2:5")
    with pytest.raises(InputError, match=r"^a.AT2:7: sample 294.2 g is beyond 10 g: the samples are not in g"):
        check_at2_sample(294.2, "a.AT2:7")
