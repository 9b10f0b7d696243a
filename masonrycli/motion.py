"""Imposed support motions: one small frozen dataclass per kind, and their velocities.

A support (ground, foundation pad) translates with an imposed velocity. Each motion kind below knows
its velocity history (:meth:`velocity_at`, vectorised over time), a one-line description
(:meth:`describe`) and its TOML spelling (``TOML_KEYS``, ``TOML_REQUIRED``, :meth:`toml_fields`);
:func:`support_velocity` evaluates all supports of a scenario at many instants at once. Record files
(CSV) are read in :mod:`masonrycli.records`.

Kinds
-----
:class:`Fixed` (``fixed``)
    v(t) = 0.
:class:`Constant` (``constant``)
    v(t) = ``velocity`` (settlement: a foundation moving down at 1 cm/s is ``velocity = (0, -0.01)``).
:class:`Sine` (``sine``)
    v(t) = ``amplitude`` · sin(2π · ``frequency`` · t + ``phase``) · d̂, with d̂ = ``direction`` / |direction|.
:class:`Ramp` (``ramp``)
    v(t) = ``acceleration`` · clip(t, 0, ``until``): constant acceleration from rest, then constant
    velocity after ``until`` (an acceleration pulse; ``until = inf`` by default).
:class:`Record` (``record``)
    A tabulated velocity or acceleration history (earthquake record). ``time`` (n,) s; ``value`` either
    n numbers applied along d̂ (``direction``) or n (x, y) pairs. Values are multiplied by ``scale``.

    * ``quantity = "velocity"``: the velocity is interpolated linearly between samples; before the first
      sample it holds the first value, after the last sample it holds the last value.
    * ``quantity = "acceleration"``: the acceleration is interpolated linearly between samples and
      integrated exactly from v = 0 at the first sample. At the samples this *is* the cumulative
      trapezoid rule; between samples the velocity follows the exact (quadratic) integral of the linear
      acceleration rather than a chord, so that the velocity is the integral of the interpolated
      acceleration everywhere. Before the first sample v = 0 (the ground is at rest); after the last
      sample the acceleration is taken as zero, so the velocity holds its final integrated value.
    * ``baseline = "quadratic"`` (the default for acceleration records): integrated records drift (noise
      and rounding in the samples add up), so the integrated velocity v is corrected by the smallest
      polynomial that brings the ground back to rest where it started. With s = (t − t₀)/T over the
      record (length T), v_c(t) = v(t) − (c₁ s + c₂ s²) where c₁ + c₂ = v(T) (ends at rest) and
      T (c₁/2 + c₂/3) = ∫v dt (ends where it started): c₂ = 3 v(T) − 6 D/T, c₁ = 6 D/T − 2 v(T),
      D = ∫₀ᵀ v dt computed exactly for the piecewise-quadratic v. The acceleration changes by the
      straight line (c₁ + 2 c₂ s)/T. For a record that already ends at rest where it started (a
      processed PEER record) c₁ and c₂ are tiny and the correction is invisible. ``baseline = "none"``
      integrates as is. The coefficients are in :attr:`Record.baseline_correction`.
    * ``window = [a, b]``: only the samples with a <= t <= b are used, moved so that the first of them
      is at t = 0.

Units: m/s, m/s², s, Hz, rad.
"""

from __future__ import annotations

import functools
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from masonrycli.values import check_real, check_samples, check_vector, field_error, format_value

RECORD_QUANTITIES = ("velocity", "acceleration")
BASELINES = ("quadratic", "none")


def _g(x: float) -> str:
    return f"{x:g}"


def _vec(v) -> str:
    return "(" + ", ".join(_g(x) for x in v) + ")"


def _put(obj, name: str, value) -> None:
    # frozen dataclasses normalise their fields (lists -> tuples, ints -> floats) in __post_init__
    object.__setattr__(obj, name, value)


def _direction(obj) -> None:
    _put(obj, "direction", check_vector("direction", obj.direction))
    if obj.direction == (0.0, 0.0):
        raise field_error("direction", obj.direction, "must not be the zero vector")


def _time_column(t) -> np.ndarray:
    t = np.atleast_1d(np.asarray(t, dtype=np.float64))
    if t.ndim != 1:
        raise ValueError(f"t must be a 1-D array of times, got shape {t.shape}")
    return t


