"""``masonry inspect H.npz`` (masonrycli/outputs/inspect_history.py): a run history summarised from the file alone —
the run's parameters and status, frames and time span, one line per array with its shape, dtype and unit —
for a real run's history, an interrupted one, a sweep's, one written before histories described themselves;
a damaged file or an archive that is no history is one line and exit code 2. Before: every .npz was
refused ("a run history (.npz), not a recording")."""

from __future__ import annotations

import json
import os
import re

import numpy as np
import pytest

from masonrycli.execute import run_metadata
from masonrycli.outputs.history import HistoryFile
from masonrycli.outputs.inspect_history import NOT_RECORDED, inspect_history, is_history
from masonrycli.run import Simulation, simulate
from masonrycli.scenario.builtin import builtin
from masonrycli.scenario.scenario import SOLVERS

from cli_helpers import assert_one_line_error, invoke


@pytest.fixture(scope="module")
def history(tmp_path_factory):
    """The history of a real 20-step run of the wall (a frame every 10 steps: 3 frames)."""
    path = tmp_path_factory.mktemp("inspect") / "h.npz"
    result = invoke("simulate", "wall", "--duration", 0.02, "--history", path, "--no-recording")
    assert result.exit_code == 0, result.output
    return path


def _array_lines(output: str) -> dict[str, str]:
    """The array lines of inspect's output: name -> the rest of the line."""
    lines = output.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("array "))
    return {line.split()[0]: line.split(None, 1)[1] for line in lines[start + 1 :] if line.strip()}


def _rows(output: str) -> dict[str, str]:
    """The boxed table's rows: label -> value (a wrapped value's lines joined)."""
    rows: dict[str, str] = {}
    last = None
    for line in output.splitlines():
        cells = re.match(r"│ (.*?)\s*│ (.*?)\s*│$", line)
        if not cells:
            continue
        label, value = cells.groups()
        if label:
            rows[label] = value
            last = label
        else:
            rows[last] += " " + value
    return rows


def test_a_run_history_is_summarised_from_its_own_arrays(history):
    result = invoke("inspect", history)
    assert result.exit_code == 0, result.output
    with np.load(history) as npz:
        arrays = {name: npz[name] for name in npz.files}
    run, units = json.loads(str(arrays["run"])), dict(arrays["units"])
    rows = _rows(result.output)
    assert rows["scenario"] == "wall (builder:wall)"
    assert rows["status"] == "completed"
    assert rows["solver"] == SOLVERS[0]  # the default
    assert rows["tolerance"].startswith("1e-05 m/s")
    assert rows["dt"].startswith("0.001 s (duration 0.02 s")
    assert f"commit {run['commit']}" in rows["masonry"] and f"source {run['source_digest']}" in rows["masonry"]
    # frames, steps and time span as the file holds them: 3 frames at steps 0, 10, 20
    assert rows["frames"] == "3" and rows["steps"] == "0 … 20" and rows["time_span"] == "0 … 0.02 s"
    assert rows["bodies"] == f"51 blocks, 1 support, {arrays['joint_body'].shape[0]} joints"
    lines = _array_lines(result.output)
    assert set(lines) == set(arrays)  # one line per array, none cut or left out
    for name, value in arrays.items():
        shape, dtype = value.shape, "str" if value.dtype.kind == "U" else value.dtype.name
        shape_text = "(" + ", ".join(map(str, shape)) + ("," if len(shape) == 1 else "") + ")"
        assert lines[name].startswith(shape_text), (name, lines[name])
        assert f" {dtype} " in lines[name] and lines[name].endswith(units[name]), (name, lines[name])
    assert lines["intensity_pga"].startswith(f"() = {float(arrays['intensity_pga']):.4g} ")
    assert units["block_q"].startswith("(T,N,3) centroid x, y (m)")


