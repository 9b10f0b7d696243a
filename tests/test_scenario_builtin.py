"""Built-in scenarios: the paper's loadings (1 m/s at 2 Hz, 1 cm/s settlement), overrides, their errors."""

import math
import signal
from pathlib import Path

import numpy as np
import pytest

from masonrycli.errors import InputError
from masonrycli.records.read import record_motion
from masonrycli.scenario.builtin import (
    PAPER_INSTANT,
    build_assembly,
    builtin,
    override_run,
    paper_instant_hint,
)
from masonrycli.scenario.motion import Constant, Fixed, Sine
from masonrycli.scenario.scenario import RunConfig

RECORD = Path(__file__).parent / "data" / "quake_velocity.csv"


def motions_by_name(scenario):
    return {s.name: m for s, m in zip(scenario.assembly.supports, scenario.motions)}


def test_wall_is_shaken_at_one_metre_per_second_and_two_hertz():
    s = builtin("wall")
    assert s.block_count == 51 and s.run.duration == 1.0 and s.structure == {"builder": "wall", "blocks": 51}
    ground = motions_by_name(s)["ground"]
    assert ground == Sine(direction=(1.0, 0.0), amplitude=1.0, frequency=2.0)
    t = np.array([0.125, 0.3])  # a quarter period: the peak; then 1·sin(2π·2·0.3)
    v = ground.velocity_at(t)
    assert v[0] == pytest.approx([1.0, 0.0], abs=1e-15)
    assert v[1] == pytest.approx([math.sin(2 * math.pi * 2 * 0.3), 0.0], abs=1e-15)


def test_arch_right_foundation_settles_one_centimetre_per_second():
    s = builtin("arch")
    assert s.block_count == 98 and s.run.duration == 5.0
    assert motions_by_name(s) == {"left-foundation": Fixed(), "right-foundation": Constant(velocity=(0.0, -0.01))}


def test_overrides_reach_structure_loading_material_and_run():
    s = builtin("wall", courses=2, amp=0.5, freq=3.0, friction=0.4, density=2000.0, dt=2e-3, record_every=5)
    assert s.structure == {"builder": "wall", "courses": 2} and s.block_count == 51  # 2 courses × 25 + 1
    assert motions_by_name(s)["ground"] == Sine(direction=(1.0, 0.0), amplitude=0.5, frequency=3.0)
    assert (s.material.friction, s.material.density) == (0.4, 2000.0)
    assert all(b.density == 2000.0 for b in s.assembly.blocks)
    assert (s.run.dt, s.run.record_every, s.run.duration) == (2e-3, 5, 1.0)
    shaken = builtin("arch", settlement=0.0, amp=1.0, voussoirs=20, duration=None)
    assert shaken.block_count == 20 + 68
    assert set(map(type, shaken.motions)) == {Sine}
    assert motions_by_name(builtin("wall", amp=0.0))["ground"] == Fixed()


@pytest.mark.parametrize(
    "name, overrides, message",
    [
        ("wall", {"settlement": 0.01}, "--settlement 0.01: the wall stands on one ground; settlement applies to arch"),
        ("arch", {"settlement": -1.0}, "--settlement -1: must be >= 0 (a downward velocity, m/s)"),
        (
            "arch",
            {"settlement": 0.01, "amp": 1.0},
            "--settlement 0.01 with --amp 1: choose one loading (settle or shake)",
        ),
        ("arch", {"amp": 1.0}, "--amp 1: the arch settles its right foundation by default; shake both"),
        ("aqueduct", {"freq": 3.0}, "--freq 3: the aqueduct settles its right foundation by default; shake"),
        ("arch", {"settlement": 0.0, "freq": 3.0}, "--freq 3 without --amp: nothing shakes the arch"),
        ("arch", {"settlement": float("nan")}, "--settlement nan: must be a finite number"),
        ("arch", {"freq": -1.0}, "--freq: frequency = -1.0: must be >= 0"),
        ("wall", {"freq": 0.0}, "--freq 0: the velocity 1 m/s · sin(2π·0·t) is 0, nothing moves"),  # ran, intact
        ("arch", {"settlement": 0.0, "amp": 1.0, "freq": 0.0}, "--freq 0: the velocity 1 m/s · sin(2π·0·t) is 0"),
        ("wall", {"freq": -2.0}, "--freq: frequency = -2.0: must be >= 0"),
        ("wall", {"density": 0.0, "friction": -1.0}, "--density: density = 0.0: must be > 0"),
        ("wall", {"dt": 2.0}, "--dt: dt = 2.0: must be <= duration (1.0)"),
        ("wall", {"duration": 0.01, "dt": 0.02}, "--duration and --dt: dt = 0.02: must be <= duration (0.01)"),
        ("wall", {"blockz": 3}, 'builder "wall": unknown option "blockz" of builder "wall" (did you mean "blocks"?)'),
        ("tower", {}, "unknown built-in scenario 'tower' (expected one of wall, arch, aqueduct)"),
        ("wall", {"scale": 2.0}, "--scale 2 goes with --record (it multiplies the record)"),
        # it said "(the record replaces the sine)": the arch settles by default, it has no sine
        (
            "arch",
            {"record": RECORD, "settlement": 0.01},
            f"--record {RECORD} with --settlement 0.01: choose one loading (the record shakes both foundations instead)",
        ),
    ],
)
def test_bad_override_is_one_line_naming_the_option(name, overrides, message):
    with pytest.raises(InputError) as info:
        builtin(name, **overrides)
    assert str(info.value).startswith(message) and "\n" not in str(info.value)


