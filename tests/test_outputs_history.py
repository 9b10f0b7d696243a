"""The history file: streamed to disk (memory flat in the run's length), the same arrays as the in-memory
history, and both histories and the recorder honour the one sink contract."""

from __future__ import annotations

import json
import tracemalloc

import numpy as np

from masonrycli.outputs.history import History, HistoryFile
from masonrycli.run import Simulation, simulate
from masonrycli.scenario.scenario import Material, RunConfig, scenario_from_builder


def wall(duration: float, record_every: int = 1):
    return scenario_from_builder(
        "wall", {"blocks": 51}, RunConfig(duration=duration, record_every=record_every), Material(), {}
    )


def test_history_file_matches_the_in_memory_history(tmp_path):
    sc = wall(0.03, record_every=5)
    memory = History([b.name for b in sc.assembly.blocks], [s.name for s in sc.assembly.supports])
    path = tmp_path / "h.npz"
    streamed = HistoryFile(path, memory.block_name, memory.support_name)
    result = simulate(sc, [memory, streamed])
    streamed.close(result.status, result.message)
    on_disk, expected = np.load(path), memory.arrays()
    assert set(on_disk.files) == set(expected) | {"status", "note", "units", "run"}
    for name, value in expected.items():
        nan_ok = value.dtype.kind == "f"
        assert on_disk[name].dtype == value.dtype and np.array_equal(on_disk[name], value, equal_nan=nan_ok), name
    assert str(on_disk["status"]) == "completed" and on_disk["time"].shape == (7,)
    assert not streamed.scratch.exists()


def test_history_file_names_the_unit_of_every_array_it_holds(tmp_path):
    # a user with the file and plain numpy: dict(h["units"]) has a non-empty row for every array, and "run"
    # is the JSON of the parameters it was given (before: neither, the units only in the README)
    sc = wall(0.002)
    path = tmp_path / "h.npz"
    streamed = HistoryFile(path, [b.name for b in sc.assembly.blocks], [s.name for s in sc.assembly.supports])
    streamed.run_info = {"scenario": "wall", "dt_s": 0.001, "commit": "abc1234"}
    streamed.run_values["intensity_pgv"] = 1.0
    result = simulate(sc, [streamed])
    streamed.close(result.status, result.message)
    h = np.load(path)
    units = dict(h["units"])
    assert set(units) == set(h.files) and all(units.values())
    assert units["time"].startswith("s") and units["cell_stress"].startswith("Pa") and "rad" in units["block_q"]
    assert json.loads(str(h["run"])) == {"scenario": "wall", "dt_s": 0.001, "commit": "abc1234"}


def test_history_file_memory_is_flat_in_the_frame_count(tmp_path):
    """Finding 6: the history was held in memory until the end (945 MB for 20 s of the 51-block wall)."""
    sim = Simulation(wall(0.01))
    sim.step()
    frame = sim.frame()

    def peak(frames: int) -> int:
        hist = HistoryFile(tmp_path / f"h{frames}.npz", sim.model.block_name, sim.model.support_name)
        tracemalloc.start()
        for _ in range(frames):
            hist.on_frame(frame)
        hist.close()
        size = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert np.load(tmp_path / f"h{frames}.npz")["block_q"].shape == (frames, 51, 3)
        return size

    # Beyond the 1 MB copy buffer of close(), 3× the frames need no more memory (in memory it was 3×).
    small, large = peak(2000), peak(6000)
    assert large < 1.1 * small, (small, large)


def test_support_velocities_are_not_tabulated_for_the_whole_run():
    """Finding 6: a 10⁹-step run allocated its support-velocity table before step 1 (gigabytes)."""
    from masonrycli.model import SupportVelocity, build_model
    from masonrycli.scenario.motion import Sine, support_velocity

    sc = scenario_from_builder(
        "wall",
        {"blocks": 51},
        RunConfig(duration=50.0, dt=1e-4),
        Material(),
        {"ground": Sine(direction=(1.0, 0.0), amplitude=1.0, frequency=2.0)},
    )
    table = build_model(sc).support_velocity
    assert isinstance(table, SupportVelocity) and len(table) == 500_001
    full = support_velocity(sc.motions, np.arange(len(table), dtype=np.float64) * 1e-4)
    for k in (0, 1, 4095, 4096, 123_457, 500_000):
        assert np.array_equal(table[k], full[k])  # bit-identical to the whole table
    assert len(table._rows) <= SupportVelocity.CHUNK
