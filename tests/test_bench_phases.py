"""The phase benchmark's plumbing (benchmarks/bench_phases.py): a wrapped launcher still returns what it
returns and adds its CPU time to its phase, a missing one is left alone, and a revision compared with itself
is bit-identical with every phase reported."""

import time
from types import SimpleNamespace

import pytest

from benchmarks import bench_phases


def test_a_wrapped_call_returns_its_value_and_adds_its_cpu_time_to_its_phase():
    def busy(x, scale=1):
        end = time.process_time() + 0.02
        while time.process_time() < end:
            pass
        return x * scale

    owner, totals = SimpleNamespace(work=busy), {"work": 1.0}
    bench_phases._timed(owner, "work", "work", totals)
    bench_phases._timed(owner, "absent", "absent", totals)  # an older revision without that launcher
    assert owner.work(3, scale=2) == 6
    assert totals["work"] >= 1.02 and "absent" not in totals and not hasattr(owner, "absent")


@pytest.mark.slow
def test_the_working_tree_against_itself_on_the_small_wall_is_bit_identical():
    row = bench_phases.compare("worktree", "worktree", "wall-51", 0.02, 1, False)
    assert row["bit_identical"]
    for side in ("base", "new"):
        ms = row[side]["ms_per_step"]
        assert set(ms) == set(bench_phases.PHASES) and ms["solve"] > 0.0 and ms["before_solve"] > 0.0
        assert row[side]["cpu_per_sim_s"] > 0.0