class _Directed:
    """The ``unit_direction`` of the kinds with a ``direction`` (Sine, Record)."""

    @property
    def unit_direction(self) -> np.ndarray:
        """``direction`` normalised, shape (2,)."""
        return np.asarray(self.direction, dtype=np.float64) / math.hypot(*self.direction)


class Motion:
    """Base of the motion kinds: the interface every support motion offers.

    ``kind`` is the TOML name; ``TOML_KEYS`` the keys a ``motion = {...}`` table of this kind may hold,
    ``TOML_REQUIRED`` those it must hold. Subclasses are frozen dataclasses whose ``__post_init__``
    validates and normalises the fields; error messages start with the field name
    (``amplitude = nan: must be a finite number``) so callers can prefix a location.
    """

    kind: ClassVar[str]
    TOML_KEYS: ClassVar[tuple[str, ...]]
    TOML_REQUIRED: ClassVar[tuple[str, ...]] = ()

    @property
    def role(self) -> str:
        """``"fixed"`` for a fixed support, ``"driven"`` otherwise (the ``Support.role`` value)."""
        return "driven"

    def velocity_at(self, t) -> np.ndarray:
        """Support velocity at times ``t`` (T,) s, shape (T, 2), m/s. Vectorised over time."""
        raise NotImplementedError

    def describe(self) -> str:
        """One human-readable line, e.g. ``sine 1 m/s · sin(2π·2 Hz·t) along (1, 0)``."""
        raise NotImplementedError

    def peak_speed(self, duration: float) -> float:
        """m/s, the largest |v(t)| for 0 <= t <= ``duration`` (an upper bound for a sine: its amplitude)."""
        return 0.0

    def toml_fields(self, inline_records: bool = False) -> dict:
        """The ``motion = {...}`` table of this motion, ``kind`` first (what the scenario writer emits)."""
        raise NotImplementedError


@dataclass(frozen=True)
class Fixed(Motion):
    """A support that does not move."""

    kind: ClassVar[str] = "fixed"
    TOML_KEYS: ClassVar[tuple[str, ...]] = ("kind",)

    @property
    def role(self) -> str:
        return "fixed"

    def velocity_at(self, t) -> np.ndarray:
        return np.zeros((_time_column(t).shape[0], 2), dtype=np.float64)

    def describe(self) -> str:
        return "fixed"

    def toml_fields(self, inline_records: bool = False) -> dict:
        return {"kind": self.kind}


@dataclass(frozen=True)
class Constant(Motion):
    """Constant velocity ``velocity`` (vx, vy) m/s (a settling foundation)."""

    velocity: tuple[float, float] = (0.0, 0.0)

    kind: ClassVar[str] = "constant"
    TOML_KEYS: ClassVar[tuple[str, ...]] = ("kind", "velocity")
    TOML_REQUIRED: ClassVar[tuple[str, ...]] = ("velocity",)

    def __post_init__(self):
        _put(self, "velocity", check_vector("velocity", self.velocity))

    def velocity_at(self, t) -> np.ndarray:
        return np.tile(np.asarray(self.velocity, dtype=np.float64), (_time_column(t).shape[0], 1))

    def describe(self) -> str:
        return f"constant velocity {_vec(self.velocity)} m/s"

    def peak_speed(self, duration: float) -> float:
        return math.hypot(*self.velocity)

    def toml_fields(self, inline_records: bool = False) -> dict:
        return {"kind": self.kind, "velocity": list(self.velocity)}


@dataclass(frozen=True, kw_only=True)
class Sine(_Directed, Motion):
    """``amplitude`` (m/s) · sin(2π ``frequency`` (Hz) · t + ``phase`` (rad)) along ``direction``
    (normalised on use)."""

    amplitude: float = 0.0
    frequency: float = 0.0
    direction: tuple[float, float] = (1.0, 0.0)
    phase: float = 0.0

    kind: ClassVar[str] = "sine"
    TOML_KEYS: ClassVar[tuple[str, ...]] = ("kind", "direction", "amplitude", "frequency", "phase")
    TOML_REQUIRED: ClassVar[tuple[str, ...]] = ("amplitude", "frequency")

    def __post_init__(self):
        _direction(self)
        _put(self, "amplitude", check_real("amplitude", self.amplitude))
        _put(self, "frequency", check_real("frequency", self.frequency, ge=0.0))
        _put(self, "phase", check_real("phase", self.phase))

    def velocity_at(self, t) -> np.ndarray:
        s = self.amplitude * np.sin(2.0 * np.pi * self.frequency * _time_column(t) + self.phase)
        return s[:, None] * self.unit_direction[None, :]

    def describe(self) -> str:
        ph = f" + {_g(self.phase)}" if self.phase else ""
        return f"sine {_g(self.amplitude)} m/s · sin(2π·{_g(self.frequency)} Hz·t{ph}) along {_vec(self.direction)}"

    def peak_speed(self, duration: float) -> float:
        return abs(self.amplitude)

    def toml_fields(self, inline_records: bool = False) -> dict:
        return {
            "kind": self.kind,
            "direction": list(self.direction),
            "amplitude": self.amplitude,
            "frequency": self.frequency,
            "phase": self.phase,
        }


