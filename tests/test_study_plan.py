"""The options of ``masonry sweep`` checked into a study (masonrycli.study.plan), without the command line:
each bad or conflicting option is one line naming it, the first problem wins, and nothing is written
before the study runs."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from masonrycli.errors import InputError
from masonrycli.records.read import G_STANDARD
from masonrycli.study.plan import plan_study

from synthetic_records import band_limited, write_at2

BLOCK = Path(__file__).parent / "data" / "block_on_ground.toml"  # a sine-shaken block, 1 s


@pytest.fixture
def block(tmp_path, monkeypatch) -> str:
    monkeypatch.chdir(tmp_path)  # the default table, plot and recording are named in the working folder
    shutil.copy(BLOCK, tmp_path / "block.toml")
    return "block.toml"


def _refused(target: str, **options) -> str:
    with pytest.raises(InputError) as refused:
        plan_study(target, **options)
    return str(refused.value)


def test_a_bad_axis_is_one_line_naming_it(block):
    assert _refused(block, params=["amp=1:2"]) == "--param amp=1:2: a range is LO:HI:N (e.g. amp=0.1:1.0:10)"
    # the axes are checked before the options that go together: the first problem is the one said
    assert _refused(block, params=["amp=1:2"], workers=2, scheduler="tcp://x:1").startswith("--param amp=1:2:")


def test_a_repeated_axis_or_a_search_without_its_range_comes_before_the_files_beside_out(block, tmp_path):
    # "--out's plot s.png: the file exists" was said first; with --force the run then said "given twice"
    (tmp_path / "s.png").write_bytes(b"png")
    twice = {"params": ["amp=0.1", "amp=0.2"], "out": Path("s.csv")}
    assert _refused(block, **twice) == "--param amp: given twice"
    alone = {"params": ["amp=0.1,0.2"], "find": "freq", "out": Path("s.csv")}
    assert _refused(block, **alone) == "--find freq: give its range too, e.g. --param freq=0.1:1.0:4"
    one = {"params": ["amp=0.1"], "find": "amp", "out": Path("s.csv")}
    assert _refused(block, **one) == "--find amp: needs a numeric range LO:HI:N with N >= 2"
    assert _refused(block, params=["amp=0.1,0.2"], out=Path("s.csv")).startswith("--out's plot s.png: the file exists")


@pytest.mark.parametrize(
    "options, message",
    [
        ({"params": []}, "nothing to sweep: give --param NAME=..., or --records DIR"),
        (
            {"workers": 2, "scheduler": "tcp://x:1"},
            "--workers with --scheduler: the existing cluster has its own workers",
        ),
        ({"workers": -1}, "--workers -1: must be >= 0"),
        ({"rtol": 0.1}, "--rtol 0.1: goes with --find (a grid reports every run's state)"),
        ({"outcome": "sliding"}, "--outcome sliding: goes with --find (a grid reports every run's state)"),
        ({"find": "amp", "rtol": 1.0}, "--rtol 1: must be in (0, 1)"),
        ({"recording": Path("x.rrd"), "no_recording": True}, "--recording x.rrd with --no-recording: choose one"),
        ({"im": "d5_95"}, "--im d5_95: expected one of pga, pgv, arias, sa"),
    ],
)
def test_conflicting_or_bad_options_are_one_line_naming_them(block, options, message):
    options = {"params": ["amp=0.1,0.2"]} | options
    assert _refused(block, **options) == message


def test_a_checked_study_has_the_defaults_and_nothing_is_written(block, tmp_path):
    plan = plan_study(block, params=["amp=0.1,0.2"], no_recording=True, stop_at_collapse=False)
    request = plan.request
    assert request.out == Path(f"study-{plan.name}.parquet")
    assert (request.outcome, request.rtol, request.find, request.stop_at_collapse) == ("collapse", 0.005, None, False)
    assert [(a.name, a.values) for a in request.axes] == [("amp", (0.1, 0.2))]
    # the plot beside the table is named as the --out's: the user gave no --plot
    assert plan.picture.path == request.out.with_suffix(".png") and plan.recording is None
    assert [p.name for p in tmp_path.iterdir()] == ["block.toml"]


def _record(folder: Path, seconds: float) -> Path:
    folder.mkdir()
    t, u, v, a = band_limited(seconds, 0.01, [1.0, 2.5], [0.03, 0.01], seed=0)
    write_at2(folder / "syn0.AT2", a / G_STANDARD, 0.01)
    return folder


def test_records_make_the_first_axis_and_the_runs_shorter_than_them_a_warning(block, tmp_path):
    folder = _record(tmp_path / "records", 1.5)
    said = []
    plan = plan_study(block, records=[folder], scale="0.5,1", out=Path("s.csv"), warn=said.append)
    assert [(a.name, a.values) for a in plan.request.axes] == [("record", ("syn0.AT2",)), ("scale", (0.5, 1.0))]
    # the scenario file's 1 s stands; the warning is said by run_study once the table is checked
    assert plan.base.scenario.run.duration == 1.0 and said == []
    assert plan.request.warnings == (
        "the runs' 1 s are shorter than 1 of 1 records (longest 1.5 s, syn0.AT2): their shaking after t = 1 s "
        "is not applied",
    )
    assert plan.request.warn == said.append


def test_a_built_in_without_duration_lasts_the_longest_record(block, tmp_path):
    folder = _record(tmp_path / "records", 1.5)
    plan = plan_study("wall", records=[folder], out=Path("s.csv"))
    run = plan.base.scenario.run
    assert run.duration == pytest.approx(1.5) and plan.request.warnings == ()
    # with a --duration the runs are that long, and shorter than the record
    plan = plan_study("wall", records=[folder], out=Path("s.csv"), duration=1.0)
    assert plan.base.scenario.run.duration == 1.0 and "shorter than 1 of 1 records" in plan.request.warnings[0]


def test_the_runs_shorter_than_records_warning_names_the_longest_record(block, tmp_path):
    folder = tmp_path / "records"
    folder.mkdir()
    for name, seconds in (("a-short.AT2", 1.5), ("b-long.AT2", 3.0)):
        t, u, v, a = band_limited(seconds, 0.01, [1.0, 2.5], [0.03, 0.01], seed=0)
        write_at2(folder / name, a / G_STANDARD, 0.01)
    plan = plan_study(block, records=[folder], scale="1", out=Path("s.csv"))
    # both are longer than the scenario's 1 s; the 3 s one is named with its 3 s, not the first late one
    assert plan.request.warnings == (
        "the runs' 1 s are shorter than 2 of 2 records (longest 3 s, b-long.AT2): their shaking after t = 1 s "
        "is not applied",
    )


def test_a_record_set_gets_the_warnings_simulate_gives_each_record(block, tmp_path):
    # '--records recs --scale 9.81' (an .AT2 converted twice), '--scale 1,40' (16 g) and a record sampled
    # every 0.5 ms on the 1 ms steps ran without a word; 'simulate --record' warns of each
    folder = _record(tmp_path / "records", 0.5)
    twice = plan_study("wall", records=[folder], scale="1,9.81", out=Path("a.csv")).request.warnings
    assert len(twice) == 1 and "is read in g and converted to m/s² already; scale 9.81 converts it again" in twice[0]
    strong = plan_study("wall", records=[folder], scale="1,400", out=Path("b.csv")).request.warnings
    assert len(strong) == 1 and "the record syn0.AT2 peaks at" in strong[0] and "(scale 400)" in strong[0]
    fine = tmp_path / "fine"
    fine.mkdir()
    t, u, v, a = band_limited(0.2, 0.0005, [2.0], [0.01], seed=0)
    write_at2(fine / "fine.AT2", a / G_STANDARD, 0.0005)
    said = plan_study("wall", records=[fine], out=Path("c.csv")).request.warnings
    assert said == (
        'support "ground": the record fine.AT2 is sampled every 0.0005 s, finer than dt = 0.001 s: the steps skip '
        "samples and alias its content above 500 Hz (dt = 0.0005 follows every sample)",
    )
    # a record as it is, run whole on steps that follow it: nothing to say
    assert plan_study("wall", records=[folder], scale="0.5,1", out=Path("d.csv")).request.warnings == ()


def test_a_dt_need_not_divide_the_built_in_s_duration_when_the_records_set_it(tmp_path):
    # 'masonry sweep wall --records recs --dt 0.003' said "--dt: dt = 0.003: does not divide duration = 1.0"
    # (the built-in's 1 s, which the records replace: the runs last 1.5 s, 500 steps of 0.003 s)
    folder = _record(tmp_path / "records", 1.5)
    run = plan_study("wall", records=[folder], dt=0.003, out=Path("s.csv")).base.scenario.run
    assert run.dt == 0.003 and round(run.duration / run.dt) == 500 and run.duration == pytest.approx(1.5)
    # a dt wrong on its own is still refused as the option, and a --duration still has to fit
    assert _refused("wall", records=[folder], dt=0.0, out=Path("s.csv")) == "--dt: dt = 0.0: must be > 0"
    assert "duration = 1.0 is not a whole number of steps of dt = 0.003" in _refused(
        "wall", records=[folder], dt=0.003, duration=1.0
    )


def test_a_sine_axis_over_records_says_their_axis_is_scale(tmp_path):
    # '--records recs --param amp=0.5,1' said "--param amp: wall has no sine motion" (it has one, which the
    # records replace): the records' intensity is --scale
    folder = _record(tmp_path / "records", 0.5)
    assert _refused("wall", records=[folder], params=["amp=0.5,1"], out=Path("s.csv")) == (
        "--param amp: wall has no sine motion (--records drives it by the records: their axis is --scale)"
    )


def test_a_vertical_component_in_a_record_set_is_named(tmp_path):
    # an unzipped NGA-West2 search (each recording's H1, H2 and UP .AT2 files) ran the vertical components
    # along x as horizontal records, without a word
    folder = tmp_path / "records"
    folder.mkdir()
    t, u, v, a = band_limited(0.5, 0.01, [2.0], [0.01], seed=0)
    write_at2(folder / "RSN6_IMPVALL.I_I-ELC180.AT2", a / G_STANDARD, 0.01)
    write_at2(folder / "RSN6_IMPVALL.I_I-ELCUP.AT2", a / G_STANDARD, 0.01)
    write_at2(folder / "q3.AT2", a / G_STANDARD, 0.01, title="IMPERIAL VALLEY 10/15/79 2316, EL CENTRO ARRAY #6, UP")
    write_at2(folder / "q4.AT2", a / G_STANDARD, 0.01, title="IMPERIAL VALLEY 10/15/79 2316, EL CENTRO ARRAY #6, 230")
    said = plan_study("wall", records=[folder], out=Path("s.csv")).request.warnings
    assert said == (
        "--records: RSN6_IMPVALL.I_I-ELCUP.AT2, q3.AT2 are vertical components (PEER's UP / DWN, ESM's Z, K-NET's UD), run along x as "
        "the others: leave them out of the set (a scenario file's vertical = … applies one with its horizontal)",
    )


def _mixed_set(folder: Path) -> int:
    """A record set of each kind: an .AT2 file (DT 5 ms), a CSV of one value per line and the same velocity
    with its times i·0.01 s written out here (Python's i * 0.01, not the reader's); the .AT2's NPTS."""
    folder.mkdir()
    t, u, v, a = band_limited(0.4, 0.005, [2.0, 4.0], [0.01, 0.005], seed=1)
    write_at2(folder / "syn.AT2", a / G_STANDARD, 0.005)
    values = v[::2].tolist()
    (folder / "one.csv").write_text("velocity\n" + "".join(f"{x!r}\n" for x in values))
    (folder / "two.csv").write_text("time,velocity\n" + "".join(f"{i * 0.01!r},{x!r}\n" for i, x in enumerate(values)))
    return t.size


