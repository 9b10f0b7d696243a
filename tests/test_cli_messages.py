"""One-line usage errors (masonrycli/cli/messages.py): a numeric option given text, or a number with its
unit, says what to write and in which unit the option is read (the units of docs/scenario-format.md and of
the options' help), never converting; a closed stdout and a Ctrl-C before the run (user_errors)."""

from pathlib import Path

import pytest

from cli_helpers import assert_one_line_error, invoke, runner

DATA = Path(__file__).parent / "data"
RUN = ("simulate", "wall", "--duration", "0.01", "--no-recording")


@pytest.mark.parametrize(
    "option, value, message",
    [
        ("--dt", "0.001s", "--dt 0.001s: must be a number (write 0.001, in s, without the unit)"),
        (
            "--dt",
            "20ms",
            "--dt 20ms: must be a number (it is read in s: convert 20 ms to s and write the number alone)",
        ),
        ("--amp", "1m/s", "--amp 1m/s: must be a number (write 1, in m/s, without the unit)"),
        ("--amp", "3 cm/s", "--amp 3 cm/s: must be a number (it is read in m/s: convert 3 cm/s to m/s"),
        ("--freq", "2Hz", "--freq 2Hz: must be a number (write 2, in Hz, without the unit)"),
        ("--density", "2.5t/m3", "--density 2.5t/m3: must be a number (it is read in kg/m³: convert 2.5 t/m3 to kg/m³"),
        (
            "--friction",
            "0.6mu",
            '--friction 0.6mu: must be a number (write 0.6, without "mu": this setting has no unit)',
        ),
        ("--record-every", "10steps", '--record-every 10steps: must be an integer (write 10, without "steps"'),
        ("--blocks", "51 blocks", '--blocks 51 blocks: must be an integer (write 51, without "blocks"'),
        ("--dt", "abc", "--dt abc: must be a number"),
        # a hint only when a unit follows the number: "12abc" said "convert 12 abc to m", "5x" "convert 5 x"
        ("--thickness", "12abc", "--thickness 12abc: must be a number"),
        ("--thickness", "5x", "--thickness 5x: must be a number"),
        ("--thickness", "3 kN", "--thickness 3 kN: must be a number (it is read in m: convert 3 kN to m and write"),
        ("--thickness", "12mm", "--thickness 12mm: must be a number (it is read in m: convert 12 mm to m and write"),
        ("--courses", "3abc", "--courses 3abc: must be an integer"),
        ("--courses", "3mm", '--courses 3mm: must be an integer (write 3, without "mm": this setting has no unit)'),
        # float() and int() read "1_0" as 10: on the command line a typo, run with dt = 10 before
        ("--dt", "1_0", "--dt 1_0: must be a number (an underscore is not a digit separator here)"),
        ("--blocks", "5_1", "--blocks 5_1: must be an integer (an underscore is not a digit separator here)"),
        # a decimal comma and a percentage said "must be a number" and no more
        ("--friction", "0,6", "--friction 0,6: must be a number (write 0.6: the decimal separator is a point)"),
        ("--dt", "0,001", "--dt 0,001: must be a number (write 0.001: the decimal separator is a point)"),
        ("--thickness", "1,500", "--thickness 1,500: must be a number"),  # 1.5 or 1500: no guess
        ("--friction", "60%", "--friction 60%: must be a number (write 0.6: a percentage is written as a fraction)"),
        ("--thickness", "50%", "--thickness 50%: must be a number"),  # a length in m is no fraction
    ],
)
def test_a_number_option_given_text_says_what_to_write(option, value, message):
    result = invoke(*RUN, option, value)
    assert_one_line_error(result, message)
    if message.endswith(("must be a number", "must be an integer")):
        assert result.output.strip().endswith(message)  # plain garbage: no hint


