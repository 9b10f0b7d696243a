"""What a first-time viewer reads without touching a panel, read back from the file: the Run panel's first lines
give the run's verdict, and the Legend under the structure says what the crosses of the Live tab are.

Found by opening the README's recordings in the headless viewer as a newcomer would (2026-11-29): a wall
that collapsed at 0.747 s ('masonry simulate wall --amp 2 --freq 1 --duration 2') opened on "Status:
completed" with its state 30 rows down the Parameters table, below the panel's fold; the principal stress
axes the Live tab opens on were explained in the Run panel alone, 40 rows down."""

from __future__ import annotations

import math
import re

import numpy as np

from masonrycli.recording import Recorder, inspect_recording

import recording_fixtures as fx
from cli_helpers import invoke, words
from recording_fixtures import strict_rerun  # noqa: F401 (autouse)


def _head(document: str) -> str:
    """The Run panel's lines above its Parameters table: what shows at first open."""
    return document.split("## Parameters")[0]


def test_the_run_panel_gives_the_verdict_above_its_parameters(tmp_path):
    out = tmp_path / "w.rrd"
    result = invoke("simulate", "wall", "--courses", 4, "--length", 1.2, "--duration", 0.1, "--out", out)
    assert result.exit_code == 0, result.output
    document = inspect_recording(out)["metadata"]
    for label, key in (("State", "state"), ("Peak drift", "peak drift")):
        row = re.search(rf"\| result\.{key} \| (.*?) \|\n", document)
        assert row is not None, document
        assert f"**{label}:** {row.group(1)}" in _head(document), _head(document)
    # the summary's words, as the terminal gave them
    state = re.search(r"\*\*State:\*\* (.*)\n", document).group(1)
    assert f"state {words(state)}" in words(result.output.replace("│", " "))
    assert state.startswith("damaged (residual drift")


def test_no_verdict_line_while_a_run_has_no_result(tmp_path):
    """A recording closed without a result (an interrupted or API run's recorder) keeps its Status line alone."""
    static, q0 = fx.wall()
    path = tmp_path / "r.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
        for f in fx.frames(static, q0, 3):
            rec.log_frame(f)
    head = _head(inspect_recording(path)["metadata"])
    assert "**Status:** completed" in head and "**State:**" not in head and "**Peak drift:**" not in head


def _ladder_ceil(x: float) -> float:
    """Smallest 1, 1.5, 2, 2.5, 3, 4, 5, 6 or 8 × 10^k at or above x (the scales' round numbers)."""
    e = math.floor(math.log10(x))
    return min(m * 10.0**k for k in (e, e + 1) for m in (1, 1.5, 2, 2.5, 3, 4, 5, 6, 8) if m * 10.0**k >= x)


def test_the_legend_says_what_the_principal_stress_axes_are(tmp_path):
    static, q0 = fx.wall(ragged=False)  # 0.3 x 0.2 m blocks
    frames = fx.frames(static, q0, 3)
    path = tmp_path / "r.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
        for f in frames:
            rec.log_frame(f)
    legend = fx.static_value(path, "/run/legend", "TextDocument:text")[0]
    line = next((ln for ln in legend.splitlines() if "Principal stress axes" in ln), None)
    assert line is not None, legend
    assert "black = compression" in line and "magenta = tension" in line and "Live" in line
    # the half-length at full scale: 0.45 x the median block's smaller side (0.2 m); full scale at the 98th
    # percentile of |principal stress| over the one batch, rounded up to a round number (kPa here)
    stress = np.concatenate([f.tensors["cell_principal_stress"].ravel() for f in frames])
    full = _ladder_ceil(float(np.percentile(np.abs(stress[np.isfinite(stress)]), 98)))
    assert 1e3 <= full < 1e6
    assert f"half-length {0.45 * fx.BLOCK_H:.3g} m at {full / 1e3:.3g} kPa" in line, line


def test_the_legend_stays_seven_lines_at_1920_px(tmp_path):
    """The Legend panel of a 1920 x 1080 window shows seven lines of about 185 characters: the paper run's
    legend, principal stress axes included, was eight (its Magnified line cut); each bullet now wraps to at
    most two lines there and they make seven."""
    from masonrycli.recording.document import legend_markdown

    legend = legend_markdown(1.5e-5, 0.2, 1.0, paper_t=0.1, arrow_cap=1.2, axes=(0.09, 6e4))
    bullets = [ln.replace("**", "") for ln in legend.splitlines() if ln.startswith("- ")]
    assert len(bullets) == 5 and bullets[-1].startswith("- Magnified")
    assert sum(math.ceil(len(b) / 185) for b in bullets) <= 7, [len(b) for b in bullets]


