"""The colour of each tensor field: its range followed frame by frame, block colours, legend labels.

One :class:`FieldColours` per recording. A field's range (``masonrycli.recording.colour_range.RangeTracker``) is refitted
when the data leave it or shrink well inside it; each range's tick labels are made once, since a range
holds for many frames. No rerun here: the recorder sends what this computes.
"""

from __future__ import annotations

import numpy as np

from masonrycli.recording.colormap import map_positions, tick_label
from masonrycli.recording.colour_range import RangeTracker, positions, sqrt_scale
from masonrycli.recording.document import viewer_safe_text
from masonrycli.recording.layout import FieldSpec
from masonrycli.recording.static_content import LUTS, TICKS


class FieldColours:
    """Range trackers and tick labels of ``fields`` (a tuple of :class:`FieldSpec`)."""

    def __init__(self, fields) -> None:
        self._trackers = {f.key: RangeTracker(f.kind, f.floor) for f in fields if f.scale == "linear"}
        self._batch: dict[str, tuple] = {}  # field key -> its last batch's (ranges, below, above)
        self._labels: dict[tuple[str, object], list[str]] = {}  # (field, range) -> tick labels
        self.field_ranges: dict[str, tuple[float, float]] = {}
        """The range each field has at the last frame coloured."""

    def range_changes(self) -> dict[str, int]:
        """How often each field's range was refitted."""
        return {k: t.changes for k, t in self._trackers.items()}

    def colour(self, f: FieldSpec, values: np.ndarray, initial: int = 0, times=None):
        """Per frame: the range (tracked), block colours (F, N), legend labels, range ends (F,) each.

        ``times`` (F,) s: the bar's title says the frame's instant ("Spherical stress p, t = 0.100 s"): the
        quick start opens on the paper's Fig. III.2 pinned at 0.1 s, its time line at 1.000 s, and nothing on
        the view said which instant it showed (the Legend, below, did); a live tab's title runs with the time.

        The ``initial`` first frames (the state as built, before the first step: NaN stresses, zero strains)
        take the range of the frame after them and are not shown to the tracker: fitted to them, the range
        was refitted at the first computed frame, one refit more per field saying nothing.

        A field on the square-root scale (``f.scale``) takes the ranges of its linear twin's batch, which
        must be coloured first (``layout.COLOURED`` order): one range per field, whatever its views."""
        if f.scale != "linear":
            ranges, below, above = self._batch[f.key]
        else:
            ranges, below, above = self._follow(f, values, initial)
            self._batch[f.key] = ranges, below, above
        lo = np.array([r.lo for r in ranges])
        hi = np.array([r.hi for r in ranges])
        per_frame = (-1,) + (1,) * (values.ndim - 1)
        position = positions(f.kind, values, lo.reshape(per_frame), hi.reshape(per_frame))
        if f.scale == "sqrt":
            position = sqrt_scale(f.kind, position)
        colors = map_positions(position, LUTS[f.kind])
        title = viewer_safe_text(f.title)
        titles = [title] * len(ranges) if times is None else [f"{title}, t = {t:.3f} s" for t in times]
        labels: list[str] = []
        ticks, last = [], None
        for r, n_below, n_above, name in zip(ranges, below.tolist(), above.tolist(), titles):
            if r is not last:  # a range holds for many frames
                ticks, last = self._tick_labels(f, r), r
            labels += ticks
            labels += [name, f"{n_below} below" if n_below else "", f"{n_above} above" if n_above else ""]
        if f.scale == "linear":
            self.field_ranges[f.key] = (float(lo[-1]), float(hi[-1]))
        return colors, labels, lo, hi

    def _follow(self, f: FieldSpec, values: np.ndarray, initial: int):
        """The tracked ranges of a batch and its cells below / above them (:meth:`colour`'s ``initial``)."""
        tracker = self._trackers[f.key]
        if 0 < initial < len(values):
            ranges, below, above = tracker.follow(values[initial:])
            first = [ranges[0].outside(v)[:2] for v in values[:initial]]
            ranges = [ranges[0]] * initial + ranges
            below = np.concatenate([np.array([c[0] for c in first], dtype=below.dtype), below])
            above = np.concatenate([np.array([c[1] for c in first], dtype=above.dtype), above])
        else:  # a batch of the initial frame alone (a run stopped in its first step): fitted to it
            ranges, below, above = tracker.follow(values)
        return ranges, below, above

    def _tick_labels(self, f: FieldSpec, r) -> list[str]:
        """The legend's tick labels of range ``r`` (a range holds for many frames: made once per range)."""
        labels = self._labels.get((f.name, r))
        if labels is None:
            span = max(-r.lo, r.hi)
            labels = [tick_label(v, f.unit, span, f.kind == "signed") for v in r.ticks(TICKS, f.scale)]
            self._labels[(f.name, r)] = labels
        return labels
