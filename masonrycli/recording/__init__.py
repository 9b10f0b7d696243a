"""Rerun recording of a run: the only package that imports rerun.

- ``recorder``: ``Recorder`` writes one run's ``.rrd`` from its frames; ``RecordingStatic`` is its input.
- ``scales`` (joint-resultant and glyph scales fixed once a run), ``reach`` (how far the drawing reached: the
  view at close) and ``run_panels`` (the Run panel and the Legend logged): the recorder's parts.
- ``batching``: when the recorder sends what it buffered (batch sizes, every second, steps' health).
- ``layout``: entity paths, field specs, colours, scale constants, the default blueprint, the paper's tabs.
- ``field_colours``: each field's colour range followed frame by frame, block colours and legend labels.
- ``document``: the run document (status, parameters, scales, versions) shown beside the views.
- ``static_content``: ``RecordingStatic`` and what is logged once (styles, drawing plane, colour bars).
- ``arrays``: posed polygons, Arrow line strips and the frame buffer behind ``send_columns``.
- ``fills`` and ``overlays``: what a batch of frames draws (the coloured block fills; glyphs, arrows, hinges).
- ``carried_fill``: a bridge's fill (soil, dead load) drawn over the blocks carrying it, moving with them.
- ``readback``: ``inspect_recording`` (summary of a file), ``recording_path_problem`` (another file, a missing path or a
  folder, in one line) and ``screenshot_recording`` (headless viewer).
- ``_rerun_private``: the only use of rerun's private API, kept small and explained there.
"""

import os

# Rerun's Rust side logs write failures as raw coloured lines on stderr; the recorder turns them into
# OSError and the command line into one line of its own. Set before rerun is first imported; a user's
# RUST_LOG wins.
os.environ.setdefault("RUST_LOG", "off")

from masonrycli.recording.document import viewer_safe_text  # noqa: E402
from masonrycli.recording.layout import (
    COMPRESSION_RGBA,
    ENTITY_PATHS,
    FIELDS,
    HINGE_RGBA,
    OPEN_RGBA,
    SLIP_RGBA,
    STICK_RGBA,
    TENSION_RGBA,
    FieldSpec,
    build_blueprint,
)
from masonrycli.recording.readback import inspect_recording, recording_path_problem, screenshot_recording
from masonrycli.recording.recorder import APPLICATION_ID, Recorder
from masonrycli.recording.static_content import RecordingStatic

__all__ = [
    "APPLICATION_ID",
    "COMPRESSION_RGBA",
    "ENTITY_PATHS",
    "FIELDS",
    "HINGE_RGBA",
    "OPEN_RGBA",
    "SLIP_RGBA",
    "STICK_RGBA",
    "TENSION_RGBA",
    "FieldSpec",
    "Recorder",
    "RecordingStatic",
    "build_blueprint",
    "inspect_recording",
    "recording_path_problem",
    "screenshot_recording",
    "viewer_safe_text",
]
