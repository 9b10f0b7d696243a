"""What a valid scenario may still have wrong: one line each for ``masonry run``, ``simulate``, ``check``,
``limit`` and ``sweep`` to print before anything runs.

* :func:`record_warnings`: a record the run does not follow whole (it starts after the run ends, goes on
  after it, is sampled finer than dt, or peaks beyond 10 g as scaled), or not as its file gives it (the
  baseline correction changes its acceleration by more than ``BASELINE_CHANGE`` of its peak).
* :func:`setting_warnings`: settings in the wrong units or sign — a gravity pointing up (the blocks fly
  off, or limit analysis finds "no equilibrium") or far from 9.81 m/s² (cm/s², or g), a density below
  any masonry unit's (t/m³ or g/cm³: stresses and forces 1000× too small, the motion unchanged), a block
  larger than any stone (a drawing in millimetres).
* :func:`idle_driven_supports`: a support marked driven (a GeoJSON's ``support_role``) that no motion drives.
* :func:`scenario_warnings`: those and the scenario's own (geometry: a block touching nothing, no
  support, a GeoJSON property not used).

Warnings, not errors: each of these has a use (a foam-block model, a tilt beyond 90°) the checks cannot
rule out, but run as they are they said "completed" with nothing to tell the usual mistake apart.
"""

from __future__ import annotations

import math
import os

import numpy as np

from masonrycli.records.read import G_STANDARD, vertical_at2
from masonrycli.records.units import MAX_AT2_G, NEAR_CONVERSION
from masonrycli.scenario.scenario import Scenario
from masonrycli.scenario.values import quote_string

MIN_DENSITY = 100.0
"""kg/m³: lighter blocks are warned about (masonry units weigh 1200–3000 kg/m³, timber 400–700): a density in
t/m³ or g/cm³ (2.5 for stone) is 1000× too small."""
MAX_BLOCK_SIZE = 20.0
"""m: a block whose bounding box is longer is warned about (the largest cut stones, Baalbek's, are 20 m long): a
drawing in millimetres (a 300 × 200 mm block read as 300 × 200 m)."""
NUMBERED_SAMPLES = 50
"""Records with at least this many samples at t = 0, 1, 2, … s (or 1, 2, 3, …) are warned about: sample numbers
(no accelerograph samples once a second)."""
GRAVITY_RANGE = (0.5 * G_STANDARD, 2.0 * G_STANDARD)
"""m/s²: a gravity of another size is warned about: cm/s² (981) or g (1) — but not one below 0.01 g, which is
no gravity on purpose (limit analysis refuses it in its own line)."""
BASELINE_CHANGE = 0.15
"""A record whose baseline correction changes its acceleration, at some instant, by more than this fraction of
its peak is warned about: it does not end at rest where it started (a shake table's sine from rest, 0.8 g at 2 Hz for
1 s: the correction adds up to 48 % of the peak, the peak becomes 0.8977 g). Acceleration, not velocity: the
structure feels the ground's acceleration (a uniform velocity is not felt), and bringing a drifting velocity
back is what the correction is for (an unprocessed noise burst's PGV changes by 30 % and more). The figures,
``python -m benchmarks.baseline_shapes`` (docs/scenario-format.md, "baseline correction"): a sine from rest of n
cycles 95 %/n (warned up to 6 cycles); the test suite's tapered synthetic records ≤ 4e-5; 1500 decaying noise
bursts of each kind: white ≤ 4.4 %, Kanai–Tajimi-filtered (never processed, rich in drift) ≤ 11.8 %,
Clough–Penzien ≤ 2.3 %: none warns."""


def scenario_warnings(scenario: Scenario) -> list[str]:
    """Every warning of ``scenario``: its own (geometry), its settings', its records'."""
    return [*scenario.warnings, *setting_warnings(scenario), *record_warnings(scenario)]


def setting_warnings(scenario: Scenario) -> list[str]:
    """One line for a gravity pointing up or of an unlikely size, one for densities below ``MIN_DENSITY``, one
    for blocks larger than ``MAX_BLOCK_SIZE``."""
    out = []
    gx, gy = scenario.run.gravity
    size = math.hypot(gx, gy)
    shown = f"[run] gravity = [{gx:g}, {gy:g}]"
    if gy > 0.0:
        out.append(
            f"{shown} points up (y is up: the blocks fall towards -y, [0, -9.81]; a tilting test turns it by "
            "less than 90°)"
        )
    if size >= 0.01 * G_STANDARD and not GRAVITY_RANGE[0] <= size <= GRAVITY_RANGE[1]:
        out.append(
            f"{shown} is {size:g} m/s², {size / G_STANDARD:.3g} g: gravity is in m/s² ([0, -9.81]; not cm/s², not g)"
        )
    light = [b for b in scenario.assembly.blocks if b.density < MIN_DENSITY]
    if light:
        first = light[0]
        which = f'block "{first.name}"' if len(light) == 1 else f'{len(light)} blocks (first "{first.name}")'
        out.append(
            f"{which}: density {first.density:g} kg/m³, lighter than any masonry unit (stone 2000–2800 kg/m³): a "
            f"density in t/m³ or g/cm³ makes the stresses and forces {1000:g}× too small"
        )
    big = [b for b in scenario.assembly.blocks if _size(b) > MAX_BLOCK_SIZE]
    if big:
        first = big[0]
        x0, y0, x1, y1 = first.polygon.bounds
        which = f'block "{first.name}"' if len(big) == 1 else f'{len(big)} blocks (first "{first.name}")'
        out.append(
            f"{which}: {x1 - x0:g} × {y1 - y0:g} m, larger than any cut stone ({MAX_BLOCK_SIZE:g} m): lengths are in "
            "metres (millimetres? divide the coordinates, or --block-length / --block-height, by 1000)"
        )
    return out


