"""The idle-visit count (benchmarks/bench_idle.py): its counting copy of the accelerated sweep follows the
engine's path (it asserts so on every call), and its tallies add up."""

from benchmarks import bench_idle


def test_the_counts_of_a_short_run_add_up():
    row = bench_idle.measure("wall-51", 0.03)  # 30 steps: the wall settles, its head joints stay open
    assert row["calls"] == 30 and row["sweeps"] > 30
    visits = sum(s["visits"] for s in row["by_status"].values())
    assert visits == row["visits"]
    assert all(0 <= s["idle"] <= s["visits"] for s in row["by_status"].values())
    idle = sum(s["idle"] for s in row["by_status"].values())
    assert abs(row["idle_share"] - idle / visits) < 1e-12
    shares = [row["skippable"][str(k)]["visits"] for k in bench_idle.KS]
    assert shares == sorted(shares, reverse=True)  # a longer idle run is rarer
    for k in bench_idle.KS:  # a visit after K idle visits of its contact: one that the visit's contact made
        s = row["skippable"][str(k)]
        assert s["missed"] <= s["visits"] and sum(s["by_status"].values()) == s["visits"]
    assert 0 <= row["contacts_idle_whole_step"] <= row["contacts"]
