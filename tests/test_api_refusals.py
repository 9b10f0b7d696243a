"""Every refusal of the bad-input catalogue (tests/bad_input_files.py, bad_input_geometry.py,
bad_input_options.py, bad_input_paths.py) that ``masonry
simulate``, ``run`` or ``check`` makes with exit 2 is the Python API's too, in the same words: each row's options,
as the command line converts them, given to :func:`masonrycli.api.simulate` raise the
:class:`~masonrycli.errors.InputError` whose text is the command's line with its options spelled as the API's
keywords (``duration=``, not ``--duration``: :mod:`masonrycli.option_spelling`) (a row the command line's parser refuses,
"--dt abc", has no Python counterpart: a number is a number there)."""

from __future__ import annotations

import ast
import inspect
import re

import click
import pytest
import typer
from bad_input_files import FILE_ROWS
from bad_input_geometry import GEOMETRY_ROWS
from bad_input_options import OPTION_ROWS
from bad_input_paths import PATH_ROWS
from test_bad_input_catalogue import write_files

from geometry_library.values import TypedNumber
from masonrycli import api
from masonrycli.cli.app import app
from masonrycli.errors import InputError
from masonrycli.option_spelling import python_spelling
from masonrycli.scenario.builtin import BUILT_IN

from cli_helpers import invoke, words

ROWS = [
    row
    for row in FILE_ROWS + GEOMETRY_ROWS + OPTION_ROWS + PATH_ROWS
    if row[2][0] in ("simulate", "run", "check") and row[3] == 2
]
TARGET = {"run": "scenario_file", "check": "target"}


def _keywords(argv: list[str]):
    """(target, keywords) of a command line as its command parses them, or None if the parser refuses it."""
    group = typer.main.get_command(app)
    root = click.Context(group, info_name="masonry")
    name, *rest = argv
    command = group.get_command(root, name)
    target = None
    if name == "simulate":
        command, target, rest = command.get_command(root, rest[0]), rest[0], rest[1:]
        if command is None:
            return None
    try:
        params = command.make_context(name, list(rest), parent=root).params
    except Exception:  # noqa: BLE001 (typer's own click's errors: a parse error, a --help)
        return None
    target = params.pop(TARGET[name]) if target is None else target
    given = {k: _typed(v) for k, v in params.items() if v is not None and v is not False}
    given.pop("no_recording", None)  # the API's default
    if "out" in given:
        given["recording"] = given.pop("out")
    return target, given


def _typed(value):
    """A number as a Python user would type it: the literal of its text on the command line ("-1" an int)."""
    if isinstance(value, TypedNumber):
        try:
            return ast.literal_eval(value.text)
        except (ValueError, SyntaxError):  # "nan", "inf": float() reads them, Python needs float("nan")
            return float(value)
    return value


_NUMBER = re.compile(r"-?\d+(?:\.\d*)?(?:e[-+]?\d+)?")


def _numbers_alike(text: str) -> str:
    """``text`` with every number in one spelling: "duration 1e5" and "duration 100000.0" say the same."""
    return _NUMBER.sub(lambda m: repr(float(m.group())), text)


PARSED = [row for row in ROWS if _keywords(list(row[2])) is not None]
"""The rows the command line's parser takes (it refuses "--dt abc", "--bogus", a missing value: no Python
counterpart, those are left out here)."""


def test_most_rows_have_a_python_counterpart():
    assert len(ROWS) >= 130 and len(PARSED) >= len(ROWS) - 12


@pytest.mark.parametrize("name, files, argv, code, fragment", PARSED, ids=[row[0] for row in PARSED])
def test_the_api_refuses_as_the_command_line(name, files, argv, code, fragment, tmp_path, monkeypatch):
    write_files(tmp_path, files)
    monkeypatch.chdir(tmp_path)
    argv = [a.format(d=tmp_path) for a in argv]
    parsed = _keywords(argv)
    said = words(invoke(*argv).output)
    target, keywords = parsed
    with pytest.raises(InputError) as refused:
        api.simulate(target, **keywords)
    spelled = python_spelling(said, api._keywords())
    assert _numbers_alike(f"error: {words(str(refused.value))}") == _numbers_alike(spelled)
    assert not re.search(rf"--({'|'.join(k.replace('_', '-') for k in keywords)})\b", str(refused.value))


BAD_CALLS = [  # (keywords, the keyword the message names first): every keyword a value of which can be refused
    ({"duration": -1}, "duration=-1"),
    ({"duration": 4.99, "dt": 0.02}, "duration="),
    ({"dt": 0}, "dt=0"),
    ({"theta": 2}, "theta=2"),
    ({"tolerance": 1e-300}, "tolerance=1e-300"),
    ({"max_iterations": 0}, "max_iterations=0"),
    ({"record_every": 0}, "record_every=0"),
    ({"solver": "x"}, "solver="),
    ({"friction": -1}, "friction=-1"),
    ({"amp": float("nan")}, "amp=nan"),
    ({"freq": 0, "amp": 1}, "freq=0"),
    ({"blocks": 3.5}, "blocks=3.5"),
    ({"courses": 0}, "courses="),
    ({"length": 0.45}, "length=0.45"),
    ({"block_length": -1}, "block_length="),
    ({"block_height": -1}, "block_height="),
    ({"density": -1}, "density=-1"),
    ({"thickness": 0}, "thickness=0"),
    ({"settle": -1}, "settle=-1"),
    ({"pga": "x"}, "pga=x"),
    ({"scale": 2}, "scale="),
    ({"record_dt": 0.01}, "record_dt="),
    ({"baseline": "none"}, "baseline="),
    ({"recording": 3}, "recording=3"),
    ({"history": 3}, "history=3"),
    ({"magnify": -1}, "magnify=-1"),
]


