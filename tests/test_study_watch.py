"""The study's watch on its cluster (masonrycli.study.watch): a scheduler that stops answering is said, and
again when it answers."""

from __future__ import annotations

import time

from masonrycli.study import watch


class SilentThenAnswering:
    """A client whose scheduler does not answer its first ``silent`` looks (each waits out its timeout)."""

    def __init__(self, silent: int):
        self.silent, self.looks = silent, 0

    def nthreads(self, callback_timeout):
        self.looks += 1
        if self.looks <= self.silent:
            time.sleep(callback_timeout)
            raise TimeoutError
        return {"tcp://10.0.0.7:40213": 1}


def _said_by_a_silent_scheduler(where: str, waiting: int, lines: int) -> list[str]:
    """The watch's first ``lines`` lines (10 s at most) over a scheduler silent for its first 8 looks, with
    ``waiting`` runs waiting."""
    said: list[str] = []
    with watch.WorkerWatch(SilentThenAnswering(8), said.append, where, lambda: waiting):
        end = time.monotonic() + 10
        while len(said) < lines and time.monotonic() < end:
            time.sleep(0.02)
    return said


def test_a_scheduler_that_stops_answering_is_said_and_again_when_it_answers(monkeypatch):
    # a scheduler stopped (kill -STOP) mid-study: its connection stayed open, and the study waited 60 s without
    # a line, then went on when it was continued
    monkeypatch.setattr(watch, "WATCH_EVERY", 0.02)
    monkeypatch.setattr(watch, "ASK_TIMEOUT", 0.1)
    monkeypatch.setattr(watch, "NO_ANSWER_WAIT", 0.3)
    said = _said_by_a_silent_scheduler("--scheduler tcp://h:8786", waiting=3, lines=2)
    assert said == [
        "--scheduler tcp://h:8786: the scheduler has not answered for 0.3 s (stopped, its machine overloaded or cut "
        "off?), 3 runs waiting: the study goes on when it answers (Ctrl-C stops it, every finished row written)",
        "--scheduler tcp://h:8786: the scheduler answers again: the study goes on",
    ]


def test_a_scheduler_that_answers_is_not_said_to_be_silent(monkeypatch):
    monkeypatch.setattr(watch, "WATCH_EVERY", 0.02)
    said: list[str] = []
    with watch.WorkerWatch(SilentThenAnswering(0), said.append, "X", lambda: 3):
        time.sleep(0.3)
    assert said == []


def test_one_run_waiting_is_one_run(monkeypatch):
    # "… 1 runs waiting" when the last point was left
    monkeypatch.setattr(watch, "WATCH_EVERY", 0.02)
    monkeypatch.setattr(watch, "ASK_TIMEOUT", 0.1)
    monkeypatch.setattr(watch, "NO_ANSWER_WAIT", 0.3)
    said = _said_by_a_silent_scheduler("X", waiting=1, lines=1)
    assert ", 1 run waiting: the study goes on when it answers" in said[0], said
