"""An exported table resampled onto a lab's sample times (``masonry export H.npz --times lab.csv``).

A run is recorded every ``--record-every`` steps; a shake-table test at its own sample times (200 Hz, 256 Hz,
an optical system's frames), which need not fall on the run's frames. Each exported column is taken at
the lab's times, and written beside the lab's own columns (left unchanged):

    for each lab time t (checked inside the run: first frame ≤ t ≤ last frame):
        k = the frame at or before t, w = (t − t_k) / (t_{k+1} − t_k)
        a count (an integer column: hinges) = its value at frame k   # an event is not interpolated
        every other column = (1 − w) · value_k + w · value_{k+1}       # displacements, velocities, forces, energies

Accelerations are linearly interpolated too: the frames' central differences (``export``), each the mean
over the two recorded intervals around its frame, so a low-pass of width 2 × ``--record-every`` × dt,
whatever the lab's rate. An empty cell (the base shear at t = 0, no force solved yet) makes the samples
between its frame and the next empty.
"""

from __future__ import annotations

import numpy as np

from masonrycli.errors import InputError
from masonrycli.outputs.export import Table
from masonrycli.outputs.lab_file import LabFile

REL_SLACK = 1e-9
"""A lab time this close to the run's first or last frame (relative to the run's span, at least 1 s) is
that frame: ``4.0`` in the lab file against a last frame at step × dt = 3.9999999999999996."""


def interpolate(time: np.ndarray, values: np.ndarray, at: np.ndarray) -> np.ndarray:
    """``values`` (frames along axis 0) at the times ``at`` (inside ``time``): linear for floats, the value
    at the frame at or before for integers (module docstring)."""
    k = np.clip(np.searchsorted(time, at, side="right") - 1, 0, len(time) - 1)
    if values.dtype.kind in "biu" or len(time) == 1:
        return values[k]
    k = np.minimum(k, len(time) - 2)
    w = (at - time[k]) / (time[k + 1] - time[k])
    out = (1 - w) * values[k] + w * values[k + 1]
    # on a frame (w = 0 or 1) its own value, exactly: not 0 × NaN from an empty neighbour, nor a rounding
    out = np.where(w == 0, values[k], out)
    return np.where(w == 1, values[k + 1], out)


def check_inside(lab: LabFile, time: np.ndarray, shown: str) -> np.ndarray:
    """The lab's times, those within :data:`REL_SLACK` of the run's ends put on them; :class:`InputError`
    naming the first sample outside the run."""
    slack = REL_SLACK * max(1.0, float(time[-1] - time[0]))
    at = lab.time.copy()
    before = np.flatnonzero(at < time[0] - slack)
    after = np.flatnonzero(at > time[-1] + slack)
    for outside, side, edge in ((before, "before the run's first", time[0]), (after, "after the run's last", time[-1])):
        if outside.size:
            i = outside[0]
            count = f"{outside.size} sample{'s' if outside.size > 1 else ''} outside it"
            raise InputError(
                f"{lab.path}:{lab.lines[i]}: time {lab.rows[i][lab.time_column]} is {side} frame, t = {edge:g} s, "
                f"of {shown} ({count}: cut the lab file to the run, or run it longer)"
            )
    return np.clip(at, time[0], time[-1])


def resample(table: Table, lab: LabFile, shown: str) -> Table:
    """``table`` (``time (s)`` its first column) at the lab's times: the lab's columns as they are, then the
    table's without its time (a name the lab has already gets ``masonry `` before it)."""
    time = table.values[0]
    at = check_inside(lab, time, shown)
    out = Table(notes=list(table.notes), main=table.main, point=table.point)
    for i, name in enumerate(lab.header):
        out.names.append(name)
        out.values.append(np.array([row[i] for row in lab.rows], dtype=object))
    taken = set(lab.header)
    for name, value in zip(table.names[1:], table.values[1:]):
        out.names.append(f"masonry {name}" if name in taken else name)
        out.values.append(interpolate(time, value, at))
    if len(time) > 1 and len(at) > 1 and np.median(np.diff(time)) > 1.5 * np.median(np.diff(at)):
        frame, sample = np.median(np.diff(time)), np.median(np.diff(at))
        out.notes.append(
            f"{shown}: frames every {frame * 1e3:g} ms, the lab's samples every {sample * 1e3:g} ms: masonry's "
            f"columns are straight lines between frames (record the run with a smaller --record-every)"
        )
    return out
