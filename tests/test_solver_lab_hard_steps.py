"""The lab's hard-step capture and replay (benchmarks/solver_lab/hard_steps.py): a set captured into a
directory of one's choice replays from it, and the engine's replay gives each step the units the run spent."""

import json

from benchmarks.solver_lab import hard_steps


def test_capture_into_a_directory_replays_from_it(tmp_path):
    # h8 (8 courses) for 4 steps of 1 ms, every step kept (min_units 1): the set goes to tmp_path alone.
    hard_steps.capture(["h8"], 0, 1, motions=[(1.0, 2.0, 0.0)], duration=0.004, directory=tmp_path)
    index = json.loads((tmp_path / "index-h8-c0.json").read_text())
    assert len(index) == 4
    assert all((tmp_path / f"{name}.npz").exists() for name in index)
    doc = hard_steps.replay(["main"], 1, None, None, directory=tmp_path)
    assert doc["dir"] == str(tmp_path) and doc["steps"] == sorted(index)
    replayed = doc["variants"]["main"]["steps"]
    assert {n: s["units"] for n, s in replayed.items()} == {n: e["units"] for n, e in index.items()}
    # A momentum window of 1 sweep hands every step that does not converge in momentum's first sweeps to
    # stalled.py: such a step records where momentum stalled, and one its body-order stage finishes is
    # labelled "bodies", not "momentum0" (momentum's own solve).
    forced = hard_steps.replay(["first_stall=1"], 1, None, None, directory=tmp_path)
    steps = forced["variants"]["first_stall=1"]["steps"].values()
    handed = [s for s in steps if s["stalled_at"] is not None]
    assert handed and all(s["by"] != "momentum0" for s in handed)
    assert all(s["by"] == "momentum0" for s in steps if s["stalled_at"] is None and s["converged"])
    assert any(s["by"] == "bodies" for s in handed)


def test_capture_with_constants_set_replays_under_the_same_variant(tmp_path):
    # A capture with --set runs the variant's trajectory: its steps replayed under that variant get the
    # units the capture run spent on them, and each entry names the override. The JOURNAL's old spelling of
    # a field (the module constant it replaced) still names it.
    variant = "momentum.STALL_SWEEPS=1"
    assert hard_steps.tuning_of(hard_steps._parse(variant)).first_stall == 1
    hard_steps.capture(["h8"], 0, 1, [(1.0, 2.0, 0.0)], 0.004, tmp_path, override=variant)
    index = json.loads((tmp_path / "index-h8-c0.json").read_text())
    assert len(index) == 4 and all(e["override"] == variant for e in index.values())
    doc = hard_steps.replay([variant], 1, None, None, directory=tmp_path)
    assert {n: s["units"] for n, s in doc["variants"][variant]["steps"].items()} == {
        n: e["units"] for n, e in index.items()
    }


def test_stages_split_each_step_into_the_units_the_engine_spent(tmp_path):
    # hard stages: momentum's units, the body-order stage's calls and the round-robin's resumes add up to the
    # units dispatch.solve spends on the step; momentum's history is one residual a sweep, ending on the residual
    # its own solve stopped at (the first stage re-run with caps 1, 2, …). A 1-sweep window hands steps over.
    from dataclasses import replace

    from masonrycli.engine.tuning import TUNING

    hard_steps.capture(["h8"], 0, 1, motions=[(1.0, 2.0, 0.0)], duration=0.004, directory=tmp_path)
    doc = hard_steps.stages(1, None, tmp_path, replace(TUNING, first_stall=1))
    assert len(doc) == 4
    for s in doc.values():
        m = s["momentum"]
        assert len(m["history"]) == m["units"] and m["low"] == min(m["history"])
        spent = m["units"] + sum(c["units"] for c in s["stage"]) + sum(d for _, d, _ in s["resumes"])
        assert spent == s["units"]
        if not s["stage"]:  # momentum's own solve ended the step
            assert m["history"][-1] == s["residual"]
    assert any(s["stage"] for s in doc.values())


def test_capture_by_the_float32_solver_replays_by_it(tmp_path):
    # Steps captured from a run of "nlgs-accel32" (a shaken wall: no step at rest, which the engine would
    # solve in float64) carry that solver: replayed, each gets the units the run spent on it, which the
    # float64 path does not give them.
    import numpy as np

    hard_steps.capture(["h8"], 0, 1, [(1.0, 2.0, 0.0)], 0.03, tmp_path, solver="nlgs-accel32")
    index = json.loads((tmp_path / "index-h8-c0.json").read_text())
    assert {e["solver"] for e in index.values()} == {"nlgs-accel32"}
    doc = hard_steps.replay(["main"], 1, None, None, directory=tmp_path)
    assert {n: s["units"] for n, s in doc["variants"]["main"]["steps"].items()} == {
        n: e["units"] for n, e in index.items()
    }
    as_float64 = {}
    for name, entry in index.items():
        if entry["solver"] == "nlgs-accel32":
            z = dict(np.load(tmp_path / f"{name}.npz"))
            z["solver"] = np.array("nlgs-accel")
            np.savez_compressed(tmp_path / f"{name}.npz", **z)
            as_float64[name] = hard_steps.replay_step(name, tmp_path)["units"]
    assert any(as_float64[n] != index[n]["units"] for n in as_float64)