@dataclass(frozen=True, kw_only=True)
class Ramp(Motion):
    """Constant ``acceleration`` (ax, ay) m/s² from rest until ``until`` s (inf: never), then constant
    velocity."""

    acceleration: tuple[float, float] = (0.0, 0.0)
    until: float = math.inf

    kind: ClassVar[str] = "ramp"
    TOML_KEYS: ClassVar[tuple[str, ...]] = ("kind", "acceleration", "until")
    TOML_REQUIRED: ClassVar[tuple[str, ...]] = ("acceleration",)

    def __post_init__(self):
        _put(self, "acceleration", check_vector("acceleration", self.acceleration))
        _put(self, "until", check_real("until", self.until, gt=0.0, allow_inf=True))

    def velocity_at(self, t) -> np.ndarray:
        tc = np.clip(_time_column(t), 0.0, self.until)
        return tc[:, None] * np.asarray(self.acceleration, dtype=np.float64)[None, :]

    def describe(self) -> str:
        until = "" if math.isinf(self.until) else f" until {_g(self.until)} s"
        return f"ramp acceleration {_vec(self.acceleration)} m/s²{until}"

    def peak_speed(self, duration: float) -> float:
        return math.hypot(*self.acceleration) * min(self.until, max(duration, 0.0))

    def toml_fields(self, inline_records: bool = False) -> dict:
        kv = {"kind": self.kind, "acceleration": list(self.acceleration)}
        if math.isfinite(self.until):
            kv["until"] = self.until
        return kv