@pytest.mark.parametrize(
    "args, message",
    [
        # same unit, other unit, unitless option, plain garbage — on each command that takes numbers
        (
            ("run", "/no/such.toml", "--duration", "1s"),
            "--duration 1s: must be a number (write 1, in s, without the unit)",
        ),
        (
            ("check", "/no/such.toml", "--record-dt", "10ms"),
            "--record-dt 10ms: must be a number (it is read in s: convert 10 ms",
        ),
        (
            ("simulate", "arch", "--settlement", "1cm/s"),
            "--settlement 1cm/s: must be a number (it is read in m/s: convert 1 cm/s",
        ),
        (
            ("limit", "arch", "--load", "point", "--at", "-2", "--spread", "30deg"),
            "--spread 30deg: must be a number (write 30, in °, without the unit)",
        ),
        (
            ("build", "arch", "--span", "2m", "--out", "x.geojson"),
            "--span 2m: must be a number (write 2, in m, without the unit)",
        ),
        (
            ("limit", "wall", "--friction", "0.6mu"),
            '--friction 0.6mu: must be a number (write 0.6, without "mu": this setting has',
        ),
        (
            ("sweep", "wall", "--param", "amp=1", "--dt", "20ms"),
            "--dt 20ms: must be a number (it is read in s: convert 20 ms to s",
        ),
        (
            ("sweep", "wall", "--param", "amp=1", "--rtol", "1%"),
            "--rtol 1%: must be a number (write 0.01: a percentage is written as a fraction)",
        ),
        (("sweep", "wall", "--param", "amp=1", "--rtol", "abc"), "--rtol abc: must be a number"),
        (
            ("sweep", "wall", "--param", "amp=1", "--workers", "2cores"),
            '--workers 2cores: must be an integer (write 2, without "cores"',
        ),
        # --param: a value, a range bound, plain garbage
        (
            ("sweep", "wall", "--param", "freq=2Hz,3"),
            "--param freq=2Hz,3: '2Hz' is not a number (write 2, in Hz, without the unit)",
        ),
        (
            ("sweep", "wall", "--param", "amp=0.1:20cm/s:3"),
            "--param amp=0.1:20cm/s:3: '20cm/s' is not a number (it is read in m/s: convert 20 cm/s to m/s and write",
        ),
        (
            ("sweep", "wall", "--param", "amp=0.1m/s:1:3"),
            "'0.1m/s' is not a number (write 0.1, in m/s, without the unit)",
        ),
        (("sweep", "wall", "--param", "amp=abc"), "--param amp=abc: 'abc' is not a number"),
        (("sweep", "wall", "--param", "amp=12abc,2"), "--param amp=12abc,2: '12abc' is not a number"),
        (("sweep", "wall", "--param", "amp=5x,2"), "--param amp=5x,2: '5x' is not a number"),
        (("sweep", "wall", "--param", "blocks=5abc,7"), "--param blocks=5abc,7: '5abc' is not a number"),
        (
            ("sweep", "wall", "--param", "blocks=51blocks,7"),
            "--param blocks=51blocks,7: '51blocks' is not a number (write 51, without \"blocks\"",
        ),
        (("sweep", "wall", "--param", "amp=1", "--workers", "2abc"), "--workers 2abc: must be an integer"),
        # not a unit: a hex literal read as 0 and "x10" said "(it is read in m: convert 0 x10 to m ...)"
        (("simulate", "wall", "--thickness", "0x10"), "--thickness 0x10: must be a number"),
        (
            ("build", "arch", "--ring-thickness", "0xff", "--out", "x.geojson"),
            "--ring-thickness 0xff: must be a number",
        ),
        (("sweep", "wall", "--param", "amp=0x1,2"), "--param amp=0x1,2: '0x1' is not a number"),
        # digits with an underscore: a typo on the command line (float() reads "1_0" as 10)
        (
            ("sweep", "wall", "--param", "amp=1_0,2"),
            "--param amp=1_0,2: '1_0' is not a number (an underscore is not a digit separator here)",
        ),
        (("sweep", "wall", "--param", "amp=1:2:1_0"), "--param amp=1:2:1_0: N = '1_0' must be a whole number"),
        (
            ("sweep", "wall", "--param", "amp=1", "--workers", "1_0"),
            "--workers 1_0: must be an integer (an underscore is not a digit separator here)",
        ),
        (
            ("build", "arch", "--span", "3_6", "--out", "x.geojson"),
            "--span 3_6: must be a number (an underscore is not a digit separator here)",
        ),
    ],
)
def test_every_command_says_what_to_write_for_its_numbers(args, message):
    result = invoke(*args)
    assert_one_line_error(result, message)
    if message.endswith(("is not a number", "must be a number", "must be an integer")):
        assert result.output.strip().endswith(message)  # plain garbage: no hint


