"""The recording's plots (masonrycli/recording/series.py, residual_range.py), read back: the solver's health once
per step from the initial frame, the kinetic energy on a plot of its own, the residual's unit and a range not set
by its first steps, the largest displacement relative to a shaken ground, no legend on a one-series plot, the
balance error as a log10 share."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.recording import Recorder, inspect_recording
from masonrycli.recording.layout import PLOT_NAMES
from masonrycli.recording.readback import blueprint_views

import recording_fixtures as fx
from recording_fixtures import (  # noqa: F401 (fixtures: strict_rerun autouse, wall, written)
    strict_rerun,
    temporal_rows,
    wall_fixture,
    written_fixture,
)


def test_solver_health_once_per_step_and_the_initial_frame_shown(wall, tmp_path):
    """log_step values are logged at every step; the initial frame without forces is shown at t = 0 (it was
    left out: the recording began at the first computed frame, step 10)."""
    static, q0 = wall
    frames = fx.frames(static, q0, 4)
    empty = type(frames[0])(**{**frames[0].__dict__, "contact_force": np.zeros_like(frames[0].contact_force)})
    path = tmp_path / "steps.rrd"

    class Stats:
        def __init__(self, k):
            self.iterations, self.residual, self.contact_count = 10 + k, 10.0 ** (-3 - k % 3), 40

    with Recorder(path, static, {**fx.METADATA, "nlgs_tolerance": 1e-4}, batch_frames=2) as rec:
        rec.log_frame(empty)
        for k in range(1, 31):
            rec.log_step(k, k * static.dt, Stats(k))
            if k % 10 == 0:
                rec.log_frame(frames[k // 10])
    iterations = temporal_rows(path, "/series/solver/iterations", "Scalars:scalars")
    residual = temporal_rows(path, "/series/solver/log10_residual", "Scalars:scalars")
    assert sorted(iterations) == list(range(1, 31)) == sorted(residual)
    assert iterations[7] == [17.0]
    np.testing.assert_allclose(residual[7], [-4.0, -4.0])  # log10 residual, log10 tolerance
    assert inspect_recording(path)["steps"] == (0, 30) and inspect_recording(path)["frames"] == 4


def test_the_kinetic_energy_has_a_plot_of_its_own(written):
    """The first plot at open was "Kinetic and dissipated energy (J)": the dissipated energy only grows, so
    the kinetic energy read as a flat line at 0 ('masonry simulate aqueduct': about 0.5 J under 250 J
    dissipated). The kinetic energy is plotted alone, first; the dissipated energy beside the support work
    that feeds it and the potential change."""
    path, _, frames, _ = written
    views = blueprint_views(path)
    assert views[PLOT_NAMES["energy_kinetic"]]["origin"] == "/series/energy/kinetic"
    kinetic = fx.temporal_rows(path, "/series/energy/kinetic", "Scalars:scalars")
    assert {f.step: [f.energy_kinetic] for f in frames} == {k: list(v) for k, v in kinetic.items()}
    large = views[PLOT_NAMES["energy_large"]]["origin"]
    rows = fx.temporal_rows(path, large, "Scalars:scalars")
    last = frames[-1]
    np.testing.assert_allclose(rows[last.step][:2], [last.support_work, last.energy_dissipated])
    assert not any("dissipated" in n and "inetic" in n for n in views)


def test_the_residual_plot_names_its_unit(written):
    """ "NLGS residual (log10) and tolerance": ticks -5 .. -5.3 and no unit on screen. The residual is the
    RMS contact-law violation of a sweep in m/s (--tolerance's unit); the plot's name says so."""
    views = blueprint_views(written[0])
    assert views["Residual (log10 m/s)"]["origin"] == "/series/solver/log10_residual"


def test_the_largest_displacement_is_relative_to_a_shaken_ground(written):
    """The plot drew the blocks' travel with their shaken ground ('masonry simulate wall --freq 2 --amp 1':
    0.22 m at 0.8 s, of which the ground's 0.16 m) where the run summary and the magnified view take the
    displacement relative to it. Now the same reference: the supports' common translation comes off."""
    path, _, frames, _ = written
    q0, g0 = frames[0].block_q[:, :2], frames[0].support_q[0, :2]
    rows = fx.temporal_rows(path, "/series/blocks/max_displacement", "Scalars:scalars")
    for f in frames[1:]:
        relative = np.linalg.norm(f.block_q[:, :2] - q0 - (f.support_q[0, :2] - g0), axis=1).max()
        absolute = np.linalg.norm(f.block_q[:, :2] - q0, axis=1).max()
        assert rows[f.step][0] == pytest.approx(relative, rel=1e-12, abs=1e-15)
        assert abs(relative - absolute) > 1e-4 or abs(f.support_q[0, 0] - g0[0]) < 1e-4


def test_a_plot_of_one_named_series_has_no_legend(written):
    """The legend box sat bottom left over the start of every curve, and on a plot of one series repeated
    its name ("kinetic" under "Kinetic energy (J)", "contacts" under "Contacts"). Those plots have none, nor
    the balance error (its legend covered its first 300 ms); the plots of several series keep theirs."""
    views = blueprint_views(written[0])
    hidden = {n for n, v in views.items() if v["kind"] == "TimeSeries" and v["legend"] is False}
    assert hidden == {
        PLOT_NAMES[k] for k in ("energy_kinetic", "energy_balance", "max_displacement", "iterations", "contacts")
    }


@pytest.mark.parametrize("low_steps, fixed", [(2, True), (10, False)])
def test_the_residual_plot_is_not_ranged_by_its_first_steps(wall, tmp_path, low_steps, fixed):
    """'masonry simulate wall --record syn1.AT2 --scale 3': the first steps converged to 1e-7.5 m/s under a
    1e-5 tolerance, the plot spanned 2.5 decades for them and the run read as a flat line on the tolerance.
    The range runs from the smallest residual but those more than a decade under the tolerance to the
    largest, unless more than 5 % of the steps lie that low (then the viewer fits them all)."""
    static, q0 = wall
    frames = fx.frames(static, q0, 5)
    path = tmp_path / f"r{low_steps}.rrd"

    class Stats:
        def __init__(self, k):
            self.iterations, self.contact_count = 10, 40
            self.residual = 1e-7 if k <= low_steps else 10.0 ** (-4.5 + 0.01 * (k % 50))  # largest 10**-4.01

    with Recorder(path, static, {**fx.METADATA, "nlgs_tolerance": 1e-4}, batch_frames=2) as rec:
        for k in range(1, 101):
            rec.log_step(k, k * static.dt, Stats(k))
            if k % 25 == 0:
                rec.log_frame(frames[k // 25])
    y_range = blueprint_views(path)[PLOT_NAMES["residual"]]["y_range"]
    if fixed:
        lo, hi = -4.5, -4.0  # the smallest but the first steps'; the tolerance over the largest residual
        # 8 % of the plot above the lines; under them 8 % and the legend's two rows, 10 % each (plot_range)
        height = (hi - lo) / (1.0 - 0.08 - 0.08 - 0.2)
        assert y_range == pytest.approx((lo - 0.28 * height, hi + 0.08 * height))
    else:
        assert y_range is None


def test_the_balance_error_is_plotted_as_a_log10_share():
    """The balance error was plotted in joules: at round-off on the quick start's wall, its ticks read
    "0.000 000 000 03 J". It is now log10 of its share of the largest term, by hand here."""
    from masonrycli.recording.series import BALANCE_FLOOR, balance_log10

    kinetic, potential_change, dissipated, work = (
        np.array(x, dtype=float) for x in ([2, 1, 0], [0, -0.5, 0], [0, 0.5, 0], [1, 1, 0])
    )
    out = balance_log10(kinetic, potential_change, dissipated, work)
    # |2 + 0 + 0 − 1| / 2; an exact balance; nothing moved yet
    np.testing.assert_allclose(out, [np.log10(0.5), np.log10(BALANCE_FLOOR), np.log10(BALANCE_FLOOR)])


def test_the_balance_error_plot_reads_the_frames_energies(written):
    path, _, frames, _ = written
    rows = fx.temporal_rows(path, "/series/energy/balance_error", "Scalars:scalars")
    ref = frames[0].energy_potential  # the fixture's first frame is as built
    for f in frames[1:]:
        terms = [f.energy_kinetic, f.energy_potential - ref, f.energy_dissipated, f.support_work]
        share = abs(terms[0] + terms[1] + terms[2] - terms[3]) / max(abs(x) for x in terms)
        assert rows[f.step][0] == pytest.approx(np.log10(max(share, 1e-16)), abs=1e-9)
