"""The plots of a real recording read as they open, read back from the file: every plot of several series
with a legend keeps its lines off its edges and out of its legend's corner, and each support component has
one colour of its own, the same in Support v and Support u.

Found opening recordings in the headless viewer as a newcomer would (2026-11-29): a settling arch's Support u
plot ran its lines along its top and bottom edges, the ESM record's ground ux dipped behind the legend, and
in Energies the legend hid the start of the support work and the lines at 0; the viewer gave the arch's
left-foundation vy and right-foundation vy the same pink, and ground vx was orange in Support v but pink in
Support u."""

from __future__ import annotations

import numpy as np
import pytest

from masonrycli.recording.layout import PLOT_NAMES, SERIES
from masonrycli.recording.readback import blueprint_views

from cli_helpers import invoke
from recording_fixtures import static_value, temporal_rows

PAD = 0.05  # share of the plot's height kept empty above and below the lines, at least
LEGEND_ROW = 23 / 240  # one legend row: ~23 px of a ~240 px plot at 1920 x 1080


@pytest.fixture(scope="module")
def arch(tmp_path_factory):
    """A settling arch (its right foundation sinks at 1 cm/s, the left one still): two supports."""
    path = tmp_path_factory.mktemp("plots") / "arch.rrd"
    result = invoke("simulate", "arch", "--duration", 0.1, "--out", path)
    assert result.exit_code == 0, result.output
    return path


def _values(path, key: str) -> np.ndarray:
    rows = temporal_rows(str(path), f"/{SERIES[key]}", "Scalars:scalars")
    return np.array([v for row in rows.values() for v in row], dtype=float)


@pytest.mark.parametrize(("key", "rows"), [("support_displacement", 4), ("energy_large", 3), ("support_velocity", 4)])
def test_a_plot_of_several_series_keeps_its_lines_off_its_edges_and_its_legend(arch, key, rows):
    values = _values(arch, key)
    assert values.size and np.ptp(values) > 0, values
    y_range = blueprint_views(arch)[PLOT_NAMES[key]]["y_range"]
    assert y_range is not None, f"{PLOT_NAMES[key]}: the viewer's fit puts its lines on its edges"
    low, high = y_range
    height = high - low
    assert (high - max(values.max(), 0.0)) / height >= PAD, (y_range, values.max())
    # under the lowest line: the margin and the legend's rows (bottom left)
    assert (min(values.min(), 0.0) - low) / height >= PAD + rows * LEGEND_ROW, (y_range, values.min())
    assert np.ptp(np.r_[values, 0.0]) / height >= 0.3, y_range  # the lines still use a good part of it


def test_each_support_component_has_its_own_colour_the_same_in_both_support_plots(arch):
    velocity = static_value(arch, f"/{SERIES['support_velocity']}", "SeriesLines:colors")
    displacement = static_value(arch, f"/{SERIES['support_displacement']}", "SeriesLines:colors")
    names = static_value(arch, f"/{SERIES['support_velocity']}", "SeriesLines:names")
    assert names == ["left-foundation vx", "left-foundation vy", "right-foundation vx", "right-foundation vy"]
    assert velocity is not None and len(velocity) == 4, velocity
    assert len(set(velocity)) == 4, velocity  # the two vy lines told apart
    assert displacement == velocity  # ux has vx's colour, uy vy's


def test_the_residual_plot_keeps_its_tolerance_off_its_top_edge_and_its_residuals_out_of_its_legend(arch):
    """The residual plot's range had a 5 % margin each side: the tolerance's line (the top of the plot when
    every step converges) lay on the top edge, and the legend's two rows (bottom left) over the lowest
    residuals. Residuals more than a decade under the tolerance may lie below (residual_range's module doc)."""
    values = _values(arch, "residual")
    tolerance = values.max()  # log10 of the tolerance: every step at or under it
    values = values[np.isfinite(values) & (values >= tolerance - 1.0)]
    y_range = blueprint_views(arch)[PLOT_NAMES["residual"]]["y_range"]
    assert y_range is not None
    low, high = y_range
    height = high - low
    assert (high - values.max()) / height >= PAD, (y_range, values.max())
    assert (values.min() - low) / height >= PAD + 2 * LEGEND_ROW, (y_range, values.min())


def test_the_sweeps_plot_runs_from_0(arch):
    """Fitted to its data, the Sweeps per step plot of the ESM record's wall (2 to 22 sweeps a step) had one
    tick, "10", and no 0: how many sweeps a step took could not be read. Its range runs from 0 now."""
    values = _values(arch, "iterations")
    y_range = blueprint_views(arch)[PLOT_NAMES["iterations"]]["y_range"]
    assert y_range is not None
    low, high = y_range
    assert low <= 0.0 and (high - values.max()) / (high - low) >= PAD, (y_range, values.max())
    assert blueprint_views(arch)[PLOT_NAMES["iterations"]]["legend"] is False  # one series: no legend
