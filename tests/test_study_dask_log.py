"""Dask's own log lines during a study go to ``<out>.dask.log``, not to stderr among masonry's lines
(masonrycli/study/dask_log.py): a worker that died under a point gave 'distributed.scheduler - ERROR - Task
run-… marked as failed because 4 workers died while trying to run it' on stderr, once a point."""

from __future__ import annotations

import csv
import logging
import os
import re

import pyarrow.parquet as pq
import pytest
from rich.console import Console

from masonrycli.scenario.motion import Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder
from masonrycli.study import store
from masonrycli.study.axes import StudyBase, parse_axis
from masonrycli.study.dask_log import DaskLog, log_path
from masonrycli.study.study import StudyRequest, run_study

from cli_helpers import words

DIED = "Task run-1f2e marked as failed because 4 workers died while trying to run it"


def test_nothing_logged_writes_no_file_and_the_handlers_come_back(tmp_path):
    import distributed  # noqa: F401 (its stderr handler installed, as in a study)

    before = {name: list(logging.getLogger(name).handlers) for name in ("distributed", "tornado", "bokeh")}
    path = tmp_path / "s.csv.dask.log"
    with DaskLog(path) as log:
        logging.getLogger("distributed.worker").info("Start worker at tcp://…")  # below WARNING: not kept
    assert not path.exists() and log.said() is None
    assert {name: list(logging.getLogger(name).handlers) for name in before} == before
    with DaskLog(path) as log:
        logging.getLogger("distributed.nanny").warning("Restarting worker")
    with DaskLog(path) as log:  # a resumed study appends
        logging.getLogger("distributed.scheduler").error(DIED + "\nsecond line")
        logging.getLogger("distributed.scheduler").error("another")
    lines = path.read_text().splitlines()
    assert [line.split(" - ", 1)[-1] for line in lines] == [
        "distributed.nanny - WARNING - Restarting worker",
        f"distributed.scheduler - ERROR - {DIED}",
        "second line",
        "distributed.scheduler - ERROR - another",
    ]
    assert log.said() == f"Dask logged 2 errors ({DIED}): in {path} (what became of each run is in its row)"
    assert log_path(tmp_path / "s.csv") == path


@pytest.mark.slow
def test_dask_s_errors_during_a_study_go_to_its_log_file_not_to_stderr(tmp_path, monkeypatch, capfd):
    # A real LocalCluster study (worker processes; the scheduler in this process, where the ERROR lines come
    # from); its scheduler logs the line of a point given up after its workers died while the first row is kept.
    append = store.Journal.append

    def append_and_log(journal, row):
        append(journal, row)
        logging.getLogger("distributed.scheduler").error(DIED)

    monkeypatch.setattr(store.Journal, "append", append_and_log)
    scenario = scenario_from_builder(
        "wall", {"blocks": 12}, RunConfig(duration=0.1), Material(), {"ground": Sine(amplitude=0.1, frequency=2.0)}
    )
    out = tmp_path / "study.parquet"
    said: list[str] = []
    request = StudyRequest(axes=[parse_axis("amp=0.1,0.2")], out=out, workers=1, warn=said.append)
    result = run_study(StudyBase(scenario), request, Console(quiet=True))
    assert len(pq.read_table(out).to_pylist()) == 2 and result.failed == 0
    err = capfd.readouterr().err
    assert "distributed" not in err and "marked as failed" not in err, err
    kept = (tmp_path / "study.parquet.dask.log").read_text()
    assert kept.count(f"distributed.scheduler - ERROR - {DIED}") == 2, kept
    assert result.warnings[-1] == (
        f"Dask logged 2 errors ({DIED}): in {tmp_path / 'study.parquet.dask.log'} (what became of each run is in its "
        "row)"
    )
    assert said == []  # said once the table is shown (result.warnings), not before
    # distributed's own handlers are back: a later Dask in the same process (a notebook) logs as before
    assert all(type(h).__name__ != "_ToFile" for h in logging.getLogger("distributed").handlers)


# Run as `python -m point_kills_worker sweep …`: masonry's command line, the point amp=0.2 ending its worker process
# (as an out-of-memory kill would); the task travels by reference to this module, which the workers import too.
_POINT_KILLS_WORKER = """
import os, time
from masonrycli.__main__ import main
from masonrycli.study import runner

made = runner.run_task

def run_task(base, params, *args):
    if params.get("amp") == 0.2:
        time.sleep(0.3)
        os._exit(1)
    return made(base, params, *args)

runner.run_task = run_task
if __name__ == "__main__":
    main()
"""


@pytest.mark.slow
def test_a_point_that_kills_its_workers_leaves_dask_s_lines_in_the_log_file_and_one_line_on_stderr(tmp_path):
    # the whole command, a real LocalCluster: the point's workers die 4 times, the scheduler gives the task up
    # ('distributed.scheduler - ERROR - Task run-… marked as failed because 4 workers died …', on stderr before)
    import subprocess
    import sys

    from test_sweep_cluster import ENV, ROOT

    (tmp_path / "point_kills_worker.py").write_text(_POINT_KILLS_WORKER)
    out = tmp_path / "s.csv"
    sweep = [sys.executable, "-m", "point_kills_worker", "sweep", "wall", "--param", "blocks=12", "--duration", "0.3"]
    sweep += ["--param", "amp=0.1,0.2,0.3", "--workers", "1", "--out", out, "--no-recording"]
    env = ENV | {
        "PYTHONPATH": f"{tmp_path}{os.pathsep}{ROOT}",
        "DASK_DISTRIBUTED__DEPLOY__LOST_WORKER_TIMEOUT": "0.1s",  # each death drops the worker: the watch's restart
    }
    proc = subprocess.run(sweep, capture_output=True, text=True, env=env, timeout=600, cwd=tmp_path)
    assert proc.returncode == 5, proc.stdout + proc.stderr  # the point's row failed
    assert "distributed" not in proc.stderr and "Traceback" not in proc.stderr, proc.stderr
    said = words(proc.stderr)
    log = tmp_path / "s.csv.dask.log"
    # given up once alone, and once or more beside the good points before (the runner runs it again alone)
    assert re.search(
        r"warning: Dask logged \d+ errors? \(Task run-\S+ marked as failed because 4 workers died while trying to run "
        rf"it\): in {re.escape(str(log))} \(what became of each run is in its row\)",
        said,
    ), said
    assert "error: 1 of 3 rows failed" in said, said
    assert "distributed.scheduler - ERROR - Task run-" in log.read_text()
    rows = list(csv.DictReader(open(out)))
    assert [r["status"] for r in rows] == ["completed", "error", "completed"]
