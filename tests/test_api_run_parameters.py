"""``Run.parameters``: the run's parameters as its history keeps them (the ``run`` array, JSON). A teacher reading
a study's histories with ``api.read_history`` had to ``json.loads(str(run["run"]))`` to learn which point of the
study each one was; now ``run.parameters["study_point"]``, beside ``run.outcome``, makes the study's table again."""

from __future__ import annotations

import csv

from masonrycli import api

from cli_helpers import invoke


def test_a_study_s_histories_say_their_point(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    args = ["sweep", "wall", "-p", "blocks=12", "-p", "freq=1,2", "--duration", "0.01", "--workers", "0"]
    result = invoke(*args, "--no-recording", "--out", "s.csv", "--histories", "h")
    assert result.exit_code == 0, result.output
    with open("s.csv", newline="") as fh:
        table = {float(row["freq"]): row["state"] for row in csv.DictReader(fh)}
    runs = [api.read_history(path) for path in sorted((tmp_path / "h").glob("*.npz"))]
    points = [run.parameters["study_point"] for run in runs]
    assert points == [{"blocks": 12, "freq": 1.0}, {"blocks": 12, "freq": 2.0}]
    # the study's table again, from its histories: point and verdict
    assert {p["freq"]: run.outcome["state"] for p, run in zip(points, runs)} == table
    assert runs[0].parameters["dt_s"] == 1e-3 and runs[0].parameters["scenario"] == "wall"


def test_a_run_s_parameters_name_its_call():
    run = api.simulate("wall", blocks=12, duration=0.01, friction=0.6)
    assert run.parameters["command"] == "api.simulate('wall', blocks=12, duration=0.01, friction=0.6)"
    assert (run.parameters["friction"], run.parameters["blocks"]) == (0.6, 12)