def test_record_dt_spaces_the_one_column_files_of_a_set_and_no_other(block, tmp_path):
    import dataclasses

    npts = _mixed_set(tmp_path / "records")
    records = plan_study(block, records=[Path("records")], record_dt=0.01, out=Path("s.csv")).base.records
    one, at2, two = records["one.csv"], records["syn.AT2"], records["two.csv"]
    # the one-column file is the file with times i·0.01 s; the others keep their own times
    assert one == dataclasses.replace(two, source=one.source, time_step=0.01) and one.time_step == 0.01
    assert two.time_step is None and two.time.tolist() == [i * 0.01 for i in range(two.time.size)]
    assert at2.time_step is None and at2.time.tolist() == [i * 0.005 for i in range(npts)]


@pytest.mark.parametrize(
    "options, message",
    [
        (
            {"records": [Path("records")]},
            "records/one.csv:2: one value per line, no times: give the time between samples: --record-dt SECONDS",
        ),
        (
            {"records": [Path("records/two.csv"), Path("records/syn.AT2")], "record_dt": 0.01},
            "--record-dt 0.01: no file of --records is one value per line (the .AT2 files and the CSVs with a time "
            "column keep their own times): leave it out",
        ),
        (
            {"params": ["amp=0.1"], "record_dt": 0.01},
            "--record-dt: goes with --records (the time between the samples of its one-column files)",
        ),
        # the value is checked as simulate checks it, before any file is read
        ({"records": [Path("nowhere")], "record_dt": 0.0}, "--record-dt 0: must be > 0"),
        ({"records": [Path("nowhere")], "record_dt": float("nan")}, "--record-dt nan: must be a finite number"),
        (
            {"records": [Path("records")], "record_dt": 10.0},
            "--record-dt 10: must be within 1e-06–1 s, likely a typo (accelerographs sample every 1–20 ms; 10 for "
            "10 ms would stretch the record 1000-fold)",
        ),
    ],
)
def test_record_dt_refusals_are_one_line_naming_it(block, tmp_path, options, message):
    _mixed_set(tmp_path / "records")
    assert _refused(block, out=Path("s.csv"), **options) == message
    assert sorted(p.name for p in tmp_path.iterdir()) == ["block.toml", "records"]
