"""``--pga``: a record scaled so that the ground motion as applied peaks at a site's design PGA."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli import api
from masonrycli.records.read import G_STANDARD, record_motion
from masonrycli.study.store import read_rows

from cli_helpers import assert_one_line_error, invoke, words
from synthetic_records import band_limited, write_at2


@pytest.fixture
def at2(tmp_path):
    t, u, v, a = band_limited(1.0, 0.005, [2.0, 4.5], [0.004, 0.001], seed=5)
    # not at rest at its end (a record cut short): the baseline correction moves its peak
    write_at2(tmp_path / "quake.AT2", a[: len(a) * 3 // 4] / G_STANDARD, 0.005)
    return tmp_path / "quake.AT2"


def applied_peak(record, steps: int, dt: float) -> float:
    """m/s²: the largest step-to-step change of the record's x velocity over the run, per dt (slow: a loop)."""
    v = [float(record.velocity_at(np.array([k * dt]))[0, 0]) for k in range(steps + 1)]
    return max(abs(v[k + 1] - v[k]) for k in range(steps)) / dt


@pytest.mark.parametrize("given", ["0.3", "0.3g", "2.941995m/s2", "294.1995gal"])
def test_a_record_scaled_to_a_pga_is_applied_at_that_peak(at2, tmp_path, given):
    npz = tmp_path / "h.npz"
    result = invoke(
        "simulate", "wall", "--blocks", 12, "--record", at2, "--pga", given, "--no-recording", "--history", npz,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    h = np.load(npz)
    steps = int(h["step"][-1])
    # the scale that makes it: the record's own peak as applied (baseline-corrected, at the run's steps)
    scale = 0.3 * G_STANDARD / applied_peak(record_motion(at2), steps, 1e-3)
    assert scale != pytest.approx(0.3 * G_STANDARD / record_motion(at2).peak_acceleration, rel=1e-3)
    np.testing.assert_allclose(
        h["support_v"][:, 0, :], record_motion(at2, scale=scale).velocity_at(h["time"]), rtol=1e-12, atol=1e-15
    )
    assert float(h["intensity_pga"]) == pytest.approx(0.3 * G_STANDARD, rel=1e-12)
    assert "(0.3 g)" in result.output


def test_check_and_the_api_take_the_pga_and_check_says_the_scale(at2):
    steps = round(record_motion(at2).end_time / 1e-3)  # simulate runs the whole record
    scale = 0.25 * G_STANDARD / applied_peak(record_motion(at2), steps, 1e-3)
    result = invoke("check", "wall", "--blocks", 12, "--record", at2, "--pga", "0.25")
    assert result.exit_code == 0, result.output
    assert f"× {scale:.6g}" in result.output
    made = api.scenario("wall", blocks=12, record=at2, pga="2.4516625 m/s2")
    assert made.motions[0].scale == pytest.approx(scale, rel=1e-12)
    assert api.scenario("wall", blocks=12, record=at2, pga=0.25).motions[0].scale == made.motions[0].scale


@pytest.mark.parametrize(
    "args, said",
    [
        (("--pga", "0.25", "--scale", "2"), "--pga with --scale: give one"),
        (("--pga", "0.25", "g"), "(g): --pga takes its unit joined to the number (--pga 0.25g), or the number alone"),
        (("--pga", "0.25x"), "--pga': 0.25x: x is not a unit of acceleration"),
        (("--pga", "3kN"), "3kN: kN is not a unit of acceleration"),
        (("--pga", "0"), "0: must be a peak acceleration above 0 and at most 10 g"),
        (("--pga", "25"), "25: must be a peak acceleration above 0 and at most 10 g"),
    ],
)
def test_a_bad_pga_is_one_line(at2, args, said):
    assert_one_line_error(invoke("check", "wall", "--record", at2, *args), said)
    assert_one_line_error(invoke("simulate", "wall", "--record", at2, "--no-recording", *args), said)


def test_a_pga_without_a_record_says_it_scales_one():
    said = "--pga: scales a ground-motion record, and its sine motion is not a record (give --record FILE)"
    assert_one_line_error(invoke("simulate", "wall", "--pga", "0.25", "--no-recording"), said)
    assert_one_line_error(invoke("check", "arch", "--pga", "0.25"), "nothing shakes it")


def test_a_study_scales_each_record_to_its_points_pga(at2, tmp_path):
    # a study over PGA was --scale values worked out by hand per record; the rows' pga (as applied) then missed
    # the values meant by the baseline correction's change of the peak
    other = tmp_path / "other.AT2"
    t, u, v, a = band_limited(0.6, 0.005, [3.0], [0.002], seed=9)
    write_at2(other, a / G_STANDARD, 0.005)
    out, histories = tmp_path / "s.csv", tmp_path / "h"
    result = invoke(
        "sweep", "wall", "--param", "blocks=12", "--records", at2, "--records", other, "--param", "pga_g=0.1,0.3",
        "--duration", 0.75, "--workers", 0, "--no-recording", "--out", out, "--histories", histories,
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    rows = read_rows(out)
    pairs = [("other.AT2", 0.1), ("other.AT2", 0.3), ("quake.AT2", 0.1), ("quake.AT2", 0.3)]
    assert sorted((r["record"], r["pga_g"]) for r in rows) == pairs
    for row in rows:
        assert row["pga"] == pytest.approx(row["pga_g"] * G_STANDARD, rel=1e-12)
        record = record_motion(tmp_path / row["record"])
        scale = row["pga_g"] * G_STANDARD / applied_peak(record, 750, 1e-3)
        h = np.load(next(histories.glob(f"*{row['record']}*pga_g={row['pga_g']:g}*.npz")))
        np.testing.assert_allclose(
            h["support_v"][:, 0, :], record_motion(tmp_path / row["record"], scale=scale).velocity_at(h["time"]),
            rtol=1e-12, atol=1e-15,
        )  # fmt: skip


@pytest.mark.parametrize(
    "args, said",
    [
        (("--param", "pga_g=0.25", "--scale", "1"), "--param pga_g: sets each record's scale, which --scale sets too"),
        (("--param", "pga_g=0,0.25"), "--param pga_g=0.0: a peak ground acceleration in g, above 0 and at most 10"),
        (("--param", "pga=0.25"), '--param pga: unknown parameter (records are scaled to a PGA in g by "pga_g"'),
        (("--pga", "0.25"), "--pga: a study takes it as an axis: --param pga_g=VALUE"),
    ],
)
def test_a_bad_pga_axis_is_one_line(at2, args, said):
    assert_one_line_error(invoke("sweep", "wall", "--records", at2, *args), said)


def test_a_pga_axis_on_a_sine_says_it_scales_records():
    said = "--param pga_g=0.25: scales a ground-motion record, and its sine motion is not a record (give --records"
    assert_one_line_error(invoke("sweep", "wall", "--param", "pga_g=0.25", "--workers", 0), said)


def test_check_gives_the_ground_motion_the_run_will_apply(at2, tmp_path):
    # check showed "× 0.25" and no PGA: a --scale 0.25 read as "PGA 0.25 g" (0.0775 g applied on the 20 s record
    # it was found with) was seen only after the run
    result = invoke("check", "wall", "--blocks", 12, "--record", at2, "--scale", 0.25, "--duration", 0.5)
    assert result.exit_code == 0, result.output
    npz = tmp_path / "h.npz"
    args = ("--blocks", 12, "--record", at2, "--scale", 0.25, "--duration", 0.5, "--no-recording", "--history", npz)
    assert invoke("simulate", "wall", *args).exit_code == 0
    h = np.load(npz)
    pga = 0.25 * applied_peak(record_motion(at2), 500, 1e-3)
    assert float(h["intensity_pga"]) == pytest.approx(pga, rel=1e-12)
    said = words(result.output.replace("│", " "))
    assert (
        f"intensity ground: PGA {pga:.3g} m/s² ({pga / G_STANDARD:.3g} g), PGV {float(h['intensity_pgv']):.3g} m/s, "
        f"Arias {float(h['intensity_arias']):.3g} m/s, D5–95 {float(h['intensity_d5_95']):.3g} s, "
        f"Sa(0.5 s) {float(h['intensity_sa']):.3g} m/s²"
    ) in said
    # the default wall's sine, 1 m/s at 2 Hz: 2π·2·1 = 12.6 m/s², 1.28 g
    assert "PGA 12.6 m/s² (1.28 g), PGV 1 m/s" in words(invoke("check", "wall").output.replace("│", " "))
    assert "intensity" not in invoke("check", "arch").output  # a settling foundation shakes nothing


def test_a_fragility_over_pga_levels_counts_its_collapses_per_pga():
    from masonrycli.study.curves import fragility_series

    rows = [
        {"record": r, "pga_g": p, "pga": p * G_STANDARD * (1 + 1e-15), "state": "collapsed" if p > 0.3 else "intact"}
        for r in ("a.AT2", "b.AT2")
        for p in (0.2, 0.4)
    ]
    fraction = [s for s in fragility_series(rows, "pga", None, "m/s²") if s.key == "fraction"][0]
    assert fraction.label == "fraction collapsed per PGA"  # it said "per scale" of a study with no scale
    np.testing.assert_allclose(fraction.x, [0.2 * G_STANDARD, 0.4 * G_STANDARD], rtol=1e-12)
    assert list(fraction.y) == [0.0, 1.0]


def test_a_run_cut_short_applies_the_whole_record_so_scaled(at2, tmp_path):
    # --pga scaled the part of the record the run reached: a run cut before the record's peak ran it stronger
    # than the record scaled to that PGA (x1.12 for --duration 3 on a 20 s record peaking at 3.4 s)
    record = record_motion(at2)
    whole = applied_peak(record, round(record.end_time / 1e-3), 1e-3)
    early = applied_peak(record, 200, 1e-3)
    assert early < 0.9 * whole  # the record peaks after 0.2 s
    npz = tmp_path / "h.npz"
    args = ("--blocks", 12, "--record", at2, "--pga", 0.3, "--duration", 0.2, "--no-recording", "--history", npz)
    result = invoke("simulate", "wall", *args)
    assert result.exit_code == 0, result.output
    assert "its shaking after t = 0.2 s is not applied" in words(result.output)
    h = np.load(npz)
    scale = 0.3 * G_STANDARD / whole
    np.testing.assert_allclose(
        h["support_v"][:, 0, :], record_motion(at2, scale=scale).velocity_at(h["time"]), rtol=1e-12
    )
    assert float(h["intensity_pga"]) == pytest.approx(scale * early, rel=1e-12)


def test_a_record_of_zeros_in_a_set_is_named(at2, tmp_path):
    # a record of zeros among a study's files said '--param pga_g=0.4: the record never accelerates …': which one?
    write_at2(tmp_path / "flat.AT2", np.zeros(50), 0.01)
    said = "--param pga_g=0.4: flat.AT2 never accelerates the ground along x"
    assert_one_line_error(invoke("sweep", "wall", "--records", tmp_path, "--param", "pga_g=0.4", "--workers", 0), said)
    said = "--pga: flat.AT2 never accelerates the ground along x"
    assert_one_line_error(invoke("simulate", "wall", "--record", tmp_path / "flat.AT2", "--pga", "0.4"), said)
