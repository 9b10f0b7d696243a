"""A ground-motion record as a support motion: :class:`Record`, the ``record`` kind of :mod:`masonrycli.scenario.motion`.

A tabulated velocity or acceleration history (earthquake record). ``time`` (n,) s; ``value`` either n
numbers applied along d̂ (``direction``) or n (x, y) pairs, kept as read-only float64 arrays (a 3-million-
sample record as Python tuples cost 0.7 s of start-up). Values are multiplied by ``scale``; ``quantity``
says whether they are velocities (interpolated linearly) or accelerations (integrated exactly,
``baseline`` drift-corrected); ``window = [a, b]`` uses only the samples with a <= t <= b, moved to start
at t = 0. How: :mod:`masonrycli.records.velocity`. Record files are read in :mod:`masonrycli.records.read`;
:func:`time_step_problem` checks a one-column file's time step (there and for ``--record-dt``).

What sets it apart from the closed-form kinds: its samples are checked (an error names the sample),
compared as arrays (the hash takes their ends), pickled for a study's workers without the prepared
arrays, and it tells the run document and the scenario warnings its start and end times, peak
acceleration, sample interval and the baseline correction it subtracted.

Units: m/s, m/s², s.
"""

from __future__ import annotations

import dataclasses
import functools
import os
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from geometry_library.values import number_problem
from masonrycli.errors import InputError
from masonrycli.records.velocity import RecordArrays, correction_acceleration, record_arrays, record_velocity
from masonrycli.scenario.motion import Motion, _Directed, _direction, _g, _put, _time_column, _vec
from masonrycli.scenario.values import check_real, check_samples, check_vector, field_error, format_value

RECORD_QUANTITIES = ("velocity", "acceleration")
BASELINES = ("quadratic", "none")
BASELINE_PROBLEM = 'must be "quadratic" or "none"'
"""Why a ``baseline`` is refused: the scenario file's key and ``--baseline`` say it alike."""


def unused_baseline(baseline: str | None, records: dict, option: str = "--baseline", given: str = "") -> list[str]:
    """The warnings for an explicit ``baseline`` (None: not given) over ``records`` (name -> :class:`Record`)
    of which some are velocity records: their samples are used as given, never corrected (the drift the
    correction takes out is the integration's, and a velocity record is not integrated; one that does not
    end at rest is its own motion, a shake table's). It did nothing there without a word. ``quadratic``
    with no acceleration record among them asks for what cannot be made: :class:`InputError` (exit 2),
    rather than a run of a motion other than the one asked for; ``none`` runs as asked, with a line saying
    the option had no bearing; over a mixed set ``quadratic`` names the velocity records it leaves as given.
    ``given``: how the lines name the setting (default ``--baseline quadratic``; a scenario file's
    ``baseline = "quadratic"``)."""
    velocity = [name for name, record in records.items() if record.quantity == "velocity"]
    if baseline is None or not velocity:
        return []
    given = given or f"{option} {baseline}"
    names = ", ".join(velocity[:3]) + (" …" if len(velocity) > 3 else "")
    plural = len(velocity) > 1
    kind = f"{'are velocity records' if plural else 'is a velocity record'}, used as given"
    if len(velocity) < len(records):  # none: every record as given, as asked
        return [f"{given}: {names} {kind}; it corrects the acceleration records"] if baseline == "quadratic" else []
    if baseline == "quadratic":
        raise InputError(
            f"{given}: {names} {kind}: the drift correction is of acceleration records, which are "
            f"integrated (leave {option} out)"
        )
    return [f"{given}: {names} {kind} whatever {option} says (it applies to acceleration records)"]


MIN_TIME_STEP, MAX_TIME_STEP = 1e-6, 1.0
"""s: the sample spacing a one-column record may be given (accelerographs sample at 50-1000 Hz): beyond 1 s
a likely typo (10 for 10 ms stretched the record 1000-fold), below 1 µs no accelerogram."""


