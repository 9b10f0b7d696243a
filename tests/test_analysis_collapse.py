"""Collapse, damage and the first sliding / rocking, on hand-made states and on single blocks whose
thresholds are known in closed form (sliding: A·2πf > μg; rocking: A·2πf > g·B/H)."""

from __future__ import annotations

import math
import re
from types import SimpleNamespace

import numpy as np
import pytest

from masonrycli.analysis.collapse import RULES, CollapseMonitor, CollapseRule
from masonrycli.run import Simulation, simulate
from masonrycli.scenario.toml_file import loads_scenario

from engine_helpers import PerStep

G = 9.81
F = 2.0


def block_scenario(width, height, friction, amp, duration=0.1, dt=1e-3):
    return loads_scenario(
        f"""
[run]
duration = {duration}
dt = {dt}
gravity = [0.0, -{G}]
[material]
friction = {friction}
[[block]]
polygon = [[{-width / 2}, 0.0], [{width / 2}, 0.0], [{width / 2}, {height}], [{-width / 2}, {height}]]
[[support]]
name = "ground"
polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]
motion = {{ kind = "sine", amplitude = {amp}, frequency = {F} }}
"""
    )


def two_block_monitor(rule=None):
    # two 1 m × 0.5 m blocks stacked on a ground support (index 2)
    verts = [
        np.array([[0, 0], [1, 0], [1, 0.5], [0, 0.5]], float),
        np.array([[0, 0.5], [1, 0.5], [1, 1], [0, 1]], float),
    ]
    q0 = np.array([[0.5, 0.25, 0.0], [0.5, 0.75, 0.0], [0.0, -0.5, 0.0]])
    return CollapseMonitor(SimpleNamespace(block_count=2, body_q0=q0), verts, 0, rule or CollapseRule()), q0


def test_monitor_definitions_on_hand_made_states():
    mon, q0 = two_block_monitor()
    assert mon.height == 1.0 and mon.top.tolist() == [1]
    q = q0.copy()
    q[1, 0] += 0.2
    q[2, 0] += 0.1  # the ground moved too: drift is relative to it
    assert mon.drift(q) == pytest.approx(0.1)
    assert mon.max_block_displacement(q) == pytest.approx(0.1)
    mon.observe(0.1, rock=0.0, slide=0.0, fall=0.0, turn=0.0, drift=0.1)
    assert mon.collapse_time is None and mon.peak_drift == pytest.approx(0.1)
    assert mon.state(q, hinges=0, max_opening=0.0) == "damaged"  # 10 % residual drift
    assert mon.state(q0, hinges=0, max_opening=0.0) == "intact"
    assert mon.state(q0, hinges=1, max_opening=0.0) == "damaged"
    assert mon.state(q0, hinges=0, max_opening=0.006) == "damaged"
    mon.observe(0.2, rock=0.0, slide=0.0, fall=1.02, turn=0.0, drift=0.0)  # fell by more than its height
    assert mon.collapse_time == 0.2 and "fell" in mon.collapse_reason
    assert mon.state(q0, 0, 0.0) == "collapsed"
    mon.observe(0.3, rock=0.0, slide=0.0, fall=2.0, turn=1.0, drift=0.0)
    assert mon.collapse_time == 0.2  # the first time is kept
    mon, _ = two_block_monitor()
    mon.observe(0.3, rock=2e-4, slide=0.0, fall=0.0, turn=math.radians(46), drift=0.0)
    assert mon.collapse_time == 0.3 and "turned" in mon.collapse_reason and mon.rock_time == 0.3
    mon, _ = two_block_monitor()
    mon.observe(0.4, rock=0.0, slide=2e-4, fall=0.0, turn=0.0, drift=-0.26)
    assert mon.collapse_time == 0.4 and "drifted" in mon.collapse_reason and mon.slide_time == 0.4
    assert mon.rock_time is None
    assert set(RULES) >= {"wall", "arch", "aqueduct", "default"}


@pytest.mark.parametrize(
    "width, height, friction, closed_form, outcome",
    [
        (0.8, 0.4, 0.6, 0.6 * G / (2 * math.pi * F), "slide_time"),  # B/H = 2: slides first
        (0.25, 1.0, 0.8, G * 0.25 / (2 * math.pi * F), "rock_time"),  # B/H = 0.25, μ = 0.8: rocks
    ],
)
def test_first_sliding_and_rocking_at_the_closed_form_threshold(width, height, friction, closed_form, outcome):
    other = {"slide_time": "rock_time", "rock_time": "slide_time"}[outcome]
    below = simulate(block_scenario(width, height, friction, 0.99 * closed_form)).outcome
    above = simulate(block_scenario(width, height, friction, 1.01 * closed_form)).outcome
    assert math.isnan(below[outcome]) and math.isnan(below[other]) and below["state"] == "intact"
    assert 0.0 < above[outcome] < 0.05 and math.isnan(above[other])


