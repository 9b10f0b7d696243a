"""The Python API (masonrycli/api.py, docs/python.md): the command line's own code from Python. A run's arrays
are those of the history ``masonry simulate|run … --history`` writes, bit for bit; a bad value is refused with
the line the command prints before its exit 2; nothing is written unless asked; the page's code blocks run."""

from __future__ import annotations

import contextlib
import json
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from masonrycli import api
from masonrycli.errors import InputError
from masonrycli.option_spelling import python_spelling
from masonrycli.outputs.history import RESULT_KEYS

from cli_helpers import invoke, words
from synthetic_records import band_limited, write_at2

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"


def _same_arrays(mine: dict, theirs, *, same_start: bool = False) -> None:
    """Every array equal in dtype, shape and bits; ``run`` (the JSON of the parameters) equal but for the time
    each run started and the API's call (``command``: test_run_provenance; a test's in-process command names
    none)."""
    assert set(mine) == set(theirs.files if hasattr(theirs, "files") else theirs)
    for name, value in mine.items():
        other = theirs[name]
        if name == "run":
            first, second = json.loads(str(value)), json.loads(str(other))
            first.pop("command", None), second.pop("command", None)
            if not same_start:
                first.pop("started"), second.pop("started")
            assert first == second
            continue
        assert value.dtype == other.dtype and value.shape == other.shape, name
        assert np.array_equal(value, other, equal_nan=value.dtype.kind == "f"), name


def _quake(tmp_path) -> Path:
    path = tmp_path / "q.AT2"
    _, _, _, acc = band_limited(0.05, 0.005, [20.0, 35.0], [0.0005, 0.0002])
    write_at2(path, acc / 9.81, 0.005)
    return path


CASES = {
    "sine": (
        ("simulate", "wall", "--amp", "0.5", "--freq", "3", "--record-every", "5"),
        "wall",
        {"amp": 0.5, "freq": 3.0, "record_every": 5},
    ),
    "record": (
        ("simulate", "wall", "--record", "{quake}", "--scale", "0.5"),
        "wall",
        {"record": "{quake}", "scale": 0.5},
    ),
    "settled": (
        ("run", str(DATA / "wall_shaken.toml"), "--settle", "0.02"),
        str(DATA / "wall_shaken.toml"),
        {"settle": 0.02},
    ),
    "file": (
        ("run", str(DATA / "wall_shaken.toml"), "--friction", "0.5"),
        str(DATA / "wall_shaken.toml"),
        {"friction": 0.5},
    ),
}


@pytest.mark.parametrize("case", CASES)
def test_a_run_s_arrays_are_the_command_line_s_history_bit_for_bit(case, tmp_path):
    # the same values through `masonry simulate|run … --history` and api.simulate: every array of the file,
    # its units table and the run's parameters too (but for the second it started)
    args, target, options = CASES[case]
    quake = str(_quake(tmp_path))
    args = [a.format(quake=quake) for a in args]
    options = {k: v.format(quake=quake) if isinstance(v, str) else v for k, v in options.items()}
    h = tmp_path / "h.npz"
    result = invoke(*args, "--duration", "0.05", "--no-recording", "--history", h)
    assert result.exit_code == 0, result.output
    said = pytest.warns(UserWarning, match="settled 0.02 s") if case == "settled" else contextlib.nullcontext()
    with said:  # as the command line's 'warning: settled 0.02 s under its own weight …' line
        run = api.simulate(target, duration=0.05, **options)
    with np.load(h) as written:
        _same_arrays(run.arrays, written)
    assert run.status == "completed" and run.time[-1] == pytest.approx(0.05)


# (API keywords, the command line's options): each refused alike
REFUSED = [
    ({"amp": float("nan")}, ["--amp", "nan"]),
    ({"dt": 0.3}, ["--dt", "0.3"]),
    ({"blocks": -3}, ["--blocks", "-3"]),
    ({"settlement": 0.01}, ["--settlement", "0.01"]),
    ({"freq": 0.0}, ["--freq", "0"]),
    ({"scale": 2}, ["--scale", "2"]),
    ({"record": "missing.AT2"}, ["--record", "missing.AT2"]),
    ({"duration": -1}, ["--duration", "-1"]),
    ({"friction": -0.2}, ["--friction", "-0.2"]),
    ({"solver": "gauss"}, ["--solver", "gauss"]),
    ({"history": "h.npz"}, ["--history", "h.npz"]),  # exists: refused without force
    ({"history": "h.txt"}, ["--history", "h.txt"]),
    ({"recording": "w.rrd", "history": "w.rrd"}, ["--out", "w.rrd", "--history", "w.rrd"]),
]


