"""Pictures of a study, as PNG (matplotlib, headless Agg backend).

* **state map** — one cell per run over two swept parameters, coloured intact / damaged / collapsed
  (failed runs grey), the collapse time written in collapsed cells; one swept parameter gives a strip.
* **fragility curve** — the fraction of runs collapsed at each stripe (same scale) against the mean
  intensity measure, every run as a tick at 0 or 1, and the fitted lognormal curve.
* **threshold curve** — ``<param>_threshold`` against the other swept parameter (``--find``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

UNITS = {"amp": "m/s", "freq": "Hz", "phase": "rad", "duration": "s", "dt": "s"}
STATE_COLOURS = {"intact": "#2e9e5b", "damaged": "#f0a030", "collapsed": "#d03030", "": "#a0a0a0"}


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path: Path) -> Path:
    # PNG whatever the name: the caller writes a temporary ".part" file (masonrycli.outputs.written_whole)
    fig.savefig(path, format="png", dpi=120, bbox_inches="tight")
    return path


def _label(name: str) -> str:
    unit = UNITS.get(name.rpartition(".")[2])
    return f"{name} ({unit})" if unit else name


def state_map(rows: list[dict], x: str, y: str | None, path: Path, title: str) -> Path:
    """PNG of the states over parameters ``x`` (and ``y``): one coloured cell per run."""
    from matplotlib.patches import Patch

    plt = _pyplot()
    xs = sorted({r[x] for r in rows})
    ys = sorted({r[y] for r in rows}) if y else [0]
    fig, ax = plt.subplots(figsize=(1.2 + 0.7 * len(xs), 1.2 + 0.55 * len(ys)))
    for r in rows:
        i, j = xs.index(r[x]), ys.index(r[y]) if y else 0
        colour = STATE_COLOURS.get(r.get("state") or "", STATE_COLOURS[""])
        ax.add_patch(plt.Rectangle((i - 0.5, j - 0.5), 1, 1, color=colour, ec="white", lw=1.5))
        t = r.get("collapse_time")
        if r.get("state") == "collapsed" and t == t:
            ax.text(i, j, f"{t:.2f} s", ha="center", va="center", fontsize=7, color="white")
    ax.set_xlim(-0.5, len(xs) - 0.5)
    ax.set_ylim(-0.5, len(ys) - 0.5)
    ax.set_xticks(range(len(xs)), [f"{v:g}" if not isinstance(v, str) else v for v in xs], rotation=45)
    ax.set_xlabel(_label(x))
    if y:
        ax.set_yticks(range(len(ys)), [f"{v:g}" if not isinstance(v, str) else v for v in ys])
        ax.set_ylabel(_label(y))
    else:
        ax.set_yticks([])
    handles = [Patch(color=STATE_COLOURS[s], label=s) for s in ("intact", "damaged", "collapsed")]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    ax.set_title(title, fontsize=10)
    path = _save(fig, path)
    plt.close(fig)
    return path


def fragility_curve(rows: list[dict], im: str, fit, path: Path, title: str, unit: str) -> Path:
    """PNG: runs (ticks at 0/1), collapsed fraction per scale stripe, and the fitted lognormal."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    x = np.array([r[im] for r in rows], dtype=float)
    c = np.array([r.get("state") == "collapsed" for r in rows], dtype=float)
    ax.plot(x, c, "|", color="#555555", ms=12, label="runs (collapsed = 1)")
    if rows and "scale" in rows[0]:
        for s in sorted({r["scale"] for r in rows}):
            sel = np.array([r["scale"] == s for r in rows])
            ax.plot(np.nanmean(x[sel]), c[sel].mean(), "o", color="#d03030")
        ax.plot([], [], "o", color="#d03030", label="fraction collapsed per scale")
    if fit is not None:
        grid = np.linspace(0, np.nanmax(x) * 1.2, 300)[1:]
        ax.plot(
            grid,
            fit.probability(grid),
            "-",
            color="#1f5fa8",
            label="lognormal: not resolved (runs separated: β → 0)"
            if fit.separated
            else f"lognormal: θ = {fit.median:.3g} {unit}, β = {fit.dispersion:.2f}",
        )
    ax.set_xlabel(f"{im} ({unit})")
    ax.set_ylabel("P(collapse)")
    ax.set_ylim(-0.05, 1.05)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(title, fontsize=10)
    path = _save(fig, path)
    plt.close(fig)
    return path


def threshold_curve(rows: list[dict], find: str, x: str | None, path: Path, title: str) -> Path:
    """PNG of ``<find>_threshold`` against parameter ``x`` (a bar per point without another axis)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    key = f"{find}_threshold"
    if x:
        pts = sorted((r[x], r[key]) for r in rows)
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color="#d03030")
        ax.set_xlabel(_label(x))
    else:
        ax.bar([0], [rows[0][key]] if rows else [0], color="#d03030")
        ax.set_xticks([])
    ax.set_ylabel(key)
    ax.set_title(title, fontsize=10)
    path = _save(fig, path)
    plt.close(fig)
    return path
