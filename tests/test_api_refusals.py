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
from pathlib import Path

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


API_WORDS = {"sim-magnify-no-recording": "magnify=5 draws in the recording: give recording= too (a path, or True)"}
"""Rows whose API message is its own: ``--no-recording`` is the API's default, not a choice made."""

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
    spelled = "error: " + python_spelling(said.removeprefix("error: "), api._keywords(), given=keywords)
    if name in API_WORDS:  # the API's own sentence, where the command line's is about a flag it has not
        spelled = f"error: {API_WORDS[name]}"
    assert _numbers_alike(f"error: {words(str(refused.value))}") == _numbers_alike(spelled)
    assert not re.search(rf"--({'|'.join(k.replace('_', '-') for k in keywords)})\b", str(refused.value))


QUAKE = str(Path(__file__).parent / "data" / "quake_velocity.csv")

BAD_CALLS = [  # (target, keywords, the message): every keyword a value of which can be refused, each message read
    # as a sentence in keyword spelling. It said "duration= and dt=0.02: does not divide duration = 4.99 …",
    # "courses= must be a positive integer, got 0", "scale=: goes with record=", "add force= to replace it",
    # "settlement=0 amp= A freq=3", "not a int" (the command line's wording respelled word by word)
    ("wall", {"duration": -1}, "duration=-1: must be > 0"),
    (
        "wall",
        {"duration": 4.99, "dt": 0.02},
        "duration=4.99 is not a whole number of steps of dt=0.02 (249.5 steps); use dt=0.01996 (250 steps) or change the duration",
    ),
    (
        "wall",
        {"dt": 0.3},
        "duration=1.0 is not a whole number of steps of dt=0.3 (3.33333 steps); use dt=0.333333 (3 steps) or change the duration",
    ),
    (
        "wall",
        {"duration": 100000.0, "dt": 0.0001},
        "duration=100000.0 at dt=0.0001 is 1,000,000,000 steps (at most 100,000,000)",
    ),
    ("wall", {"duration": 1.0, "dt": 1e-310}, "dt=1e-310: must be >= 1e-09 s (a likely typo)"),
    ("wall", {"dt": 0}, "dt=0: must be > 0"),
    ("wall", {"dt": 2}, "dt=2: must be <= duration (1.0)"),
    ("wall", {"theta": 2}, "theta=2: must be <= 1"),
    (
        "wall",
        {"tolerance": 1e-300},
        "tolerance=1e-300: must be >= 1e-15 m/s (float64 resolves a 1 m/s velocity to 2.2e-16 m/s; a likely typo)",
    ),
    ("wall", {"max_iterations": 0}, "max_iterations=0: must be >= 1"),
    ("wall", {"record_every": 0}, "record_every=0: must be >= 1"),
    ("wall", {"solver": "x"}, 'solver="x": must be one of nlgs-accel32, nlgs-accel, nlgs'),
    ("wall", {"friction": -1}, "friction=-1: must be >= 0"),
    ("wall", {"amp": float("nan")}, "amp=nan (amplitude): must be a finite number"),
    ("wall", {"freq": -1}, "freq=-1 (frequency): must be >= 0"),
    (
        "wall",
        {"freq": 0, "amp": 1},
        'freq=0: the velocity 1 m/s · sin(2π·0·t) is 0, nothing moves (amp=0 for no shaking; a constant velocity is a scenario file\'s motion = { kind = "constant", ... })',
    ),
    ("wall", {"blocks": 3.5}, "blocks=3.5: must be an integer"),
    ("wall", {"blocks": 0}, "blocks=0: must be a positive integer"),
    ("wall", {"courses": 0}, "courses=0: must be a positive integer"),
    (
        "wall",
        {"blocks": 51, "courses": 5},
        "blocks=51 and courses=5: 51 blocks cannot be laid in running bond with 5 courses (courses × full blocks per odd course: 1×51, 2×25, 6×8, 34×1)",
    ),
    (
        "wall",
        {"courses": 5},
        "courses=5: 51 blocks cannot be laid in running bond with 5 courses (courses × full blocks per odd course: 1×51, 2×25, 6×8, 34×1)",
    ),
    ("wall", {"length": 0.45}, "length=0.45 m is not a whole number of 0.3 m blocks (0.3 m is 1, 0.6 m is 2)"),
    ("wall", {"block_length": -1}, "block_length=-1: must be a positive number"),
    ("wall", {"block_height": -1}, "block_height=-1: must be a positive number"),
    ("wall", {"density": -1}, "density=-1: must be > 0"),
    ("wall", {"thickness": 0}, "thickness=0: must be > 0"),
    ("wall", {"settle": -1}, "settle=-1: must be in (0, 10] s (0.5 lets a traced wall's gaps close)"),
    (
        "wall",
        {"settlement": 0.01},
        "settlement=0.01: the wall stands on one ground; settlement applies to arch and aqueduct",
    ),
    (
        "arch",
        {"amp": 1},
        "amp=1: the arch settles its right foundation by default; shake both foundations with settlement=0, amp=1",
    ),
    ("arch", {"settlement": 0.01, "amp": 1}, "settlement=0.01 with amp=1: choose one loading (settle or shake)"),
    (
        "arch",
        {"freq": 3},
        "freq=3: the arch settles its right foundation by default; shake both foundations with settlement=0, amp=A, freq=3",
    ),
    ("aqueduct", {"settlement": 0, "freq": 3}, "freq=3 without amp=: nothing shakes the aqueduct (give amp=A)"),
    ("arch", {"settlement": -1}, "settlement=-1: must be >= 0 (a downward velocity, m/s)"),
    ("arch", {"voussoirs": 1}, "voussoirs=1: must be an integer ≥ 2"),
    ("arch", {"span": -1}, "span=-1: must be a positive number"),
    ("arch", {"ring_thickness": 0.0001}, "ring_thickness=0.0001 m is absurd (a likely typo: 0.001 to 1000 m)"),
    ("aqueduct", {"pier_courses": 0}, "pier_courses=0: must be an integer ≥ 1"),
    ("wall", {"pga": "x"}, "pga=x: must be a number, in g (0.25), or with its unit (0.25g, 2.45m/s2, 245gal)"),
    ("wall", {"scale": 2}, "scale=2 goes with record= (it multiplies the record)"),
    (
        "wall",
        {"record_dt": 0.01},
        "record_dt=0.01 goes with record= (the time between the samples of a one-column file)",
    ),
    (
        "wall",
        {"baseline": "none"},
        'baseline=none goes with record= (a scenario file\'s own record takes baseline = "none" in its table)',
    ),
    ("wall", {"record": QUAKE, "amp": 1}, "record=QUAKE with amp=1: choose one loading (the record replaces the sine)"),
    ("wall", {"record": QUAKE, "baseline": "off"}, 'baseline=off: must be "quadratic" or "none"'),
    ("wall", {"recording": 3}, "recording=3: a path (str or pathlib.Path), not an int"),
    ("wall", {"history": 3}, "history=3: a path (str or pathlib.Path), not an int"),
    ("wall", {"recording": "r.txt"}, "recording=r.txt: the file name must end in .rrd"),
    ("wall", {"history": "h.npz"}, "history=h.npz: the file exists (add force=True to replace it)"),
    ("wall", {"magnify": -1}, "magnify=-1: must be between 1 and 1e+06"),
    ("wall", {"magnify": 5}, "magnify=5 draws in the recording: give recording= too (a path, or True)"),
]