@pytest.mark.parametrize("options, args", REFUSED, ids=lambda v: " ".join(map(str, v)) if isinstance(v, list) else None)
def test_a_bad_value_is_refused_with_the_command_line_s_line(options, args, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "h.npz").write_bytes(b"")
    cli_args = args if "--out" in args else [*args, "--no-recording"]
    result = invoke("simulate", "wall", *cli_args)
    assert result.exit_code == 2, result.output
    with pytest.raises(InputError) as refused:
        api.simulate("wall", **options)
    # the same line, its options named by the keywords given (duration=, not --duration)
    said = words(result.output).removeprefix("error: ")
    assert python_spelling(said, api._keywords(), given=options) == str(refused.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["h.npz"]  # neither wrote anything


@pytest.mark.parametrize(
    "options, args, said",
    [
        ({"recording": "x.rrd/"}, ["--out", "x.rrd/"], 'x.rrd/: a path ending in "/" names a folder, not a file'),
        ({"history": "h.npz/."}, ["--history", "h.npz/."], 'h.npz/.: a path ending in "/." names a folder'),
        ({"record": ""}, ["--record", ""], "the path is empty"),  # said as record='': the path is empty
    ],
)
def test_a_path_is_read_by_the_command_line_s_parser(options, args, said, tmp_path, monkeypatch):
    # the parser's refusals are the command line's own words around the same reason ("Invalid value for
    # '--out' / '-o': …"); Path("x.rrd/") is x.rrd, which the API wrote without a word
    monkeypatch.chdir(tmp_path)
    assert said in words(invoke("simulate", "wall", *args).output)
    keyword = {"--out": "recording"}.get(args[0], args[0][2:])
    # the path once, as the keyword's value ('recording=: x.rrd/: …' said it apart from its keyword)
    with pytest.raises(InputError, match=re.escape(f"{keyword}={said}" if said[0] != "t" else f"{keyword}='': {said}")):
        api.simulate("wall", duration=0.01, **options)
    assert list(tmp_path.iterdir()) == []


def test_an_option_the_command_does_not_take_is_one_line_naming_the_close_ones(tmp_path):
    with pytest.raises(InputError, match=r"^no such option: blok= for wall \(did you mean blocks\?\)$"):
        api.scenario("wall", blok=3)
    with pytest.raises(InputError, match="no such option: span= for wall"):
        api.scenario("wall", span=4.0)  # the arch's: `masonry simulate wall --span 4` has no such option
    wall = api.scenario("wall", duration=0.05)
    with pytest.raises(InputError, match="no such option: amp= for a Scenario already made .*api.scenario"):
        api.simulate(wall, amp=0.5)  # the loading goes with the structure: api.scenario("wall", amp=0.5)
    with pytest.raises(InputError, match="no such option: record= for a Scenario already made"):
        api.simulate(wall, record="q.AT2")  # it would run the wall's 1 s, not the record's length
    assert api.scenario(wall, dt=5e-4, friction=0.5).run.dt == 5e-4
    with pytest.raises(InputError, match="give wall, arch, aqueduct"):
        api.scenario(51)
    with pytest.raises(
        InputError, match=r"no such option: out= for wall \(the recording is simulate\(recording=PATH\)\)"
    ):
        api.simulate("wall", out="w.rrd")  # the command line's --out


def test_ctrl_c_ends_the_run_interrupted_with_its_frames(tmp_path):
    # a notebook's "interrupt the kernel" is a SIGINT: the run ends after the step under way and returns what it
    # reached (files whole), as the command line does; Python's own handler is back afterwards
    def interrupt(frame):
        if frame.step == 20:
            os.kill(os.getpid(), signal.SIGINT)

    h = tmp_path / "h.npz"
    run = api.simulate("wall", duration=0.1, record_every=10, on_frame=interrupt, history=h)
    assert run.status == "interrupted" and run.note == "interrupted at t = 0.0200 s (step 20 of 100)"
    assert list(run["step"]) == [0, 10, 20]
    with np.load(h) as written:
        assert str(written["status"]) == "interrupted" and list(written["step"]) == [0, 10, 20]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_nothing_is_written_unless_asked_and_runs_keep_no_state(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    first = api.simulate("wall", duration=0.02, amp=0.5, record_every=1)
    other = api.simulate("wall", duration=0.02, amp=1.0, record_every=1)
    again = api.simulate("wall", duration=0.02, amp=0.5, record_every=1)
    assert list(tmp_path.iterdir()) == []  # no recordings/ folder, no history
    assert first.recording is None and first.history is None
    _same_arrays(first.arrays, again.arrays)
    assert not np.array_equal(first["block_q"], other["block_q"])


def test_files_asked_for_are_written_read_back_and_viewed(tmp_path, monkeypatch):
    h, rec = tmp_path / "runs" / "w.npz", tmp_path / "runs" / "w.rrd"
    run = api.simulate("wall", duration=0.02, amp=0.5, history=h, recording=rec)
    assert run.history == h and run.recording == rec and rec.stat().st_size > 0
    back = api.read_history(h)
    _same_arrays(run.arrays, back.arrays)
    assert back.status == "completed" and back.unit("time") == "s, time of the frame"
    # the verdict the file keeps (result_*) is the run's: read_history said None whatever the file held
    assert set(back.outcome) == set(RESULT_KEYS) and back.outcome["state"] == run.outcome["state"]
    for key in RESULT_KEYS:
        assert back.outcome[key] == run.outcome[key] or np.isnan(back.outcome[key]) and np.isnan(run.outcome[key])
    with np.load(h) as npz:  # a history written before histories kept the verdict: None
        older = {k: npz[k] for k in npz.files if not k.startswith("result_")}
    np.savez(tmp_path / "older.npz", **older)
    assert api.read_history(tmp_path / "older.npz").outcome is None
    with pytest.raises(InputError, match="history=.*exists.*add force="):
        api.simulate("wall", duration=0.02, history=h)  # never overwritten without force
    api.simulate("wall", duration=0.02, history=h, force=True)
    monkeypatch.chdir(tmp_path)
    default = api.simulate("wall", duration=0.02, recording=True)  # the command line's default name
    assert default.recording.parent == Path("recordings") and default.recording.name.startswith("wall-")
    started = []
    monkeypatch.setattr(subprocess, "Popen", lambda args: started.append(args) or "viewer")
    assert api.view(rec) == "viewer" and started[0][1:] == [str(rec)]
    with pytest.raises(InputError, match="no such history"):
        api.read_history(tmp_path / "none.npz")


@pytest.mark.parametrize(
    "name, said",
    [
        ("w.rrd", "w.rrd: a Rerun recording (.rrd), not a history (.npz); masonry inspect summarises it"),
        ("s.toml", "s.toml: a scenario file (TOML), not a history (.npz); masonry run runs it"),
    ],
)
def test_a_file_of_another_kind_is_named_as_such(name, said, tmp_path, monkeypatch):
    # read_history and masonry export said "w.rrd: not a readable history (.npz): BadZipFile: File is not a zip file"
    monkeypatch.chdir(tmp_path)
    (tmp_path / name).write_text("x")
    with pytest.raises(InputError) as refused:
        api.read_history(name)
    assert str(refused.value) == said
    assert words(invoke("export", name).output) == f"error: {said}"


def test_the_views_of_the_arrays(tmp_path):
    frames = []
    run = api.simulate("wall", duration=0.05, amp=0.5, on_frame=frames.append)
    assert [f.time for f in frames] == list(run.time)  # every recorded frame, the history's
    assert all(f.contact_force.shape == f.contact_point.shape == (len(f.contact_body), 2) for f in frames)
    assert [b.name for b in api.scenario("wall").assembly.blocks] == run.block_names  # docs/python.md draws so
    u = run.displacement
    assert u.shape == (len(run.time), 51, 3) and not u[0].any()
    assert run.block("c01-b01") == run.block_names.index("c01-b01")
    with pytest.raises(InputError, match="did you mean c01-b01"):
        run.block("c1-b01")
    hinged = run.hinged_joints()
    assert len(hinged) == run["hinge_count"][-1] == run.outcome["hinges"]
    assert all("|" in name for name in hinged)
    table = run.table()
    # the top course's drift at the end is the summary's residual drift (the same definition, collapse.md)
    assert table["drift ratio (-)"][-1] == pytest.approx(run.outcome["residual_drift"], rel=1e-9, abs=1e-15)
    assert run.unit("cell_spherical_stress").startswith("Pa")
    with pytest.raises(KeyError, match="did you mean energy_kinetic"):
        run["energy_kinetc"]


def test_a_notebook_shows_nothing_but_what_the_user_prints(monkeypatch, capsys):
    # in Jupyter rich displays a console's output under the cell whatever its file: every api.simulate showed the
    # summary table (found running docs/python.md's cells in an ipykernel). Here rich is made to believe it is in
    # Jupyter, and what it would display is counted.
    import rich.console
    import rich.jupyter

    shown = []
    monkeypatch.setattr(rich.console, "_is_jupyter", lambda: True)
    monkeypatch.setattr(rich.jupyter, "display", lambda segments, text: shown.append(text))
    run = api.simulate("wall", duration=0.02, amp=0.5)
    assert shown == [] and capsys.readouterr() == ("", "") and run.summary.startswith("wall — completed")


def test_import_masonrycli_names_the_api_and_does_not_load_it():
    # the first thing a student tries; the package stays light for the commands (no engine, no numba)
    code = (
        "import sys, masonrycli; assert 'from masonrycli import api' in masonrycli.__doc__; "
        "assert 'masonrycli.api' not in sys.modules and 'numba' not in sys.modules; "
        "assert masonrycli.api.simulate is sys.modules['masonrycli.api'].simulate"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)})


