"""The lab's ensembles (benchmarks/solver_lab/ensemble.py): a run's JSON holds what compare pairs and
divides, and compare's figures are those worked out by hand."""

import json
import math

import pytest

from benchmarks.solver_lab import ensemble


def _run(case, amplitude, mean, steps=10, unconverged=0, cpu=1.0, frequency=2.0):
    return {
        "case": case,
        "amplitude": amplitude,
        "frequency": frequency,
        "phase": 0.0,
        "duration": 0.01,
        "mean": mean,
        "total": round(mean * steps),
        "unconverged": unconverged,
        "cpu_s": cpu,
    }


def _doc(runs):
    return {"engine": {"path": "/x", "commit": "0" * 40, "dirty": False}, "duration": 0.01, "runs": runs}


def test_run_writes_per_run_figures_keyed_by_motion(tmp_path):
    out = tmp_path / "a.json"
    ensemble.run(["h8"], [(1.0, 2.0, 0.0), (0.8, 2.5, 0.0)], 0.004, out, jitter=1e-3, copies=range(2))
    doc = json.loads(out.read_text())
    assert doc["engine"]["path"] and doc["duration"] == 0.004
    runs = doc["runs"]
    assert [(r["case"], r["amplitude"], r["frequency"], r["phase"], r["copy"]) for r in runs] == [
        ("h8", 1.0, 2.0, 0.0, 0),
        ("h8", 1.0, 2.0, 0.0, 1),
        ("h8", 0.8, 2.5, 0.0, 0),
        ("h8", 0.8, 2.5, 0.0, 1),
    ]  # the nominal motion, not the jittered one: the key compare pairs by
    for r in runs:
        assert r["steps"] == 4 == len(r["units"]) and r["jitter"] == 1e-3
        assert r["total"] == sum(r["units"]) and r["max"] == max(r["units"]) and r["mean"] == r["total"] / 4
        assert r["unconverged"] == 0 and r["cpu_s"] >= 0.0 and not r["diverged"]
    same = ensemble.compare(out, out)["h8"]
    assert same["geomean"] == 1.0 and same["equal"] == 4 and same["interval90"] == (1.0, 1.0)


def test_compare_figures_by_hand(tmp_path):
    # case w: ratios 0.5, 1, 2 → geometric mean 1, median 1; Σ units (500 + 2000 + 8000) / 7000 = 1.5.
    # The bootstrap mean of the logs is (k₂ − k₀₅) ln 2 / 3 over resamples of 3: P(all three 0.5) = 1/27
    # < 5 % ≤ P(≤ one more 0.5 than 2) = 4/27, so the interval is exactly 2^(∓2/3).
    # Case v: two runs, both 0.8 → interval (0.8, 0.8). A run B lacks is left out.
    a = _doc(
        [_run("w", 1.0, 100.0), _run("w", 1.1, 200.0, unconverged=2), _run("w", 1.2, 400.0, cpu=3.0)]
        + [_run("v", 1.0, 50.0), _run("v", 1.0, 40.0, frequency=1.5), _run("v", 9.0, 1.0)]
    )
    b = _doc(
        [_run("w", 1.2, 800.0, cpu=1.0), _run("w", 1.0, 50.0, unconverged=1), _run("w", 1.1, 200.0)]
        + [_run("v", 1.0, 40.0), _run("v", 1.0, 32.0, frequency=1.5)]
    )
    pa, pa2, pb = tmp_path / "a.json", tmp_path / "a2.json", tmp_path / "b.json"
    pa.write_text(json.dumps(_doc(a["runs"][:2])))  # A in two files, pooled by compare
    pa2.write_text(json.dumps(_doc(a["runs"][2:])))
    pb.write_text(json.dumps(b))
    out = ensemble.compare(f"{pa},{pa2}", pb)
    w, v = out["w"], out["v"]
    assert w["runs"] == 3 and w["geomean"] == pytest.approx(1.0) and w["median"] == 1.0
    assert (w["min"], w["max"], w["better"], w["worse"], w["equal"]) == (0.5, 2.0, 1, 1, 1)
    assert w["interval90"] == pytest.approx((2 ** (-2 / 3), 2 ** (2 / 3)))
    assert w["total_ratio"] == pytest.approx(1.5) and w["unconverged"] == (2, 1)
    lo, hi = w["total_interval90"]  # sums of resampled runs: between the smallest and largest run ratio
    assert 0.5 <= lo < 1.5 < hi <= 2.0
    assert w["cpu_ratio"] == pytest.approx(3.0 / 5.0)
    assert v["runs"] == 2 and v["geomean"] == pytest.approx(0.8) and v["interval90"] == pytest.approx((0.8, 0.8))
    assert v["better"] == 2 and math.isclose(v["total_ratio"], 0.8)
    assert v["total_interval90"] == pytest.approx((0.8, 0.8))


def test_motion_text():
    assert ensemble.parse_motion("1.2,2") == (1.2, 2.0, 0.0)
    assert ensemble.parse_motion("1,2,0.5") == (1.0, 2.0, 0.5)
    with pytest.raises(ValueError):
        ensemble.parse_motion("1")
    assert len(ensemble.MOTIONS) == 12 and (1.0, 2.0, 0.0) in ensemble.MOTIONS


def test_shifted_copies_pair_an_engine_with_itself(tmp_path):
    runs = [_run("s", 1.0, 100.0) | {"copy": 0}, _run("s", 1.0, 300.0) | {"copy": 1}, _run("s", 1.0, 150.0)]
    runs[2]["copy"] = 2
    path = tmp_path / "s.json"
    path.write_text(json.dumps(_doc(runs)))
    s = ensemble.compare(path, path, shift=1)["s"]  # copy 1 against 0, copy 2 against 1: ratios 3 and 0.5
    assert s["runs"] == 2 and s["geomean"] == pytest.approx(math.sqrt(1.5)) and (s["better"], s["worse"]) == (1, 1)
    assert s["total_ratio"] == pytest.approx(4500 / 4000)


def test_set_changes_the_engine_for_these_runs_only(tmp_path):
    plain = ensemble.run(["h8"], [(1.0, 2.0, 0.0)], 0.003, tmp_path / "a.json")
    varied = ensemble.run(["h8"], [(1.0, 2.0, 0.0)], 0.003, tmp_path / "b.json", override="first_stall=1")
    again = ensemble.run(["h8"], [(1.0, 2.0, 0.0)], 0.003, tmp_path / "c.json")
    assert again["runs"][0]["units"] == plain["runs"][0]["units"]  # these runs only
    assert varied["engine"]["override"] == "first_stall=1" and "override" not in plain["engine"]
    assert json.loads((tmp_path / "b.json").read_text())["engine"]["override"] == "first_stall=1"
    # a one-sweep window sends the cold first step to stalled.py at once: other sweep units
    assert varied["runs"][0]["units"] != plain["runs"][0]["units"]
