"""``masonry report H.npz`` (masonrycli/outputs/run_report.py): the page's numbers are the run's summary's, the
export's and an independent reading of the history's arrays; its files are written whole and never replaced."""

from __future__ import annotations

import csv
import json
import re

import numpy as np
import pytest

from masonrycli import api
from masonrycli.records.read import G_STANDARD

from cli_helpers import invoke, words
from synthetic_records import band_limited, write_at2


@pytest.fixture(scope="module")
def at2(tmp_path_factory):
    folder = tmp_path_factory.mktemp("record")
    t, u, v, a = band_limited(1.0, 0.005, [2.0, 4.5], [0.004, 0.001], seed=5)
    write_at2(folder / "site.AT2", a / G_STANDARD, 0.005)
    return folder / "site.AT2"


@pytest.fixture(scope="module")
def shaken(at2, tmp_path_factory):
    """A 12-block wall under the record at 1.5 g (it rocks: a drift to compare), every step a frame: (history, the summary's words)."""
    npz = tmp_path_factory.mktemp("run") / "h.npz"
    args = ("--blocks", 12, "--record", at2, "--pga", 1.5, "--record-every", 1)
    result = invoke("simulate", "wall", *args, "--no-recording", "--history", npz)
    assert result.exit_code == 0, result.output
    return npz, words(result.output.replace("│", " "))


def rows(page: str) -> dict[str, str]:
    """The page's table rows, label -> value (a cell's escaped '|' read back)."""
    out = {}
    for line in page.splitlines():
        cells = re.split(r"(?<!\\) \| ", line.strip().strip("|").strip())
        if line.startswith("| ") and len(cells) == 2 and cells[0]:
            out[cells[0].strip()] = cells[1].strip().replace("\\|", "|")
    return out


def export_column(npz, tmp_path, name: str) -> np.ndarray:
    out = tmp_path / "s.csv"
    assert invoke("export", npz, "--top", "--out", out).exit_code == 0
    with open(out, newline="") as f:
        table = list(csv.DictReader(f))
    return np.array([float(r[name]) for r in table])


def test_the_page_says_what_the_run_s_summary_said(shaken):
    npz, summary = shaken
    result = invoke("report", npz)
    assert result.exit_code == 0, result.output
    page = rows(result.output)
    # each of the result's rows is the summary's row of the same run, word for word
    for label in ("state", "peak drift", "hinged joints (end)", "unconverged steps"):
        assert f"{label} {page[label]}" in summary, label
    ground = ", ".join(f"{k} {page[k]}" for k in ("PGA", "PGV", "Arias", "D5–95", "Sa(0.5 s)"))
    assert f"ground motion (ground) {ground}" in summary
    assert page["PGA"] == f"{1.5 * G_STANDARD:.3g} m/s² (1.5 g)"  # the --pga asked for, as applied
    # what was run: inspect's rows (the size of the built-in, the material, masonry's version and source)
    inspected = words(invoke("inspect", npz).output.replace("│", " "))
    for label in ("scenario", "structure", "material", "masonry"):
        assert f"{label} {page[label]}" in inspected, label
    assert page["structure"] == "wall: blocks 12" and "site.AT2" in page["loading"]


def test_the_drifts_are_export_s_and_the_history_s_own(shaken, tmp_path):
    npz, _ = shaken
    h = np.load(npz)
    drift = export_column(npz, tmp_path, "drift ratio (-)")
    peak, residual, height = (float(h[f"result_{k}"]) for k in ("peak_drift", "residual_drift", "height"))
    # every step is a frame: the peak the run watched every step is the largest of export's column
    assert peak == pytest.approx(np.abs(drift).max(), rel=1e-12)
    assert residual == pytest.approx(drift[-1], rel=1e-12, abs=1e-15)
    # independently of export and of the run: the top course (centroids within half a block of the highest),
    # its mean x displacement less the ground's, over the blocks' vertical extent as built
    q, extent = h["block_q"], h["block_extent"]
    y0 = q[0, :, 1]
    top = y0 >= y0.max() - 0.5 * np.median(extent[:, 3] - extent[:, 1])
    assert top.sum() >= 1 and height == pytest.approx(extent[:, 3].max() - extent[:, 1].min(), rel=1e-12)
    ground = h["support_q"][:, 0, 0] - h["support_q"][0, 0, 0]
    mine = ((q[:, top, 0] - q[0, top, 0]).mean(axis=1) - ground) / height
    assert peak == pytest.approx(np.abs(mine).max(), rel=1e-12)
    assert peak > 1e-6  # the wall moved: the comparison is of a drift, not of zeros
    page = rows(invoke("report", npz).output)
    shown = f"{100 * peak:.3g} % of the height ({1000 * peak * height:.3g} mm over {height:.3g} m)"
    assert page["peak drift"].startswith(shown)
    assert page["residual drift"] == f"{100 * residual:.3g} % of the height ({1000 * residual * height:.3g} mm)"
    hinged = [f"{a}|{b}" for a, b in _names(h)[h["joint_body"][h["joint_hinged"][-1]]]]
    assert page["hinged joints (end)"].startswith(f"{len(hinged)}")
    assert all(name in page["hinged joints (end)"] for name in hinged[:8])


def _names(h) -> np.ndarray:
    return np.array([*map(str, h["block_name"]), *map(str, h["support_name"])])