def test_record_replaces_the_sine_on_every_shaken_support():
    shaken = motions_by_name(builtin("arch", record=RECORD, scale=2.0))
    expected = record_motion(RECORD, scale=2.0)
    assert shaken == {"left-foundation": expected, "right-foundation": expected}


def test_override_run_leaves_unset_values():
    s = builtin("wall", blocks=7, courses=1)
    same = override_run(s, duration=None, dt=None, friction=None)
    assert same.run == s.run and same.material == s.material
    changed = override_run(s, theta=0.75, friction=0.3)
    assert (changed.run.theta, changed.material.friction, changed.run.dt) == (0.75, 0.3, s.run.dt)
    with pytest.raises(InputError, match=r"^--friction: friction = -1\.0: must be >= 0$"):
        override_run(s, friction=-1.0)


def test_override_run_names_the_values_the_run_would_have():
    # --dt 1e-9 --duration 0.5 said "--dt: ... gives 1,000,000,000 steps for duration 1.0": the wall's
    # default duration, which this run would not have had; the message is the one of the values given
    s = builtin("wall")
    with pytest.raises(InputError) as info:
        override_run(s, dt=1e-9, duration=0.5)
    assert str(info.value) == (
        "--duration and --dt: duration = 0.5 at dt = 1e-09 is 500,000,000 steps (at most 100,000,000)"
    )
    with pytest.raises(InputError, match=r"^--dt: dt = 0\.0: must be > 0$"):
        override_run(s, duration=0.02, dt=0.0)  # wrong on its own: named alone
    with pytest.raises(InputError, match=r"^--tolerance: tolerance = -1\.0: must be > 0$"):
        override_run(s, record_every=0, tolerance=-1.0)  # both wrong: the one the message is about


def test_paper_instant_hint_only_within_the_run():
    assert paper_instant_hint("wall", RunConfig(duration=1.0)) == (
        "The paper's Figs. III.2–III.5 are at t = 0.1 s (step 100): the recording opens on them, pinned there."
    )
    assert paper_instant_hint("arch", RunConfig(duration=5.0, dt=0.5)).endswith(
        "t = 5 s (step 10): the recording opens on them, pinned there."
    )
    assert paper_instant_hint("arch", RunConfig(duration=1.0)) == ""
    # the aqueduct's recording pins the tabs of Figs. III.7–III.10 at 5 s too: the summary did not say so
    assert paper_instant_hint("aqueduct", RunConfig(duration=5.0)).endswith(
        "(step 5000): the recording opens on them, pinned there."
    )
    from masonrycli.recording.layout import PAPER_FIGURES

    assert {k: t for k, (_, t) in PAPER_INSTANT.items()} == {k: t for k, (t, _) in PAPER_FIGURES.items()}


def test_paper_instant_hint_says_when_no_frame_is_recorded_there():
    # --record-every 30 records steps 90 and 120: the hint said "pinned there" and the tabs pinned to 0.1 s
    # showed step 90 under the paper's figure numbers (--record-every 200: the structure as built, no stress).
    unrecorded = paper_instant_hint("wall", RunConfig(duration=1.0, record_every=30))
    assert unrecorded == (
        "The paper's Figs. III.2–III.5 are at t = 0.1 s, step 100, which --record-every 30 does not record (a "
        "divisor of 100 does): the recording has no tabs pinned there."
    )
    assert paper_instant_hint("wall", RunConfig(duration=1.0, dt=0.008)).endswith(
        "at t = 0.1 s, not a step of --dt 0.008: the recording has no tabs pinned there."
    )
    assert paper_instant_hint("wall", RunConfig(duration=1.0, record_every=25)).endswith("pinned there.")
    assert paper_instant_hint("wall", RunConfig(duration=1.0, dt=0.004, record_every=5)).startswith(
        "The paper's Figs. III.2–III.5 are at t = 0.1 s (step 25)"
    )
    # the last frame is always recorded: the arch's 5 s run has its instant at its last step
    assert paper_instant_hint("arch", RunConfig(duration=5.0, record_every=30)).endswith("pinned there.")