def test_slender_block_overturns_and_early_stop_keeps_the_same_steps():
    scenario = block_scenario(0.25, 1.0, 0.8, 0.5, duration=2.0)  # 2.6 × the rocking threshold
    full_steps, early_steps = PerStep(), PerStep()
    full = simulate(scenario, [full_steps])
    assert full.outcome["state"] == "collapsed" and full.outcome["peak_drift"] > 0.25
    t_c = full.outcome["collapse_time"]
    assert 0.5 < t_c < 2.0 and full.extra["state"].startswith(f"collapsed at t = {t_c:.3f} s")
    sim = Simulation(scenario)
    early = simulate(scenario, [early_steps], sim=sim, stop_at_collapse=True)
    assert early.status == "completed" and "stopped at collapse" in early.message
    assert early.steps == round(t_c / 1e-3) < full.steps
    assert early.outcome["collapse_time"] == t_c
    assert early_steps.rows == full_steps.rows[: early.steps]


def test_block_at_rest_is_intact():
    result = simulate(block_scenario(0.8, 0.4, 0.6, 0.0))
    assert result.outcome["state"] == "intact" and result.outcome["hinges"] == 0
    assert result.extra["state"].startswith("intact (residual drift")


class _Watch:
    """Stands in for the solver in CollapseMonitor.update: no contacts (its public views, as watch_step reads)."""

    contact_body = np.zeros((0, 2), dtype=np.int32)
    contact_pack = np.zeros((0, 1))
    contact_status = np.zeros(0, dtype=np.int8)


def test_a_sliver_riding_a_settling_support_has_not_fallen():
    # A 1 m block and a 0.04 m sliver (the aqueduct's spandrel blocks cut along the extrados are down
    # to 3.6 cm) on a support that settles 5 cm, carrying both with it: nothing fell. Before, the
    # sliver's 5 cm drop was 1.25 × its own height and the default aqueduct "collapsed at t = 4.414 s".
    verts = [
        np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float),
        np.array([[1, 0], [2, 0], [2, 0.04], [1, 0.04]], float),
    ]
    q0 = np.array([[0.5, 0.5, 0.0], [1.5, 0.02, 0.0], [1.0, -0.5, 0.0]])
    mon = CollapseMonitor(SimpleNamespace(block_count=2, body_q0=q0), verts, None, CollapseRule())
    q = q0.copy()
    q[:, 1] -= 0.05
    mon.update(1.0, _Watch(), q, np.zeros_like(q))
    assert mon.collapse_time is None
    # the same sliver dropping 5 cm while its support stays put still has not fallen by a median
    # block height (0.52 m) ...
    q = q0.copy()
    q[1, 1] -= 0.05
    mon.update(2.0, _Watch(), q, np.zeros_like(q))
    assert mon.collapse_time is None
    # ... but a block falling more than that past the settlement of the support has.
    q = q0.copy()
    q[:, 1] -= 0.05
    q[1, 1] -= 0.6
    mon.update(3.0, _Watch(), q, np.zeros_like(q))
    assert mon.collapse_time == 3.0 and "fell" in mon.collapse_reason


def test_a_drift_says_whether_the_structure_slid_on_its_base_or_leans():
    # A squat block on a ground too fast for its friction (A·2πf = 12.6 m/s² > μg) only slides: the drift rule
    # called that "collapsed" with "the top drifted", which reads as toppling. The reason now says it slid on its
    # base (top and base the same block, the same distance); the hand-made states tell the other cases.
    res = simulate(block_scenario(0.4, 0.2, 0.6, 1.0, duration=1.0))
    mon_reason = res.outcome["collapse_reason"]
    assert mon_reason.startswith("the top drifted by more than 0.25 × the height: it slid on its base, the top ")
    top, base = (float(x) for x in re.search(r"the top (\S+) m, the base (\S+) m$", mon_reason).groups())
    assert top == base > 0.25 * 0.2
    mon, q0 = two_block_monitor()
    assert mon.base.tolist() == [0] and mon.top.tolist() == [1]
    for lower, upper, how in (
        (0.3, 0.3, "it slid on its base"),
        (0.0, 0.3, "it leans"),
        (0.15, 0.3, "it slid and leans"),
    ):
        m, _ = two_block_monitor()
        q = q0.copy()
        q[0, 0] += lower
        q[1, 0] += upper
        m.observe(0.1, rock=0.0, slide=0.0, fall=0.0, turn=0.0, drift=upper)
        assert m.collapse_reason == "the top drifted by more than 0.25 × the height"  # observe: the rule alone
        assert m._how_it_drifted(q, upper) == f": {how}, the top {upper:.3g} m, the base {lower:.3g} m"
