"""Fragility curve: probability of collapse against an intensity measure, lognormal.

P(collapse | IM = x) = Φ(ln(x / θ) / β), θ the median (the IM at which half the runs collapse) and β
the dispersion, fitted by maximum likelihood over the runs (each run a Bernoulli trial: collapsed or
not at its IM), the usual fit for incremental dynamic analyses and multiple-stripe analyses.

A record study over another swept parameter as well (``--param friction=0.5,0.7``) gets one fit per value
of it (:func:`fit_by`): one curve over runs of two frictions is the fragility of neither (the 48 runs of a
rubble wall at μ = 0.5 and 0.7 gave one θ = 4.48 m/s², β = 0.63, between θ = 3.09 and 6.66 m/s² apart).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Fragility:
    """θ (median, IM units), β (dispersion of ln IM), n runs, how many collapsed, the IM's name."""

    median: float
    dispersion: float
    runs: int
    collapsed: int
    im: str
    separated: tuple[float, float] | None = None
    """(highest IM that stood, lowest that collapsed) when every collapse lies above every survivor: the
    likelihood then grows without end as β -> 0, so β is only the bound the fit stopped at (not resolved)."""
    unbounded: bool = False
    """β stopped at its upper bound (5): the collapses do not come at larger IM than the runs that stood
    (every one below them: the likelihood grows as β -> ∞, the curve flattening to 1/2), so no curve is
    resolved. It printed "β = 5.000" as a fit."""

    def probability(self, x) -> np.ndarray:
        from scipy.stats import norm

        x = np.asarray(x, dtype=np.float64)
        return norm.cdf(np.log(np.maximum(x, 1e-300) / self.median) / self.dispersion)


def fit_lognormal(im, collapsed, name: str = "im") -> Fragility | None:
    """Maximum-likelihood θ, β of runs at intensities ``im`` (> 0) that ``collapsed`` (bool) or not.

    None when the data cannot define a curve: fewer than 2 runs, or all runs on one side (no collapse,
    or all collapsed) — then any θ below/above the data fits and the maximum is at infinity.
    """
    from scipy.optimize import minimize
    from scipy.stats import norm

    x = np.asarray(im, dtype=np.float64)
    y = np.asarray(collapsed, dtype=bool)
    keep = np.isfinite(x) & (x > 0)
    x, y = x[keep], y[keep]
    if x.size < 2 or y.all() or not y.any():
        return None
    lx = np.log(x)

    def nll(p):
        ln_theta, ln_beta = p
        z = (lx - ln_theta) / math.exp(ln_beta)
        return -(norm.logcdf(z[y]).sum() + norm.logsf(z[~y]).sum())

    start = np.array([np.median(lx), math.log(max(np.std(lx), 0.1))])
    # β is kept in [0.01, 5]: runs perfectly separated by the IM drive the likelihood's maximum to β -> 0
    bounds = [(None, None), (math.log(0.01), math.log(5.0))]
    start[1] = min(max(start[1], bounds[1][0]), bounds[1][1])
    options = {"xatol": 1e-10, "fatol": 1e-12, "maxiter": 4000}
    best = minimize(nll, start, method="Nelder-Mead", bounds=bounds, options=options)
    stood, fell = float(x[~y].max()), float(x[y].min())
    dispersion = float(math.exp(best.x[1]))
    return Fragility(
        median=float(math.exp(best.x[0])),
        dispersion=dispersion,
        runs=int(x.size),
        collapsed=int(y.sum()),
        im=name,
        separated=(stood, fell) if stood < fell else None,
        unbounded=dispersion > 5.0 * (1 - 1e-6),
    )


@dataclass(frozen=True)
class FitGroup:
    """The runs of one value of the study's other swept parameters (``label``: ``friction = 0.5``; "" when
    there are none), and their fit (None: no curve, :func:`fit_lognormal`)."""

    label: str
    rows: list
    fit: Fragility | None


def fit_by(rows: list[dict], im: str, by: list[str]) -> list[FitGroup]:
    """One :class:`FitGroup` per combination of the values of parameters ``by`` in ``rows`` (failed runs
    left out by the caller), in the rows' order; one group of every row when ``by`` is empty (or no row)."""
    from masonrycli.study.curves import point_groups

    if not rows:
        return [FitGroup("", [], None)]
    out = []
    for label, indices in point_groups(rows, by):
        members = [rows[i] for i in indices]
        fit = fit_lognormal([r[im] for r in members], [r["state"] == "collapsed" for r in members], im)
        out.append(FitGroup(label, members, fit))
    return out
