"""``masonry sweep --settle S``: each variant of the structure (a builder option, the friction, a run setting) comes
to rest under its own weight as itself before its runs. Only the base scenario was settled: a point that rebuilt
the structure (``--param voussoirs=9``) started as drawn, and one of another friction from where the base's came to
rest. Referenced against the settling of the variant built on its own (masonrycli.settle, as ``masonry run
--settle`` does it), not against what the study printed."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from rich.console import Console

from masonrycli.run import simulate
from masonrycli.scenario.motion import Sine
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder
from masonrycli.settle import settled_scenario
from masonrycli.study.axes import apply_point
from masonrycli.study.plan import plan_study
from masonrycli.study.study import run_study

from cli_helpers import assert_one_line_error, invoke

SETTLE = 0.3


def _arch(voussoirs: int, friction: float | None = None):
    """The study's arch (both foundations at 1 m/s, 2 Hz, shaken: plan._shaken) built on its own."""
    material = Material() if friction is None else Material(friction=friction)
    motions = {s: Sine(amplitude=1.0, frequency=2.0) for s in ("left-foundation", "right-foundation")}
    return scenario_from_builder("arch", {"voussoirs": voussoirs}, RunConfig(duration=0.2), material, motions)


def _corners(scenario) -> np.ndarray:
    return np.concatenate(
        [np.asarray(b.polygon.exterior.coords, dtype=float).ravel() for b in scenario.assembly.blocks]
    )


def test_each_variant_starts_from_its_own_settled_shape(tmp_path):
    plan = plan_study(
        "arch", params=["voussoirs=9,13", "friction=0.5,0.8"], settle=SETTLE, duration=0.2, out=tmp_path / "s.csv"
    )
    assert len(plan.base.settled) == 4  # settled in the command, once a variant, and sent with the base
    for voussoirs in (9, 13):
        for friction in (0.5, 0.8):
            point = apply_point(plan.base, {"voussoirs": voussoirs, "friction": friction})
            alone = settled_scenario(_arch(voussoirs, friction), SETTLE)  # as `masonry run --settle` does
            drawn = _corners(_arch(voussoirs, friction))
            assert np.array_equal(_corners(point), _corners(alone))
            assert not np.array_equal(_corners(point), drawn)  # it moved (5-8e-6 mm): the test sees a difference
    said = [w for w in plan.request.warnings if "under its own weight" in w]
    assert len(said) == 4 and said[0].startswith("friction=0.5 voussoirs=9: settled 0.3 s under its own weight"), said
    assert said[0].endswith(" before its runs: each starts there, at rest"), said


def test_a_variant_that_does_not_stand_is_refused_naming_its_point(tmp_path, monkeypatch):
    import masonrycli.settle as settle

    def settles(scenario, duration):  # the 13-voussoir arch "does not stand as drawn" (as a traced wall may not)
        if scenario.structure.get("voussoirs") == 13:
            from masonrycli.errors import InputError

            raise InputError("the wall does not stand as drawn: under its own weight, …")
        return settled_scenario(scenario, duration)

    monkeypatch.setattr(settle, "settled_scenario", settles)
    result = invoke("sweep", "arch", "--param", "voussoirs=9,13", "--settle", "0.3", "--out", tmp_path / "s.csv")
    assert_one_line_error(result, "--param voussoirs=13: the wall does not stand as drawn")
    assert not (tmp_path / "s.csv").exists()


@pytest.mark.slow
def test_a_study_s_rows_are_the_settled_variants_runs_on_a_local_cluster_and_in_process(tmp_path):
    rows = {}
    for workers in (0, 1):  # in the command's process; on a worker process, the base (and its settled) sent to it
        plan = plan_study(
            "arch",
            params=["voussoirs=9,13"],
            settle=SETTLE,
            duration=0.2,
            workers=workers,
            out=tmp_path / f"s{workers}.csv",
            no_recording=True,
        )
        rows[workers] = run_study(plan.base, plan.request, Console(quiet=True)).rows
    for local, serial in zip(rows[1], rows[0]):
        for key in serial.keys() - {"wall_time", "cpu_time", "command"}:
            a, b = local[key], serial[key]
            assert a == b or (isinstance(a, float) and math.isnan(a) and math.isnan(b)), (key, local, serial)
    for row in rows[0]:
        alone = simulate(settled_scenario(_arch(row["voussoirs"]), SETTLE), stop_at_collapse=True)
        assert row["energy_dissipated"] == alone.energy_dissipated and row["steps"] == alone.steps
        assert row["max_opening"] == alone.outcome["max_opening"]
        assert row["peak_drift"] == alone.outcome["peak_drift"]
    assert Path(tmp_path / "s0.csv").exists()