MAX_ACCELEROGRAM_STEP = 0.1
"""s: the coarsest sample spacing of an acceleration record whose header gives it (an .AT2 file's DT, K-NET's
Sampling Freq, ESM's SAMPLING_INTERVAL_S). Sampled every 0.1 s, a record holds nothing above 5 Hz (its Nyquist
frequency), where the ground acceleration of an earthquake carries much of its energy (up to 10-25 Hz) and a
wall's rocking and a stone's impacts lie: accelerographs sample at 50-200 Hz (DT 0.005-0.02 s; 0.04 s in the
oldest digitised records). An .AT2 file's DT of 10 s was read as a record of 70 s whose peaks a run of 0.5 s
interpolated linearly, with a warning about its length only: a typo or a damaged header, never a record."""


def time_step_problem(value, acceleration: bool = False) -> str | None:
    """What is wrong with ``value`` as the time step of a record (s), or None: a one-column record's
    (``--record-dt``, a velocity or an acceleration), or with ``acceleration`` that of an accelerogram's header
    (at most :data:`MAX_ACCELEROGRAM_STEP`)."""
    problem = number_problem(value, gt=0.0, unit="s")
    if problem is None and not MIN_TIME_STEP <= float(value) <= MAX_TIME_STEP:
        problem = (
            f"must be within {MIN_TIME_STEP:g}–{MAX_TIME_STEP:g} s, likely a typo (accelerographs sample every "
            "1–20 ms; 10 for 10 ms would stretch the record 1000-fold)"
        )
    if problem is None and acceleration and float(value) > MAX_ACCELEROGRAM_STEP:
        problem = (
            f"an acceleration record sampled every {float(value):g} s holds nothing above {0.5 / float(value):.3g} Hz, "
            f"where earthquakes shake and walls rock (accelerographs sample every 5–20 ms): at most "
            f"{MAX_ACCELEROGRAM_STEP:g} s, so a typo or a damaged header"
        )
    return problem


