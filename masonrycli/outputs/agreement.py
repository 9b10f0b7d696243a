"""How well a computed time history agrees with a measured one (``masonry export … --times lab.csv --compare
COLUMN``): the measures a shake-table comparison reports, on the samples where both have a value.

With m the measured and c the computed series at the same times t (c converted to m's unit):

    peak            the value of largest magnitude of each, and its time; ratio |c peak| / |m peak|
    final           the last sample of each (a dry-stone wall keeps its slip: the residual displacement)
    RMS error       sqrt(mean((c − m)²)); relative: over sqrt(mean(m²))
    correlation     Pearson's r of c and m (shape, neither offset nor scale)
    Sprague–Geers   with ψ_xy = ∫ x y dt (trapezoids on t): magnitude M = sqrt(ψ_cc / ψ_mm) − 1,
                    phase P = arccos(ψ_mc / sqrt(ψ_mm ψ_cc)) / π, combined C = sqrt(M² + P²)
                    (Sprague & Geers 2004; 0 for identical series; M > 0 computed too large, P in [0, 1])

The unit of a column is read from its name, ``LVDT top (mm)``, ``top ux rel (m)`` (:data:`UNITS`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from masonrycli.records.units import G_STANDARD, SCALED_UNITS, unit_key

UNITS = {
    **{unit: (kind, G_STANDARD if unit == "g" else factor) for unit, (kind, factor) in SCALED_UNITS.items()},
    "m": ("length", 1.0),
    "cm": ("length", 1e-2),
    "mm": ("length", 1e-3),
    "um": ("length", 1e-6),
    "µm": ("length", 1e-6),
    "in": ("length", 0.0254),
    "ft": ("length", 0.3048),
    "m/s": ("velocity", 1.0),
    "cm/s": ("velocity", 1e-2),
    "mm/s": ("velocity", 1e-3),
    "m/s2": ("acceleration", 1.0),
    "m/s²": ("acceleration", 1.0),
    "cm/s2": ("acceleration", 1e-2),
    "cm/s²": ("acceleration", 1e-2),
    "gal": ("acceleration", 1e-2),
    "mm/s2": ("acceleration", 1e-3),
    "g": ("acceleration", 9.80665),
    "rad": ("angle", 1.0),
    "mrad": ("angle", 1e-3),
    "deg": ("angle", math.pi / 180),
    "°": ("angle", math.pi / 180),
    "n": ("force", 1.0),
    "kn": ("force", 1e3),
    "n m": ("moment", 1.0),
    "kn m": ("moment", 1e3),
    "-": ("ratio", 1.0),
    "%": ("ratio", 1e-2),
}
"""Unit (as written in a column's name, lower case, ``^2`` written ``2``) → (quantity, factor to SI): the
velocities and accelerations a record's header is read in (:data:`masonrycli.records.units.SCALED_UNITS`:
in/s, ft/s², …), and lengths, angles, forces and moments."""

_UNIT = re.compile(r"[\(\[]\s*([^\(\)\[\]]+?)\s*[\)\]]\s*$")


def column_unit(name: str) -> tuple[str, str, float] | None:
    """``(unit as written, quantity, factor to SI)`` of a column named ``… (unit)`` or ``… [unit]``, or None."""
    found = _UNIT.search(name)
    if found is None:
        return None
    key = re.sub(r"\s+", " ", found.group(1).lower()).replace("^2", "2").replace("**2", "2").replace("·", " ")
    key = key.replace("nm", "n m") if key in ("nm", "knm") else key
    if key not in UNITS and ("/" in key or "-" in key):  # cm/sec^2, m/s/s, m s-2 as --record reads them; not ms
        key = unit_key(key)
    if key not in UNITS:
        return None
    return (found.group(1), *UNITS[key])


@dataclass(frozen=True)
class Agreement:
    """The measures of the module docstring, in the measured series' unit (``samples``: how many were compared)."""

    samples: int
    peak_measured: float
    peak_measured_time: float
    peak_computed: float
    peak_computed_time: float
    peak_ratio: float
    final_measured: float
    final_computed: float
    rms_error: float
    relative_rms_error: float
    correlation: float
    magnitude: float
    phase: float
    combined: float


def _integral(t: np.ndarray, y: np.ndarray) -> float:
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t))) if len(t) > 1 else float(y.sum())