def test_out_writes_the_page_and_its_figure_whole_and_never_replaces_them(shaken, tmp_path):
    npz, _ = shaken
    out = tmp_path / "site" / "report.md"
    result = invoke("report", npz, "--out", out)
    assert result.exit_code == 0, result.output
    text = out.read_text(encoding="utf-8")
    assert "![The top's drift and the ground's acceleration against time](report.png)" in text
    assert (tmp_path / "site" / "report.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in (tmp_path / "site").iterdir()) == ["report.md", "report.png"]  # no .part left
    again = invoke("report", npz, "--out", out)
    assert again.exit_code == 2 and "--out" in again.output and "the file exists (add --force" in again.output
    assert out.read_text(encoding="utf-8") == text
    assert invoke("report", npz, "--out", out, "--force").exit_code == 0
    # without --out: the same page on stdout, with no figure
    printed = invoke("report", npz).output
    assert rows(printed) == rows(text) and "![" not in printed


def test_a_sine_s_page_and_the_api_s(tmp_path):
    npz = tmp_path / "w.npz"
    run = api.simulate("wall", duration=0.1, blocks=12, history=npz)
    page = invoke("report", npz).output
    assert rows(page)["PGA"] == "12.6 m/s² (1.28 g)"  # the default wall's 1 m/s at 2 Hz
    assert api.read_history(npz).report() == page  # the API's page of the file is the command's
    in_memory = rows(run.report())  # the run's own arrays, not read back from the file: the same page
    assert in_memory == rows(page) and in_memory["state"].split(" (")[0] == run.outcome["state"]
    assert rows(api.simulate("wall", duration=0.02, blocks=12).report())["history"] == "the run"  # no file
    out = tmp_path / "r.md"
    assert run.report(out) == out.read_text(encoding="utf-8") and (tmp_path / "r.png").exists()


def test_a_history_written_before_the_verdict_was_kept_says_so(shaken, tmp_path):
    npz, _ = shaken
    with np.load(npz) as h:
        old = {k: h[k] for k in h.files if not k.startswith("result_")}
    older = tmp_path / "old.npz"
    np.savez(older, **old)
    page = rows(invoke("report", older).output)
    assert page["state"].startswith("not recorded")
    drift = export_column(older, tmp_path, "drift ratio (-)")
    assert page["peak drift"].startswith(f"{100 * np.abs(drift).max():.3g} % of the height over the recorded frames")


def test_the_command_that_made_the_history_comes_first(tmp_path, monkeypatch):
    npz = tmp_path / "w.npz"
    args = ("simulate", "wall", "--blocks", 12, "--duration", 0.01, "--no-recording", "--history", npz)
    assert invoke(*args).exit_code == 0  # run in-process by a test: no command of masonry's to name
    assert "command" not in rows(invoke("report", npz).output)
    monkeypatch.setattr("sys.argv", ["/venv/bin/masonry", *map(str, args), "--force"])
    assert invoke(*args, "--force").exit_code == 0
    page = invoke("report", npz).output
    assert (
        page.split("\n")[6]
        == f"| command | masonry simulate wall --blocks 12 --duration 0.01 --no-recording --history {npz} --force |"
    )


def test_a_runs_outputs_say_one_start(tmp_path, monkeypatch):
    # each output asked the clock when it was opened (execute.run_metadata): the history, the recording and the
    # in-memory run could name seconds apart, and the page of the file differed from the run's own page (seen
    # in CI: 'started' 15:45:15 against 15:45:14). A clock that moves a second at every question shows it.
    import datetime as real
    import json

    from masonrycli import execute

    class Ticking(real.datetime):
        calls = 0

        @classmethod
        def now(cls, tz=None):
            cls.calls += 1
            return real.datetime(2026, 11, 29, 12, 0, cls.calls)

    monkeypatch.setattr(execute, "datetime", Ticking)
    npz, rrd = tmp_path / "w.npz", tmp_path / "w.rrd"
    run = api.simulate("wall", duration=0.01, blocks=12, history=npz, recording=rrd)
    with np.load(npz) as h:
        started = json.loads(str(h["run"]))["started"]
    assert rows(run.report())["started"] == started == rows(invoke("report", npz).output)["started"]


def test_the_page_says_where_the_joints_open_most_on_the_map_too(at2, tmp_path):
    """A wall traced in Lambert-93 shaken at 1.5 g: the state's line gives the largest opening, the page now names
    the block whose joints open most and where it stands, in the run's coordinates and on the survey's map."""
    import surveyed_wall

    wall = tmp_path / "l93.geojson"
    surveyed_wall.write(wall, offset=surveyed_wall.LAMBERT93, slip=0.0, ndigits=6)
    npz = tmp_path / "h.npz"
    args = ("--record", at2, "--pga", 1.5, "--duration", 0.5, "--settle", 0.2)
    result = invoke("run", wall, *args, "--no-recording", "--history", npz)
    assert result.exit_code == 0, result.output
    h = np.load(npz, allow_pickle=False)
    k = int(np.argmax(h["block_max_opening"][-1]))
    x, y = h["block_q"][-1][k, :2]
    origin = json.loads(str(h["run"]))["reading"]["map_origin_m"]
    said = rows(invoke("report", npz).stdout)["most open (end)"]
    assert said.startswith(f"{h['block_name'][k]}'s joints, {1000 * h['block_max_opening'][-1][k]:.3g} mm; ")
    assert f"its centroid at ({x:.3f}, {y:.3f}) m (on the map ({x + origin[0]:.3f}, {y + origin[1]:.3f}))" in said
