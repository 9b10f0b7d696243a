"""A scenario's support motions checked against its run, once the command line's overrides are applied: a
sine the time step can follow (below 1/(2 dt)) and no support faster than ``MAX_SUPPORT_SPEED``; the refusal
names the scenario file's line of the key that set the frequency or the speed, when it still holds the value
run."""

from __future__ import annotations

import os

from masonrycli.errors import InputError, input_path
from masonrycli.scenario.scenario import MAX_SUPPORT_SPEED, Scenario


def check_sampling(scenario: Scenario) -> None:
    """Raise :class:`InputError` for a sine faster than the time step can follow: at or above 1/(2 dt) the
    steps sample it at aliased phases (``--freq 1e9`` at dt = 1e-3 s sampled sin(2π·10⁶·k) = 0: the ground
    never moved, and nothing said so; at exactly 1/(2 dt), two steps a period, ``--dt 0.25`` on the 2 Hz
    wall, it is sampled at sin(π·k) = 0 too: PGA 3e-15 m/s², exit 0); and for a support moving faster
    than ``MAX_SUPPORT_SPEED`` within the run. Called once the command line's overrides are applied."""
    dt = scenario.run.dt
    source = str(scenario.source)
    where = "" if source.startswith("builder:") or not source else f"{source}: "
    for support, m in zip(scenario.assembly.supports, scenario.motions):
        peak = m.peak_speed(scenario.run.duration)
        if not peak <= MAX_SUPPORT_SPEED:
            if where:  # the line of the key that sets the speed, as the aliased sine's below
                where = _speed_where(source, support.name, m)
            raise InputError(
                f'{where}support "{support.name}": {m.describe()} moves at up to {peak:.3g} m/s, more than '
                f"{MAX_SUPPORT_SPEED:g} m/s (a likely typo: a block that fast is a diverged run)"
            )
        if m.kind == "sine" and m.amplitude != 0.0 and m.frequency * dt >= 0.5:
            if where:  # a scenario file's line, as its other errors give: the frequency's, else the dt's
                where = _sampling_where(source, support.name, m.frequency, dt)
            raise InputError(
                f'{where}support "{support.name}": frequency = {m.frequency:g} Hz is '
                f"{'above' if m.frequency * dt > 0.5 else 'at'} 1/(2 dt) = {0.5 / dt:g} Hz: steps of dt = {dt:g} s "
                f"sample it at aliased phases (dt = {0.05 / m.frequency:.3g} s gives 20 steps a period)"
            )


def _sampling_where(source: str, support: str, frequency: float, dt: float) -> str:
    """``<file>:<line>: `` of the aliased sine's ``frequency`` key, else of ``[run] dt``: see _file_where."""
    return _file_where(source, (("support", support, "motion"), "frequency", frequency), (("run",), "dt", dt))


_SPEED_KEYS = {"sine": "amplitude", "constant": "velocity", "ramp": "acceleration"}
"""The motion key that sets a support's peak speed, by kind (a record's is spread over its samples: none)."""


def _speed_where(source: str, support: str, motion) -> str:
    """``<file>:<line>: `` of the key that sets a too-fast support's speed (``amplitude``, ``velocity``,
    ``acceleration``; a record's ``file``, or its inline ``value``): see _file_where."""
    if motion.kind == "record":
        key, value = _record_key(source, motion)
    else:
        key = _SPEED_KEYS.get(motion.kind)
        value = getattr(motion, key, None) if key else None
        value = list(value) if isinstance(value, tuple) else value  # a vector is a TOML array
    return _file_where(source, *([] if value is None else [(("support", support, "motion"), key, value)]))


def _record_key(source: str, record) -> tuple:
    """(key, test of the file's value): the ``file`` that names the record, resolved as the scenario reads it
    (relative to its folder, ``~``), or the inline ``value`` samples. Another file (a sweep's ``--records``)
    is not the record: no line."""
    if record.source:
        folder = os.path.dirname(os.path.abspath(source))

        def names_it(given) -> bool:
            return isinstance(given, str) and input_path(folder, given) == record.source

        return "file", names_it

    def holds_it(given) -> bool:
        import numpy as np

        try:
            return np.array_equal(np.asarray(given, dtype=float), record.value)
        except (TypeError, ValueError):
            return False

    return "value", holds_it


def _file_where(source: str, *candidates) -> str:
    """``<file>:<line>: `` of the first (table path, key, value) the file gives with the value the run has
    (``--dt`` or a sweep's ``--param`` may have replaced it: toml_lines.file_key_line); ``<file>: `` when
    none is found (a geometry file, a key not written in the file)."""
    from masonrycli.scenario.toml_lines import file_key_line

    for path, key, value in candidates:
        line = file_key_line(source, path, key, value)
        if line is not None:
            return f"{source}:{line}: "
    return f"{source}: "
