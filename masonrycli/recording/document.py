"""The run document (status, parameters, scales, versions) and the legend shown under the structure views.

Rewritten whenever a scale is fixed and when the recorder closes; the last one logged wins. Every text
that reaches the viewer goes through ``viewer_safe_text``.
"""

from __future__ import annotations

import functools
import importlib.metadata
import math
import platform
import re
from typing import Final

import numpy as np
import rerun as rr

from masonrycli import __version__ as MASONRY_VERSION
from masonrycli.recording.colormap import tick_label
from masonrycli.recording.colour_range import BULK_TRIM, HOLD_SPAN, MIN_SPAN, OUTSIDE_SHARE
from masonrycli.recording.layout import (
    AXES,
    FIELD_TABS,
    FIELDS,
    LIVE_TAB,
    MAGNIFIED_TAB,
    ROBUST_PERCENTILE,
    SQRT_FIELDS,
    SQRT_TABS,
    tabs_legend,
)


def run_document(
    metadata: dict,
    status: str,
    note: str,
    *,
    last: tuple[int, float] | None,
    wall_time: float,
    frames: int,
    dt: float,
    friction: float,
    blocks: int,
    supports: int,
    force_scale: float | None,
    block_height: float,
    glyph_length: float,
    axis_scale: dict[str, float],
    field_ranges: dict[str, tuple[float, float]],
    range_changes: dict[str, int] | None = None,
    magnify: float | None = None,
) -> str:
    """Markdown of the run document.

    ``last``: (step, time) of the last frame logged, None before the first; ``wall_time``: s since the
    recording was opened; ``force_scale`` (m per N), ``axis_scale`` (glyph set -> |λ| at full length),
    ``field_ranges`` (the last range of each field), ``range_changes`` (how often each was refitted) and
    ``magnify`` (the magnified view's factor) as the recorder has them so far.
    """
    line = status
    if last is not None:
        at = f"t = {last[1]:.3f} s (step {last[0]})"
        line = f"{status}, last frame {at}" if status in ("completed", "running") else f"{status} at {at}"
    if note:  # the caller's note usually says it all ("interrupted at t = ..."): do not repeat it
        line = note if note.startswith(status) else f"{line}: {note}"
    pct = f"{ROBUST_PERCENTILE:g}th percentile"
    changes = range_changes or {}
    lines = [
        f"# masonry — {metadata.get('scenario', 'run')}",
        "",
        f"**Status:** {line}",
        "",
        # the verdict on the first lines the Run panel shows: a collapsed wall's panel said "Status: completed"
        # and its parameters, the state 30 rows down the table (result.state), under the panel's fold
        *_verdict_lines(metadata.get("result")),
        f"**Run time:** {wall_time:.2f} s · **frames:** {frames} · "
        f"**dt:** {dt:g} s · **friction:** {friction:g} · "
        f"**blocks:** {blocks} · **supports:** {supports}",
        "",
        # what made it, on the first lines a user sees (before: the solver and the code only far down the table)
        f"**solver:** {metadata.get('solver', '—')} · **masonry** {metadata.get('masonry', '—')}, "
        f"commit {metadata.get('commit', '—')}, source {metadata.get('source_digest', '—')}",
        "",
        *parameters_markdown(metadata),
        "",
        "## How to read the views",
        "",
        legend_markdown(force_scale, block_height, magnify),
        "- **Principal axes**: two segments per cell along the eigenvectors, half-length proportional "
        f"to |λ|, {glyph_length:.3g} m (at most 0.45 × the block's smaller side) at the value below (longer "
        f"ones clipped; the {pct} of the first "
        "batch); black = compression / contraction, magenta = tension / extension. Stress axes in the "
        "main view and the spherical-stress tabs; the triangles of the cells (as built) in the volumetric "
        "strain rate tabs.",
        *(f"  - {n.replace('_', ' ')}: full length at |λ| = {_fmt_scale(axis_scale.get(n), '')}" for n in AXES),
        "- **Colour ranges follow the data**: each field's range is checked against every recorded frame "
        f"and refitted from that frame on only when more than {100 * OUTSIDE_SHARE:g} % of the cells fall "
        f"outside it or the cells, leaving out the {100 * BULK_TRIM:g} % most extreme at each end, span less "
        f"than {100 * MIN_SPAN:g} % of it (on the signed strain-rate scale: in two frames in a row, or less than "
        f"{100 * HOLD_SPAN:g} % in one); the colour bar always shows "
        "the range in force (five ticks) and how many cells are beyond it.",
        *(
            f"- **{SQRT_TABS[f.name]}** (not one of the paper's views): {f.title.split(',')[0].lower()} on a "
            "square-root scale, with the range of its linear tab: a cell's colour stands at √(value / range end) "
            "of the bar from its zero end, so the bulk of a field with a few extreme cells (a tall wall's joints "
            "after an impact) is not pale; the ticks are the values at evenly spaced colours (0, 1/16, 1/4, 9/16 "
            "and 1 × the range end)."
            for f in SQRT_FIELDS
        ),
        "",
        "| field | colour map | last range | refits |",
        "|---|---|---|---|",
    ]
    maps = {"signed": "blue–grey–red, zero grey", "negative": "blues, zero white", "positive": "viridis"}
    for f in FIELDS:
        r = field_ranges.get(f.key)
        rng = "none yet" if r is None else f"{r[0]:.4g} … {r[1]:.4g} {f.unit}"
        lines.append(f"| {f.title} | {maps[f.kind]} | {rng} | {changes.get(f.key, 0)} |")
    lines += [
        "",
        "## Versions",
        "",
        "| package | version |",
        "|---|---|",
        *(f"| {k} | {v} |" for k, v in _versions().items()),
    ]
    return "\n".join(lines) + "\n"