def test_every_numeric_option_has_a_known_unit():
    """An option added without a unit in SETTING_UNITS (by its setting) or OPTION_UNITS gives no hint."""
    import typing

    import typer

    from geometry_library.values import unit_of
    from masonrycli.cli.app import app

    commands = typer.main.get_command(app).commands
    numeric = [
        (name, p.name)
        for group in ("simulate", "run", "check", "limit", "build", "sweep")
        for name, command in (getattr(commands[group], "commands", None) or {group: commands[group]}).items()
        for p in command.params
        if {float, int} & {(a := p.type_descriptor.annotation), *typing.get_args(a)}
    ]
    assert len(numeric) > 20
    assert [option for option in numeric if unit_of(option[1]) is None] == []


def test_other_usage_errors_keep_their_message_and_the_help_pointer():
    assert_one_line_error(invoke(*RUN, "--no-such-option"), "No such option", "--help lists the options")
    assert_one_line_error(invoke(*RUN, "--amp", "nan"), "--amp: amplitude = nan: must be a finite number")
    assert_one_line_error(invoke(*RUN, "--amp", "inf"), "--amp: amplitude = inf: must be a finite number")
    assert invoke(*RUN, "--amp", "-1").exit_code == 0  # a sine of opposite sign: accepted, as before


def test_a_whole_number_option_given_a_fraction_or_a_control_character_says_so_on_one_line(tmp_path):
    # "--blocks 51.5" said "(write 51.5, without quotes)": no quote was typed, and 51.5 is what was refused
    result = invoke(*RUN, "--blocks", "51.5")
    assert_one_line_error(result, "--blocks 51.5: must be an integer")
    assert result.output.strip().endswith("--blocks 51.5: must be an integer")
    # a newline in the value printed the message on two lines
    assert_one_line_error(invoke(*RUN, "--dt", "1\nx"), "--dt 1\\nx: must be a number")


def test_the_scale_axis_is_named_by_its_option(tmp_path):
    # "--scale 0.5x:2:3" was reported as "--param scale=0.5x:2:3", an option not typed
    (tmp_path / "r.csv").write_text("0.01\n0.02\n0.0\n")
    args = ("sweep", "wall", "--records", tmp_path, "--record-dt", "0.01", "--scale", "0.5x:2:3")
    assert_one_line_error(invoke(*args), "--scale 0.5x:2:3: '0.5x' is not a number (write 0.5, without \"x\"")


