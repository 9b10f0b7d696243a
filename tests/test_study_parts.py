"""The parts of a study without a cluster: axes, grid points, threshold bisection, rows on disk, fragility."""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
from scipy.stats import norm

from masonrycli.errors import InputError
from masonrycli.outputs.files import OutputFile
from masonrycli.records.read import record_motion
from masonrycli.scenario.motion import Constant, Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder
from masonrycli.study import store
from masonrycli.study.axes import Axis, StudyBase, apply_point, check_axes, grid, parse_axis
from masonrycli.study.curves import fit_label
from masonrycli.study.drivers import FindDriver, GridDriver
from masonrycli.study.fragility import fit_lognormal
from masonrycli.study.task import check_outcome, empty_result, reached, run_task


def test_a_range_s_values_are_the_decimals_it_names():
    # np.linspace(0.4, 0.8, 5) holds 0.6000000000000001 and 0.7000000000000001: a study's rows and CSV had them
    assert parse_axis("friction=0.4:0.8:5").values == (0.4, 0.5, 0.6, 0.7, 0.8)
    assert parse_axis("amp=0.1:1.0:10").values == tuple(k / 10 for k in range(1, 11))
    assert parse_axis("pga_g=0.1:1.0:10").values[2] == 0.3  # not 0.30000000000000004
    third = parse_axis("scale=0.32:1.6:10").values[1]  # not a short decimal: kept to 15 digits
    assert third == float(f"{0.32 + 1.28 / 9:.15g}") and abs(third - (0.32 + 1.28 / 9)) < 1e-15
    assert parse_axis("x=0.123456789012345:0.2:2").values[0] == 0.123456789012345  # LO as typed


def test_parse_axis_forms_and_errors():
    assert parse_axis("amp=0.1:1.0:4").values == pytest.approx((0.1, 0.4, 0.7, 1.0))
    assert parse_axis("ground.amp=0.2,0.8").values == (0.2, 0.8)
    assert parse_axis("blocks=12,51").values == (12, 51) and isinstance(parse_axis("blocks=12").values[0], int)
    assert parse_axis("friction=0.6").values == (0.6,)
    for text, fragment in [
        ("amp", "expected NAME=LO:HI:N"),
        ("amp=1:2", "a range is LO:HI:N"),
        ("amp=1:2:x", "must be a whole number"),
        ("amp=2:1:3", "HI must be >= LO"),
        ("amp=1:2:1", "N must be >= 2"),
        ("amp=a,b", "'a' is not a number$"),
        ("amp=0.1m/s:1:3", r"'0.1m/s' is not a number \(write 0.1, in m/s, without the unit\)"),
        ("amp=0.1,2Hz", r"'2Hz' is not a number \(it is read in m/s: convert 2 Hz to m/s"),
        ("freq=2 Hz", r"'2 Hz' is not a number \(write 2, in Hz, without the unit\)"),
        ("friction=0.6mu", r"\(write 0.6, without \"mu\": this setting has no unit\)"),
        ("amp=nan", "values must be finite"),
        ("blocks=12.5", "blocks takes whole numbers"),
        ("amp=0:1:1000000000", "N = 1000000000 values, more than 1000000"),  # used to allocate for minutes
    ]:
        with pytest.raises(InputError, match=fragment):
            parse_axis(text)
    with pytest.raises(InputError, match=r"grid has 1000000000000 points \(1000000 amp × 1000000 freq\)"):
        check_axes([parse_axis("amp=0:1:1000000"), parse_axis("freq=1:2:1000000")])
    assert grid([Axis("a", (1, 2)), Axis("b", (3, 4))]) == [
        {"a": 1, "b": 3},
        {"a": 1, "b": 4},
        {"a": 2, "b": 3},
        {"a": 2, "b": 4},
    ]


@pytest.fixture(scope="module")
def arch_base():
    motions = {"left-foundation": Sine(amplitude=1.0, frequency=2.0), "right-foundation": Constant(velocity=(0, -0.01))}
    return StudyBase(scenario_from_builder("arch", {}, RunConfig(duration=0.1), Material(), motions))