def agreement(t, measured, computed) -> Agreement | None:
    """The measures of ``computed`` against ``measured`` at times ``t``, on the samples where both are finite;
    None when fewer than 2 are."""
    t, m, c = (np.asarray(x, dtype=float) for x in (t, measured, computed))
    keep = np.isfinite(m) & np.isfinite(c)
    t, m, c = t[keep], m[keep], c[keep]
    if len(t) < 2:
        return None
    im, ic = int(np.argmax(np.abs(m))), int(np.argmax(np.abs(c)))
    rms_m = math.sqrt(float(np.mean(m**2)))
    rms_e = math.sqrt(float(np.mean((c - m) ** 2)))
    with np.errstate(invalid="ignore", divide="ignore"):
        r = float(np.corrcoef(m, c)[0, 1]) if np.std(m) > 0 and np.std(c) > 0 else math.nan
    mm, cc, mc = _integral(t, m * m), _integral(t, c * c), _integral(t, m * c)
    if mm > 0 and cc > 0:
        magnitude = math.sqrt(cc / mm) - 1
        phase = math.acos(max(-1.0, min(1.0, mc / math.sqrt(mm * cc)))) / math.pi
    else:
        magnitude = phase = math.nan
    return Agreement(
        samples=len(t),
        peak_measured=float(m[im]),
        peak_measured_time=float(t[im]),
        peak_computed=float(c[ic]),
        peak_computed_time=float(t[ic]),
        peak_ratio=abs(c[ic]) / abs(m[im]) if m[im] != 0 else math.nan,
        final_measured=float(m[-1]),
        final_computed=float(c[-1]),
        rms_error=rms_e,
        relative_rms_error=rms_e / rms_m if rms_m > 0 else math.nan,
        correlation=r,
        magnitude=magnitude,
        phase=phase,
        combined=math.hypot(magnitude, phase),
    )


def describe(a: Agreement, measured: str, computed: str, unit: str) -> list[str]:
    """The measures as lines for the terminal."""
    return [
        f"{computed} (masonry) against {measured} (lab), {a.samples} samples, in {unit}:",
        f"  peak           lab {a.peak_measured:.4g} at {a.peak_measured_time:g} s, masonry {a.peak_computed:.4g} "
        f"at {a.peak_computed_time:g} s: ratio {a.peak_ratio:.3f}",
        f"  final          lab {a.final_measured:.4g}, masonry {a.final_computed:.4g}",
        f"  RMS error      {a.rms_error:.4g} {unit} ({a.relative_rms_error:.3f} of the lab's RMS)",
        f"  correlation    r = {a.correlation:.4f}",
        f"  Sprague–Geers  M = {a.magnitude:+.3f} (magnitude), P = {a.phase:.3f} (phase), C = {a.combined:.3f}",
    ]


def _a(quantity: str) -> str:
    """'a length', 'an acceleration' (it said 'a acceleration', 'a angle')."""
    return f"{'an' if quantity[0] in 'aeiou' else 'a'} {quantity}"


def compare(table, spec: str, lab_path: str, lab_lines: list[int], time: np.ndarray) -> list[str]:
    """The measures of ``--compare spec`` on a resampled ``table`` (:func:`masonrycli.outputs.resample.resample`):
    ``LAB COLUMN`` against the table's first target (``table.main``), or ``LAB COLUMN=MASONRY COLUMN``.
    Raises :class:`InputError` (one line) for a column neither has, a lab column without a unit or of another
    quantity, a cell that is no number."""
    from masonrycli.errors import InputError

    measured, _, computed = spec.partition("=")
    measured, computed = measured.strip(), computed.strip() or table.main
    columns = dict(zip(table.names, table.values))
    lab = [n for n, v in columns.items() if v.dtype == object]  # the lab's columns are its cells, as text
    ours = [n for n in columns if n not in lab]
    for name, among, where in ((measured, lab, f"{lab_path}'s columns"), (computed, ours, "masonry's columns")):
        if name not in among:
            raise InputError(f"--compare {spec}: no column '{name}' among {where} ({', '.join(among)})")
    lab_unit, theirs = column_unit(measured), column_unit(computed)
    if lab_unit is None:
        raise InputError(
            f"--compare {spec}: the lab column '{measured}' names no unit masonry knows (its name ends in "
            f"one: '{measured} (mm)'; {', '.join(k for k in UNITS if k.isascii())})"
        )
    if theirs is None or theirs[1] != lab_unit[1]:
        what = _a(theirs[1]) if theirs else "no known unit"
        raise InputError(f"--compare {spec}: '{measured}' is {_a(lab_unit[1])}, '{computed}' {what}")
    cells = columns[measured]
    values = np.full(len(cells), np.nan)
    for i, cell in enumerate(cells):
        if cell.strip():
            try:
                values[i] = float(cell)
            except ValueError:
                raise InputError(f"{lab_path}:{lab_lines[i]}: '{measured}' = '{cell}' is not a number") from None
    result = agreement(time, values, columns[computed] * theirs[2] / lab_unit[2])
    if result is None:
        return [f"--compare {spec}: fewer than 2 samples where both have a value: no measure"]
    return describe(result, measured, computed, lab_unit[0])
