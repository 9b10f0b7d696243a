"""Imposed support motions: one small frozen dataclass per kind, and their velocities.

A support (ground, foundation pad) translates with an imposed velocity. Each motion kind below knows
its velocity history (:meth:`velocity_at`, vectorised over time), a one-line description
(:meth:`describe`) and its TOML spelling (``TOML_KEYS``, ``TOML_REQUIRED``, :meth:`toml_fields`);
:func:`support_velocity` evaluates all supports of a scenario at many instants at once. The TOML
``kind`` -> class table is ``masonrycli.scenario.toml_bodies.MOTION_KINDS``.

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
:class:`~masonrycli.records.motion.Record` (``record``)
    A tabulated velocity or acceleration history (earthquake record), in :mod:`masonrycli.records.motion`.

Units: m/s, m/s², s, Hz, rad.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from masonrycli.scenario.values import check_real, check_vector, field_error

MAX_PHASE = 1e4
"""rad — a sine's phase beyond ±this is refused as a likely typo: the sine repeats every 2π, so any phase can
be given within one turn, and a large one only costs precision (``phase = 1e300`` swallowed 2π·f·t whole:
sin(1e300) every step, a constant velocity that ran without a word)."""


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
        phase = self.phase  # as given, for the message
        _put(self, "phase", check_real("phase", self.phase))
        if abs(self.phase) > MAX_PHASE:
            raise field_error(
                "phase", phase, f"must be within ±{MAX_PHASE:g} rad (the sine repeats every 2π; a likely typo)"
            )

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