def test_apply_point_changes_what_it_names(arch_base, tmp_path):
    s = apply_point(arch_base, {"amp": 0.5, "freq": 3.0, "friction": 0.7, "duration": 0.2})
    assert s.motions[0] == Sine(amplitude=0.5, frequency=3.0) and s.motions[1] == Constant(velocity=(0, -0.01))
    assert s.material.friction == 0.7 and s.run.duration == 0.2
    s = apply_point(arch_base, {"left-foundation.phase": 1.0})
    assert s.motions[0].phase == 1.0
    s = apply_point(arch_base, {"voussoirs": 20})
    assert s.block_count == arch_base.scenario.block_count - 10 and s.motions == arch_base.scenario.motions
    for params, fragment in [
        ({"bogus": 1.0}, "--param bogus: unknown parameter"),
        ({"scale": 2.0}, "has no record motion"),
        ({"pad.amp": 1.0}, "no support named 'pad'"),
        ({"right-foundation.amp": 1.0}, "has no sine motion on right-foundation"),
        ({"freq": -1.0}, "--param freq: frequency = -1.0: must be >= 0"),
        ({"dt": 1.0}, "must be <= duration"),
    ]:
        with pytest.raises(InputError, match=fragment):
            apply_point(arch_base, params)
    rec = record_motion(_csv(tmp_path), quantity="acceleration")
    base = StudyBase(arch_base.scenario, {"q.csv": rec})
    s = apply_point(base, {"record": "q.csv", "scale": 2.0})
    assert s.motions[0].scale == 2.0 and s.motions[0].time is rec.time and s.motions[1].kind == "constant"


def _csv(tmp_path):
    (tmp_path / "q.csv").write_text("0,0\n0.05,1\n0.1,0\n")
    return tmp_path / "q.csv"


def _row(amp, threshold):
    # a fake run: the outcome happens from `threshold` on
    row = empty_result("", 0.1) | {"status": "completed", "state": "collapsed" if amp >= threshold else "intact"}
    return row | {"slide_time": 0.01 if amp >= threshold else math.nan}


def test_a_point_the_builder_refuses_names_the_point_and_the_builder_once(arch_base):
    # said 'builder "arch": arch: ring_thickness ...' (the builder twice, the point not at all)
    with pytest.raises(InputError) as info:
        apply_point(arch_base, {"pier_width": 0.2, "amp": 0.5})
    assert str(info.value).startswith('--param pier_width=0.2: builder "arch": ring_thickness 0.35 m is wider')


def _search(driver: FindDriver, outcome_at) -> list[dict]:
    """Run ``driver`` to the end, the fake run at each point producing the outcome where ``outcome_at``."""
    queue = driver.start()
    while queue:
        p = queue.pop()
        queue += driver.feed(p, _row(1.0 if outcome_at(p) else -1.0, 0.0))
    return driver.rows()


def test_find_driver_bisects_an_outcome_that_comes_below_a_value():
    # "--find friction --outcome sliding": a block slides below a friction. The row said "sliding already at
    # friction = 0.1, not at friction = 2: it comes below a value here", with no threshold; now the mirrored
    # bracket: the largest friction that slides, the smallest that does not
    driver = FindDriver([Axis("friction", (0.1, 0.7, 2.0))], "friction", "sliding", 0.005, done={})
    (row,) = _search(driver, lambda p: p["friction"] < 1.28)
    assert row["holds"] == "below" and row["note"] == "" and row["status"] == "completed"
    assert row["friction_lo"] < 1.28 <= row["friction_hi"]
    assert row["friction_hi"] - row["friction_lo"] <= 0.005 * row["friction_hi"]
    assert abs(row["friction_threshold"] - 1.28) <= 0.0025 * 1.28
    # 3 values, then the bracket 0.7..2 halved until narrower than 0.5 % of its top
    assert row["evaluations"] == 3 + math.ceil(math.log2((2.0 - 0.7) / (0.005 * 1.28)))