def _axes_legend(axes: tuple[float, float | None] | None) -> str:
    """The legend's line on the principal stress axes (the Live tab opens on them: the crosses in every block
    were explained in the Run panel alone, 40 rows down), empty without ``axes``."""
    if axes is None:
        return ""
    length, stress = axes
    scale = (
        "scale not fixed yet"
        if not stress
        else f"half-length {length:.3g} m at {tick_label(stress, 'Pa', stress, False)} (longer ones clipped)"
    )
    return (
        f"- **Principal stress axes** ({LIVE_TAB} and p tabs): a cross per block along the principal directions, "
        f"black = compression, magenta = tension; {scale}.\n"
    )


def _verdict_lines(result: object) -> list[str]:
    """The run's state and peak drift as the summary words them (``metadata["result"]``, set before the
    closing document), each a line; none before the run has ended or without them."""
    if not isinstance(result, dict):
        return []
    rows = (("State", result.get("state")), ("Peak drift", result.get("peak drift")))
    return [line for label, value in rows if value for line in (f"**{label}:** {value}", "")]


def parameters_markdown(metadata: dict) -> list[str]:
    """The Parameters table's lines (a run's document, a limit recording's panel): one row per dotted key."""
    rows = (f"| {k} | {v} |" for k, v in _flatten(metadata))
    return ["## Parameters", "", "| parameter | value |", "|---|---|", *rows]