@dataclass(frozen=True, kw_only=True)
class Record(_Directed, Motion):
    """A tabulated velocity or acceleration history (see the module docstring).

    time : (n,) s, strictly increasing, n >= 2.
    value : n floats (along ``direction``) or n (x, y) pairs, m/s or m/s² (before ``scale``).
    direction : (dx, dy) axis of a 1-component record; normalised on use.
    quantity : "velocity" | "acceleration" — what ``value`` holds.
    scale : multiplies ``value``.
    window : (a, b) s, or None — the part of the record used, moved to start at t = 0.
    baseline : "quadratic" | "none" — drift correction of acceleration records (module docstring).
    source : where the record came from (absolute file path, or "" for inline data).
    vertical_source : file of the vertical component (then ``value`` holds (x, y) pairs), or "".
    """

    time: tuple[float, ...] = ()
    value: tuple = ()
    direction: tuple[float, float] = (1.0, 0.0)
    quantity: str = "velocity"
    scale: float = 1.0
    window: tuple[float, float] | None = None
    baseline: str = "quadratic"
    source: str = ""
    vertical_source: str = ""

    kind: ClassVar[str] = "record"
    TOML_KEYS: ClassVar[tuple[str, ...]] = (
        "kind",
        "file",
        "vertical",
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
            raise field_error("baseline", self.baseline, 'must be "quadratic" or "none"')
        for key in ("source", "vertical_source"):
            if not isinstance(getattr(self, key), str):
                raise field_error(key, getattr(self, key), "must be a string")
        time, value = self.time, self.value
        if isinstance(time, np.ndarray):
            time = time.tolist()
        if isinstance(value, np.ndarray):
            value = value.tolist()
        if not isinstance(time, (list, tuple)) or not isinstance(value, (list, tuple)):
            raise field_error("time", time, "time and value must be sequences")
        if len(time) < 2:
            raise field_error("time", time, f"a record needs at least 2 samples, got {len(time)}")
        if len(value) != len(time):
            raise field_error("value", value, f"has {len(value)} samples but time has {len(time)}")
        t = check_samples("time", time)
        times = np.asarray(t, dtype=np.float64)
        later = times[1:] > times[:-1]
        if not later.all():
            i = int(np.argmin(later)) + 1
            raise field_error(f"time[{i}]", t[i], f"must be > the previous time {format_value(t[i - 1])}")
        # the first sample says which: [x, y] pairs, or numbers along the direction (judged from all of
        # them, [1.0, "b"] blamed value[0] = 1.0 for not being 2 numbers [x, y])
        v = check_samples("value", value, pairs=isinstance(value[0], (list, tuple, np.ndarray)))
        _put(self, "time", t)
        _put(self, "value", v)
        if self.window is not None:
            w = check_vector("window", self.window, names="[start, end]")
            if not w[1] > w[0]:
                raise field_error("window", w, "must be [start, end] with end > start")
            inside = int(np.count_nonzero((times >= w[0]) & (times <= w[1])))
            if inside < 2:
                raise field_error("window", w, f"holds {inside} samples of the record (at least 2 needed)")
            _put(self, "window", w)

    @property
    def is_vector(self) -> bool:
        """True for (x, y) records, False for 1-component records applied along ``direction``."""
        return bool(self.value) and isinstance(self.value[0], tuple)

    @property
    def corrected(self) -> bool:
        """True when the baseline correction applies (an acceleration record with baseline "quadratic")."""
        return self.quantity == "acceleration" and self.baseline == "quadratic"

    @functools.cached_property
    def _arrays(self):
        """Precomputed (time (n,), value (n,2) scaled, nodal velocity (n,2) uncorrected, baseline (2, 2)).

        ``baseline`` rows are c₁ and c₂ (m/s, one column per axis), zero when not corrected.
        """
        time = np.asarray(self.time, dtype=np.float64)
        value = np.asarray(self.value, dtype=np.float64)
        if value.ndim == 1:
            value = value[:, None] * self.unit_direction[None, :]
        value = value * self.scale
        if self.window is not None:
            keep = (time >= self.window[0]) & (time <= self.window[1])
            time, value = time[keep] - time[keep][0], value[keep]
        baseline = np.zeros((2, 2))
        if self.quantity == "acceleration":
            # cumulative trapezoid from v = 0 at the first sample
            h = np.diff(time)[:, None]
            nodal_v = np.zeros_like(value)
            nodal_v[1:] = np.cumsum(0.5 * h * (value[:-1] + value[1:]), axis=0)
            if self.baseline == "quadratic":
                # D = exact integral of the piecewise-quadratic velocity, interval by interval:
                #   ∫₀ʰ (v_i + a_i τ + (a_{i+1} − a_i) τ²/(2h)) dτ = h v_i + h² a_i / 2 + h² (a_{i+1} − a_i) / 6
                d = (h * nodal_v[:-1] + h * h * value[:-1] / 2.0 + h * h * (value[1:] - value[:-1]) / 6.0).sum(axis=0)
                length, v_end = time[-1] - time[0], nodal_v[-1]
                baseline[1] = 3.0 * v_end - 6.0 * d / length
                baseline[0] = 6.0 * d / length - 2.0 * v_end
        else:
            nodal_v = value
        for a in (time, value, nodal_v, baseline):
            a.setflags(write=False)
        return time, value, nodal_v, baseline

    @property
    def start_time(self) -> float:
        """s on the run's clock: the first sample used (0 with a window; a CSV's own first time else)."""
        return float(self._arrays[0][0])

    @property
    def end_time(self) -> float:
        """s on the run's clock: the last sample used (after the window's shift to t = 0); the record
        has shaken all it holds by then."""
        return float(self._arrays[0][-1])

    @property
    def sample_interval(self) -> float:
        """s: the shortest spacing of the samples used (a step longer than this skips samples)."""
        return float(np.diff(self._arrays[0]).min())

    @property
    def baseline_correction(self) -> dict:
        """What the baseline correction subtracted, for the run document: ``{"baseline": "quadratic",
        "c1": [x, y], "c2": [x, y], "length": T}`` (m/s, s; see the module docstring), or
        ``{"baseline": "none"}``."""
        if not self.corrected:
            return {"baseline": "none"}
        time, _, _, baseline = self._arrays
        return {
            "baseline": "quadratic",
            "formula": "v_c(t) = v(t) - (c1 s + c2 s^2), s = t/T",
            "c1": baseline[0].tolist(),
            "c2": baseline[1].tolist(),
            "length": float(time[-1] - time[0]),
        }

    def velocity_at(self, t) -> np.ndarray:
        t = _time_column(t)
        out = np.zeros((t.shape[0], 2), dtype=np.float64)
        time, value, nodal_v, baseline = self._arrays
        if self.quantity == "velocity":
            out[:, 0] = np.interp(t, time, value[:, 0])
            out[:, 1] = np.interp(t, time, value[:, 1])
        else:
            # exact integral of the piecewise-linear acceleration:
            #   i = interval holding t (clamped), tau = clip(t - t_i, 0, h_i)
            #   v = v_i + a_i tau + (a_{i+1} - a_i) tau^2 / (2 h_i)
            # tau clamps to 0 before the record (v = v_0 = 0) and to h_i after it (v = v_n).
            i = np.clip(np.searchsorted(time, t, side="right") - 1, 0, time.shape[0] - 2)
            h = (time[i + 1] - time[i])[:, None]
            tau = np.clip(t - time[i], 0.0, h[:, 0])[:, None]
            a0, a1 = value[i], value[i + 1]
            out[:] = nodal_v[i] + a0 * tau + (a1 - a0) * (tau * tau) / (2.0 * h)
            if self.corrected:
                s = (np.clip(t, time[0], time[-1]) - time[0])[:, None] / (time[-1] - time[0])
                out -= baseline[0] * s + baseline[1] * (s * s)
        return out

    def peak_speed(self, duration: float) -> float:
        # at the samples used and at the run's end: exact for a velocity record (linear between
        # samples); for an acceleration record the velocity between samples is quadratic and may
        # slightly exceed its samples' (enough to tell 1 m/s from a typo's 1e300)
        time = self._arrays[0]
        t = np.append(time[time <= duration], duration)
        return float(np.hypot(*self.velocity_at(t).T).max())

    def describe(self) -> str:
        src = os.path.basename(self.source) if self.source else "inline"
        axis = "" if self.is_vector else f" along {_vec(self.direction)}"
        if self.vertical_source:
            src += f" + vertical {os.path.basename(self.vertical_source)}"
        scale = "" if self.scale == 1.0 else f" × {_g(self.scale)}"
        window = "" if self.window is None else f", window {_g(self.window[0])}–{_g(self.window[1])} s"
        corrected = ", baseline-corrected" if self.corrected else ""
        return (
            f"record of {self.quantity} ({src}, {len(self.time)} samples, "
            f"{_g(self.time[0])}–{_g(self.time[-1])} s{window}{corrected}){scale}{axis}"
        )

    def toml_fields(self, inline_records: bool = False) -> dict:
        kv: dict = {"kind": self.kind}
        if self.source and not inline_records:
            kv["file"] = self.source
            if self.vertical_source:
                kv["vertical"] = self.vertical_source
        else:
            kv["time"] = list(self.time)
            kv["value"] = [list(v) if isinstance(v, tuple) else v for v in self.value]
        kv.update(quantity=self.quantity, scale=self.scale)
        if not self.is_vector:
            kv["direction"] = list(self.direction)
        if self.window is not None:
            kv["window"] = list(self.window)
        if self.quantity == "acceleration":
            kv["baseline"] = self.baseline
        return kv


MOTION_KINDS: dict[str, type[Motion]] = {cls.kind: cls for cls in (Fixed, Constant, Sine, Ramp, Record)}
"""TOML ``kind`` -> motion class."""


def support_velocity(motions: Sequence[Motion], t) -> np.ndarray:
    """Imposed velocities of all supports at times ``t``.

    Parameters
    ----------
    motions : one :class:`Motion` per support, in support order (S of them).
    t : (T,) times, s (a scalar is treated as shape (1,)).

    Returns
    -------
    (T, S, 2) float64 support velocities, m/s. Vectorised over time (a Python loop runs over supports only).
    """
    t = _time_column(t)
    out = np.zeros((t.shape[0], len(motions), 2), dtype=np.float64)
    for s, motion in enumerate(motions):
        out[:, s, :] = motion.velocity_at(t)
    return out