def test_find_driver_ends_below_zero_and_around_zero():
    # "× hi" never held for a bracket below 0: --find amp over amp=-1:-0.1:3 ran the same point for ever
    driver = FindDriver([Axis("amp", (-1.0, -0.55, -0.1))], "amp", "sliding", 0.005, done={})
    (row,) = _search(driver, lambda p: p["amp"] < -0.468)
    assert row["holds"] == "below" and row["amp_lo"] < -0.468 <= row["amp_hi"]
    assert row["amp_hi"] - row["amp_lo"] <= 0.005 * 0.469 and row["evaluations"] < 20
    # a threshold at 0 exactly has no relative width to reach: it ends where float64 has no middle left
    driver = FindDriver([Axis("amp", (-1.0, 1.0))], "amp", "sliding", 0.005, done={})
    (row,) = _search(driver, lambda p: p["amp"] > 0.0)
    assert row["amp_lo"] <= 0.0 < row["amp_hi"] and row["evaluations"] < 1200


def test_find_driver_notes_an_outcome_at_both_ends_or_neither():
    axis = [Axis("friction", (0.1, 0.7, 2.0))]
    (row,) = _search(FindDriver(axis, "friction", "sliding", 0.005, done={}), lambda p: True)
    assert math.isnan(row["friction_threshold"]) and row["holds"] == ""
    assert row["note"] == "sliding already at friction = 0.1" and row["friction_hi"] == 0.1  # the curve's mark
    (row,) = _search(FindDriver(axis, "friction", "sliding", 0.005, done={}), lambda p: False)
    assert math.isnan(row["friction_threshold"]) and row["holds"] == "" and math.isnan(row["friction_hi"])
    assert row["note"] == "no sliding up to friction = 2"
    # at both ends, not between: neither direction fits; the note says so and a grid shows the rest
    (row,) = _search(FindDriver(axis, "friction", "sliding", 0.005, done={}), lambda p: p["friction"] != 0.7)
    assert (
        math.isnan(row["friction_threshold"])
        and row["holds"] == ""
        and row["note"]
        == (
            "sliding already at friction = 0.1, not at friction = 0.7, again at friction = 2: it comes and goes over "
            "the range (a grid shows where it holds)"
        )
    )


def test_find_driver_says_when_its_runs_are_not_monotone():
    # the wall at 2 Hz collapses at 1.25 m/s and stands at 1.5 m/s: --find amp gave one threshold as if it
    # were the only one. The runs that show it are named, in the row's note and a warning line.
    axes = [Axis("amp", (0.25, 0.5, 0.75, 1.0, 1.25, 1.5)), Axis("freq", (2.0,))]
    driver = FindDriver(axes, "amp", "collapse", 0.005, done={})
    (row,) = _search(driver, lambda p: 0.9 < p["amp"] < 1.4)
    assert row["holds"] == "above" and 0.75 < row["amp_threshold"] < 1.0
    assert row["note"] == "not monotone: collapse at amp = 1.25, not at amp = 1.5"
    assert driver.warnings == [
        f"--find amp (freq = 2): collapse at amp = 1.25, not at amp = 1.5: not monotone in amp, so the threshold "
        f"{row['amp_threshold']:g} is one of several — a grid over the range shows where it holds"
    ]
    # mirrored: sliding below a friction, then again above a friction that does not slide
    driver = FindDriver([Axis("friction", (0.1, 0.4, 0.7, 1.0))], "friction", "sliding", 0.005, done={})
    (row,) = _search(driver, lambda p: p["friction"] < 0.3 or 0.6 < p["friction"] < 0.8)
    assert row["holds"] == "below" and row["note"] == "not monotone: sliding at friction = 0.7, not at friction = 0.4"
    assert len(driver.warnings) == 1 and "sliding at friction = 0.7, not at friction = 0.4: not" in driver.warnings[0]
    # the range's ends both reached, not between: the note says it already; the warning line too
    driver = FindDriver([Axis("friction", (0.1, 0.7, 2.0))], "friction", "sliding", 0.005, done={})
    (row,) = _search(driver, lambda p: p["friction"] != 0.7)
    assert row["note"].endswith("it comes and goes over the range (a grid shows where it holds)")
    assert driver.warnings == [
        "--find friction: sliding at friction = 0.1, not at friction = 0.7: not monotone in friction, so no "
        "threshold — a grid over the range shows where it holds"
    ]
    # monotone searches say nothing
    for outcome_at in (lambda p: p["amp"] > 0.6, lambda p: True, lambda p: False):
        driver = FindDriver(axes, "amp", "collapse", 0.005, done={})
        (row,) = _search(driver, outcome_at)
        assert driver.warnings == [] and not row["note"].startswith("not monotone")


