"""Imposed support motions and their velocities.

A support (ground, foundation pad) translates with an imposed velocity. :class:`Motion` describes one
support's velocity history; :func:`support_velocity` evaluates the velocities of all supports at many
instants at once, vectorised over time.

Kinds
-----
``fixed``
    v(t) = 0.
``constant``
    v(t) = ``velocity`` (settlement: a foundation moving down at 1 cm/s is ``velocity = (0, -0.01)``).
``sine``
    v(t) = ``amplitude`` · sin(2π · ``frequency`` · t + ``phase``) · d̂, with d̂ = ``direction`` / |direction|.
``ramp``
    v(t) = ``acceleration`` · clip(t, 0, ``until``): constant acceleration from rest, then constant
    velocity after ``until`` (an acceleration pulse; ``until = inf`` by default).
``record``
    A tabulated velocity or acceleration history (earthquake record), see :func:`load_record_csv`.
    ``record_time`` (n,) s; ``record_value`` either n numbers applied along d̂ (``direction``) or n
    (x, y) pairs. Values are multiplied by ``scale``.

    * ``quantity = "velocity"``: the velocity is interpolated linearly between samples; before the first
      sample it holds the first value, after the last sample it holds the last value.
    * ``quantity = "acceleration"``: the acceleration is interpolated linearly between samples and
      integrated exactly from v = 0 at the first sample. At the samples this *is* the cumulative
      trapezoid rule; between samples the velocity follows the exact (quadratic) integral of the linear
      acceleration rather than a chord, so that the velocity is the integral of the interpolated
      acceleration everywhere. Before the first sample v = 0 (the ground is at rest); after the last
      sample the acceleration is taken as zero, so the velocity holds its final integrated value
      (a record that does not end at rest keeps the ground drifting, as a real baseline error would).

Units: m/s, m/s², s, Hz, rad.
"""

from __future__ import annotations

import functools
import math
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from masonrycli.errors import InputError
from masonrycli.values import check_real, check_vector, field_error, format_value, is_real, shorten

MOTION_KINDS = ("fixed", "constant", "sine", "ramp", "record")
RECORD_QUANTITIES = ("velocity", "acceleration")