def test_an_interrupted_history_says_where_it_stopped(tmp_path):
    scenario = builtin("wall", duration=0.02)
    sim = Simulation(scenario)
    sink = HistoryFile(tmp_path / "i.npz", sim.model.block_name, sim.model.support_name)
    sink.run_info = run_metadata(scenario, sim)
    result = simulate(scenario, [sink], sim=sim, stop=lambda: True)  # a Ctrl-C after the first step
    sink.close(result.status, result.message)
    info = inspect_history(tmp_path / "i.npz")
    assert (info["status"], info["frames"], info["steps"]) == ("interrupted", 2, (0, 1))
    shown = invoke("inspect", tmp_path / "i.npz")
    assert shown.exit_code == 0, shown.output
    # walk-through 2026-11-29: "interrupted: interrupted at t = …", the note naming its status again
    assert _rows(shown.output)["status"] == "interrupted at t = 0.0010 s (step 1 of 20)"


def test_a_sweep_history_names_its_study_point(history, tmp_path):
    with np.load(history) as npz:
        arrays = {name: npz[name] for name in npz.files}
    run = json.loads(str(arrays["run"])) | {"study_point": {"amp": 0.5, "freq": 2.0}}  # as study/task.py adds it
    np.savez(tmp_path / "amp=0.5_freq=2.npz", **(arrays | {"run": np.asarray(json.dumps(run))}))
    shown = invoke("inspect", tmp_path / "amp=0.5_freq=2.npz")
    assert shown.exit_code == 0, shown.output
    assert _rows(shown.output)["study point"] == "amp = 0.5, freq = 2.0"


def test_an_old_history_without_units_or_run_is_summarised(tmp_path):
    """Written before histories carried units, run and status: what is missing is said, not guessed."""
    old = tmp_path / "old.npz"
    time = np.array([0.0, 0.01, 0.02])
    np.savez(
        old,
        time=time,
        step=np.array([0, 10, 20]),
        block_q=np.zeros((3, 2, 3)),
        block_name=np.array(["b0", "b1"]),
        support_name=np.array(["ground"]),
    )
    shown = invoke("inspect", old)
    assert shown.exit_code == 0, shown.output
    rows = _rows(shown.output)
    for label in ("scenario", "status", "solver", "tolerance", "dt", "masonry"):
        assert rows[label] == NOT_RECORDED, (label, rows[label])
    assert rows["frames"] == "3" and rows["time_span"] == "0 … 0.02 s" and rows["bodies"] == "2 blocks, 1 support"
    assert rows["units"].startswith(NOT_RECORDED)
    lines = _array_lines(shown.output)
    assert set(lines) == {"time", "step", "block_q", "block_name", "support_name"}
    assert lines["block_q"] == f"(3, 2, 3)  float64  {NOT_RECORDED}"
    assert all(line.endswith(NOT_RECORDED) for line in lines.values())


