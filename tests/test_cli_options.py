"""The options of every command (masonrycli/cli/options.py): what --help says of them (their defaults, only
those a structure takes, -h as --help). Choices in any case and a ~ the shell left: test_cli_option_values.py."""

from __future__ import annotations

import re

import pytest

from masonrycli import __version__

from cli_helpers import invoke, runner


def test_help_and_version():
    result = invoke("--help")
    assert result.exit_code == 0
    for command in ("simulate", "run", "check", "build", "inspect"):
        assert command in result.output
    # listed in the order a user meets them, the quick start's command first (simulate and build came last)
    listed = re.findall(r"^│ ([a-z]+) ", result.output, flags=re.MULTILINE)  # a command's row, not its wrapped text
    assert listed == ["simulate", "run", "check", "build", "inspect", "export", "report", "limit", "sweep", "docs"], (
        listed
    )
    result = invoke("--version")
    assert result.exit_code == 0 and __version__ in result.output
    result = invoke("simulate", "wall", "--help")
    assert result.exit_code == 0 and "--freq" in result.output and "--amp" in result.output


@pytest.mark.parametrize(
    "command", [(), ("simulate",), ("simulate", "wall"), ("build", "arch"), ("sweep",), ("inspect",)]
)
def test_h_is_help(command):
    # walk-through 2026-11-28: "masonry -h" said "error: No such option: -h (masonry --help lists the options)"
    result = invoke(*command, "-h")
    assert result.exit_code == 0 and result.output == invoke(*command, "--help").output


@pytest.mark.parametrize(
    "group, commands",
    [
        ((), ("run", "sweep", "limit", "check", "inspect", "simulate", "build")),
        (("simulate",), ("wall", "arch", "aqueduct")),
        (("build",), ("wall", "arch", "aqueduct")),
    ],
)
def test_command_list_keeps_each_summary_on_one_line(group, commands):
    # The list showed run's and check's docstrings with their source line breaks ("options given here" /
    # "override the file's values." on two lines of a 120-column terminal); their fix, a copy of each
    # docstring, left inspect's broken ("run history (the run's" / "parameters, …", walk-through 2026-11-29)
    # and check's copy without "the loading".
    from masonrycli.cli.app import app

    from cli_helpers import runner

    out = runner.invoke(app, [*group, "--help"], env={"COLUMNS": "250"}).output
    rows = {}
    for line in out.splitlines():
        cells = line.strip("│ ").split(maxsplit=1)
        if len(cells) == 2 and cells[0] in commands:
            assert cells[0] not in rows, out  # one line each
            rows[cells[0]] = " ".join(cells[1].split())
    assert sorted(rows) == sorted(commands), out
    said = {
        "run": "options given here override the file's values.",
        "check": "print a summary (blocks, supports, mass, bounding box, steps, the loading, outputs); nothing is "
        "computed or written.",
        "inspect": "a run history (its parameters, status, frames and each array's unit) or a study's table (its rows "
        "and each column's unit).",
    }
    for name, summary in rows.items():
        assert summary.endswith(said.get(name, ".")), summary


def _option_help(command: list[str]) -> dict[str, str]:
    """Each option of ``masonry COMMAND --help`` with its help text (joined over wrapped lines)."""
    from masonrycli.cli.app import app

    from cli_helpers import runner

    out = runner.invoke(app, [*command, "--help"], env={"COLUMNS": "250"}).output
    options, name = {}, None
    for line in out.splitlines():
        cells = line.strip("│ ").split()
        if cells and cells[0].startswith("--"):
            name = cells[0]
            options[name] = " ".join(cells[2:])
        elif name and cells and not line.startswith(("╭", "╰")):
            options[name] += " " + " ".join(cells)
    return options