def _page_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "python.md").read_text(), flags=re.S)


def test_the_python_page_runs_as_a_notebook(tmp_path, monkeypatch):
    # its blocks one after the other in one namespace, as a notebook's cells, in an empty folder
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    blocks = _page_blocks()
    assert len(blocks) >= 8
    namespace: dict = {}
    for k, code in enumerate(blocks):
        exec(compile(code, f"docs/python.md block {k + 1}", "exec"), namespace)
    assert (
        (tmp_path / "wall-drift.png").stat().st_size > 0
        and (tmp_path / "wall-end.png").stat().st_size > 0
        and (tmp_path / "runs" / "wall.npz").is_file()
    )
    assert namespace["run"].outcome["state"] == "damaged"
    assert namespace["message"] == "amp=nan (amplitude): must be a finite number"
    # the study run from the notebook's Python: its 4 rows, and a history naming the sweep that made it
    assert [row["state"] for row in namespace["rows"]] == ["damaged"] * 4
    # the table names the sweep too, as the page's `python -m masonrycli sweep` ran it (a CSV column)
    assert {row["command"] for row in namespace["rows"]} == {f"masonry {' '.join(namespace['study'][3:])}"}
    assert "| command | masonry sweep wall --param freq=1,2 " in namespace["point"].report()
    assert namespace["point"].parameters["study_point"] == {"freq": 2.0, "friction": 0.7}  # the page's comment


