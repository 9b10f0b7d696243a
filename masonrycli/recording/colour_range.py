"""Colour ranges that follow the data while a run is recorded (numpy only).

A recording is written while the run progresses, so a field's colour range cannot wait for the last
frame. ``RangeTracker`` keeps one range per field and checks it against every recorded frame; it is
refitted to that frame (and the new range logged from that frame on) only when the frame breaks one
of two rules:

* **coverage** — at most ``OUTSIDE_SHARE`` (2 %) of the frame's defined cells lie outside the range;
* **use** — the frame's *bulk* spans at least ``MIN_SPAN`` of the range: its defined cells from the lowest to
  the highest once the ``BULK_TRIM`` (1 %) most extreme of them at each end are left out (rounded down). A
  range fitted to a violent moment must not flatten the quiet frames after it, nor a quiet start the growth
  that follows; and a few extreme cells (an impact's, a hinge's) must not hold a range the other cells use a
  sliver of. Until 2026-11-29 the span ran from the frame's min to its max: on the 64-course wall one cell
  kept the p range at −2.5 MPa after an impact while 99 % of the cells lay above −0.77 MPa (median −35 kPa).
  The cells left out are at most the 2 % the coverage rule lets lie outside, half at each end, and lie at
  or beyond the cells a refit keeps inside, so a fresh refit keeps the use rule (the rounding below aside):
  a quantile rule that left out more (say 10 %) would fail right after its own refits on a heavy-tailed
  field and refit frame after frame.

  On a **signed** scale (the volumetric strain rate) one frame whose bulk spans less than ``MIN_SPAN`` but at
  least ``HOLD_SPAN`` (35 %) keeps the range; the second such frame in a row refits it (``SHRINK_AFTER``). The
  rate is the noisiest field: on the settled aqueduct (2 s) the top percent of its cells (the hinges) halves
  and doubles from frame to frame, and the range shrank at one frame to grow back at the next — 44 refits in
  200 frames, 26 with the hold (5 s: 96 -> 73), the share of frames with half the cells in the palest tenth
  unchanged (100 %; the same on wall-248, the shaken aqueduct and the arch; wall-51 83 -> 84 %), the ranges at
  the paper's instants unchanged (walls 0.1 s, arch and aqueduct 5 s). On the one-sided stress scales the same
  hold kept ranges fitted to a peak through the frames after it: the shaken aqueduct's p had half its cells in
  the palest tenth in 85 % of its frames instead of 75 %, so they refit at the first short frame as before.

A refit leaves at most ``OUTSIDE_SHARE`` of the cells outside (rounded down, so a frame of fewer than 50
cells keeps every cell inside): on a one-sided scale all at its far end, on a signed one half at each end;
it rounds the ends outwards to 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k, which leaves some
headroom, so a range typically holds for many frames. A range never shrinks below the field's
``floor`` (a physical magnitude below which the values are noise: a still structure is not coloured
by its round-off). Every frame therefore satisfies both rules (a signed one's short frames spanning at least
``HOLD_SPAN``), except where the floor applies or the frame allows no range that does (its cells all about equal).

Three kinds of scale (``ScaleKind``):

* ``"negative"`` — values ≤ 0 (the spherical stress p, compression negative): one-sided, [lo, 0];
* ``"positive"`` — values ≥ 0 (deviatoric parts): one-sided, [0, hi];
* ``"signed"`` — both signs (volumetric strain rate): diverging about 0 with independent ends lo < 0 < hi,
  each half of the colour map stretched over its own side (zero stays the middle colour).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final, Literal

import numpy as np

from masonrycli.recording.colormap import nice_ceil

ScaleKind = Literal["negative", "positive", "signed"]
Scale = Literal["linear", "sqrt"]

OUTSIDE_SHARE: Final = 0.02
"""Largest share of a frame's defined cells allowed outside the logged range."""
MIN_SPAN: Final = 0.45
"""Smallest share of the range the frame's bulk must span (see ``BULK_TRIM``; clipped to the range)."""
BULK_TRIM: Final = OUTSIDE_SHARE / 2
"""Share of a frame's defined cells left out at each end (rounded down) of the span the use rule measures:
a few extreme cells (an impact's) cannot hold a range the other cells use a sliver of."""
SHRINK_AFTER: Final = {"signed": 2, "negative": 1, "positive": 1}
"""Frames in a row whose bulk spans less than ``MIN_SPAN`` (but at least ``HOLD_SPAN``) of the range before it is
refitted, per kind of scale: a signed field (the volumetric strain rate) keeps its range through one such frame."""
HOLD_SPAN: Final = 0.35
"""Below this share of the range a frame's bulk refits the range at once, whatever ``SHRINK_AFTER`` allows."""
SIGNED_MIN_SIDE: Final = 0.1
"""On a signed scale, neither side is shorter than this fraction of the other (zero stays readable)."""


