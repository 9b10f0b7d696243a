"""Small helpers shared by the engine tests: load a validation scenario, run it, return the history."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from masonrycli.outputs.history import History
from masonrycli.run import simulate
from masonrycli.scenario.toml_file import load_scenario

DATA = Path(__file__).parent / "data"


def scenario(name: str, **run_overrides):
    sc = load_scenario(DATA / "validation" / name)
    if run_overrides:
        sc = replace(sc, run=replace(sc.run, **run_overrides))
    return sc


def run_history(sc) -> tuple[dict, object]:
    hist = History([b.name for b in sc.assembly.blocks], [s.name for s in sc.assembly.supports])
    result = simulate(sc, sinks=[hist])
    assert result.status == "completed", result.message
    return {k: np.asarray(v) for k, v in hist.arrays().items()}, result


class PerStep:
    """A sink keeping every step's solver statistics (what the run kept itself before)."""

    def __init__(self):
        self.rows = []

    def on_frame(self, frame) -> None:
        pass

    def log_step(self, step: int, time_s: float, stats) -> None:
        self.rows.append((stats.iterations, stats.residual, stats.contact_count))