def test_find_driver_searches_again_a_row_that_said_the_outcome_comes_below():
    # a table written before the downward search: its row had no threshold and that note; resumed, it is run
    # again (and an upward row of then is kept, marked as found upwards)
    axes = [Axis("friction", (0.1, 0.7, 2.0)), Axis("amp", (0.2, 0.4))]
    old_below = {
        "amp": 0.2,
        "friction_threshold": math.nan,
        "note": "sliding already at friction = 0.1, not at "
        "friction = 2: it comes below a value here; --find looks for the smallest value that brings it",
    }
    old_above = {"amp": 0.4, "friction_threshold": 0.9, "note": ""}
    done = {store.row_key(r, ["amp"]): r for r in (old_below, old_above)}
    driver = FindDriver(axes, "friction", "sliding", 0.005, done=done)
    assert {p["amp"] for p in driver.start()} == {0.2} and driver.skipped == 1
    assert [r["holds"] for r in driver.rows()] == ["above"]


def test_find_driver_bisects_to_rtol_and_reports_the_ends():
    axes = [Axis("amp", (0.1, 0.4, 0.7, 1.0)), Axis("freq", (1.0, 2.0, 3.0))]
    thresholds = {1.0: 0.55, 2.0: 0.05, 3.0: 5.0}
    driver = FindDriver(axes, "amp", "collapse", 0.005, done={})
    queue = driver.start()
    assert len(queue) == 12
    runs = 0
    while queue:
        p = queue.pop()
        runs += 1
        queue += driver.feed(p, _row(p["amp"], thresholds[p["freq"]]))
    rows = {r["freq"]: r for r in driver.rows()}
    r = rows[1.0]
    assert r["amp_lo"] < 0.55 <= r["amp_hi"] and (r["amp_hi"] - r["amp_lo"]) <= 0.005 * r["amp_hi"]
    assert abs(r["amp_threshold"] - 0.55) <= 0.0025 * 0.55 and r["evaluations"] == 4 + 7
    assert math.isnan(rows[2.0]["amp_threshold"]) and "collapse already at amp = 0.1" in rows[2.0]["note"]
    assert math.isnan(rows[3.0]["amp_threshold"]) and "no collapse up to amp = 1" in rows[3.0]["note"]
    assert runs == 12 + 7 and len(driver.finished) == 3
    assert r["holds"] == "above" and rows[2.0]["holds"] == rows[3.0]["holds"] == ""
    assert "not at" not in rows[2.0]["note"]  # it collapses at every amplitude tried
    # resume: a finished point is not searched again
    again = FindDriver(axes, "amp", "collapse", 0.005, done={store.row_key(rows[1.0], ["freq"]): rows[1.0]})
    assert {p["freq"] for p in again.start()} == {2.0, 3.0} and again.skipped == 1