@dataclass(frozen=True)
class ColourRange:
    """One field's colour range: [lo, hi], lo ≤ 0 ≤ hi for every kind."""

    kind: ScaleKind
    lo: float
    hi: float

    def position(self, values: np.ndarray) -> np.ndarray:
        """Where each value sits on the colour map, 0 (lo) … 1 (hi); < 0 or > 1 outside; NaN stays NaN.

        Signed: [lo, 0] → [0, ½] and [0, hi] → [½, 1] (zero is the middle colour).
        """
        return positions(self.kind, values, self.lo, self.hi)

    def ticks(self, count: int = 5, scale: Scale = "linear") -> np.ndarray:
        """``count`` (odd) tick values at evenly spaced colour positions on ``scale``, lo first; zero is one
        of them (on the square-root scale the ticks of [−800, 0] kPa are −800, −450, −200, −50, 0)."""
        t = np.linspace(0.0, 1.0, count)
        if scale == "sqrt":
            t = sqrt_scale(self.kind, t, inverse=True)
        if self.kind == "signed":
            return np.where(t < 0.5, self.lo * (1.0 - 2.0 * t), self.hi * (2.0 * t - 1.0))
        return self.lo + t * (self.hi - self.lo)

    def outside(self, values: np.ndarray) -> tuple[int, int, int]:
        """(cells below lo, cells above hi, defined cells) of one frame."""
        v = np.asarray(values, dtype=np.float64).ravel()
        v = v[np.isfinite(v)]
        return int((v < self.lo).sum()), int((v > self.hi).sum()), int(v.size)

    def span(self, values: np.ndarray) -> float:
        """Share of the range covered by the frame's bulk (:func:`bulk_ends`), clipped to [lo, hi] (0 if no cell)."""
        bottom, top, defined = bulk_ends(np.reshape(values, (1, -1)))
        if defined[0] == 0:
            return 0.0
        return float((min(top[0], self.hi) - max(bottom[0], self.lo)) / (self.hi - self.lo))