def _size(block) -> float:
    """m: the longer side of the block's bounding box."""
    x0, y0, x1, y1 = block.polygon.bounds
    return max(x1 - x0, y1 - y0)


def idle_driven_supports(assembly, motions) -> list[str]:
    """One line for the supports the structure marks driven (a GeoJSON's ``support_role``, a builder's
    ``right_role``) that no motion drives: the role follows the motion, so they stay fixed — and the run
    said "loading: none" with nothing about the role given."""
    idle = [s.name for s, m in zip(assembly.supports, motions) if s.role == "driven" and m.kind == "fixed"]
    if not idle:
        return []
    names = ", ".join(quote_string(n) for n in idle)
    return [
        f"support{'s' if len(idle) > 1 else ''} {names}: driven, but given no motion, so fixed (a scenario file's "
        "[[support]] table with its name and a motion drives it)"
    ]


def record_warnings(scenario: Scenario, upright: bool = True) -> list[str]:
    """One line per record that the run does not follow whole:

    * it starts after the run ends (a CSV stamped with clock times, 100.0, 100.1, … s): the run never
      reaches a sample, and said "completed … intact";

    * it goes on after the run ends: its shaking after that is not applied (a 40 s PEER record run for
      the built-in wall's 1 s was cut to its first second, and nothing said so);
    * it is sampled more finely than dt: the steps see its velocity every dt only, and its content above
      1/(2 dt) comes back aliased (the record's counterpart of check_sampling's sine);
    * it peaks beyond 10 g as scaled (no earthquake comes near: a CSV in cm/s read as m/s, or a scale
      meant as a unit conversion applied twice, ran "completed … collapsed" without a word);
    * it is an ESM or K-NET file (converted from its header's cm/s², gal or cm/s on reading) scaled by 0.01:
      converted twice (the warning names the file's own unit);
    * it is an .AT2 file (in g, converted on reading) scaled by g (9.81, or 981 for cm/s²): converted twice,
      a 0.3 g record ran at 2.9 g, under the 10 g line.
    * its times are 0, 1, 2, … s: a spreadsheet's sample numbers (a 1000-sample record ran as 1000 s at 1 Hz,
      or, numbered from 1, "starts after the run ends" with a window as the advice);
    * it is an .AT2 file of a vertical component (PEER's …UP.AT2) shaking the ground horizontally: the up
      file of an NGA-West2 zip given to ``--record`` ran along x without a word (``upright``: a sweep's
      record set names those in one line of its own).
    """
    run = scenario.run
    unseen: dict[tuple[str, float, float], list[str]] = {}
    late: dict[tuple[str, float], list[str]] = {}
    fine: dict[tuple[str, float], list[str]] = {}
    strong: dict[tuple[str, float, float], list[str]] = {}
    twice: dict[tuple[str, float, float], list[str]] = {}
    shrunk: dict[tuple[str, float, float], list[str]] = {}
    numbered: dict[tuple[str, float], list[str]] = {}
    sideways: dict[str, list[str]] = {}
    changed: dict[tuple[str, float, float, float], list[str]] = {}
    for support, m in zip(scenario.assembly.supports, scenario.motions):
        if m.kind != "record":
            continue
        name = os.path.basename(m.source) if m.source else "(inline)"
        if _numbered(m.time):  # its window and length warnings would be about sample numbers read as s
            numbered.setdefault((name, float(m.time[0])), []).append(f'"{support.name}"')
        elif m.start_time >= run.duration:
            unseen.setdefault((name, m.start_time, m.end_time), []).append(f'"{support.name}"')
        elif m.end_time > run.duration + 0.5 * run.dt:
            late.setdefault((name, m.end_time), []).append(f'"{support.name}"')
        if m.sample_interval < run.dt * (1.0 - 1e-9):
            fine.setdefault((name, m.sample_interval), []).append(f'"{support.name}"')
        if name.lower().endswith(".at2") and any(
            abs(m.scale / g - 1.0) < NEAR_CONVERSION for g in (G_STANDARD, 100 * G_STANDARD)
        ):
            twice.setdefault((name, m.peak_acceleration / G_STANDARD, m.scale), []).append(f'"{support.name}"')
        elif abs(m.scale / 0.01 - 1.0) < NEAR_CONVERSION and (unit := _cm_unit(m.source)):
            peak = m.peak_acceleration if m.quantity == "acceleration" else m.peak_speed(m.end_time)
            shrunk.setdefault((name, unit, m.quantity, peak, m.scale), []).append(f'"{support.name}"')
        elif m.peak_acceleration > MAX_AT2_G * G_STANDARD:
            strong.setdefault((name, m.peak_acceleration / G_STANDARD, m.scale), []).append(f'"{support.name}"')
        applied, change = m.baseline_change
        if change > BASELINE_CHANGE * m.peak_acceleration:
            changed.setdefault((name, m.peak_acceleration, applied, change), []).append(f'"{support.name}"')
        # along x (or as the horizontal of a vertical pair): an up component along y (direction [0, 1]) is meant
        horizontal = m.vertical_source or abs(m.direction[0]) >= abs(m.direction[1])
        if upright and m.source and horizontal and vertical_at2(m.source):
            sideways.setdefault(name, []).append(f'"{support.name}"')

    def who(names: list[str]) -> str:
        return f"support{'s' if len(names) > 1 else ''} {', '.join(names)}"

    return (
        [
            f"{who(names)}: the record {name} starts at t = {start:g} s, after the run's {run.duration:g} s: none "
            "of its shaking is applied (record times count from the run's t = 0; a scenario file's "
            f"window = [{start:g}, {end:g}] moves it there)"
            for (name, start, end), names in unseen.items()
        ]
        + [
            f"{who(names)}: the record {name} lasts {end:g} s but the run {run.duration:g} s; its shaking after "
            f"t = {run.duration:g} s is not applied (--duration {end:g} runs it all)"
            for (name, end), names in late.items()
        ]
        + [
            f"{who(names)}: the record {name} is sampled every {step:g} s, finer than dt = {run.dt:g} s: the steps skip "
            f"samples and alias its content above {0.5 / run.dt:g} Hz (dt = {step:g} follows every sample)"
            for (name, step), names in fine.items()
        ]
        + [
            f"{who(names)}: the record {name} peaks at {peak:.3g} g as applied (scale {scale:g}); the strongest "
            f"earthquakes reach 3–4 g: check its units and the scale"
            for (name, peak, scale), names in strong.items()
        ]
        + [
            f"{who(names)}: the record {name} is read in g and converted to m/s² already; scale {scale:g} converts "
            f"it again ({peak:.3g} g as applied; the scale multiplies the record, 1 is as recorded)"
            for (name, peak, scale), names in twice.items()
        ]
        + [
            f"{who(names)}: the record {name} is read in its header's unit ({unit}) and converted to {_SI[quantity]} "
            f"already; scale {scale:g} converts it again ({peak:.3g} {_SI[quantity]} as applied, 100 times too weak; "
            "the scale multiplies the record, 1 is as recorded)"
            for (name, unit, quantity, peak, scale), names in shrunk.items()
        ]
        + [
            f"{who(names)}: the record {name} has its samples at t = {first:g}, {first + 1:g}, {first + 2:g}, … s: "
            "sample numbers, not times? (give its times in s, or its values alone with --record-dt / time_step)"
            for (name, first), names in numbered.items()
        ]
        + [
            f"{who(names)}: the record {name} is a vertical component (PEER's UP / DWN, ESM's Z, K-NET's UD), applied horizontally: give "
            "a horizontal one (H1 / H2), or this one as a scenario file's vertical = … beside its horizontal"
            for name, names in sideways.items()
        ]
        + [
            f"{who(names)}: the record {name} does not end at rest where it started: its baseline correction changes the "
            f"acceleration by up to {change / G_STANDARD:.3g} g ({100 * change / peak:.0f} % of its peak): its peak "
            f"{peak / G_STANDARD:.4g} g becomes {applied / G_STANDARD:.4g} g as applied (×{applied / peak:.4g}); "
            '--baseline none (a scenario file\'s baseline = "none") applies it as given'
            for (name, peak, applied, change), names in changed.items()
        ]
    )


_SI = {"acceleration": "m/s²", "velocity": "m/s"}


def _cm_unit(source: str) -> str:
    """The unit an ESM or K-NET file's header gives when its samples were converted from centimetres on reading
    (an ESM file's UNITS as written: cm/s^2, gal, cm/s; gal for K-NET), "" for any other file: a CSV (a plain
    table named .asc too) is read in its own units, scale 0.01 converting its cm/s²; an ESM file in m/s² or mm/s
    is not converted twice by 0.01."""
    from masonrycli.records.esm import esm_units, is_esm
    from masonrycli.records.knet import is_knet

    if not source:
        return ""
    if is_knet(source):
        return "gal"
    units = esm_units(source) if is_esm(source) else None
    return units[0] if units and units[1] == 0.01 else ""


def _numbered(time) -> bool:
    """The sample times are 0, 1, 2, … or 1, 2, 3, … (at least ``NUMBERED_SAMPLES`` of them): a spreadsheet's
    row numbers taken for times, a 1000-sample accelerogram then lasting 1000 s at 1 Hz."""
    n = len(time)
    return n >= NUMBERED_SAMPLES and float(time[0]) in (0.0, 1.0) and bool(np.all(np.diff(time) == 1.0))
