"""A record scaled to a peak ground acceleration: ``--pga`` (simulate, run, check; ``api``'s ``pga=``).

A site's design earthquake is a PGA (0.25 g); a record peaks where it peaks, and ``--scale`` multiplies it
as recorded. The run reports the PGA of the motion *as applied* (baseline-corrected, at the run's steps:
:mod:`masonrycli.records.intensity`), which is not the samples' peak times the scale (0.8 % lower on a 20 s
synthetic record: 0.25 / 0.312 g gave 0.248 g). So the scale is found from the motion as applied. The
support velocity is linear in the scale (the integration and the least-squares baseline are linear maps), so

    v   = the shaking support's x velocity at t_k = k dt, k = 0 … n, with the records as read
          (n: the run's steps, or the record's end in steps when it is longer: the whole record)
    a   = max_k |v[k+1] − v[k]| / dt                 (the PGA as records/intensity.py measures it)
    every record's scale  ×=  PGA / a

makes the run's PGA the one asked for, to round-off, when the run reaches the record's peak; a run cut
before it applies the record so scaled up to its end (a warning says it is cut).
"""

from __future__ import annotations

import dataclasses
import math
import os
import re

import numpy as np

from masonrycli.errors import InputError
from masonrycli.records.units import G_STANDARD, unit_factor

MAX_PGA_G = 10.0
"""g: a larger target is refused (the strongest records peak at 3–4 g; the runs' 10 g line, caveats.py)."""

_NUMBER_UNIT = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S.*?)?\s*")


def pga_in_g(text: str) -> float:
    """The PGA ``text`` gives, in g: a number in g (``0.25``), or a number and an acceleration unit
    (``0.25g``, ``0.25 g``, ``2.45m/s2``, ``2.45 m/s²``, ``245gal``, ``245 cm/s^2``: any spelling a record's
    header is read in, :func:`masonrycli.records.units.unit_factor`). Raises :class:`InputError` (the
    message without the option's name)."""
    found = _NUMBER_UNIT.fullmatch(str(text))
    if found is None:
        raise InputError(f"{text}: must be a number, in g (0.25), or with its unit (0.25g, 2.45m/s2, 245gal)")
    number, unit = float(found.group(1)), found.group(2)
    if unit is not None:
        known = unit_factor(unit)
        if known is None or known[0] != "acceleration":
            raise InputError(f"{text}: {unit} is not a unit of acceleration (g, m/s2, gal, cm/s2)")
        number *= known[1] / G_STANDARD
    if not (math.isfinite(number) and 0.0 < number <= MAX_PGA_G):
        raise InputError(f"{text}: must be a peak acceleration above 0 and at most {MAX_PGA_G:g} g")
    return number


def with_pga(scenario, pga: float | None, scale: float | None = None):
    """``scenario`` as it is for ``pga`` None, else :func:`scaled_to_pga`; ``scale``: the ``--scale`` given
    too (None: not given), refused beside ``--pga``, which sets it."""
    if pga is None:
        return scenario
    if scale is not None:
        raise InputError("--pga with --scale: give one (--pga sets the record's scale)")
    return scaled_to_pga(scenario, pga)


CHUNK_STEPS = 1 << 20
"""Most steps whose velocities are held at once (16 MB): the whole run's at once took 12.5 GB and 73 s before
``masonry check wall --record q.AT2 --pga 0.25 --duration 100000`` could refuse its 295 GB recording."""


def applied_peak(record, n_steps: int, dt: float) -> float:
    """m/s²: max_k |v[k+1] − v[k]| / dt over the run's steps k < ``n_steps`` of ``record``'s x velocity, as
    records/intensity.py measures the PGA. After the record's last sample its velocity is constant (the
    integral stops, the baseline's s stays 1: records/velocity.py), so the steps past it, which change
    nothing, are not evaluated, and the others are taken CHUNK_STEPS at a time:

        last = min(n_steps, ceil(end / dt) + 2)      (every step that can differ from its successor)
        for each chunk k0 … k1 of 0 … last: peak = max(peak, max |diff v(k0 dt … k1 dt)|)

    The times are the integers k times dt, as in one array: the same peak to the bit."""
    last = min(n_steps, math.ceil(record.end_time / dt) + 2)
    peak = 0.0
    for k0 in range(0, last, CHUNK_STEPS):
        k1 = min(k0 + CHUNK_STEPS, last)
        velocity = record.velocity_at(np.arange(k0, k1 + 1, dtype=np.float64) * dt)[:, 0]
        peak = max(peak, float(np.abs(np.diff(velocity)).max()))
    return peak / dt


def scaled_to_pga(scenario, pga: float, option: str = "--pga", give: str = "--record FILE"):
    """``scenario`` with every record motion's scale multiplied so that its ground motion as applied (the
    shaking support's, over the run's steps) peaks at ``pga`` g; ``option`` names the setting in errors,
    ``give`` how a record is given where it is. Raises :class:`InputError` when no record shakes the
    structure, or when it never accelerates."""
    from masonrycli.records.intensity import shaking_support

    j = shaking_support(scenario.motions)
    if j is None or scenario.motions[j].kind != "record":
        what = "nothing shakes it" if j is None else f"its {scenario.motions[j].kind} motion is not a record"
        raise InputError(f"{option}: scales a ground-motion record, and {what} (give {give})")
    # over the whole record at the run's steps, whatever the run's length: a run cut before the record's peak
    # applies the record so scaled up to its end (and is warned it is cut), where scaling the part it runs to
    # the PGA inflated the record (--duration 3 on a 20 s synthetic record peaking at 3.4 s: ×1.12)
    record, dt = scenario.motions[j], scenario.run.dt
    peak = applied_peak(record, max(scenario.run.n_steps, math.ceil(record.end_time / dt) + 2), dt)
    if not peak > 0.0:  # named: in a set of records, '--param pga_g=0.4: the record never …' left which to find
        name = os.path.basename(record.source) if record.source else "the record"
        raise InputError(f"{option}: {name} never accelerates the ground along x")
    factor = pga * G_STANDARD / peak
    motions = tuple(
        dataclasses.replace(m, scale=m.scale * factor) if m.kind == "record" else m for m in scenario.motions
    )
    return dataclasses.replace(scenario, motions=motions)