def bulk_ends(frames: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per row of ``frames`` (F, C): the lowest and highest value of its bulk — its defined cells less the
    ``BULK_TRIM`` share of them (rounded down) at each end — and its count of defined cells, (F,) each;
    +inf and −inf for a row without a defined cell."""
    v = np.asarray(frames, dtype=np.float64)
    v = np.where(np.isfinite(v), v, np.nan)
    defined = np.isfinite(v).sum(axis=1)
    if v.shape[1] == 0:
        return np.full(len(v), np.inf), np.full(len(v), -np.inf), defined
    trim = np.floor(BULK_TRIM * defined).astype(np.int64)
    if (defined == v.shape[1]).all():  # every cell defined (the usual batch): the two ranks alone, not a sort
        ranks = np.unique([trim[0], max(v.shape[1] - 1 - int(trim[0]), 0)])
        ordered = np.partition(v, ranks, axis=1)  # the same values at those ranks as a sort puts there
    else:
        ordered = np.sort(v, axis=1)  # NaN sort last: a row's defined cells are its first `defined`
    rows = np.arange(len(v))
    bottom = np.where(defined > 0, ordered[rows, trim], np.inf)
    top = np.where(defined > 0, ordered[rows, np.maximum(defined - 1 - trim, 0)], -np.inf)
    return bottom, top, defined


def positions(kind: ScaleKind, values: np.ndarray, lo, hi) -> np.ndarray:
    """:meth:`ColourRange.position` with ``lo`` and ``hi`` that may be arrays broadcast against ``values``
    (one range per frame of a batch): the same element-wise arithmetic, hence the same numbers."""
    v = np.asarray(values, dtype=np.float64)
    if kind == "signed":
        with np.errstate(invalid="ignore"):
            return np.where(v < 0.0, 0.5 - 0.5 * v / lo, 0.5 + 0.5 * v / hi)
    return (v - lo) / (hi - lo)


def _zero_position(kind: ScaleKind) -> tuple[float, float]:
    """(the colour position of zero, the length of the map on one side of it) for a ``kind`` of scale."""
    return {"negative": (1.0, 1.0), "positive": (0.0, 1.0), "signed": (0.5, 0.5)}[kind]


def sqrt_scale(kind: ScaleKind, position: np.ndarray, inverse: bool = False) -> np.ndarray:
    """Linear colour positions (:func:`positions`) → positions on the signed square-root scale, where a value
    sits at √(|value| / |range end on its side|) of the map from zero, towards that end; ``inverse``: back.

    Zero stays where it is (white on the blues, grey in the middle of the diverging map) and the ends stay
    the range's ends; a value beyond an end stays beyond it (below 0 or above 1), NaN stays NaN. A stress field
    with a few joints at MN and the bulk of the cells at tens of kPa (a tall wall after an impact) has its median
    at 1/20 of the linear map, next to white; at √(1/20) ≈ 0.22 of this one.
    """
    zero, side = _zero_position(kind)
    d = (np.asarray(position, dtype=np.float64) - zero) / side  # signed share of the side, ±1 at the ends
    mapped = np.square(d) if inverse else np.sqrt(np.abs(d))
    with np.errstate(invalid="ignore"):  # NaN keeps its NaN sign
        return zero + side * np.sign(d) * mapped


def nice_floor_negative(x: float) -> float:
    """−nice_ceil(−x) for x < 0: the nice number at or below x."""
    return -nice_ceil(-x)


def fit_range(values: np.ndarray, kind: ScaleKind, floor: float) -> ColourRange:
    """The range a refit gives for one frame (see the module docstring); ``floor`` > 0 in the field's unit."""
    v = np.sort(np.asarray(values, dtype=np.float64).ravel())
    v = v[np.isfinite(v)]
    budget = int(math.floor(OUTSIDE_SHARE * v.size))
    if kind == "positive":
        wrong_side = int((v < 0.0).sum())  # counted outside whatever the range
        keep = max(budget - wrong_side, 0)
        top = v[v.size - 1 - keep] if v.size else 0.0
        return ColourRange(kind, 0.0, nice_ceil(max(top, floor)))
    if kind == "negative":
        wrong_side = int((v > 0.0).sum())
        keep = max(budget - wrong_side, 0)
        bottom = v[keep] if v.size else 0.0
        return ColourRange(kind, -nice_ceil(max(-bottom, floor)), 0.0)
    low_budget = budget // 2
    bottom = v[low_budget] if v.size else 0.0
    top = v[v.size - 1 - (budget - low_budget)] if v.size else 0.0
    lo_mag, hi_mag = max(-bottom, floor), max(top, floor)
    lo_mag, hi_mag = max(lo_mag, SIGNED_MIN_SIDE * hi_mag), max(hi_mag, SIGNED_MIN_SIDE * lo_mag)
    return ColourRange(kind, -nice_ceil(lo_mag), nice_ceil(hi_mag))


class RangeTracker:
    """The colour range of one field over a run, checked against every frame (module docstring).

    >>> tracker = RangeTracker("positive", floor=1e-6)
    >>> r = tracker.update(np.array([0.0, 0.3, 0.9]))   # first frame: fitted, [0, 1]
    >>> tracker.update(np.array([0.0, 0.5, 0.8])) is r  # still covers and is used: kept
    True
    """

    def __init__(self, kind: ScaleKind, floor: float) -> None:
        if not floor > 0.0:
            raise ValueError(f"floor must be > 0, got {floor!r}")
        self.kind, self.floor = kind, float(floor)
        self.current: ColourRange | None = None
        self.changes = 0
        """How many times the range was (re)fitted."""
        self.short = 0
        """Frames in a row, up to the last one, kept although their bulk spanned less than ``MIN_SPAN``."""

    def update(self, values: np.ndarray) -> ColourRange:
        """The range for this frame: the current one if the frame keeps both rules, else a refit."""
        r = self.current
        if r is None or not self._holds(r, values):
            return self._refit(values)
        return r

    def _refit(self, values: np.ndarray) -> ColourRange:
        self.short = 0
        fitted = fit_range(values, self.kind, self.floor)
        if fitted != self.current:
            self.current, self.changes = fitted, self.changes + 1
        return self.current

    def follow(self, frames: np.ndarray) -> tuple[list[ColourRange], np.ndarray, np.ndarray]:
        """:meth:`update` on each row of ``frames`` (F, ...) in turn: the range of every frame, and its
        cells below and above that range (as :meth:`ColourRange.outside`), (F,) int each.

        The same ranges as F calls of ``update``, but both rules are checked on all the frames a range
        holds for at once: a batch costs a few numpy calls per refit instead of a dozen per frame.
        """
        v = np.asarray(frames, dtype=np.float64).reshape(len(frames), -1)
        n_frames = len(v)
        finite = np.isfinite(v)
        bottom, top, defined = bulk_ends(v)
        budget = np.floor(OUTSIDE_SHARE * defined)
        ranges: list[ColourRange] = []
        below = np.zeros(n_frames, dtype=np.int64)
        above = np.zeros(n_frames, dtype=np.int64)
        k, window = 0, 4
        while k < n_frames:
            r = self.current
            while r is not None and k < n_frames:  # the frames from k on that keep both rules with r
                # A window that doubles while the range holds: refits early in a run come every few
                # frames, later ones rarely.
                w = slice(k, min(k + window, n_frames))
                lo_count = ((v[w] < r.lo) & finite[w]).sum(axis=1)
                hi_count = ((v[w] > r.hi) & finite[w]).sum(axis=1)
                with np.errstate(invalid="ignore"):  # frames without a defined cell: inf − inf
                    span = (np.minimum(top[w], r.hi) - np.maximum(bottom[w], r.lo)) / (r.hi - r.lo)
                covered = lo_count + hi_count <= budget[w]
                used = (defined[w] == 0) | (span >= MIN_SPAN)
                # a frame of a short bulk (HOLD_SPAN <= span < MIN_SPAN) is kept while it is at most the
                # SHRINK_AFTER - 1st of such frames in a row (the run carried over from the frames before)
                short = ~used & (span >= HOLD_SPAN)
                at = np.arange(len(short))
                last_other = np.maximum.accumulate(np.where(short, -1, at))
                run = np.where(last_other < 0, at + 1 + self.short, at - last_other)
                holds = covered & (used | (short & (run < SHRINK_AFTER[self.kind])))
                held = int(np.argmin(holds)) if not holds.all() else len(holds)
                ranges += [r] * held
                below[k : k + held], above[k : k + held] = lo_count[:held], hi_count[:held]
                if held:
                    self.short = int(run[held - 1]) if short[held - 1] else 0
                k += held
                if held < len(holds):
                    window = 4
                    break
                window *= 2
            if k == n_frames:
                break
            r = self._refit(v[k])  # a frame that breaks a rule (or the first one)
            ranges.append(r)
            below[k], above[k], _ = r.outside(v[k])
            k += 1
        return ranges, below, above

    def _holds(self, r: ColourRange, values: np.ndarray) -> bool:
        below, above, defined = r.outside(values)
        if below + above > math.floor(OUTSIDE_SHARE * defined):
            return False
        span = r.span(values) if defined else 1.0
        if span >= MIN_SPAN:
            self.short = 0
            return True
        if span >= HOLD_SPAN and self.short + 1 < SHRINK_AFTER[self.kind]:
            self.short += 1
            return True
        return False