@pytest.mark.parametrize("given, named", BAD_CALLS, ids=[" ".join(g) for g, _ in BAD_CALLS])
def test_a_bad_call_names_the_keyword_as_typed(given, named):
    # a notebook user read '--tolerance', '--duration 4.99' and looked for flags the API does not have
    with pytest.raises(InputError) as refused:
        api.simulate("wall", **({"duration": 0.01} | given))
    said = str(refused.value)
    assert named in said and "--" not in said.split(" masonry ")[0], said


def test_the_unconverged_warning_names_the_keywords():
    with pytest.warns(RuntimeWarning) as caught:
        api.simulate("wall", duration=0.01, max_iterations=2)
    first, said = (str(w.message) for w in caught)  # the first unconverged step as it ends, the count at the end
    assert "× tolerance=1e-05 m/s; the run goes on" in first and "--" not in first
    assert "above tolerance=1e-05 m/s" in said and "Raise max_iterations= " in said and "--" not in said


def test_the_command_line_keeps_its_flags():
    said = words(invoke("simulate", "wall", "--duration", "-1", "--no-recording").output)
    assert said == "error: --duration: duration = -1: must be > 0"


OUTPUTS = {"out", "no_recording", "history", "force", "magnify", "stop_at_collapse"}
"""simulate()'s own keywords: the command line's output options, not the scenario's."""


@pytest.mark.parametrize("target", ["wall", "arch", "aqueduct", "s.toml"])
def test_the_api_takes_the_options_of_its_command_and_no_other(target):
    # an option added to `masonry simulate NAME` or `masonry run` and not applied by api.scenario fails here
    # (settle= came to `run` beside the API, which refused it: 'no such option'), not in a user's notebook
    group = typer.main.get_command(app)
    command = group.commands["simulate"].commands[target] if target in BUILT_IN else group.commands["run"]
    expected = {p.name for p in command.params} - OUTPUTS - {"scenario_file"}
    assert set(api._option_names(target)) == expected
    assert OUTPUTS - {"out", "no_recording"} <= set(inspect.signature(api.simulate).parameters)


@pytest.mark.parametrize(
    "given, said",
    [
        ({"freq": [1, 2, 3]}, "freq: 3 values (1,2,3): one run takes one value; loop over them"),
        ({"friction": (0.4, 0.6)}, "friction: 2 values (0.4,0.6): one run takes one value"),
    ],
)
def test_several_values_for_one_keyword_say_how_to_run_them(given, said):
    # a student passed freq=[1, 2, 3] expecting three runs: 'must be a number' read as a wrong type
    with pytest.raises(InputError) as refused:
        api.simulate("wall", duration=0.01, **given)
    key, values = next(iter(given.items()))
    assert str(refused.value).startswith(said)
    assert f"masonry sweep --param {key}={','.join(map(str, values))} " in str(refused.value)


@pytest.fixture(scope="module")
def run():
    return api.simulate("wall", blocks=12, duration=0.01)


@pytest.mark.parametrize(
    "method, given, said",
    [
        ("table", {"blocks": ["nope"]}, "blocks=nope: no such block in the run"),
        ("table", {"courses": [99]}, "courses=99: the run has 1 courses"),
        ("table", {"ground": "x"}, "ground=x: no such support in the run"),
        ("report", {"out": "r.txt"}, "out=r.txt: the file name must end in .md"),
        ("report", {"out": 3}, "out=3: a path"),
    ],
)
def test_a_run_s_methods_name_their_keywords(run, method, given, said, tmp_path, monkeypatch):
    # Run.table(courses=[99]) said '--course 99: …', a flag of masonry export the method does not have
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError) as refused:
        getattr(run, method)(**given)
    assert str(refused.value).startswith(said) and "--" not in str(refused.value), refused.value


def test_a_report_that_exists_says_force_as_the_method_takes_it(run, tmp_path):
    run.report(tmp_path / "r.md")
    with pytest.raises(InputError, match=r"r\.md: the file exists \(add force= to replace it\)") as refused:
        run.report(tmp_path / "r.md")
    assert str(refused.value).startswith("out=")


def test_a_warning_the_caller_s_filters_hide_stays_hidden(monkeypatch):
    # the warnings said again from the caller's line must be those the caller's filters let through: a library's
    # DeprecationWarning, hidden by Python's defaults, came out as one of the notebook's own (its __main__)
    import warnings

    from masonrycli import execute

    check_run = execute.check_run

    def with_a_library_warning(*args, **kwargs):
        warnings.warn_explicit("a library's deprecation", DeprecationWarning, "somelib.py", 1, module="somelib")
        return check_run(*args, **kwargs)

    monkeypatch.setattr(execute, "check_run", with_a_library_warning)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("ignore", DeprecationWarning)  # Python's defaults: shown for __main__ only
        warnings.filterwarnings("default", category=DeprecationWarning, module=__name__)
        api.simulate("wall", blocks=12, duration=0.002)
    assert [str(w.message) for w in said if w.category is DeprecationWarning] == []