@dataclass(frozen=True, kw_only=True, eq=False)
class Record(_Directed, Motion):
    """A tabulated velocity or acceleration history (see :mod:`masonrycli.records.velocity`).

    time : (n,) s, strictly increasing, n >= 2; kept as a read-only float64 array.
    value : n floats (along ``direction``) or n (x, y) pairs, m/s or m/s² (before ``scale``); kept as a
        read-only float64 array (n,) or (n, 2).
    direction : (dx, dy) axis of a 1-component record; normalised on use.
    quantity : "velocity" | "acceleration" — what ``value`` holds.
    scale : multiplies ``value``.
    window : (a, b) s, or None — the part of the record used, moved to start at t = 0.
    baseline : "quadratic" | "none" — drift correction of acceleration records.
    source : where the record came from (absolute file path, or "" for inline data).
    vertical_source : file of the vertical component (then ``value`` holds (x, y) pairs), or "".
    time_step : s, the spacing of a one-column file's samples (``time`` is then 0, time_step, 2 time_step,
        …), or None: the samples came with their times.

    Equal records have equal fields, the samples compared as arrays; the hash takes their ends only.
    """

    time: np.ndarray = ()
    value: np.ndarray = ()
    direction: tuple[float, float] = (1.0, 0.0)
    quantity: str = "velocity"
    scale: float = 1.0
    window: tuple[float, float] | None = None
    baseline: str = "quadratic"
    source: str = ""
    vertical_source: str = ""
    time_step: float | None = None

    kind: ClassVar[str] = "record"
    TOML_KEYS: ClassVar[tuple[str, ...]] = (
        "kind",
        "file",
        "vertical",
        "time_step",
        "time",
        "value",
        "quantity",
        "scale",
        "direction",
        "window",
        "baseline",
    )

    def __post_init__(self):
        _direction(self)
        if self.quantity not in RECORD_QUANTITIES:
            raise field_error("quantity", self.quantity, 'must be "velocity" or "acceleration"')
        _put(self, "scale", check_real("scale", self.scale))
        if self.baseline not in BASELINES:
            raise field_error("baseline", self.baseline, BASELINE_PROBLEM)
        for key in ("source", "vertical_source"):
            if not isinstance(getattr(self, key), str):
                raise field_error(key, getattr(self, key), "must be a string")
        if self.time_step is not None:
            problem = time_step_problem(self.time_step)
            if problem:
                raise field_error("time_step", self.time_step, problem)
            _put(self, "time_step", float(self.time_step))
        time, value = self.time, self.value
        if not all(isinstance(x, (list, tuple)) or (isinstance(x, np.ndarray) and x.ndim) for x in (time, value)):
            raise field_error("time", time, "time and value must be sequences")
        if len(time) < 2:
            raise field_error("time", time, f"a record needs at least 2 samples, got {len(time)}")
        if len(value) != len(time):
            raise field_error("value", value, f"has {len(value)} samples but time has {len(time)}")
        t = check_samples("time", time)
        later = t[1:] > t[:-1]
        if not later.all():
            i = int(np.argmin(later)) + 1
            raise field_error(f"time[{i}]", t[i], f"must be > the previous time {format_value(t[i - 1])}")
        # the first sample says which: [x, y] pairs, or numbers along the direction (judged from all of
        # them, [1.0, "b"] blamed value[0] = 1.0 for not being 2 numbers [x, y])
        v = check_samples("value", value, pairs=isinstance(value[0], (list, tuple, np.ndarray)))
        if self.time_step is not None and not np.array_equal(t, np.arange(t.size) * self.time_step):
            raise field_error("time_step", self.time_step, "the times are not 0, time_step, 2 time_step, ...")
        _put(self, "time", t)
        _put(self, "value", v)
        if self.window is not None:
            w = check_vector("window", self.window, names="[start, end]")
            if not w[1] > w[0]:
                raise field_error("window", w, "must be [start, end] with end > start")
            inside = int(np.count_nonzero((t >= w[0]) & (t <= w[1])))
            if inside < 2:
                raise field_error("window", w, f"holds {inside} samples of the record (at least 2 needed)")
            _put(self, "window", w)

    def _settings(self) -> tuple:
        return tuple(getattr(self, f.name) for f in dataclasses.fields(self) if f.name not in ("time", "value"))

    def __eq__(self, other) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return (
            self._settings() == other._settings()
            and np.array_equal(self.time, other.time)
            and self.value.shape == other.value.shape
            and np.array_equal(self.value, other.value)
        )

    def __hash__(self) -> int:
        return hash((self._settings(), self.value.shape, float(self.time[0]), float(self.time[-1])))

    def __getstate__(self) -> dict:
        # pickled for a study's workers: without the cached _arrays (3 more arrays of the record's size)
        return {k: v for k, v in self.__dict__.items() if k != "_arrays"}

    def __setstate__(self, state: dict) -> None:
        for key in ("time", "value"):
            state[key].setflags(write=False)  # unpickled arrays are writeable
        self.__dict__.update(state)

    @property
    def is_vector(self) -> bool:
        """True for (x, y) records, False for 1-component records applied along ``direction``."""
        return self.value.ndim == 2

    @property
    def corrected(self) -> bool:
        """True when the baseline correction applies (an acceleration record with baseline "quadratic")."""
        return self.quantity == "acceleration" and self.baseline == "quadratic"

    @functools.cached_property
    def _arrays(self) -> RecordArrays:
        """The samples prepared for evaluation: direction, scale, window, integration, baseline."""
        return record_arrays(
            self.time, self.value, self.unit_direction, self.scale, self.window, self.quantity, self.baseline
        )

    @property
    def start_time(self) -> float:
        """s on the run's clock: the first sample used (0 with a window; a CSV's own first time else)."""
        return float(self._arrays.time[0])

    @property
    def end_time(self) -> float:
        """s on the run's clock: the last sample used (after the window's shift to t = 0); the record
        has shaken all it holds by then."""
        return float(self._arrays.time[-1])

    @property
    def peak_acceleration(self) -> float:
        """m/s²: the largest acceleration of the samples used, scaled (of the samples for an acceleration
        record; between them for a velocity one), before the baseline correction."""
        a = self._arrays
        if self.quantity != "acceleration":
            return float(np.hypot(*(np.diff(a.value, axis=0) / np.diff(a.time)[:, None]).T).max())
        return float(np.hypot(*a.value.T).max())

    @property
    def baseline_change(self) -> tuple[float, float]:
        """m/s²: ``(applied peak, largest change)`` of the acceleration the baseline correction makes — the
        peak of the samples used, scaled, minus the correction's straight line, and that line's largest
        size (at an end of the record); ``(peak_acceleration, 0)`` when not corrected."""
        if not self.corrected:
            return self.peak_acceleration, 0.0
        a = self._arrays
        change = correction_acceleration(a)
        return float(np.hypot(*(a.value - change).T).max()), float(np.hypot(*change.T).max())

    @property
    def sample_interval(self) -> float:
        """s: the shortest spacing of the samples used (a step longer than this skips samples)."""
        return float(np.diff(self._arrays.time).min())

    @property
    def baseline_correction(self) -> dict:
        """What the baseline correction subtracted, for the run document: ``{"baseline": "quadratic",
        "c1": [x, y], "c2": [x, y], "length": T}`` (m/s, s; see :mod:`masonrycli.records.velocity`), or
        ``{"baseline": "none"}``."""
        if not self.corrected:
            return {"baseline": "none"}
        time, baseline = self._arrays.time, self._arrays.baseline
        return {
            "baseline": "quadratic",
            "formula": "v_c(t) = v(t) - (c1 s + c2 s^2), s = t/T",
            "c1": baseline[0].tolist(),
            "c2": baseline[1].tolist(),
            "length": float(time[-1] - time[0]),
        }

    def velocity_at(self, t) -> np.ndarray:
        return record_velocity(_time_column(t), self._arrays, self.quantity, self.corrected)

    def peak_speed(self, duration: float) -> float:
        # at the samples used and at the run's end: exact for a velocity record (linear between
        # samples); for an acceleration record the velocity between samples is quadratic and may
        # slightly exceed its samples' (enough to tell 1 m/s from a typo's 1e300)
        time = self._arrays.time
        t = np.append(time[time <= duration], duration)
        return float(np.hypot(*self.velocity_at(t).T).max())

    def describe(self) -> str:
        src = os.path.basename(self.source) if self.source else "inline"
        axis = "" if self.is_vector else f" along {_vec(self.direction)}"
        if self.vertical_source:
            src += f" + vertical {os.path.basename(self.vertical_source)}"
        scale = "" if self.scale == 1.0 else f" × {_g(self.scale)}"
        every = "" if self.time_step is None else f" every {_g(self.time_step)} s"
        window = "" if self.window is None else f", window {_g(self.window[0])}–{_g(self.window[1])} s"
        corrected = ", baseline-corrected" if self.corrected else ""
        return (
            f"record of {self.quantity} ({src}, {len(self.time)} samples{every}, "
            f"{_g(self.time[0])}–{_g(self.time[-1])} s{window}{corrected}){scale}{axis}"
        )

    def toml_fields(self, inline_records: bool = False) -> dict:
        kv: dict = {"kind": self.kind}
        if self.source and not inline_records:
            kv["file"] = self.source
            if self.vertical_source:
                kv["vertical"] = self.vertical_source
            if self.time_step is not None:
                kv["time_step"] = self.time_step
        else:
            kv["time"] = self.time.tolist()
            kv["value"] = self.value.tolist()
        kv.update(quantity=self.quantity, scale=self.scale)
        if not self.is_vector:
            kv["direction"] = list(self.direction)
        if self.window is not None:
            kv["window"] = list(self.window)
        if self.quantity == "acceleration":
            kv["baseline"] = self.baseline
        return kv
