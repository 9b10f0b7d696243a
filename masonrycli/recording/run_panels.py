"""The two text panels of a recording, logged static and logged again as the run goes: the Run panel (the run
document: status, parameters, scales, versions; ``document.run_document``) and the Legend (what the colours,
arrows, glyphs and tabs mean; ``document.legend_markdown``, a bridge's fill: ``carried_fill.fill_legend``).
Each text is filtered to the characters the viewer's font has (``document.viewer_safe_text``)."""

from __future__ import annotations

from dataclasses import dataclass

import rerun as rr

from masonrycli.recording.carried_fill import fill_legend, magnified_fill_note
from masonrycli.recording.document import legend_lines, legend_markdown, run_document, viewer_safe_text
from masonrycli.recording.layout import LEGEND, METADATA


@dataclass(frozen=True)
class PanelFacts:
    """What the panels say about a run at one moment (the ``Recorder``'s state then)."""

    last: tuple[int, float] | None  # (step, time s) of the last frame
    wall_time: float  # s since the recorder opened
    frames: int
    dt: float
    friction: float
    blocks: int
    supports: int
    force_scale: float | None  # m per N of the joint resultants
    block_height: float  # m
    glyph_length: float  # m
    axis_scale: dict
    field_ranges: dict
    range_changes: dict
    magnify: float | None
    main_field: str
    paper_t: float | None  # s, the paper's figures' instant when the recording has their tabs
    resultant_cap: float  # m, the longest arrow drawn
    fill_load_n: float  # N, a bridge's fill's dead load (0: none)
    fill_drawn: bool  # the fill's columns are drawn


def log_run_panels(rec: rr.RecordingStream, metadata: dict, status: str, note: str, facts: PanelFacts) -> int:
    """Log the Run panel and the Legend; returns the Legend's lines (``document.legend_lines``: its panel's
    height at close, ``layout.legend_share``)."""
    f = facts
    text = run_document(
        metadata,
        status,
        note,
        last=f.last,
        wall_time=f.wall_time,
        frames=f.frames,
        dt=f.dt,
        friction=f.friction,
        blocks=f.blocks,
        supports=f.supports,
        force_scale=f.force_scale,
        block_height=f.block_height,
        glyph_length=f.glyph_length,
        axis_scale=f.axis_scale,
        field_ranges=f.field_ranges,
        range_changes=f.range_changes,
        magnify=f.magnify,
    )
    rec.log(METADATA, rr.TextDocument(viewer_safe_text(text), media_type="text/markdown"), static=True)
    args = (f.force_scale, f.block_height, f.magnify, f.main_field, f.paper_t, f.resultant_cap)
    axes = (f.glyph_length, f.axis_scale.get("stress_axes"))
    legend = legend_markdown(*args, magnified_fill_note(f.fill_load_n, f.fill_drawn), axes=axes)
    # the blocks' one thickness; a file's blocks of several give [least, greatest] (execute.run_metadata), for
    # which no "per metre of width" holds: none said (a list here ended the run in a TypeError at close)
    thickness = metadata.get("thickness_m")
    legend += fill_legend(f.fill_load_n, thickness if isinstance(thickness, (int, float)) else None, f.fill_drawn)
    rec.log(LEGEND, rr.TextDocument(viewer_safe_text(legend), media_type="text/markdown"), static=True)
    return legend_lines(legend)
