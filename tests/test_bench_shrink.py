"""The shrinking-sweep benchmark (benchmarks/bench_shrink.py): CHECK_EVERY set for a run and restored, the
per-step mode's engine column is the engine's own run."""

from benchmarks import bench_shrink
from masonrycli.engine import shrink


def test_a_run_sets_check_every_for_itself_only_and_counts_its_sweeps():
    off = bench_shrink.one_run("wall-51", 0.02, 0, record=False)
    on = bench_shrink.one_run("wall-51", 0.02, 16, record=False)
    assert shrink.CHECK_EVERY == 0
    for row in (off, on):
        assert row["sweeps_cpu_s"] > 0.0 and row["unconverged"] == 0 and row["stalled_steps"] >= 0


def test_per_step_solves_the_same_calls_again():
    tally = bench_shrink.per_step("wall-51", 0.02, [16])
    assert tally[0]["sweeps"] > 0 and tally[16]["sweeps"] > 0
    assert abs(tally[16]["sweeps_ratio"] - tally[16]["sweeps"] / tally[0]["sweeps"]) < 1e-12
    assert shrink.CHECK_EVERY == 0