def test_outcomes():
    row = _row(1.0, 0.5) | {"peak_drift": 0.02, "rock_time": math.nan}
    assert reached(row, "collapse") and reached(row, "sliding") and not reached(row, "rocking")
    assert reached(row, "drift:0.01") and not reached(row, "drift:0.03")
    assert check_outcome("drift:0.01") == "drift:0.01"
    for bad in ("fall", "drift:x", "drift:-1"):
        with pytest.raises(InputError):
            check_outcome(bad)
    # "drift:50" (50 % meant) searched for a top drift of 50 heights: "no drift:50 up to …" at every point
    with pytest.raises(InputError, match=r"drift:50: a drift of 50 × the height, .* drift:0.5 is 50 %\)$"):
        check_outcome("drift:50")
    with pytest.raises(InputError, match=r"\(write drift:0.05: a percentage is written as a fraction\)$"):
        check_outcome("drift:5%")
    assert check_outcome("drift:1") == "drift:1"


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_rows_round_trip_and_journal(tmp_path, suffix):
    out = tmp_path / f"study{suffix}"
    rows = [
        {"amp": 0.1 + 0.2, "record": "a.AT2", "state": "intact", "error": "", "x": math.nan, "study": "1234e567"},
        {"amp": 1.0, "record": "b.AT2", "state": "", "error": "boom, it failed", "x": 2.5, "study": "1234e567"},
    ]
    journal = store.Journal(out)
    journal.append(rows[0])
    journal.close()
    assert store.read_rows(out) == [rows[0] | {"x": store.read_rows(out)[0]["x"]}]  # journal alone
    assert store.write_rows(OutputFile(out, "--out"), rows, list(rows[0])) == out
    assert not store.journal_path(out).exists() and sorted(tmp_path.iterdir()) == [out]  # no temporary file
    back = store.read_rows(out)
    assert back[0]["amp"] == 0.1 + 0.2 and back[0]["study"] == "1234e567" and math.isnan(back[0]["x"])
    assert back[1]["error"] == "boom, it failed" and back[1]["record"] == "b.AT2"
    assert store.row_key(back[0], ["amp", "record"]) == store.row_key(rows[0], ["amp", "record"])
    with pytest.raises(InputError, match="a study is written as .parquet or .csv"):
        store.check_out(tmp_path / "study.txt")


def test_grid_driver_skips_done_rows():
    axes = [Axis("amp", (0.1, 0.2, 0.3))]
    done = {store.row_key({"amp": 0.2}, ["amp"]): {"amp": 0.2, "state": "intact"}}
    driver = GridDriver(axes, done)
    assert driver.start() == [{"amp": 0.1}, {"amp": 0.3}] and driver.skipped == 1 and driver.total == 3
    driver.feed({"amp": 0.3}, {"amp": 0.3, "state": "collapsed"})
    assert [r["amp"] for r in driver.rows()] == [0.2, 0.3]


def test_failed_task_is_a_row(arch_base):
    row = run_task(arch_base, {"amp": 0.5, "dt": 1.0})
    assert row["status"] == "error" and "must be <= duration" in row["error"] and row["amp"] == 0.5
    assert math.isnan(row["pga"]) and row["state"] == ""


def test_a_row_s_cpu_time_is_its_own_not_its_neighbour_s(arch_base, monkeypatch):
    # a worker of two threads (`dask worker --nthreads 2`) runs two tasks at once: each row's cpu_time was the
    # process's, the other task's CPU too (12 runs of the wall: 11.0 s in all, 5.7 s on 1-thread workers)
    import hashlib
    import threading
    import time

    from masonrycli import run

    real, spent = run.simulate, []

    def beside_a_busy_thread(*args, **kwargs):  # a task on the worker's other thread: fixed work, GIL released
        data = bytes(20_000_000)
        before = time.process_time()
        other = threading.Thread(target=lambda: [hashlib.sha256(data).digest() for _ in range(40)])
        other.start()
        other.join()
        spent.append(time.process_time() - before)
        return real(*args, **kwargs)

    alone = run_task(arch_base, {"amp": 0.5})["cpu_time"]
    alone = min(alone, run_task(arch_base, {"amp": 0.5})["cpu_time"])  # the first may compile
    monkeypatch.setattr(run, "simulate", beside_a_busy_thread)
    row = run_task(arch_base, {"amp": 0.5})
    assert row["status"] == "completed" and spent[0] > 0.2  # the neighbour's CPU, in the process's
    assert row["cpu_time"] < alone + 0.5 * spent[0], (row["cpu_time"], alone, spent)


def test_lognormal_fit_recovers_known_median_and_dispersion():
    rng = np.random.default_rng(7)
    theta, beta = 0.8, 0.4
    im = np.exp(rng.uniform(np.log(0.2), np.log(3.0), 4000))
    collapsed = rng.uniform(size=im.size) < norm.cdf(np.log(im / theta) / beta)
    fit = fit_lognormal(im, collapsed, "sa")
    assert fit.median == pytest.approx(theta, rel=0.05) and fit.dispersion == pytest.approx(beta, rel=0.1)
    assert fit.probability([theta])[0] == pytest.approx(0.5, abs=0.03)
    assert fit_lognormal([1, 2], [True, True]) is None and fit_lognormal([1], [True]) is None
    assert fit.separated is None


