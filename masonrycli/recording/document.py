"""The run document: the Markdown page shown beside the views (status, parameters, scales, versions).

Rewritten whenever a scale is fixed and when the recorder closes; the last one logged wins. Every text
that reaches the viewer goes through ``viewer_safe_text``.
"""

from __future__ import annotations

import importlib.metadata
import platform
from typing import Final

import numpy as np
import rerun as rr

from masonrycli import __version__ as MASONRY_VERSION
from masonrycli.recording.layout import ARROW_CAP, AXES, FIELDS, ROBUST_PERCENTILE


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
) -> str:
    """Markdown of the run document.

    ``last``: (step, time) of the last frame logged, None before the first; ``wall_time``: s since the
    recording was opened; ``force_scale`` (m per N), ``axis_scale`` (glyph set -> |λ| at full length) and
    ``field_ranges`` as fixed so far by the recorder.
    """
    line = status
    if last is not None:
        at = f"t = {last[1]:.3f} s (step {last[0]})"
        line = f"{status}, last frame {at}" if status in ("completed", "running") else f"{status} at {at}"
    if note:  # the caller's note usually says it all ("interrupted at t = ..."): do not repeat it
        line = note if note.startswith(status) else f"{line}: {note}"
    pct = f"{ROBUST_PERCENTILE:g}th percentile"
    lines = [
        f"# masonry — {metadata.get('scenario', 'run')}",
        "",
        f"**Status:** {line}",
        "",
        f"**Wall time:** {wall_time:.2f} s · **frames:** {frames} · "
        f"**dt:** {dt:g} s · **friction:** {friction:g} · "
        f"**blocks:** {blocks} · **supports:** {supports}",
        "",
        "## Parameters",
        "",
        "| parameter | value |",
        "|---|---|",
        *(f"| {k} | {v} |" for k, v in _flatten(metadata)),
        "",
        "## How to read the views",
        "",
        "- **Forces**: arrow = contact force on body b at the contact point; green = stick, orange = "
        f"slip. Scale {_fmt_scale(force_scale, 'm per N')}: a force of the first batch's {pct} is "
        f"one median block height ({block_height:.3g} m) long; arrows are capped at {ARROW_CAP:g} "
        "block heights (hover an arrow for its force in N). Yellow dots: hinges.",
        "- **Principal axes**: two segments per cell along the eigenvectors, half-length proportional "
        f"to |λ|, {glyph_length:.3g} m at the value below (longer ones clipped); black = "
        "compression / contraction, magenta = tension / extension. Stress axes in the main view; "
        "strain-rate axes and the centroid triangulation in the volumetric strain rate view.",
        *(f"  - {n.replace('_', ' ')}: full length at |λ| = {_fmt_scale(axis_scale.get(n), '')}" for n in AXES),
        "- **Fields**: each colour range is fixed for the whole run, at the first batch where the field "
        f"is not zero ({pct} of |value|, rounded up); values beyond take the end colours; grey = "
        "undefined (NaN). Hover a block outline for its values.",
        "",
        "| field | colour map | range |",
        "|---|---|---|",
    ]
    for f in FIELDS:
        r = field_ranges.get(f.key)
        rng = "not fixed yet (zero so far)" if r is None else f"{r[0]:.4g} … {r[1]:.4g} {f.unit}"
        lines.append(f"| {f.title} | {'blue–grey–red' if f.signed else 'viridis'} | {rng} |")
    lines += [
        "",
        "## Versions",
        "",
        "| package | version |",
        "|---|---|",
        *(f"| {k} | {v} |" for k, v in _versions().items()),
    ]
    return "\n".join(lines) + "\n"


_SAFE_EXTRA: Final = frozenset("–—‘’“”…·•×−≤≥≈°±²³µ√∞→✓∑ΔΣ")


def viewer_safe_text(text: str) -> str:
    """``text`` with every character the viewer's font may lack replaced by "?".

    Rerun 0.41's viewer panics (the whole viewer dies) on a glyph its one bundled font (Inter) lacks,
    e.g. "∝" or CJK, in a document, label or hover text. Kept: ASCII, Latin-1, Latin Extended-A, Greek,
    basic Cyrillic and a few punctuation and math signs checked in the headless viewer.
    """

    def ok(c: str) -> bool:
        o = ord(c)
        return c in "\n\t" or 0x20 <= o < 0x7F or 0xA0 <= o < 0x180 or 0x370 <= o < 0x460 or c in _SAFE_EXTRA

    return "".join(c if ok(c) else "?" for c in text)


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
