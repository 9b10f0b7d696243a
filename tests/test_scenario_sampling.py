"""masonrycli/scenario/sampling.py: a sine at or above 1/(2 dt) and a support faster than a diverged block are
refused, in one line that names the scenario file's line of the key (the frequency, the amplitude, velocity or
acceleration, a record's file or samples) when the file still holds the value run; none when a sweep's value
or record replaced it."""

from __future__ import annotations

import dataclasses

import pytest
from scenario_helpers import BLOCK, DATA, GROUND, write

from masonrycli.errors import InputError
from masonrycli.scenario.motion import Constant
from masonrycli.scenario.sampling import check_sampling
from masonrycli.scenario.toml_file import load_scenario


def test_check_sampling_refuses_a_sine_above_half_the_step_rate():
    scenario = load_scenario(DATA / "block_on_ground.toml")  # 2 Hz, dt = 1e-3 s
    check_sampling(scenario)
    fast = dataclasses.replace(scenario, run=dataclasses.replace(scenario.run, dt=0.2))  # 2 Hz × 0.2 s = 0.4
    check_sampling(fast)  # 2.5 steps a period: still followed
    # two steps a period sample sin(π·k) = 0: the wall's ground never moved (PGA 3e-15 m/s², exit 0)
    at_limit = dataclasses.replace(scenario, run=dataclasses.replace(scenario.run, dt=0.25))
    with pytest.raises(InputError, match=r'support "ground": frequency = 2 Hz is at 1/\(2 dt\) = 2 Hz: steps of'):
        check_sampling(at_limit)
    too_fast = dataclasses.replace(scenario, run=dataclasses.replace(scenario.run, dt=0.5))
    with pytest.raises(
        InputError, match=r'block_on_ground.toml:26: support "ground": frequency = 2 Hz is above 1/\(2 dt\) = 1 Hz'
    ):
        check_sampling(too_fast)
    still = dataclasses.replace(too_fast, motions=(dataclasses.replace(too_fast.motions[0], amplitude=0.0),))
    check_sampling(still)  # a sine of zero amplitude moves nothing: any frequency


def test_check_sampling_refuses_a_support_faster_than_a_diverged_block():
    # --amp 1e30 ran (exit 0, "collapsed at t = 0.001 s"), --settlement 1e9 too, and a CSV record of
    # 1e300 m/s printed numpy's overflow warnings: a support that fast is a typo, refused like the others
    from masonrycli import run as run_module
    from masonrycli.records.motion import Record
    from masonrycli.scenario.motion import Ramp
    from masonrycli.scenario.scenario import MAX_SUPPORT_SPEED

    scenario = load_scenario(DATA / "block_on_ground.toml")  # 1 m/s sine, 1 s
    assert MAX_SUPPORT_SPEED == run_module.DIVERGENCE_SPEED  # what the run itself calls diverged

    def moving(motion):
        return dataclasses.replace(scenario, motions=(motion,))

    check_sampling(moving(dataclasses.replace(scenario.motions[0], amplitude=-1000.0)))  # at the limit
    with pytest.raises(InputError) as info:
        check_sampling(moving(dataclasses.replace(scenario.motions[0], amplitude=1e30)))
    assert str(info.value) == (
        f'{scenario.source}: support "ground": sine 1e+30 m/s · sin(2π·2 Hz·t) along (1, 0) moves at up to '
        "1e+30 m/s, more than 1000 m/s (a likely typo: a block that fast is a diverged run)"
    )
    with pytest.raises(InputError, match=r"constant velocity \(0, -1e\+09\) m/s moves at up to 1e\+09 m/s"):
        check_sampling(moving(Constant(velocity=(0.0, -1e9))))
    # a ramp reaches a·min(until, duration): 2000 m/s² for the run's 1 s is too fast, for 0.4 s not
    with pytest.raises(InputError, match=r"moves at up to 2e\+03 m/s"):
        check_sampling(moving(Ramp(acceleration=(2000.0, 0.0))))
    check_sampling(moving(Ramp(acceleration=(2000.0, 0.0), until=0.4)))
    # a record: what it reaches within the run (its samples after the run's end do not count)
    fast_late = Record(time=(0.0, 1.0, 2.0, 3.0), value=(0.0, 1.0, 1.0, 1e300), quantity="velocity")
    check_sampling(moving(fast_late))
    with pytest.raises(InputError, match=r"record of velocity \(inline, 4 samples, 0–3 s\).* up to 1e\+300 m/s"):
        check_sampling(dataclasses.replace(moving(fast_late), run=dataclasses.replace(scenario.run, duration=3.0)))