@pytest.mark.parametrize("argv", [("simulate", "wall"), ("sweep", "wall", "--param", "amp=0.1,0.2")])
def test_a_ctrl_c_while_the_arguments_are_read_is_one_line(argv, monkeypatch):
    # walk-through 2026-11-28: SIGINT 0.39 s into `masonry sweep wall …` (1 in 10 tries): exit 130 and nothing on
    # stdout or stderr; typer turns a KeyboardInterrupt of the argument parsing into a silent exit 130
    import typer.core

    def interrupted(self, *args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(typer.core.TyperCommand, "make_context", interrupted)
    result = invoke(*argv)
    assert result.exit_code == 130, result.output
    assert result.output.strip() == "error: Ctrl-C: stopped before any output was written"


@pytest.mark.parametrize(
    "args, line",
    [
        # a float option's value as the user typed it: these said 0.0, 1000000000.0, -1.0 (typer had made
        # the text a float before the check)
        (("sweep", "wall", "-p", "amp=0.1:1:4", "--find", "amp", "--rtol", "0"), "--rtol 0: must be in (0, 1)"),
        (RUN + ("--length", "0"), "--length 0: must be a positive number"),
        (
            RUN + ("--density", "1e9"),
            "--density: density = 1e9: must be between 0.001 and 100000 kg/m³ (a likely typo)",
        ),
        (RUN + ("--dt", "0e0"), "--dt: dt = 0e0: must be > 0"),
        (
            ("simulate", "arch", "--settlement", "-1", "--no-recording"),
            "--settlement -1: must be >= 0 (a downward velocity, m/s)",
        ),
        (("limit", "arch", "--friction", "-1"), "--friction: friction = -1: must be >= 0"),
        (RUN + ("--magnify", "0.50"), "--magnify 0.50: must be between 1 and 1e+06"),
        # a builder dimension's range check said "span 1e+09 m" (geometry's check_dimensions in %g)
        (
            ("simulate", "arch", "--span", "1e9", "--no-recording"),
            "--span 1e9 m is absurd (a likely typo: 0.001 to 1000 m)",
        ),
        (
            ("build", "wall", "--block-height", "1E-9", "--out", "x.geojson"),
            "--block-height 1E-9 m is absurd (a likely typo: 0.001 to 1000 m)",
        ),
        # RunConfig's dt-against-duration checks echoed the floats: "dt = 2.0", "duration 100000.0"
        (("simulate", "wall", "--no-recording", "--dt", "2"), "--dt: dt = 2: must be <= duration (1.0)"),
        (
            ("simulate", "wall", "--no-recording", "--duration", "1e5", "--dt", "1e-4"),
            "--duration and --dt: duration = 1e5 at dt = 1e-4 is 1,000,000,000 steps (at most 100,000,000)",
        ),
        (
            ("simulate", "wall", "--no-recording", "--duration", "0.50", "--dt", "0.3"),
            "--duration and --dt: duration = 0.50 is not a whole number of steps of dt = 0.3"
            " (1.66667 steps); use dt = 0.25 (2 steps) or change the duration",
        ),  # fmt: skip
    ],
)
def test_a_float_option_is_echoed_as_typed(args, line):
    result = invoke(*args)
    assert_one_line_error(result)
    assert result.output.strip() == f"error: {line}"


@pytest.mark.parametrize(
    "args, line",
    [
        (("simulate", "wall", "--amp", "0.5", "--duration", "0.01", "--amp", "1"), "--amp: given twice (0.5, then 1)"),
        (("simulate", "wall", "--freq=2", "--freq", "3"), "--freq: given twice (2, then 3)"),
        (("limit", "arch", "-o", "a.rrd", "--out", "b.rrd"), "--out: given twice (a.rrd, then b.rrd)"),
        (
            ("sweep", "wall", "-p", "amp=0.1", "--out", "x.csv", "--out", "y.csv"),
            "--out: given twice (x.csv, then y.csv)",
        ),
    ],
)
def test_an_option_of_one_value_given_twice_is_refused(args, line, tmp_path, monkeypatch):
    # click kept the last without a word: 'simulate wall --amp 0.5 … --amp 1' (a command edited from the
    # history) ran at 1 m/s
    monkeypatch.chdir(tmp_path)
    result = invoke(*args)
    assert result.exit_code == 2 and result.output.strip() == f"error: {line}: give it once", result.output
    assert list(tmp_path.iterdir()) == []


def test_options_given_many_times_on_purpose_and_flags_are_taken():
    from masonrycli.cli.app import app

    assert app_group(app)._repeated_option(["sweep", "wall", "-p", "amp=0.1", "-p", "freq=2"]) is None
    assert app_group(app)._repeated_option(["simulate", "wall", "--force", "--force"]) is None
    assert app_group(app)._repeated_option(["simulate", "wall", "--amp", "-1", "--freq", "-1"]) is None


def app_group(app):
    import typer.main

    return typer.main.get_command(app)


def test_a_closed_stdout_is_not_bad_input(tmp_path):
    # `masonry limit arch --json | head -c 10` printed "error: Broken pipe" and exit 2 (bad input); now it
    # stops quietly as click does for the other commands (exit 1, nothing on stderr).
    import os
    import subprocess
    import sys

    env = os.environ | {"RERUN_ANALYTICS": "0"}
    cmd = [sys.executable, "-m", "masonrycli", "limit", DATA / "validation" / "column5.toml", "--json"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    proc.stdout.close()  # the reader is gone before the first write
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 1 and err == "", err


def test_ctrl_c_before_the_run_is_one_line_and_exit_130(monkeypatch):
    # a Ctrl-C while the structure is built (before the run's own signal handling) exited 130 without a word
    import masonrycli.scenario.builtin

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(masonrycli.scenario.builtin, "builtin", interrupted)
    result = invoke("simulate", "wall", "--duration", 0.01, "--no-recording")
    assert result.exit_code == 130
    assert result.output.strip() == "error: Ctrl-C: stopped before any output was written"


@pytest.mark.parametrize(
    "args, said",
    [
        # a folder with a space (a student's "C:\Users\Ana Silva\…"): "Got unexpected extra argument(s) (wall.toml)"
        (("run", "my", "wall.toml"), 'a name with spaces goes between quotes: masonry run "my wall.toml"'),
        (("check", "C:/Users/Ana", "Silva/w.toml"), 'masonry check "C:/Users/Ana Silva/w.toml"'),
        (("inspect", "my", "runs/w.rrd"), 'masonry inspect "my runs/w.rrd"'),
        # "wall" is whole: a record without --record (it said 'a name with spaces …: masonry run "wall quake.AT2"')
        (
            ("run", "wall", "quake.AT2"),
            "(quake.AT2): masonry run takes one structure; a record goes after --record: "
            "masonry run wall --record quake.AT2",
        ),
        (("simulate", "wall", "--amp", "1.5", "m/s"), "(m/s): a number goes alone, without its unit"),
        (("run", "w.toml", "--duration", "1", "s"), "(s): a number goes alone, without its unit"),
    ],
)
def test_an_extra_word_says_what_it_likely_is(args, said):
    from masonrycli.cli.app import app

    result = runner.invoke(app, list(args), prog_name="masonry")
    assert_one_line_error(result, "Got unexpected extra argument(s)", said)


def test_an_extra_word_of_no_known_kind_keeps_the_parsers_line(tmp_path, monkeypatch):
    from masonrycli.cli.app import app

    result = runner.invoke(app, ["simulate", "wall", "extra"], prog_name="masonry")
    assert_one_line_error(result, "(extra) (masonry simulate wall --help lists the options)")
    # a file that exists is a whole name too: no guess of a space in it (it said 'check "w.toml extra.png"')
    monkeypatch.chdir(tmp_path)
    (tmp_path / "w.toml").write_text("")
    result = runner.invoke(app, ["check", "w.toml", "extra.png"], prog_name="masonry")
    assert_one_line_error(result, "(extra.png) (masonry check --help lists the options)")


def test_a_value_given_to_a_flag_says_it_takes_none():
    # --help shows "--no-recording <bool>": "--no-recording true" said only "Got unexpected extra argument(s)"
    from masonrycli.cli.app import app

    result = runner.invoke(app, ["simulate", "wall", "--no-recording", "true"], prog_name="masonry")
    assert_one_line_error(result, "(true): an on/off option (--no-recording, --force) takes no value")


def test_a_list_cut_at_the_space_after_a_comma_says_so():
    # "--param amp=0.5, 1" (a space after the comma, as in prose): it said "(1): an on/off option … takes no
    # value", with no on/off option on the line
    from masonrycli.cli.app import app

    result = runner.invoke(app, ["sweep", "wall", "--param", "amp=0.5,", "1", "--workers", "0"], prog_name="masonry")
    assert_one_line_error(result, "(1): a list goes without spaces after its commas: amp=0.5,1")
    result = runner.invoke(app, ["simulate", "wall", "--duration", "1", "0"], prog_name="masonry")
    assert "on/off" not in result.output  # no flag given: "0" is no flag's value


@pytest.mark.parametrize("option, value", [("--courses", "15"), ("--friction", "0.5"), ("--density", "2200")])
def test_a_run_option_given_to_a_study_names_its_axis(option, value):
    # 'sweep wall --courses 15' said "No such option: --courses (Possible options: --force, --records)"
    key = option[2:]
    said = f"{option}: a study takes it as an axis: --param {key}=VALUE (one value: every run"
    assert_one_line_error(invoke("sweep", "wall", option, value), said)
    assert_one_line_error(invoke("sweep", "wall", "--bogus", value), "No such option: --bogus")