@pytest.mark.parametrize("target, given, said", BAD_CALLS, ids=[f"{t} {' '.join(g)}" for t, g, _ in BAD_CALLS])
def test_a_bad_call_says_a_sentence_in_keyword_spelling(target, given, said, tmp_path, monkeypatch):
    # a notebook user read '--tolerance', '--duration 4.99' and looked for flags the API does not have
    monkeypatch.chdir(tmp_path)
    (tmp_path / "h.npz").write_text("an existing history")
    with pytest.raises(InputError) as refused:
        api.simulate(target, **({"duration": 0.01} if not given.keys() & {"duration", "dt"} else {}) | given)
    assert str(refused.value).replace(QUAKE, "QUAKE") == said
    assert not re.search(r"(?<![\w-])--[a-z]", said)  # no flag of the command line
    assert not re.search(r"\w=(?: |:|$)", re.sub(r"record= \(|recording= too|without amp=", "", said))  # a value


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
    with pytest.raises(InputError, match=r"r\.md: the file exists \(add force=True to replace it\)") as refused:
        run.report(tmp_path / "r.md")
    assert str(refused.value).startswith("out=")


def test_a_warning_the_caller_s_filters_hide_stays_hidden(monkeypatch):
    # the warnings said again from the caller's line must be those the caller's filters let through: a library's
    # DeprecationWarning, hidden by Python's defaults, came out as one of the notebook's own (its __main__)
    import warnings

    from masonrycli import output_plan

    check_run = output_plan.check_run

    def with_a_library_warning(*args, **kwargs):
        warnings.warn_explicit("a library's deprecation", DeprecationWarning, "somelib.py", 1, module="somelib")
        return check_run(*args, **kwargs)

    monkeypatch.setattr(output_plan, "check_run", with_a_library_warning)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("ignore", DeprecationWarning)  # Python's defaults: shown for __main__ only
        warnings.filterwarnings("default", category=DeprecationWarning, module=__name__)
        api.simulate("wall", blocks=12, duration=0.002)
    assert [str(w.message) for w in said if w.category is DeprecationWarning] == []