SINE = 'motion = { kind = "sine", direction = [1.0, 0.0], amplitude = 1.0, frequency = 2.0 }\n'
ALIASED = [  # (file text, extra arguments): 2 Hz at dt = 0.5 s is sampled at aliased phases
    (f"[run]\nduration = 1.0\ndt = 0.5\n\n{BLOCK}\n{GROUND}{SINE}", ()),
    (f"[run]\nduration = 1.0\ndt = 1e-3\n\n{BLOCK}\n{GROUND}{SINE}", ("--dt", "0.5")),  # the file's frequency
    # a builder's supports are named, in any order; the motion written as a table
    (
        '[structure]\nbuilder = "wall"\n\n[run]\nduration = 1.0\ndt = 0.5\n\n[[support]]\nname = "ground"\n'
        '[support.motion]\nkind = "sine"\namplitude = 1.0\n\nfrequency = 2.0\n',
        (),
    ),
]


@pytest.mark.parametrize("text, extra", ALIASED, ids=["file-dt", "option-dt", "builder-table"])
def test_an_aliased_sine_names_the_line_of_its_frequency(tmp_path, text, extra):
    """``masonry run s.toml`` on a sine faster than 1/(2 dt): the one line gives the file and the line of the
    frequency key, as the file's other errors do (it gave the file alone)."""
    from typer.testing import CliRunner

    from masonrycli.cli.app import app

    path = write(tmp_path, text, "s.toml")
    line = next(i for i, ln in enumerate(text.split("\n"), start=1) if "frequency = 2.0" in ln)
    result = CliRunner().invoke(app, ["run", str(path), "--no-recording", *extra])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert result.output.strip().splitlines() == [
        f'error: {path}:{line}: support "ground": frequency = 2 Hz is above 1/(2 dt) = 1 Hz: steps of '
        "dt = 0.5 s sample it at aliased phases (dt = 0.025 s gives 20 steps a period)"
    ]


TOO_FAST = [  # (file text, the key's text): each support moves faster than MAX_SUPPORT_SPEED within the run
    (f"[run]\nduration = 1.0\n\n{BLOCK}\n{GROUND}{SINE.replace('amplitude = 1.0', 'amplitude = 1e30')}", "1e30"),
    (f'[run]\nduration = 1.0\n\n{BLOCK}\n{GROUND}motion = {{ kind = "constant", velocity = [0, -1e9] }}\n', "-1e9"),
    # a builder's named support, its motion written as a table
    (
        '[structure]\nbuilder = "wall"\n\n[run]\nduration = 1.0\n\n[[support]]\nname = "ground"\n'
        '[support.motion]\nkind = "ramp"\n\nacceleration = [2000.0, 0.0]\n',
        "2000.0",
    ),
]


@pytest.mark.parametrize("text, value", TOO_FAST, ids=["sine-amplitude", "constant-velocity", "builder-ramp"])
def test_a_support_too_fast_names_the_line_of_its_speed(tmp_path, text, value):
    """``masonry run s.toml`` on a support faster than a diverged block: the one line gives the file and the
    line of the key that sets the speed (amplitude, velocity, acceleration), as the aliased sine's error does
    (it gave the file alone)."""
    from typer.testing import CliRunner

    from masonrycli.cli.app import app

    path = write(tmp_path, text, "s.toml")
    line = next(i for i, ln in enumerate(text.split("\n"), start=1) if value in ln and "name" not in ln)
    result = CliRunner().invoke(app, ["run", str(path), "--no-recording"])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    (message,) = result.output.strip().splitlines()
    assert message.startswith(f'error: {path}:{line}: support "ground": '), message
    assert "more than 1000 m/s (a likely typo: a block that fast is a diverged run)" in message