def test_lognormal_fit_of_separated_runs_says_the_dispersion_is_not_resolved():
    # Every collapse above every run that stood: the likelihood grows without end as β -> 0, and the fit
    # stopped near its 0.01 bound, which `masonry sweep` printed as "dispersion β = 0.016".
    fit = fit_lognormal([1.0, 1.5, 2.0, 3.0, 4.0], [False, False, False, True, True], "pgv")
    assert fit.separated == (2.0, 3.0) and 2.0 <= fit.median <= 3.0 and fit.dispersion < 0.05
    assert fit_lognormal([1.0, 2.0, 3.0, 4.0], [False, True, False, True]).separated is None


def test_lognormal_fit_of_collapses_below_the_runs_that_stood_is_not_resolved():
    # 'masonry sweep wall --records recs --scale=-6:6:3': the record that collapsed did so at a lower pga
    # (21.9 m/s²) than the one that stood (29.2): the likelihood grows as β -> ∞, and the fit's bound
    # was printed as a curve, "median θ = 25.3 m/s², dispersion β = 5.000"
    fit = fit_lognormal([21.9, 21.9, 29.2, 29.2], [True, True, False, False], "pga")
    assert fit.unbounded and fit.separated is None and fit_label(fit, "m/s²").startswith("lognormal: not resolved")
    resolved = fit_lognormal([1.0, 2.0, 3.0, 4.0], [False, True, False, True])
    assert not resolved.unbounded and fit_label(resolved, "m").startswith("lognormal: θ = ")


def test_closing_the_cluster_silences_its_teardown_logs(capfd):
    # Stopped with 20 000 tasks queued, the LocalCluster's scheduler (in this process) printed 21-47
    # "CRITICAL - Closed comm ... while trying to write" tracebacks under the one-line "interrupted".
    import logging
    import sys

    from masonrycli.study.study import _close

    handler = logging.StreamHandler(sys.stderr)  # as distributed's own handler
    scheduler = logging.getLogger("distributed.scheduler")
    scheduler.addHandler(handler)

    class Closing:
        def close(self):
            scheduler.critical("Closed comm <BatchedSend: closed> while trying to write")

    try:
        _close(Closing(), Closing())
        assert capfd.readouterr().err == ""
        scheduler.critical("after")  # logging works again once the cluster is closed
        assert "after" in capfd.readouterr().err
    finally:
        scheduler.removeHandler(handler)


def test_a_run_whose_output_failed_is_an_error_row_with_its_message(arch_base, tmp_path, monkeypatch):
    """simulate returns status "failed" (no exception) when a history write fails mid-run: the row said
    status "failed" with an empty error column, was not counted as failed and not run again on resume."""
    from masonrycli.outputs.history import HistoryFile

    def disk_full(self, frame):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(HistoryFile, "on_frame", disk_full)
    row = run_task(arch_base, {"amp": 0.5}, history_dir=str(tmp_path))
    assert row["status"] == "error" and row["state"] == "" and row["amp"] == 0.5
    assert row["error"].startswith("failed: cannot write --histories ") and "No space left on device" in row["error"]
    assert f"{tmp_path / 'amp=0.5.npz'}: stopped at t = " in row["error"]  # which file


