"""Intensity measures of the ground motion as applied to a run.

The measures are taken from the imposed velocity of the shaking support sampled at the run's time
steps (the motion *as applied*: scaled, windowed, baseline-corrected, cut at the run's duration — the
whole duration even when the run stops early at collapse, so the measure belongs to the loading), along
x (horizontal). The acceleration is the step-to-step difference of that velocity, which for a record is
the record's own (linearly interpolated) acceleration averaged over each step. The field's library
`eqsig` computes the Arias intensity, the significant duration and the spectral acceleration.

=========== ====== ==========================================================================
name        unit   meaning
=========== ====== ==========================================================================
``pga``     m/s²   peak |a|
``pgv``     m/s    peak |v|
``arias``   m/s    Arias intensity π/(2g) ∫ a² dt (eqsig, g = 9.81 m/s²)
``d5_95``   s      significant duration: time between 5 % and 95 % of the Arias intensity (NaN when
                   no sample lies between them: a run of a few steps)
``sa``      m/s²   5 %-damped pseudo-spectral acceleration at ``sa_period`` (eqsig, Nigam–Jennings)
=========== ====== ==========================================================================
"""

from __future__ import annotations

import numpy as np

SA_PERIOD = 0.5
"""s — default period of the spectral acceleration (a few-storey masonry wall is stiff: 0.1–0.5 s)."""
SA_DAMPING = 0.05
INTENSITY_MEASURES = ("pga", "pgv", "arias", "d5_95", "sa")
UNITS = {"pga": "m/s²", "pgv": "m/s", "arias": "m/s", "d5_95": "s", "sa": "m/s²"}


def intensity_measures(velocity, dt: float, sa_period: float = SA_PERIOD) -> dict[str, float]:
    """PGA, PGV, Arias intensity, significant duration and Sa of a ground velocity history.

    velocity : (T,) m/s, samples at t = 0, dt, 2 dt, ... (T >= 2).
    Returns ``{name: value}`` for the names of :data:`INTENSITY_MEASURES` (module docstring for units).
    """
    import eqsig
    from eqsig import im

    v = np.asarray(velocity, dtype=np.float64)
    acc = np.diff(v) / dt
    out = {"pga": float(np.abs(acc).max()), "pgv": float(np.abs(v).max())}
    if not np.any(acc):  # a still or constant-velocity ground has no intensity (and eqsig would divide by 0)
        return out | {"arias": 0.0, "d5_95": 0.0, "sa": 0.0}
    signal = eqsig.AccSignal(acc, dt)
    arias = im.calc_arias_intensity(signal)
    out["arias"] = float(arias[-1])
    # eqsig's D5–95 indexes the samples strictly between 5 % and 95 % of the final Arias intensity: a run of
    # a few steps may have none (two steps of a sine from rest), and the duration is then not resolved
    between = (arias > 0.05 * arias[-1]) & (arias < 0.95 * arias[-1])
    out["d5_95"] = float(im.calc_sig_dur(signal)) if between.any() else float("nan")
    out["sa"] = float(eqsig.sdof.pseudo_response_spectra(acc, dt, np.array([sa_period]), SA_DAMPING)[2][0])
    return out


def shaking_support(motions) -> int | None:
    """Index of the first support whose motion shakes (sine or record), or None."""
    for j, motion in enumerate(motions):
        if motion.kind in ("sine", "record"):
            return j
    return None


MAX_CHECK_STEPS = 2_000_000
"""Most steps ``masonry check`` measures the loading over (16 MB of velocities; a 10⁸-step run would take 800 MB)."""


def loading_intensity(scenario) -> tuple[str, dict[str, float]] | None:
    """``(support name, measures)`` of the ground motion a run of ``scenario`` would apply — what its summary's
    ``ground motion`` row will say, before it runs (``masonry check``) — or None when no support shakes or the
    run has more than :data:`MAX_CHECK_STEPS` steps."""
    from masonrycli.scenario.motion import support_velocity

    j, run = shaking_support(scenario.motions), scenario.run
    if j is None or run.n_steps < 2 or run.n_steps > MAX_CHECK_STEPS:
        return None
    v = support_velocity(scenario.motions[j : j + 1], np.arange(run.n_steps + 1, dtype=np.float64) * run.dt)
    return scenario.assembly.supports[j].name, intensity_measures(v[:, 0, 0], run.dt)


def describe(ims: dict[str, float], sa_period: float = SA_PERIOD) -> str:
    """One summary line, e.g. ``PGA 3.14 m/s² (0.32 g), PGV 0.5 m/s, Arias 1.2 m/s, D5–95 4.1 s, Sa(0.5 s) 5 m/s²``."""
    return (
        f"PGA {ims['pga']:.3g} m/s² ({ims['pga'] / 9.80665:.3g} g), PGV {ims['pgv']:.3g} m/s, "
        f"Arias {ims['arias']:.3g} m/s, D5–95 {ims['d5_95']:.3g} s, Sa({sa_period:g} s) {ims['sa']:.3g} m/s²"
    )