def test_damaged_files_and_other_archives_are_one_line(history, tmp_path):
    zeros = tmp_path / "zeros.npz"
    zeros.write_bytes(b"PK\x03\x04" + bytes(60))
    assert_one_line_error(invoke("inspect", zeros), "zeros.npz: not a readable history (.npz): BadZipFile")
    cut = tmp_path / "cut.npz"  # a copy stopped half way: no central directory
    cut.write_bytes(history.read_bytes()[: history.stat().st_size // 2])
    assert_one_line_error(invoke("inspect", cut), "cut.npz: not a readable history (.npz)")
    text = tmp_path / "notes.npz"
    text.write_text("time,x\n0,1\n")
    assert_one_line_error(invoke("inspect", text), "notes.npz: not a readable history (.npz)")
    other = tmp_path / "weights.npz"
    np.savez(other, w=np.ones(3), b=np.zeros(2))
    assert_one_line_error(
        invoke("inspect", other),
        "weights.npz: a NumPy archive (.npz) but not a run history (no time array; it holds w, b); "
        "inspect reads recordings (.rrd) and histories (--history H.npz)",
    )
    pickled = tmp_path / "pickled.npz"
    np.savez(pickled, time=np.zeros(2), run=np.array([{"a": 1}], dtype=object))
    assert_one_line_error(invoke("inspect", pickled), "pickled.npz: not a readable history (.npz)")


def test_a_history_damaged_inside_an_array_is_refused(history, tmp_path):
    # bytes changed inside block_q, an array inspect does not load: summarised as sound, exit 0
    import zipfile

    with zipfile.ZipFile(history) as zf:
        info = zf.getinfo("block_q.npy")
    data = bytearray(history.read_bytes())
    at = info.header_offset + 30 + len(info.filename) + len(info.extra) + info.file_size // 2
    data[at] ^= 0xFF
    damaged = tmp_path / "damaged.npz"
    damaged.write_bytes(bytes(data))
    assert_one_line_error(invoke("inspect", damaged), ": a damaged history: the array block_q fails its checksum")
    assert "not a readable" not in invoke("inspect", damaged).output


def test_a_history_under_another_name_is_still_a_history(history, tmp_path):
    renamed = tmp_path / "h.data"
    renamed.write_bytes(history.read_bytes())
    assert is_history(renamed) and is_history(history)
    assert not is_history(tmp_path / "missing.rrd") and not is_history(tmp_path)
    assert_one_line_error(invoke("inspect", tmp_path / "missing.npz"), "missing.npz: no such history")
    # walk-through 2026-11-28: a history a run still going writes said "no such history"
    (tmp_path / f".live.npz.{os.getpid()}.part").write_bytes(b"")
    assert_one_line_error(
        invoke("inspect", tmp_path / "live.npz"),
        f"live.npz: not there yet: a run still going (pid {os.getpid()}) writes it, whole at its end",
    )
    (tmp_path / "d.npz").mkdir()
    assert_one_line_error(invoke("inspect", tmp_path / "d.npz"), "d.npz: a folder, not a history")
    shown = invoke("inspect", renamed)
    assert shown.exit_code == 0 and _rows(shown.output)["scenario"] == "wall (builder:wall)", shown.output


def test_a_built_in_s_size_is_named(tmp_path):
    # "scenario │ wall (builder:wall)" was all a colleague handed the history saw of a 3 m x 0.6 m section
    path = tmp_path / "h.npz"
    args = ("--courses", 4, "--length", 0.6, "--block-height", 0.25, "--duration", 0.01, "--no-recording")
    assert invoke("simulate", "wall", *args, "--history", path).exit_code == 0
    said = invoke("inspect", path).output
    assert re.search(r"structure\s+│ wall: courses 4, length 0\.6, block_height 0\.25\s", said), said
    assert np.load(path)["block_extent"][:, 3].max() == pytest.approx(1.0)  # 4 courses of 0.25 m, as named


def _stack(path, densities) -> None:
    """Two 0.4 × 0.2 m stones, one on the other, with these density columns, on a ground polygon."""
    features = [
        {
            "type": "Feature",
            "properties": {"name": f"s{k}", "density": rho},
            "geometry": {"type": "Polygon", "coordinates": [[[0, y], [0.4, y], [0.4, y + 0.2], [0, y + 0.2], [0, y]]]},
        }
        for k, (rho, y) in enumerate(zip(densities, (0.0, 0.2)))
    ]
    ground = [[-1, -0.5], [1.4, -0.5], [1.4, 0], [-1, 0], [-1, -0.5]]
    features.append(
        {"type": "Feature", "properties": {"role": "support"}, "geometry": {"type": "Polygon", "coordinates": [ground]}}
    )
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))


@pytest.mark.parametrize(
    ("densities", "said"), [((2300, 2300), "density 2300 kg/m³"), ((2300, 2700), "density 2300–2700 (per block) kg/m³")]
)
def test_the_material_row_is_the_blocks_own_density(tmp_path, densities, said):
    """A survey whose stones carry a density column (2300 kg/m³) was reported 'density 2500 kg/m³', the default its
    blocks do not have, by inspect and by masonry report; the mass (2 × 0.08 m² × 2300 kg/m³) was right."""
    geo, h = tmp_path / "stack.geojson", tmp_path / "h.npz"
    _stack(geo, densities)
    result = invoke("run", geo, "--duration", 0.002, "--dt", 0.001, "--history", h, "--no-recording")
    assert result.exit_code == 0, result.output
    assert "2500" not in _rows(invoke("inspect", h).stdout)["material"]
    assert said in _rows(invoke("inspect", h).stdout)["material"]
    assert said in invoke("report", h).stdout
    assert np.load(h)["block_mass"].sum() == pytest.approx(0.08 * sum(densities), rel=1e-12)