def test_a_history_that_cannot_be_finished_names_its_file(arch_base, tmp_path, monkeypatch):
    """A full disk as the history was assembled (its close) said "OSError: [Errno 28] No space left on device"."""
    from masonrycli.outputs.history import HistoryFile

    def disk_full(self, *args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(HistoryFile, "close", disk_full)
    row = run_task(arch_base, {"amp": 0.5}, history_dir=str(tmp_path))
    assert row["status"] == "error" and row["amp"] == 0.5
    assert row["error"] == f"cannot write --histories {tmp_path / 'amp=0.5.npz'}: No space left on device"
    assert os.listdir(tmp_path) == []


def test_a_history_written_whole_removes_what_killed_writers_of_it_left(arch_base, tmp_path):
    # a --scheduler's worker killed inside a run left .amp=0.2_freq=3.npz.4718.part and its .rows folder (3 MB)
    # in --histories for good: the point ran again elsewhere, and the command cleans up only its local workers'
    import subprocess
    import sys

    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead, alive = int(gone.stdout), os.getppid()  # a writer that ended, and one running (another study's)
    for pid in (dead, alive):
        (tmp_path / f".amp=0.5.npz.{pid}.part").write_bytes(b"")
        (tmp_path / f".amp=0.5.npz.{pid}.part.rows").mkdir()
        (tmp_path / f".amp=0.5.npz.{pid}.part.rows" / "block_q.raw").write_bytes(b"0" * 1000)
    (tmp_path / f".amp=0.75.npz.{dead}.part").write_bytes(b"")  # another point's: its own run removes it
    row = run_task(arch_base, {"amp": 0.5}, history_dir=str(tmp_path))
    assert row["status"] == "completed", row["error"]
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        f".amp=0.5.npz.{alive}.part",
        f".amp=0.5.npz.{alive}.part.rows",
        f".amp=0.75.npz.{dead}.part",
        "amp=0.5.npz",
    ]


def test_a_history_of_the_same_study_is_replaced_another_is_kept(arch_base, tmp_path):
    # walk-through 2026-11-28: Ctrl-C on `masonry sweep wall … --histories hist`: the workers finished the runs in
    # flight and wrote their histories, whose rows the table never got; the same command then refused to resume
    # ("--histories hist/amp=1.10909.npz: the file exists (add --force to replace it)")
    import json

    import numpy as np

    for _ in range(2):  # the second run of the same study replaces the first's history
        row = run_task(arch_base, {"amp": 0.5}, history_dir=str(tmp_path), study=("abc", "/s.csv"))
        assert row["status"] == "completed", row
    assert sorted(p.name for p in tmp_path.iterdir()) == ["amp=0.5.npz"]
    run = json.loads(str(np.load(tmp_path / "amp=0.5.npz")["run"]))
    assert (run["study"], run["study_table"]) == ("abc", "/s.csv")
    run_task(arch_base, {"amp": 0.5}, history_dir=str(tmp_path), study=("xyz", "/s.csv"))  # another study's: kept
    assert sorted(p.name for p in tmp_path.iterdir()) == ["amp=0.5-2.npz", "amp=0.5.npz"]


def test_the_fragility_line_counts_the_runs_at_zero_intensity_it_leaves_out():
    # '--scale 0:6:3' printed "(1 of 4 runs collapsed)" under a table of 6 rows: the 2 at pga 0 left out unsaid
    from masonrycli.cli.sweep import _at_zero

    rows = [{"pga": 0.0}, {"pga": 0.0}, {"pga": 21.9}, {"pga": math.nan}]
    assert _at_zero(rows, "pga") == "; 3 runs at pga = 0 left out"
    assert _at_zero([{"pga": 1.0}], "pga") == ""


def test_a_swept_parameter_has_the_unit_it_is_read_in(tmp_path):
    """The axes' units come from geometry_library.values (OPTION_UNITS, SETTING_UNITS): a dict of five names in
    study/curves.py left a study over pga_g (g) or length (m) with bare plot axes and inspect columns."""
    from masonrycli.study.curves import with_unit
    from masonrycli.study.inspect_table import study_summary

    table = tmp_path / "s.csv"
    table.write_text(
        "record,length,pga_g,friction,state,pga,status,study,source\n"
        "q.AT2,0.9,0.1,0.6,intact,0.98,completed,abc,def\n"
        "q.AT2,0.9,0.2,0.6,intact,1.96,completed,abc,def\n"
    )
    rows, columns = study_summary(table)
    assert dict(columns)["pga_g"] == "g, swept" and dict(columns)["length"] == "m, swept"
    assert dict(columns)["friction"] == "swept parameter"  # no unit
    assert dict(rows)["pga_g"] == "0.1, 0.2 g"
    assert [with_unit(n) for n in ("pga_g", "ground.amp", "length", "friction")] == [
        "pga_g (g)", "ground.amp (m/s)", "length (m)", "friction"
    ]  # fmt: skip