FAST_RECORD = "time,v (m/s)\n0,0\n0.5,2\n1,0\n"  # 2 m/s at its peak: × 1000 is 2000 m/s
TOO_FAST_RECORDS = [  # (file text, the key's text): a record too fast, by its file or its inline samples
    (f'{BLOCK}\n{GROUND}motion = {{ kind = "record", file = "recs/fast.csv", scale = 1000.0 }}\n', "recs/fast.csv"),
    # the file named with "./" in a sub-table, its scale on another line: the line that names the file
    (f'{BLOCK}\n{GROUND}[support.motion]\nkind = "record"\nscale = 1000.0\nfile = "./recs/fast.csv"\n', "fast.csv"),
    (f'{BLOCK}\n{GROUND}[support.motion]\nkind = "record"\ntime = [0.0, 0.5, 1.0]\nvalue = [0, 2e3, 0]\n', "2e3"),
]


@pytest.mark.parametrize("text, value", TOO_FAST_RECORDS, ids=["file-inline-table", "file-sub-table", "inline"])
def test_a_record_too_fast_names_the_line_of_its_file(tmp_path, text, value):
    """A record that moves a support faster than 1000 m/s: the line of the ``file`` key that names it (or of
    its inline ``value``), as the sine's amplitude gives its own (it gave the file alone: ``s.toml: …``)."""
    from typer.testing import CliRunner

    from masonrycli.cli.app import app

    (tmp_path / "recs").mkdir()
    (tmp_path / "recs" / "fast.csv").write_text(FAST_RECORD)
    path = write(tmp_path, text, "s.toml")
    line = next(i for i, ln in enumerate(text.split("\n"), start=1) if value in ln)
    result = CliRunner().invoke(app, ["run", str(path), "--no-recording"])
    assert result.exit_code == 2, result.output
    (message,) = result.output.strip().splitlines()
    assert message.startswith(f'error: {path}:{line}: support "ground": record of velocity ('), message
    assert "moves at up to 2e+03 m/s, more than 1000 m/s" in message


def test_a_record_too_fast_from_a_sweep_record_set_names_no_line(tmp_path):
    """``sweep --records other.csv`` drives the support by another file than the one the scenario names: the
    ``file`` line would point at a record that is not the one run."""
    from typer.testing import CliRunner

    from masonrycli.cli.app import app

    (tmp_path / "recs").mkdir()
    (tmp_path / "recs" / "fast.csv").write_text(FAST_RECORD)
    (tmp_path / "other.csv").write_text(FAST_RECORD)
    path = write(tmp_path, TOO_FAST_RECORDS[0][0].replace("scale = 1000.0", "scale = 1.0"), "s.toml")
    args = ["sweep", str(path), "--records", str(tmp_path / "other.csv"), "--scale", "1000"]
    result = CliRunner().invoke(app, [*args, "-o", str(tmp_path / "x.csv")])
    assert result.exit_code == 2, result.output
    (message,) = result.output.strip().splitlines()
    assert f'scale=1000: {path}: support "ground": record of velocity (other.csv' in message, message


def test_a_support_too_fast_by_a_sweep_value_names_no_line(tmp_path):
    """A sweep's ``--param amp=1e30`` replaces the file's amplitude: the file's line (amplitude = 1.0) would
    mislead, so the message gives the file alone."""
    from typer.testing import CliRunner

    from masonrycli.cli.app import app

    path = write(tmp_path, f"[run]\nduration = 1.0\n\n{BLOCK}\n{GROUND}{SINE}", "s.toml")
    result = CliRunner().invoke(app, ["sweep", str(path), "-p", "amp=1e30", "-o", str(tmp_path / "x.parquet")])
    assert result.exit_code == 2, result.output
    assert result.output.strip().splitlines() == [
        f'error: --param amp=1e+30: {path}: support "ground": sine 1e+30 m/s · sin(2π·2 Hz·t) along (1, 0) '
        "moves at up to 1e+30 m/s, more than 1000 m/s (a likely typo: a block that fast is a diverged run)"
    ]
