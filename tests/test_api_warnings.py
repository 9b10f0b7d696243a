"""``api.simulate``'s warnings are said as they happen, each once, from the caller's line: a warning of the
scenario before the first step, the first unconverged step as it ends, the count at the end. They were held
until the call returned, so a student running a long record learned of a 20 kg/m³ typo or of unconverged steps
minutes later, when the run was over."""

from __future__ import annotations

import warnings

import pytest

from masonrycli import api


def _run_watching(**options):
    """The warnings said, and how many had been said when each frame was recorded: (warnings, [(t, count)])."""
    seen = []
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        api.simulate("wall", blocks=12, duration=0.05, on_frame=lambda f: seen.append((f.time, len(said))), **options)
    return said, seen


def test_a_scenario_s_warning_is_said_before_the_first_step():
    said, seen = _run_watching(density=20.0)  # kg/m³: a density typed in t/m³ times 10
    light = [w for w in said if "lighter than any masonry unit" in str(w.message)]
    assert len(light) == 1 and light[0].category is UserWarning  # once: not again as the call returns
    assert seen[0] == (0.0, 1)  # said when the run's first frame (t = 0) was recorded
    assert light[0].filename == __file__  # from the caller's line, not from masonry's


def test_the_first_unconverged_step_is_said_as_it_ends_and_the_count_at_the_end():
    said, seen = _run_watching(max_iterations=2)  # two sweeps: every step ends unconverged
    texts = [str(w.message) for w in said]
    assert len(texts) == 2, texts
    first, count = texts
    assert first.startswith("step 1 (t = 0.001 s) ended unconverged: contact-law residual ")
    assert "× tolerance=1e-05 m/s; the run goes on" in first and "--" not in first
    assert count.startswith("50 of 50 steps ended unconverged")
    assert [n for t, n in seen] == [0, 1, 1, 1, 1, 1]  # the first at step 1, before the frame of step 10
    assert all(w.category is RuntimeWarning and w.filename == __file__ for w in said)


def test_a_converged_run_says_nothing():
    said, _ = _run_watching()
    assert [str(w.message) for w in said] == []


def test_a_warning_made_an_error_by_the_caller_s_filters_names_the_keywords():
    # simplefilter("error") raised the first unconverged step's warning in masonry's words ('--tolerance')
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(RuntimeWarning) as raised:
            api.simulate("wall", blocks=12, duration=0.02, max_iterations=2)
    said = str(raised.value)
    assert said.startswith("step 1 (t = 0.001 s) ended unconverged") and "tolerance=1e-05" in said and "--" not in said