def test_the_plots_open_on_what_moved_the_structure(tmp_path):
    """An arch shaken by a .AT2 record opened its second row of plots on the solver's log10 residual, its
    ground's velocity a click away: the support's velocity shows at open when a support moved, the residual
    when none did."""
    from masonrycli.recording.layout import PLOT_NAMES
    from masonrycli.recording.readback import blueprint_tabs

    static, q0 = fx.wall()
    shaken = fx.frames(static, q0, 3)  # the ground shaken at 2 Hz
    still = [type(f)(**{**f.__dict__, "support_v": np.zeros_like(f.support_v)}) for f in shaken]
    opened = {}
    for name, frames in (("shaken", shaken), ("still", still)):
        with Recorder(tmp_path / f"{name}.rrd", static, fx.METADATA, batch_frames=4) as rec:
            for f in frames:
                rec.log_frame(f)
        (plots,) = [
            shown for names, shown in blueprint_tabs(tmp_path / f"{name}.rrd") if PLOT_NAMES["residual"] in names
        ]
        opened[name] = plots
    assert opened == {"shaken": PLOT_NAMES["support_velocity"], "still": PLOT_NAMES["residual"]}


def test_each_colour_bar_says_the_instant_its_view_shows(tmp_path):
    """The quick start opens on "Fig. III.2", pinned at t = 0.1 s, its time line at 1.000 s: nothing on the
    view said which instant it showed. Each frame's bar title carries its time, so the pinned tab reads
    0.100 s and a live tab the cursor's time."""
    from masonrycli.recording.layout import FIELD_BY_KEY
    from masonrycli.recording.readback import blueprint_views
    from masonrycli.scenario.builtin import paper_loading

    static, q0 = fx.wall()
    frames = fx.frames(static, q0, 13)  # to step 120: the paper's instant, then two frames more
    paper = {**fx.METADATA, "scenario": "wall", "duration_s": 1.0, "supports": paper_loading("wall")}
    path = tmp_path / "w.rrd"
    with Recorder(path, static, paper, batch_frames=4) as rec:
        for f in frames:
            rec.log_frame(f)
    (pinned,) = {v["pinned"] for v in blueprint_views(path).values() if v["pinned"]}
    assert pinned == ("sim_time", 0.1, 0.1)
    f = FIELD_BY_KEY["cell_volumetric_strain_rate"]  # Fig. III.2's field
    labels = fx.temporal_rows(path, f"/{f.labels}", "Points2D:labels")
    at = {round(fr.time, 9): fr.step for fr in frames}
    assert f"{f.title}, t = 0.100 s" in labels[at[0.1]]
    assert f"{f.title}, t = 0.120 s" in labels[frames[-1].step]


def test_the_support_velocity_plot_keeps_its_lines_off_its_edges_and_its_legend(tmp_path):
    """A settling arch's Support v plot ran from -0.01 to 0 m/s (the viewer's fit): the still supports' lines
    lay on its top edge, the settling vy on its bottom edge, and the legend (bottom left) hid the start of that
    line. The plot's range leaves a margin above and below the lines and, under them, room for the legend's
    rows (about 23 px each of the ~240 px plot at 1920 x 1080)."""
    from masonrycli.recording.layout import PLOT_NAMES
    from masonrycli.recording.readback import blueprint_views

    static, q0 = fx.wall()
    frames = fx.frames(static, q0, 6)
    settling = [type(f)(**{**f.__dict__, "support_v": np.array([[0.0, -0.01]])}) for f in frames]
    path = tmp_path / "settling.rrd"
    with Recorder(path, static, fx.METADATA, batch_frames=4) as rec:
        for f in settling:
            rec.log_frame(f)
    low, high = blueprint_views(path)[PLOT_NAMES["support_velocity"]]["y_range"]
    height = high - low
    assert (high - 0.0) / height >= 0.05, (low, high)  # vx and the still lines off the top edge
    rows = 2  # the ground's vx and vy in the legend
    assert (-0.01 - low) / height >= 0.05 + rows * 23 / 240, (low, high)  # the legend under the vy line
    assert 0.01 / height >= 0.3, (low, high)  # the lines still use a good part of the plot