@dataclass(frozen=True)
class Motion:
    """Imposed velocity history of one support (see the module docstring for the kinds).

    Attributes
    ----------
    kind : "fixed" | "constant" | "sine" | "ramp" | "record".
    direction : (dx, dy) — axis of ``sine`` and of 2-column ``record`` motions; normalised on use.
    amplitude : m/s — ``sine`` velocity amplitude.
    frequency : Hz — ``sine``.
    phase : rad — ``sine``.
    velocity : (vx, vy) m/s — ``constant``.
    acceleration : (ax, ay) m/s² — ``ramp``.
    until : s — ``ramp`` stops accelerating at this time (inf: never).
    record_time : (n,) s, strictly increasing — ``record``.
    record_value : n floats (along ``direction``) or n (x, y) pairs — ``record``, m/s or m/s².
    quantity : "velocity" | "acceleration" — what ``record_value`` holds.
    scale : multiplies ``record_value``.
    source : where the record came from (absolute CSV path, or "" for inline data).
    """

    kind: str = "fixed"
    direction: tuple[float, float] = (1.0, 0.0)
    amplitude: float = 0.0
    frequency: float = 0.0
    phase: float = 0.0
    velocity: tuple[float, float] = (0.0, 0.0)
    acceleration: tuple[float, float] = (0.0, 0.0)
    until: float = math.inf
    record_time: tuple[float, ...] = ()
    record_value: tuple = ()
    quantity: str = "velocity"
    scale: float = 1.0
    source: str = ""

    def __post_init__(self):
        # Normalise types (lists -> tuples, ints -> floats) and validate. Error messages start with the
        # field name ("amplitude = nan: must be a finite number") so callers can prefix a location.
        def put(name, value):
            object.__setattr__(self, name, value)

        if self.kind not in MOTION_KINDS:
            raise field_error("kind", self.kind, f"unknown motion kind (expected one of {', '.join(MOTION_KINDS)})")
        put("direction", check_vector("direction", self.direction))
        if self.direction == (0.0, 0.0):
            raise field_error("direction", self.direction, "must not be the zero vector")
        put("amplitude", check_real("amplitude", self.amplitude))
        put("frequency", check_real("frequency", self.frequency, ge=0.0))
        put("phase", check_real("phase", self.phase))
        put("velocity", check_vector("velocity", self.velocity))
        put("acceleration", check_vector("acceleration", self.acceleration))
        put("until", check_real("until", self.until, gt=0.0, allow_inf=True))
        if self.quantity not in RECORD_QUANTITIES:
            raise field_error("quantity", self.quantity, 'must be "velocity" or "acceleration"')
        put("scale", check_real("scale", self.scale))
        if not isinstance(self.source, str):
            raise field_error("source", self.source, "must be a string")
        self._check_record()

    def _check_record(self):
        time, value = self.record_time, self.record_value
        if isinstance(time, np.ndarray):
            time = time.tolist()
        if isinstance(value, np.ndarray):
            value = value.tolist()
        if not isinstance(time, (list, tuple)) or not isinstance(value, (list, tuple)):
            raise field_error("record_time", time, "record_time and record_value must be sequences")
        if self.kind != "record" and not time and not value:
            object.__setattr__(self, "record_time", ())
            object.__setattr__(self, "record_value", ())
            return
        if len(time) < 2:
            raise field_error("record_time", time, f"a record needs at least 2 samples, got {len(time)}")
        if len(value) != len(time):
            raise field_error("record_value", value, f"has {len(value)} samples but record_time has {len(time)}")
        t = tuple(check_real(f"record_time[{i}]", x) for i, x in enumerate(time))
        for i in range(1, len(t)):
            if not t[i] > t[i - 1]:
                raise field_error(f"record_time[{i}]", t[i], f"must be > the previous time {format_value(t[i - 1])}")
        if all(is_real(v) for v in value):
            v = tuple(check_real(f"record_value[{i}]", x) for i, x in enumerate(value))
        else:
            v = tuple(check_vector(f"record_value[{i}]", x) for i, x in enumerate(value))
        object.__setattr__(self, "record_time", t)
        object.__setattr__(self, "record_value", v)

    # ---------------------------------------------------------------------------------------------

    @property
    def role(self) -> str:
        """``"fixed"`` for a fixed support, ``"driven"`` otherwise (the ``Support.role`` value)."""
        return "fixed" if self.kind == "fixed" else "driven"

    @property
    def unit_direction(self) -> np.ndarray:
        """``direction`` normalised, shape (2,)."""
        d = np.asarray(self.direction, dtype=np.float64)
        return d / math.hypot(*self.direction)

    @property
    def record_is_vector(self) -> bool:
        """True for 3-column (time, x, y) records, False for 2-column (time, value along ``direction``)."""
        return bool(self.record_value) and isinstance(self.record_value[0], tuple)

    @functools.cached_property
    def _record_arrays(self):
        """Precomputed (time (n,), value (n,2) scaled, nodal velocity (n,2)) for ``record`` motions."""
        time = np.asarray(self.record_time, dtype=np.float64)
        value = np.asarray(self.record_value, dtype=np.float64)
        if value.ndim == 1:
            value = value[:, None] * self.unit_direction[None, :]
        value = value * self.scale
        if self.quantity == "acceleration":
            # cumulative trapezoid from v = 0 at the first sample
            h = np.diff(time)[:, None]
            nodal_v = np.zeros_like(value)
            nodal_v[1:] = np.cumsum(0.5 * h * (value[:-1] + value[1:]), axis=0)
        else:
            nodal_v = value
        for a in (time, value, nodal_v):
            a.setflags(write=False)
        return time, value, nodal_v

    def velocity_at(self, t) -> np.ndarray:
        """Support velocity at times ``t`` (T,) s, shape (T, 2), m/s. Vectorised over time."""
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        if t.ndim != 1:
            raise ValueError(f"t must be a 1-D array of times, got shape {t.shape}")
        out = np.zeros((t.shape[0], 2), dtype=np.float64)
        kind = self.kind
        if kind == "fixed":
            pass
        elif kind == "constant":
            out[:] = self.velocity
        elif kind == "sine":
            s = self.amplitude * np.sin(2.0 * np.pi * self.frequency * t + self.phase)
            out[:] = s[:, None] * self.unit_direction[None, :]
        elif kind == "ramp":
            tc = np.clip(t, 0.0, self.until)
            out[:] = tc[:, None] * np.asarray(self.acceleration)[None, :]
        elif kind == "record":
            time, value, nodal_v = self._record_arrays
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
        return out

    def describe(self) -> str:
        """One human-readable line, e.g. ``sine 1 m/s · sin(2π·2 Hz·t) along (1, 0)``."""
        g = lambda x: f"{x:g}"  # noqa: E731
        vec = lambda v: "(" + ", ".join(g(x) for x in v) + ")"  # noqa: E731
        if self.kind == "fixed":
            return "fixed"
        if self.kind == "constant":
            return f"constant velocity {vec(self.velocity)} m/s"
        if self.kind == "sine":
            ph = f" + {g(self.phase)}" if self.phase else ""
            return f"sine {g(self.amplitude)} m/s · sin(2π·{g(self.frequency)} Hz·t{ph}) along {vec(self.direction)}"
        if self.kind == "ramp":
            until = "" if math.isinf(self.until) else f" until {g(self.until)} s"
            return f"ramp acceleration {vec(self.acceleration)} m/s²{until}"
        src = os.path.basename(self.source) if self.source else "inline"
        axis = "" if self.record_is_vector else f" along {vec(self.direction)}"
        scale = "" if self.scale == 1.0 else f" × {g(self.scale)}"
        return (
            f"record of {self.quantity} ({src}, {len(self.record_time)} samples, "
            f"{g(self.record_time[0])}–{g(self.record_time[-1])} s){scale}{axis}"
        )


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
    t = np.atleast_1d(np.asarray(t, dtype=np.float64))
    if t.ndim != 1:
        raise ValueError(f"t must be a 1-D array of times, got shape {t.shape}")
    out = np.zeros((t.shape[0], len(motions), 2), dtype=np.float64)
    for s, motion in enumerate(motions):
        out[:, s, :] = motion.velocity_at(t)
    return out


