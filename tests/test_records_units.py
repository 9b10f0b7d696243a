"""A record header's own word on its units: refused where it disagrees with how the samples are read."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from masonrycli.errors import InputError
from masonrycli.records.units import check_at2_header, check_csv_header, csv_header, header_factor, header_quantity
from masonrycli.study.store import read_rows

from cli_helpers import assert_one_line_error, invoke, words

BLOCK = Path(__file__).parent / "data" / "block_on_ground.toml"  # a block on a sine-shaken ground, 1 s


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
        ("time,velocity (cm/s)", "velocity", 0.01, "q.csv:1: the header gives velocity in cm/s"),
        ("time,v_mm/s", "velocity", 0.001, 'in mm/s ("time,v_mm/s"), converted to m/s on reading: scale 0.001 would'),
        ("time,acc (g)", "acceleration", 9.81, 'acceleration in g ("time,acc (g)"), converted to m/s² on reading'),
        ("time,acc (g)", "acceleration", -9.80665, "scale -9.80665 would convert it again (9.81 times too strong)"),
        ("time,acc (g)", "acceleration", 9.8, "drop the scale (it multiplies the record as recorded)"),
        ("time,a [gal]", "acceleration", 0.01, "acceleration in gal"),
        ("time,a [cm/s2]", "acceleration", 0.01, 'acceleration in cm/s2 ("time,a [cm/s2]"), converted to m/s² on'),
        # US units were read as SI without a word: in/s 39x, ft/s 3.3x too large
        (
            "time,vel (in/s)",
            "velocity",
            0.0254,
            'velocity in in/s ("time,vel (in/s)"), converted to m/s on reading: scale 0.0254 would convert it again',
        ),
        ("time,v [ft/s]", "velocity", 0.3048, "velocity in ft/s"),
        ("time,acc (in/s^2)", "acceleration", 0.0254, "acceleration in in/s^2"),
        ("time,a (ft/s2)", "acceleration", 0.3048, "scale 0.3048 would convert it again (3.28 times too weak)"),
        ("time,acc (in/s2)", "velocity", 1.0, "the header says acceleration"),
        # were read as velocity in cm/s / in/s ("/s/s"), or as m/s² without a word (², mm, sec)
        ("time,a (cm/s/s)", "acceleration", 0.01, "acceleration in cm/s/s"),
        ("time,a (cm/s/s)", "velocity", 1.0, "the header says acceleration"),
        ("time,acc (in/s/s)", "acceleration", 0.0254, "scale 0.0254 would convert it again"),
        ("time,acc (cm/s²)", "acceleration", 0.01, "acceleration in cm/s² ("),
        ("time,acc (mm/s2)", "acceleration", 0.001, "scale 0.001 would convert it again (1e+03 times too weak)"),
        ("time,acc (cm/sec^2)", "acceleration", 0.01, "acceleration in cm/sec^2"),
        ("time,v (cm/sec)", "velocity", 0.01, "velocity in cm/sec"),
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
        ("time,velocity (cm/s)", "velocity", 1.0),  # read in cm/s, converted
        ("time,acc (g)", "acceleration", 1.0),
        ("time,acc (g)", "acceleration", 0.5),
        ("time,acc (g)", "acceleration", 10.0),  # a choice, not 9.81's conversion
        ("time, acc [m/s^2]", "acceleration", 1.0),
        ("time,items", "acceleration", 1.0),
        ("time,vel (in/s)", "velocity", 2.0),
        ("time (s), position in s-curve", "velocity", 1.0),
        ("time, a (m/s/s)", "acceleration", 1.0),
        ("time,a (cm/s/s)", "acceleration", 1.0),
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
    from masonrycli.records.units import MAX_AT2_G, check_at2_sample

    check_at2_sample(-MAX_AT2_G, "a.AT2:5")
    with pytest.raises(InputError, match=r"^a.AT2:7: sample 294.2 g is beyond 10 g: the samples are not in g"):
        check_at2_sample(294.2, "a.AT2:7")


# ---------------------------------------------------------------- one reading for --record, scenarios and sets

A_G, F, DT = 0.3, 2.0, 1e-3  # a(t) = 0.3 g cos(2π·2 Hz·t), 2 s (whole periods): v = 0.3 g sin(2πft)/(2πf)


def _g_csv(path, header="time (s),acc (g)"):
    t = np.arange(2001) * DT
    path.write_text(
        header + "\n" + "".join(f"{float(x)!r},{float(y)!r}\n" for x, y in zip(t, A_G * np.cos(2 * np.pi * F * t)))
    )
    return path


def test_a_csv_in_g_shakes_the_same_through_run_a_scenario_and_a_set(tmp_path):
    # the header's g is converted on reading by run/simulate/check --record, a scenario's record table and a
    # sweep --records set alike; --record refused such a file at scale 1 ("a scale of 9.81 converts them")
    from masonrycli.scenario.record_option import record_motion_option
    from masonrycli.scenario.toml_file import loads_scenario
    from masonrycli.study.record_set import _record

    f = _g_csv(tmp_path / "q.csv")
    by_run = record_motion_option(f, 2.0)  # masonry run … --record q.csv --scale 2
    by_set = dataclasses.replace(_record(f, None), scale=2.0)  # a sweep --records row at scale 2
    scenario = BLOCK.read_text().replace(
        'motion = { kind = "sine", direction = [1.0, 0.0], amplitude = 1.0, frequency = 2.0 }',
        'motion = { kind = "record", file = "q.csv", scale = 2.0 }',  # acceleration, as its header says
    )
    by_file = loads_scenario(scenario, source="s.toml", base_dir=tmp_path).motions[0]
    t = np.linspace(0.0, 2.0, 4001)
    # independent: the exact integral of 2 × 0.3 g cos(2πft) (its quadratic baseline correction is ~0: the
    # velocity ends at rest with zero mean), against the trapezoid of the samples: relative error (ω dt)²/12
    exact = 2 * A_G * 9.80665 * np.sin(2 * np.pi * F * t) / (2 * np.pi * F)
    v = by_run.velocity_at(t)[:, 0]
    trapezoid = (2 * np.pi * F * DT) ** 2 / 12  # 1.3e-5; a g read as m/s² (or converted twice) is 9.81x off
    np.testing.assert_allclose(v, exact, rtol=0, atol=2 * trapezoid * np.abs(exact).max())
    for other in (by_set, by_file):
        np.testing.assert_array_equal(other.velocity_at(t), by_run.velocity_at(t))  # bit for bit
    # through the command: the set's row at scale 2 applies 2 × 0.3 g (its pga as applied, m/s², of the
    # baseline-corrected samples: within 1e-4 of the exact peak here; 9.81x off if read as m/s² or converted twice)
    folder = tmp_path / "set"
    folder.mkdir()
    _g_csv(folder / "q.csv")
    out = tmp_path / "rows.csv"
    args = ("sweep", BLOCK, "--records", folder, "--scale", 2, "--duration", 0.02, "--workers", 0, "--out", out)
    result = invoke(*args, "--no-recording")
    assert result.exit_code == 0, result.output
    (row,) = read_rows(out)
    assert row["pga"] == pytest.approx(2 * A_G * 9.80665, rel=1e-4)


@pytest.mark.parametrize("command, target", [("check", BLOCK), ("run", BLOCK), ("simulate", "wall")])
def test_record_scale_that_converts_a_header_unit_again_is_one_line(tmp_path, command, target):
    # before, 'scale 9.81' was how --record read a CSV in g: now it would run 9.81 times too strong
    f = _g_csv(tmp_path / "q.csv")
    result = invoke(command, target, "--record", f, "--scale", 9.81)
    assert_one_line_error(
        result,
        'q.csv:1: the header gives acceleration in g ("time (s),acc (g)"), converted to m/s² on reading: scale 9.81 '
        "would convert it again (9.81 times too strong); drop the scale",
    )
    cm = tmp_path / "v.csv"
    cm.write_text("time,vel (cm/s)\n0,0\n0.1,5\n0.2,0\n")
    assert_one_line_error(invoke(command, target, "--record", cm, "--scale", 0.01), "(100 times too weak)")
    result = invoke("check", BLOCK, "--record", f)
    assert result.exit_code == 0 and "record of acceleration (q.csv" in words(result.output), result.output


def test_scenario_file_scale_of_g_on_a_csv_in_g_is_refused(tmp_path):
    # a scenario file written for the old reading (scale = 9.81 converted the g) must not run 9.81x stronger
    _g_csv(tmp_path / "q.csv")
    motion = 'motion = { kind = "record", file = "q.csv", quantity = "acceleration", scale = 9.81 }'
    s = tmp_path / "s.toml"
    s.write_text(
        BLOCK.read_text().replace(
            'motion = { kind = "sine", direction = [1.0, 0.0], amplitude = 1.0, frequency = 2.0 }', motion
        )
    )
    assert_one_line_error(
        invoke("check", s), "motion.file: q.csv:1: the header gives acceleration in g", "drop the scale"
    )
    s.write_text(s.read_text().replace("scale = 9.81", "scale = 1.0"))
    result = invoke("check", s)
    assert result.exit_code == 0, result.output