def test_paper_instant_hint_of_a_run_stopped_before_the_instant(monkeypatch, tmp_path):
    # Ctrl-C 4 s into 'simulate arch --dt 0.0001' (t < 5 s) said "the recording opens on them, pinned there";
    # the recording rightly had no such tabs.
    from masonrycli.interrupt import StopSignals

    from cli_helpers import invoke

    assert paper_instant_hint("arch", RunConfig(duration=5.0), reached=1.2) == (
        "The paper's Figs. III.7–III.10 are at t = 5 s; the run stopped before, at t = 1.2 s: the recording "
        "has no tabs pinned there."
    )
    assert paper_instant_hint("arch", RunConfig(duration=5.0), reached=5.0).endswith("pinned there.")
    polls = []

    def ctrl_c_at_step_50(self):
        polls.append(1)
        if len(polls) == 50:
            self.signum = signal.SIGINT
        return self.signum is not None

    monkeypatch.setattr(StopSignals, "requested", ctrl_c_at_step_50)
    result = invoke("simulate", "wall", "--duration", 0.2, "--out", tmp_path / "w.rrd")
    assert result.exit_code == 130, result.output
    assert "the run stopped before, at t = 0.05 s: the recording has no tabs pinned there." in result.output
    assert "opens on them" not in result.output


def test_paper_instant_hint_only_under_the_papers_loading():
    def supports(name, **loading):
        s = builtin(name, **loading)
        return {sup.name: m.describe() for sup, m in zip(s.assembly.supports, s.motions)}

    run = RunConfig(duration=5.0)
    assert paper_instant_hint("wall", run, supports("wall", freq=2.0, amp=1.0)).startswith("The paper's Figs.")
    assert paper_instant_hint("wall", run, supports("wall", blocks=248)).startswith("The paper's Figs.")
    assert paper_instant_hint("arch", run, supports("arch")).startswith("The paper's Figs.")
    assert paper_instant_hint("wall", run, supports("wall", freq=5.0)) == ""
    assert paper_instant_hint("wall", run, supports("wall", record=RECORD)) == ""
    assert paper_instant_hint("arch", run, supports("arch", settlement=0.0, amp=1.0)) == ""


def test_a_record_without_duration_runs_whole_in_steps_of_dt():
    # quake_velocity.csv ends at 0.4 s; the wall's default is 1 s, the arch's 5 s: both run the record
    assert builtin("wall", record=RECORD).run.duration == pytest.approx(0.4)
    assert builtin("wall", record=RECORD).run.n_steps == 400
    arch = builtin("arch", record=RECORD, dt=0.003)
    assert arch.run.n_steps == 134 and arch.run.duration >= 0.4  # ceil(0.4 / 0.003)
    assert builtin("wall", record=RECORD, duration=2.0).run.duration == 2.0  # --duration says otherwise
    assert builtin("wall").run.duration == 1.0
    for dt in (-1.0, float("nan")):  # a bad --dt is named, not a duration made from it
        with pytest.raises(InputError, match=r"^--dt: dt = "):
            builtin("wall", record=RECORD, dt=dt)


@pytest.mark.parametrize(
    "options, message",
    [
        ({"blocks": 3, "density": -1.0}, "--density: density = -1.0: must be > 0"),
        ({"thickness": 1e9}, "--thickness: thickness = 1000000000.0: must be between 1e-06 and 1000 m (a likely typo)"),
        ({"blocks": 0}, "--blocks 0: must be a positive integer"),
        (
            {"blocks": 51, "courses": 5},
            "--blocks and --courses: 51 blocks cannot be laid in running bond with 5 courses"
            " (courses × full blocks per odd course: 1×51, 2×25, 6×8, 34×1)",
        ),
        (
            {"courses": 5},
            "--courses: 51 blocks cannot be laid in running bond with 5 courses"  # 51: the default
            " (courses × full blocks per odd course: 1×51, 2×25, 6×8, 34×1)",
        ),
    ],
)
def test_build_assembly_refuses_a_bad_option_in_one_line_naming_it(options, message):
    with pytest.raises(InputError) as info:
        build_assembly("wall", **options)
    assert str(info.value) == message


@pytest.mark.parametrize(
    "name, options", [("wall", {"blocks": 0}), ("wall", {"courses": 0}), ("arch", {"voussoirs": 1})]
)
def test_build_assembly_refuses_a_bad_builder_option_as_simulate_does(name, options):
    """`masonry build wall --blocks 0` said "wall: block count …", `masonry simulate wall --blocks 0` (and
    sweep's --param) 'builder "wall": block count …': one mistake, one line (now "--blocks 0: must be …")."""
    with pytest.raises(InputError) as built:
        build_assembly(name, **options)
    with pytest.raises(InputError) as simulated:
        builtin(name, **options)
    assert str(built.value) == str(simulated.value)


def test_build_assembly_is_the_builders_with_the_commands_defaults():
    assert build_assembly("wall", blocks=None, density=None).block_count == 51  # the paper's wall
    assert build_assembly("wall", blocks=3, thickness=0.5).block_count == 3
