"""Dask's own log lines during a study go to ``<out>.dask.log``, not to stderr among masonry's lines
(masonrycli/study/dask_log.py): a worker that died under a point gave 'distributed.scheduler - ERROR - Task
run-… marked as failed because 4 workers died while trying to run it' on stderr, once a point."""

from __future__ import annotations

import logging

import pyarrow.parquet as pq
import pytest
from rich.console import Console

from masonrycli.scenario.motion import Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder
from masonrycli.study import store
from masonrycli.study.axes import StudyBase, parse_axis
from masonrycli.study.dask_log import DaskLog, log_path
from masonrycli.study.study import StudyRequest, run_study

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