def test_simulate_help_lists_only_what_the_structure_takes_with_its_defaults():
    # `simulate wall --help` offered --settlement ("Downward velocity of the right foundation"), which the
    # wall always refuses, and --freq / --amp / --scale showed no default (the wall is shaken at 1 m/s, 2 Hz).
    wall = _option_help(["simulate", "wall"])
    assert "--settlement" not in wall
    assert "(default 2)" in wall["--freq"] and "(default 1;" in wall["--amp"] and "(default 1)" in wall["--scale"]
    for name in ("arch", "aqueduct"):
        options = _option_help(["simulate", name])
        assert "(default 0.01;" in options["--settlement"] and "--settlement 0" in options["--amp"]
        assert "(default 2" in options["--freq"]


def test_run_and_check_help_give_the_scenario_files_values_as_defaults():
    # `run --help` said "(default 1e-3)" for --dt, although a file's [run] dt is what runs; check takes a
    # built-in too, whose values are the default there (it said "the scenario file's value" only)
    for command, value in (
        (["run"], "the scenario file's value"),
        (["check"], "the scenario file's or the built-in's value"),
    ):
        options = _option_help(command)
        assert f"(default: {value}, else 1e-3)" in options["--dt"]
        assert f"(default: {value}, else 0.5)" in options["--theta"]
        assert f"(default: {value}, else 0.6)" in options["--friction"]
        assert f"(default: {value})" in options["--duration"] and "simulate" not in options["--duration"]
    simulate = _option_help(["simulate", "wall"])
    assert "(default 1e-3)" in simulate["--dt"] and "(default 0.6)" in simulate["--friction"]


def test_sweep_help_gives_the_default_file_names():
    # --out and --plot said nothing of where the table and the picture go when not given (study-<scenario>.parquet
    # in the working folder, the plot beside it), while --recording did
    options = _option_help(["sweep"])
    assert "default study-<scenario>.parquet" in options["--out"]
    assert "(default: beside --out, .png)" in options["--plot"]
    assert "(default: beside --out, .rrd)" in options["--recording"]


def test_sweep_help_names_every_axis_a_study_takes():
    # --param's help named amp, freq, phase, scale, friction, duration, dt and builder options, not pga_g
    # (records scaled to a site's PGA), which the study has understood since 12380ab
    from masonrycli.study import axes

    names = [*axes.MOTION_PARAMS, axes.PGA_PARAM, "friction", "duration", "dt"]
    param = _option_help(["sweep"])["--param"]
    assert all(name in param for name in names), (names, param)


@pytest.mark.parametrize("command", [("simulate", "wall"), ("run",), ("sweep",), ("limit",), ("export",)])
def test_help_shows_no_type_on_an_on_off_option(command):
    # "--no-recording <bool>", "--force <bool>" (typer 0.29): a class read them as taking a value, true or false
    from masonrycli.cli.app import app

    result = runner.invoke(app, [*command, "--help"], prog_name="masonry", env={"COLUMNS": "120"})
    assert result.exit_code == 0, result.output
    flags = [line for line in result.output.splitlines() if "--force" in line or "--no-recording" in line]
    assert flags and not any("<bool>" in line for line in flags), flags


def _every_command_path():
    import typer.main

    from masonrycli.cli.app import app

    def walk(command, path):
        yield path
        for name, sub in getattr(command, "commands", {}).items():
            yield from walk(sub, (*path, name))

    return list(walk(typer.main.get_command(app), ()))


@pytest.mark.parametrize("command", _every_command_path(), ids=lambda path: " ".join(path) or "masonry")
def test_help_shows_the_help_option_as_a_plain_flag(command):
    # every page showed "--help -h <bool>": the help option (click makes it when a page is shown) was left
    # out of the flags whose type is hidden
    from masonrycli.cli.app import app

    result = runner.invoke(app, [*command, "--help"], prog_name="masonry", env={"COLUMNS": "120"})
    assert result.exit_code == 0, result.output
    rows = [line for line in result.output.splitlines() if "--help" in line and "-h" in line]
    assert len(rows) == 1 and "<bool>" not in rows[0], rows