def legend_markdown(
    force_scale: float | None,
    block_height: float,
    magnify: float | None,
    main_field: str = "cell_spherical_stress",
    paper_t: float | None = None,
    arrow_cap: float | None = None,
    magnified_fill: str = "",
    axes: tuple[float, float | None] | None = None,
) -> str:
    """The legend shown under the structure views (and in the run document): the tabs' short names first.
    ``arrow_cap``: the longest arrow drawn, m (a larger force is drawn that long; its value on hover).
    ``magnified_fill``: what the Magnified line says of a carried fill (``carried_fill.magnified_fill_note``).
    ``axes``: (half-length, m, of a principal stress axis at full length; |stress| there, Pa, None before
    the first loaded batch): given, a line on the principal stress axes the Live tab opens on."""
    scale = (
        "length proportional to the force, scale not fixed yet"
        if not force_scale
        else f"length {block_height:.3g} m (a median block height) per {block_height / force_scale / 1e3:.4g} kN"
    )
    if force_scale and arrow_cap:  # kept short: three lines of it pushed the Magnified line out of the panel
        scale += f", at most {arrow_cap:.3g} m ({arrow_cap / force_scale / 1e3:.4g} kN and up)"
    factor = "set when the run closes" if magnify is None else f"× {magnify:g}"
    return (
        f"{tabs_legend(main_field, paper_t)}\n"
        f"- **Joint forces** ({LIVE_TAB}, {FIELD_TABS['block_sliding_ratio']} and {FIELD_TABS['block_max_opening']} "
        "tabs): one arrow per joint, the resultant of its contact forces on the body above it, "
        f"centred on its point of application (line of thrust); {scale}. Green = sticking, "
        "orange = sliding, red = open at one end. Yellow dots: hinges.\n"
        f"{_axes_legend(axes)}"
        "- **Fills**: colour bar beside the structure; grey = undefined (NaN), magenta = below the range, "
        "lime green = above it. Small dark dots: block centroids (hover one: its name and values).\n"
        f"- **{MAGNIFIED_TAB}** deformed shape: displacements and rotations {factor}; grey = as built{magnified_fill}."
    )


LEGEND_LINE_CHARS: Final = 185
"""Characters of one line of the Legend panel at 1920 x 1080 (the structure column's 1150 px)."""


def legend_lines(legend: str) -> int:
    """Lines the Legend panel takes for ``legend`` at 1920 x 1080: each bullet wraps at LEGEND_LINE_CHARS."""
    bullets = [line.replace("**", "") for line in legend.splitlines() if line.strip()]
    return sum(math.ceil(len(b) / LEGEND_LINE_CHARS) for b in bullets)


_SAFE_EXTRA: Final = "–—‘’“”…·•×−≤≥≈°±²³µ√∞→✓∑ΔΣ"
_UNSAFE: Final = re.compile(f"[^\n\t\x20-\x7e\xa0-\u017f\u0370-\u045f{_SAFE_EXTRA}]")
"""One character the viewer's font may lack (the complement of the kept ranges and signs)."""


def viewer_safe_text(text: str) -> str:
    """``text`` with every character the viewer's font may lack replaced by "?".

    Rerun 0.41's viewer panics (the whole viewer dies) on a glyph its one bundled font (Inter) lacks,
    e.g. "∝" or CJK, in a document, label or hover text. Kept: ASCII, Latin-1, Latin Extended-A, Greek,
    basic Cyrillic and a few punctuation and math signs checked in the headless viewer.
    """
    return _UNSAFE.sub("?", text)


def _flatten(d: dict, prefix: str = "") -> list[tuple[str, str]]:
    """Nested metadata -> (dotted key, table-safe value) rows."""
    return [
        row
        for k, v in d.items()
        for row in (
            _flatten(v, f"{prefix}{k}.")
            if isinstance(v, dict)
            else [(f"{prefix}{k}", str(v).replace("|", "\\|").replace("\n", " "))]
        )
    ]


def _fmt_scale(x: float | None, unit: str) -> str:
    return "not fixed yet (zero so far)" if x is None else f"{x:.4g} {unit}".strip()


@functools.cache  # importlib.metadata scans the installed distributions: ~1 ms a call
def _versions() -> dict[str, str]:
    def dist(name: str) -> str:
        try:
            return importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            return "not installed"

    return {
        "masonry": MASONRY_VERSION,
        "rerun-sdk": rr.__version__,
        "numpy": np.__version__,
        "numba": dist("numba"),
        "python": platform.python_version(),
    }
