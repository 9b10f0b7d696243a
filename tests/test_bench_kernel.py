"""The kernel benchmark's plumbing (benchmarks/bench_kernel.py): captured calls replayed on copies, one last bit
of any output changes the digest, and a revision compared with itself is bit-identical."""

import numpy as np
import pytest

from benchmarks import bench_kernel


def _call(count=3, bodies=2):
    rng = np.random.default_rng(1)
    body = np.zeros((count, 2), dtype=np.int32)
    body[:, 1] = 1
    v, r, status = rng.normal(size=(bodies, 3)), rng.normal(size=(count, 2)), np.zeros(count, dtype=np.int8)
    return (body, rng.normal(size=(count, 19)), count, 0.6, 1e-5, 100, v, r, status, True, 500)


def _kernel(last_bit):
    def kernel(contact_body, pack, count, mu, tolerance, cap, v, r, status, accelerate, stall):
        v[0, 0] = np.nextafter(v[0, 0], np.inf) if last_bit else v[0, 0]
        r[:] += 1.0
        status[:] = 2
        return 7, 1e-6

    return kernel


def test_replay_leaves_the_captured_arrays_alone_and_the_digest_sees_one_last_bit():
    call = _call()
    before = [np.copy(x) for x in call[6:9]]
    seconds, same = bench_kernel.run_calls(_kernel(False), [call, call])
    assert len(seconds) == 2 and all(s >= 0.0 for s in seconds)
    for kept, now in zip(before, call[6:9], strict=True):
        assert np.array_equal(kept, now)
    assert bench_kernel.run_calls(_kernel(False), [call, call])[1] == same
    assert bench_kernel.run_calls(_kernel(True), [call, call])[1] != same


@pytest.mark.slow
def test_the_working_tree_against_itself_on_the_small_wall_is_bit_identical():
    row = bench_kernel.compare(bench_kernel.WORKTREE, bench_kernel.WORKTREE, "wall-51", 0.01, 1, 1)
    assert row["calls"] == 10 and row["bit_identical"]
    assert row["base"]["contact_sweeps"] == row["new"]["contact_sweeps"] > 0
    assert row["new_over_base"] > 0.0


def test_a_side_s_environment_is_parsed_and_set_last_and_a_bad_pair_refused(tmp_path, capsys):
    assert bench_kernel.parse_env(["NUMBA_CPU_NAME=znver5", "X=a=b"]) == {"NUMBA_CPU_NAME": "znver5", "X": "a=b"}
    assert bench_kernel.parse_env(None) == {}
    env = bench_kernel.worker_env(str(tmp_path), tmp_path, {"NUMBA_CACHE_DIR": "/elsewhere"})
    assert env["NUMBA_CACHE_DIR"] == "/elsewhere"  # the side's own value wins over the checkout's cache
    with pytest.raises(SystemExit) as exit_:
        bench_kernel.parse_env(["NUMBA_CPU_NAME"])
    assert exit_.value.code == 2 and "expected KEY=VALUE" in capsys.readouterr().err


@pytest.mark.slow
def test_the_float32_stage_under_another_cpu_name_is_bit_identical():
    # The same source compiled with another CPU's tuning (instruction scheduling only, the host's features):
    # each side's workers got their own environment, and the float32 stage's outputs are the same bits.
    row = bench_kernel.compare(bench_kernel.WORKTREE, bench_kernel.WORKTREE, "wall-51", 0.01, 1, 1, "float32",
                               {"new": {"NUMBA_CPU_NAME": "x86-64-v3"}})  # fmt: skip
    assert row["stage"] == "float32" and row["calls"] == 10 and row["bit_identical"]
    assert row["new"]["env"] == {"NUMBA_CPU_NAME": "x86-64-v3"} and row["base"]["env"] == {}
    assert row["base"]["contact_sweeps"] == row["new"]["contact_sweeps"] > 0


def test_a_revision_s_checkout_holds_its_own_geometry_library(tmp_path):
    # the base's masonrycli with the working tree's geometry_library: a base before 41d2532 (checks.py split)
    # failed with 'cannot import name validate_assembly from geometry_library.checks' in bench_phases' worker
    import subprocess
    from pathlib import Path

    root = Path(bench_kernel.checkout("HEAD", tmp_path / "head"))
    for path in ("geometry_library/checks.py", "masonrycli/run.py"):
        kept = subprocess.run(["git", "-C", str(bench_kernel.ROOT), "show", f"HEAD:{path}"], capture_output=True)
        assert (root / path).read_bytes() == kept.stdout, path
