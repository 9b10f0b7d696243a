"""masonry export FOLDER --combined: a study's histories as one long CSV (one row per run × frame, the history's
name and its study point's values as columns), read back and checked against each history's own export; a real
study's --histories; refusals as one line, exit 2, nothing written."""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_outputs_export import TIMES, hand_history, read_csv

from cli_helpers import assert_one_line_error, invoke


def study_history(path, point: dict, **extra):
    return hand_history(path, run=np.asarray(json.dumps({"gravity_m_s2": [0.0, -9.81], "study_point": point})), **extra)


def test_a_folder_as_one_long_table(tmp_path):
    folder = tmp_path / "h"
    folder.mkdir()
    study_history(folder / "record=a.AT2_scale=0.5.npz", {"record": "a.AT2", "scale": 0.5})
    study_history(folder / "record=b.AT2_scale=2.npz", {"record": "b.AT2", "scale": 2}, time=TIMES * 2)
    hand_history(folder / "z.npz")  # a history of a plain run: no study point
    result = invoke("export", folder, "--combined", "--blocks", "c")
    assert result.exit_code == 0, result.output
    table = read_csv(tmp_path / "h.csv")  # the default: FOLDER.csv beside the folder
    assert list(table)[:4] == ["history", "record", "scale", "time (s)"]
    n = len(TIMES)
    assert table["history"] == ["record=a.AT2_scale=0.5"] * n + ["record=b.AT2_scale=2"] * n + ["z"] * n
    assert table["record"] == ["a.AT2"] * n + ["b.AT2"] * n + [""] * n
    assert table["scale"] == ["0.5"] * n + ["2.0"] * n + [""] * n  # one float column, empty where a run has none
    # every run's rows are its own export's, cell for cell
    for k, name in enumerate(["record=a.AT2_scale=0.5", "record=b.AT2_scale=2", "z"]):
        assert invoke("export", folder / f"{name}.npz", "--blocks", "c", "--out", tmp_path / f"{k}.csv").exit_code == 0
        own = read_csv(tmp_path / f"{k}.csv")
        for column, cells in own.items():
            assert table[column][k * n : (k + 1) * n] == cells, (name, column)
    # groupby by hand: the second run's time column is its own (twice as long)
    assert [float(x) for x in table["time (s)"][n : 2 * n]] == pytest.approx(TIMES * 2)


def test_the_working_folder_s_table_goes_beside_it(tmp_path, monkeypatch):
    """`masonry export . --combined` inside the histories' folder: FOLDER.csv beside it, as for `h/` (it was
    written into the folder itself, ./h.csv)."""
    folder = tmp_path / "h"
    folder.mkdir()
    study_history(folder / "amp=1.npz", {"amp": 1.0})
    monkeypatch.chdir(folder)
    result = invoke("export", ".", "--combined", "--blocks", "c")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "h.csv").exists() and not (folder / "h.csv").exists()


def test_combined_with_lab_times_and_integer_points(tmp_path):
    folder = tmp_path / "h"
    folder.mkdir()
    study_history(folder / "blocks=51.npz", {"blocks": 51})
    study_history(folder / "blocks=248.npz", {"blocks": 248})
    (tmp_path / "lab.csv").write_text("time (s),x (mm)\n0.005,1\n0.03,2\n")
    out = tmp_path / "all.csv"
    result = invoke("export", folder, "--combined", "--times", tmp_path / "lab.csv", "--out", out)
    assert result.exit_code == 0, result.output
    assert invoke("export", folder, "--combined", "--times", tmp_path / "lab.csv", "--out", out).exit_code == 2
    result = invoke(
        "export", folder, "--combined", "--times", tmp_path / "lab.csv", "--compare", "x (mm)", "--out", out, "--force"
    )
    assert result.exit_code == 0, result.output
    said = " ".join(result.output.split())
    assert all(f"blocks={n}.npz: top ux rel (m) (masonry) against x (mm) (lab), 2 samples" in said for n in (51, 248))
    table = read_csv(out)
    assert table["blocks"] == ["248", "248", "51", "51"]  # sorted by file name, integers as integers
    assert table["x (mm)"] == ["1", "2", "1", "2"] and table["time (s)"] == ["0.005", "0.03"] * 2


def test_refusals_are_one_line_and_write_nothing(tmp_path):
    folder = tmp_path / "h"
    folder.mkdir()
    study_history(folder / "a.npz", {"amp": 1.0})
    # another support's name: "table ux (m)" where a has "ground ux (m)"
    study_history(folder / "b.npz", {"amp": 2.0}, support_name=np.array(["table"]))
    assert_one_line_error(
        invoke("export", folder, "--combined"), "--combined:", "b.npz has other columns than", "(table ux (m))"
    )
    assert_one_line_error(
        invoke("export", folder / "a.npz", folder / "b.npz", "--combined"), "--combined: name the table with --out"
    )
    assert_one_line_error(
        invoke("export", folder, "--combined", "--out", tmp_path), "--combined writes one table: name a file"
    )
    (tmp_path / "h.csv").write_text("mine")
    assert_one_line_error(invoke("export", folder, "--combined"), "h.csv: the file exists")
    assert (tmp_path / "h.csv").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["h", "h.csv"]
    assert sorted(p.name for p in folder.iterdir()) == ["a.npz", "b.npz"]


@pytest.mark.slow
def test_a_real_study_as_one_table(tmp_path):
    """masonry sweep --histories, then export --combined: the swept values come from the histories themselves,
    and each run's rows are its own export's."""
    folder = tmp_path / "h"
    study = ("sweep", "wall", "--param", "amp=0.5,1", "--param", "freq=2", "--duration", 0.03, "--workers", 0)
    result = invoke(*study, "--histories", folder, "--out", tmp_path / "s.csv")
    assert result.exit_code == 0, result.output
    result = invoke("export", folder, "--combined")
    assert result.exit_code == 0, result.output
    table = read_csv(tmp_path / "h.csv")
    assert list(table)[:4] == ["history", "amp", "freq", "time (s)"]
    assert table["amp"] == ["0.5"] * 4 + ["1.0"] * 4 and set(table["freq"]) == {"2.0"}
    for k, name in enumerate(["amp=0.5_freq=2", "amp=1_freq=2"]):
        assert invoke("export", folder / f"{name}.npz", "--out", tmp_path / f"{k}.csv").exit_code == 0
        own = read_csv(tmp_path / f"{k}.csv")
        assert all(table[c][4 * k : 4 * k + 4] == cells for c, cells in own.items()), name
    # the stronger shaking moves the ground twice as far: the swept value is the run's
    ux = np.array([float(x) for x in table["ground ux (m)"]])
    assert ux[7] == pytest.approx(2 * ux[3], rel=1e-12) and ux[3] > 0
