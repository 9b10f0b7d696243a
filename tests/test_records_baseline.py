"""``--baseline`` and the warning of a record its baseline correction changes (a shake table's sine from rest).

References: the applied velocity without correction is the cumulative trapezoid of the file's samples (exact
for a linear acceleration between samples), and for a sine from rest, a = A sin ωt over whole cycles, the
closed form: v(T) = 0 and D = ∫v = A T/ω, so the correction's acceleration is the line 6A/(ωT) (1 − 2t/T).
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from benchmarks.baseline_shapes import BURSTS, bursts
from masonrycli.cli.app import app
from masonrycli.errors import RecordWarning
from masonrycli.records.motion import Record
from masonrycli.records.read import G_STANDARD
from masonrycli.scenario.caveats import BASELINE_CHANGE, record_warnings
from masonrycli.scenario.toml_file import load_scenario
from masonrycli.study.plan import plan_study

from synthetic_records import band_limited, write_at2

DATA = Path(__file__).parent / "data"
BLOCK = DATA / "block_on_ground.toml"  # a sine-shaken block
runner = CliRunner()
PEAK_G, FREQ, LENGTH = 0.8, 2.0, 1.0  # the shake table's input: 0.8 g · sin(2π · 2 Hz · t) for 1 s, from rest


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], terminal_width=200)


def table_csv(path: Path, rate: float = 200.0) -> Path:
    t = np.arange(round(LENGTH * rate) + 1) / rate
    rows = [f"{float(x)!r},{float(PEAK_G * np.sin(2 * np.pi * FREQ * x))!r}" for x in t]
    path.write_text("time (s),acc (g)\n" + "\n".join(rows) + "\n")
    return path


@pytest.fixture
def table(tmp_path) -> Path:
    return table_csv(tmp_path / "table.csv")


@pytest.fixture
def at_rest(tmp_path) -> Path:
    """A record that starts and ends at rest where it started (the tapered synthetic of the suite)."""
    t, u, v, a = band_limited(2.0, 0.01, [1.5, 3.0], [0.01, 0.004], seed=3)
    write_at2(tmp_path / "quake.AT2", a / G_STANDARD, 0.01)
    return tmp_path / "quake.AT2"


def test_baseline_none_applies_the_samples_as_given(tmp_path):
    # samples every 1 ms, the run's steps: at each frame the velocity is the trapezoid sum of the samples
    table = table_csv(tmp_path / "table.csv", rate=1000.0)
    t = np.arange(1001) * 1e-3
    a = PEAK_G * G_STANDARD * np.sin(2 * np.pi * FREQ * t)
    given = np.concatenate([[0.0], np.cumsum(0.5 * 1e-3 * (a[1:] + a[:-1]))])
    omega = 2 * np.pi * FREQ
    exact = PEAK_G * G_STANDARD / omega * (1 - np.cos(omega * t))  # the sine's own integral, from rest
    np.testing.assert_allclose(given, exact, rtol=0, atol=2e-5 * exact.max())  # (ω dt)²/12
    for command in (("simulate", "wall", "--blocks", 12), ("run", BLOCK)):
        npz = tmp_path / f"{command[0]}.npz"
        result = invoke(
            *command, "--record", table, "--baseline", "none", "--duration", 1.0, "--dt", 1e-3, "--record-every", 1,
            "--no-recording", "--history", npz,
        )  # fmt: skip
        assert result.exit_code == 0, result.output
        assert "does not end at rest where it started" not in result.output
        h = np.load(npz)
        np.testing.assert_array_equal(h["time"], np.arange(1001) * 1e-3)
        np.testing.assert_allclose(h["support_v"][:, 0, 0], given, rtol=1e-12, atol=1e-12)
        np.testing.assert_array_equal(h["support_v"][:, 0, 1], 0.0)
    # the default corrects it: the ground ends at rest (v(T) = 0), the velocity shifted down by its mean
    npz = tmp_path / "corrected.npz"
    result = invoke(
        "run", BLOCK, "--record", table, "--duration", 1.0, "--dt", 1e-3, "--record-every", 1, "--no-recording",
        "--history", npz,
    )  # fmt: skip
    corrected = np.load(npz)["support_v"][:, 0, 0]
    assert abs(corrected[-1]) < 1e-9 and abs(corrected.mean()) < 0.01 * abs(given.mean())


def test_the_warning_names_both_peaks_the_ratio_and_the_option(table):
    result = invoke("check", BLOCK, "--record", table)
    assert result.exit_code == 0, result.output
    lines = [ln for ln in result.output.splitlines() if ln.startswith("warning:") and "rest" in ln]
    assert len(lines) == 1, result.output
    numbers = re.search(
        r"changes the acceleration by up to ([\d.]+) g \((\d+) % of its peak\): its peak ([\d.]+) g becomes "
        r"([\d.]+) g as applied \(×([\d.]+)\); --baseline none",
        lines[0],
    )
    assert numbers and lines[0].startswith('warning: support "ground": the record table.csv'), lines[0]
    # the sine from rest is at rest at both ends (v = a/ω (1 − cos ωt), whole cycles): it ends elsewhere
    assert "the record table.csv does not end at rest where it started:" in lines[0]  # the words the other tests seek
    change, percent, peak, applied, ratio = map(float, numbers.groups())
    # the closed form (module docstring), its peak on a fine grid
    omega, amp = 2 * np.pi * FREQ, PEAK_G
    s = np.linspace(0.0, 1.0, 200_001)
    line = 6 * amp / (omega * LENGTH) * (1 - 2 * s)
    exact_applied = np.abs(amp * np.sin(omega * s * LENGTH) - line).max()
    assert change == pytest.approx(6 * amp / (omega * LENGTH), rel=2e-3)  # 0.382 g
    assert percent == round(100 * 6 / (omega * LENGTH))  # 48 %
    assert peak == pytest.approx(PEAK_G, rel=1e-4)
    assert applied == pytest.approx(exact_applied, rel=1e-3) and ratio == pytest.approx(exact_applied / amp, rel=1e-3)
    # applied as given (the option in any case, as a scenario file's word): no such warning
    as_given = invoke("check", BLOCK, "--record", table, "--baseline", "NONE")
    assert as_given.exit_code == 0 and "rest" not in as_given.output, as_given.output


def test_no_warning_for_a_record_that_starts_and_ends_at_rest(at_rest):
    result = invoke("check", BLOCK, "--record", at_rest)
    assert result.exit_code == 0, result.output
    assert "does not end at rest where it started" not in result.output and "baseline-corrected" in result.output


def test_a_scenario_files_record_warns_and_its_baseline_none_does_not(tmp_path):
    t = np.arange(201) / 200
    a = (PEAK_G * G_STANDARD * np.sin(2 * np.pi * FREQ * t)).tolist()
    text = BLOCK.read_text()
    motion = re.search(r"^motion = .*$", text, re.M).group(0)
    for baseline, warned in (("", True), (', baseline = "None"', False)):
        record = (
            f'motion = {{ kind = "record", quantity = "acceleration", time = {t.tolist()}, value = {a}{baseline} }}'
        )
        path = tmp_path / "s.toml"
        path.write_text(text.replace(motion, record))
        said = [w for w in record_warnings(load_scenario(path)) if "does not end at rest where it started" in w]
        assert len(said) == int(warned), said
        assert not said or "the record (inline) does not end at rest where it started" in said[0]


@pytest.mark.parametrize("kind", BURSTS)
def test_earthquake_like_records_do_not_warn(kind):
    # what the correction is for: an unprocessed burst drifts (its velocity ends far from 0), the correction
    # brings it back and leaves its acceleration within the threshold
    for t, a in bursts(kind, 12, seed=7, longest=20.0):  # benchmarks/baseline_shapes.py: 1500 of each
        m = Record(time=t, value=a, quantity="acceleration")
        applied, change = m.baseline_change
        assert change < BASELINE_CHANGE * m.peak_acceleration
        scenario = dataclasses.replace(load_scenario(BLOCK), motions=(m,))
        assert not [w for w in record_warnings(scenario) if "rest" in w]


@pytest.mark.parametrize(
    "args, message",
    [
        (("check", BLOCK, "--record", "TABLE", "--baseline", "linear"), '--baseline linear: must be "quadratic" or "none"'),
        (("simulate", "wall", "--record", "TABLE", "--baseline", "no"), '--baseline no: must be "quadratic" or "none"'),
        (("run", BLOCK, "--baseline", "none"), '--baseline none goes with --record (a scenario file\'s own record takes baseline = "none" in its table)'),
        (("simulate", "wall", "--baseline", "quadratic"), "--baseline quadratic goes with --record"),
        (("sweep", "wall", "--records", "TABLE", "--baseline", "linear"), '--baseline linear: must be "quadratic" or "none"'),
        (("sweep", "wall", "--param", "amp=0.1,0.2", "--baseline", "none"), "--baseline: goes with --records"),
    ],
)  # fmt: skip
def test_a_bad_baseline_is_one_line_exit_2(table, tmp_path, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    result = invoke(*[table if a == "TABLE" else a for a in args])
    assert result.exit_code == 2, result.output
    lines = [ln for ln in result.output.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith(f"error: {message}"), result.output


def test_sweep_records_take_the_baseline(table, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    warned = [
        w for w in plan_study("wall", records=[table]).request.warnings if "does not end at rest where it started" in w
    ]
    assert len(warned) == 1 and "--baseline none" in warned[0]
    plan = plan_study("wall", records=[table], baseline="none", out=Path("b.parquet"))
    assert [m.baseline for m in plan.base.records.values()] == ["none"]
    assert not [w for w in plan.request.warnings if "does not end at rest where it started" in w]


@pytest.mark.parametrize("command", [("check", BLOCK), ("simulate", "wall", "--no-recording", "--duration", 0.01)])
def test_a_baseline_on_a_velocity_record_says_it_does_not_apply(command, tmp_path):
    # "--baseline quadratic" on a velocity record did nothing, without a word: a velocity record is not
    # integrated, never corrected (its samples as given: the reference, np.interp of the file, below)
    velocity = DATA / "quake_velocity.csv"
    result = invoke(*command, "--record", velocity, "--baseline", "quadratic")
    assert result.exit_code == 2, result.output
    assert result.output.strip() == (
        f"error: --baseline quadratic: {velocity} is a velocity record, used as given: the drift correction is of "
        "acceleration records, which are integrated (leave --baseline out)"
    )
    result = invoke(*command, "--record", velocity, "--baseline", "none")
    assert result.exit_code == 0, result.output
    said = [ln for ln in result.output.splitlines() if ln.startswith("warning: --baseline")]
    assert said == [
        f"warning: --baseline none: {velocity} is a velocity record, used as given whatever --baseline says (it "
        "applies to acceleration records)"
    ], result.output
    assert invoke(*command, "--record", velocity).exit_code == 0  # not given: no word


def test_a_velocity_record_is_used_as_given():
    from masonrycli.scenario.record_option import record_motion_option

    velocity = DATA / "quake_velocity.csv"
    t, v = np.loadtxt(velocity, delimiter=",", skiprows=2, unpack=True)
    at = np.linspace(t[0], t[-1], 101)
    with pytest.warns(RecordWarning):
        applied = record_motion_option(velocity, None, baseline="none").velocity_at(at)
    assert applied[:, 0] == pytest.approx(np.interp(at, t, v), abs=1e-12) and not applied[:, 1].any()


def test_sweep_records_say_which_velocity_records_a_baseline_leaves(table, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    velocity = tmp_path / "v.csv"
    velocity.write_text((DATA / "quake_velocity.csv").read_text())
    with pytest.raises(Exception, match=r"^--baseline quadratic: v.csv is a velocity record, used as given: "):
        plan_study("wall", records=[velocity], baseline="quadratic", out=Path("a.parquet"))
    mixed = plan_study("wall", records=[table, velocity], baseline="quadratic", out=Path("b.parquet"))
    said = [w for w in mixed.request.warnings if w.startswith("--baseline")]
    assert said == [
        "--baseline quadratic: v.csv is a velocity record, used as given; it corrects the acceleration records"
    ]
    as_given = plan_study("wall", records=[table, velocity], baseline="none", out=Path("c.parquet"))
    assert not [w for w in as_given.request.warnings if w.startswith("--baseline")]
    alone = plan_study("wall", records=[velocity], baseline="none", out=Path("d.parquet")).request.warnings
    assert [w for w in alone if w.startswith("--baseline none: v.csv is a velocity record")], alone


def test_a_scenario_files_baseline_on_a_velocity_record_says_it_does_not_apply(tmp_path):
    # a record table's baseline = "quadratic" on a velocity record was taken without a word, as --baseline was
    (tmp_path / "q.csv").write_text((DATA / "quake_velocity.csv").read_text())
    lines = [
        "[[block]]",
        "polygon = [[0, 0], [0.4, 0], [0.4, 0.2], [0, 0.2]]",
        "[[support]]",
        'name = "ground"',
        "polygon = [[-1, -0.2], [1, -0.2], [1, 0], [-1, 0]]",
        'motion = { kind = "record", file = "q.csv"BASELINE }',
    ]
    said = {}
    for baseline in ("quadratic", "none", ""):
        path = tmp_path / f"s{baseline}.toml"
        path.write_text("\n".join(lines).replace("BASELINE", f', baseline = "{baseline}"' if baseline else "") + "\n")
        said[baseline] = invoke("check", path, "--duration", 0.4)
    assert said["quadratic"].exit_code == 2 and said["quadratic"].output.strip() == (
        f'error: {tmp_path / "squadratic.toml"}:6: [[support]] #1 ("ground"): motion.baseline = "quadratic": q.csv is '
        "a velocity record, used as given: the drift correction is of acceleration records, which are integrated "
        "(leave baseline out)"
    )
    assert said["none"].exit_code == 0 and (
        'motion.baseline = "none": q.csv is a velocity record, used as given whatever baseline says'
        in said["none"].output
    )
    assert said[""].exit_code == 0 and "baseline =" not in said[""].output