def test_a_scenario_shown_in_a_notebook_is_a_few_lines():
    # a cell ending in api.scenario("aqueduct") showed its repr: every block's polygon, 70 kB (14 kB for the wall)
    shown = repr(api.scenario("aqueduct"))
    assert len(shown) < 1000 and "Assembly(346 blocks (" in shown and "2 supports (left-foundation … " in shown
    assert repr(api.scenario("wall").assembly) == "Assembly(51 blocks (c01-b01 … c06-b09), 1 support (ground))"


def test_unconverged_steps_are_warned_as_the_command_line_warns_them():
    # the command line prints 'warning: 100 of 100 steps ended unconverged …' after its summary; the API's run
    # said nothing (its status 'completed', the count in Run.summary's table only)
    result = invoke("simulate", "wall", "--amp", 1, "--duration", 0.02, "--max-iterations", 5, "--no-recording")
    line = " ".join(result.output.split("warning: ", 1)[1].split())
    with pytest.warns(RuntimeWarning) as said:
        run = api.simulate("wall", amp=1.0, duration=0.02, max_iterations=5)
    # the command line's line, its options spelled as the keywords given (tolerance=, max_iterations=)
    # after the first unconverged step's own warning, said as it ended (tests/test_api_warnings.py)
    assert [str(w.message) for w in said][1:] == [python_spelling(line, api._keywords())]
    assert line.startswith("20 of 20 steps ended unconverged") and "--tolerance" in line
    assert "above tolerance=1e-05 m/s" in str(said[-1].message)
    assert run.status == "completed" and run["nlgs_unconverged"][-1] == 20