# --------------------------------------------------------------------------------------------------
# records


_SPLIT = re.compile(r"\s*[,;]\s*|\s+")


def load_record_csv(path, display: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Read a tabulated motion record.

    Format: one sample per line, ``time,value`` (2 columns: a value along the motion's direction) or
    ``time,x,y`` (3 columns: a vector). Separators: comma, semicolon or white space. Blank lines and
    lines starting with ``#`` are skipped; a single non-numeric header line before the first sample is
    allowed. Times in s, strictly increasing, at least 2 samples; all values finite.

    Returns ``(time (n,), value (n,) or (n, 2))`` float64 arrays.
    Raises :class:`InputError` with a one-line message ``<file>:<line>: <problem>``.
    ``display`` is the file name used in messages (default: ``path`` as given).
    """
    name = display if display is not None else str(path)
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except IsADirectoryError:
        raise InputError(f"{name}: cannot read record: is a directory") from None
    except OSError as exc:
        raise InputError(f"{name}: cannot read record: {exc.strerror or exc}") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(f"{name}: not a UTF-8 text file (byte {exc.start})") from None

    times: list[float] = []
    values: list = []
    ncol = 0
    header_seen = False
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        fields = [f for f in _SPLIT.split(stripped) if f != ""]
        try:
            nums = [float(f) for f in fields]
        except ValueError:
            if not times and not header_seen:
                header_seen = True
                continue
            bad = next(f for f in fields if not _is_float(f))
            raise InputError(f"{name}:{lineno}: not a number: {shorten(bad, 40)}") from None
        if ncol == 0:
            if len(nums) not in (2, 3):
                raise InputError(
                    f"{name}:{lineno}: expected 2 columns (time, value) or 3 (time, x, y), got {len(nums)}"
                )
            ncol = len(nums)
        elif len(nums) != ncol:
            raise InputError(f"{name}:{lineno}: expected {ncol} columns like the first sample, got {len(nums)}")
        if not all(math.isfinite(x) for x in nums):
            raise InputError(f"{name}:{lineno}: values must be finite, got {shorten(stripped, 40)}")
        if times and not nums[0] > times[-1]:
            raise InputError(
                f"{name}:{lineno}: time {format_value(nums[0])} is not after the previous sample's "
                f"{format_value(times[-1])} (times must be strictly increasing)"
            )
        times.append(nums[0])
        values.append(nums[1] if ncol == 2 else (nums[1], nums[2]))
    if len(times) < 2:
        raise InputError(f"{name}: a record needs at least 2 samples, found {len(times)}")
    return np.asarray(times, dtype=np.float64), np.asarray(values, dtype=np.float64)


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def record_motion(
    path, *, quantity: str = "velocity", scale: float = 1.0, direction=(1.0, 0.0), display: str | None = None
) -> Motion:
    """A ``record`` :class:`Motion` from a CSV file (see :func:`load_record_csv`).

    ``source`` is the absolute path of the file. ``direction`` applies to 2-column records only.
    """
    time, value = load_record_csv(path, display=display)
    return Motion(
        kind="record",
        direction=tuple(direction),
        record_time=tuple(time.tolist()),
        record_value=tuple(value.tolist()) if value.ndim == 1 else tuple(map(tuple, value.tolist())),
        quantity=quantity,
        scale=scale,
        source=os.path.abspath(os.fspath(path)),
    )