def test_the_run_s_verdict_and_its_words_are_rows(tmp_path):
    # the history kept result_* (4364b33) but inspect showed them as bare array lines, the words ones with no
    # value at all ('result_state  ()  str'): its table now says the state, peak and residual drift as the run's
    # summary said them, and a 0-d word is shown quoted
    h = tmp_path / "h.npz"
    ran = invoke("simulate", "wall", "--blocks", 12, "--amp", 0.5, "--duration", 0.05, "--history", h, "--no-recording")
    assert ran.exit_code == 0, ran.output
    summary, result = _rows(ran.output), invoke("inspect", h)
    rows, arrays = _rows(result.output), _array_lines(result.output)
    for label in ("state", "peak drift"):
        assert rows[label] == summary[label]
    with np.load(h) as npz:
        ratio, height, state = (
            float(npz["result_residual_drift"]),
            float(npz["result_height"]),
            str(npz["result_state"]),
        )
    assert rows["residual drift"].startswith(f"{100 * ratio:.3g} % of the height ({1000 * ratio * height:.3g} mm)")
    assert arrays["result_state"].startswith(f"() = {state!r} ") and arrays["result_collapse_reason"].startswith(
        "() = ''"
    )
    assert arrays["run"].split()[:2] == ["()", "str"]  # the run's JSON: its rows above, not a line of 2 kB
    assert list(rows)[:2] == ["scenario", "structure"]  # an in-process command: no command to name


def test_a_bridges_fill_is_a_row_of_inspect_and_of_the_report(tmp_path):
    """A filled bridge's history: inspect and masonry report said friction, density and thickness, not the fill
    the blocks carried (the 37-stone surveyed bridge's 42.7 t, more than its stones' 31.9 t). The default
    semicircle filled to its crown at 1800 kg/m³: 1800 × (5.4 × 2.15 − 30 × ½ × 2.15² sin 6°) kg."""
    import math

    h = tmp_path / "h.npz"
    args = ["arch", "--fill-to", 2.15, "--fill-density", 1800, "--settlement", 0, "--duration", 0.002, "--dt", 0.001]
    result = invoke("simulate", *args, "--history", h, "--no-recording")
    assert result.exit_code == 0, result.output
    mass = 1800.0 * (5.4 * 2.15 - 30 * 0.5 * 2.15**2 * math.sin(math.radians(6.0)))
    said = f"{mass:.6g} kg carried by the blocks under it (dead load only)"
    assert _rows(invoke("inspect", h).stdout)["fill"] == said
    assert f"| fill | {said} |" in invoke("report", h).stdout


@pytest.mark.parametrize("command", ["inspect", "report"])
def test_reading_a_history_does_not_load_the_engine(history, command):
    # 5d01658 moved the verdict's words out of masonrycli.run so that inspect need not load numba (a second of
    # import), then took RESULT_KEYS from outputs.history, which imports the engine's kernels: numba again
    import subprocess
    import sys
    from pathlib import Path

    code = (
        "import runpy, sys\n"
        f"sys.argv = ['masonry', {command!r}, {str(history)!r}]\n"
        "try:\n    runpy.run_module('masonrycli', run_name='__main__')\nexcept SystemExit as exc:\n    assert not exc.code\n"
        "print('loaded:', [m for m in ('numba', 'masonrycli.engine', 'masonrycli.run') if m in sys.modules], "
        "file=sys.stderr)\n"
    )
    root = Path(__file__).resolve().parent.parent
    env = {**os.environ, "PYTHONPATH": str(root), "RERUN_ANALYTICS": "0"}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stderr.splitlines()[-1] == "loaded: []", done.stderr
