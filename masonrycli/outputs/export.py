"""``masonry export H.npz --out S.csv``: a run history as a table a spreadsheet, pandas or MATLAB reads.

One row per recorded frame (every ``--every``-th), one column per quantity, the unit in the column's name
(``time (s)``, ``c08-b04 ux rel (m)``): ``pandas.read_csv(S)`` or Excel open it as it is.

What each column is (README "Export a history"):

* the **ground** — the reference support (``--ground``; by default the only one, else the first that moves
  sideways): its displacement from t = 0, ``ux uy`` (m), its imposed velocity ``vx vy`` (m/s) and
  acceleration ``ax ay`` (m/s², by the rule below: a shake-table's input as the run applied it);
* each **target** — a block by name, ``course N`` (the mean of the N-th course from the bottom) or
  ``top`` (the mean of the top course): ``ux uy`` (m) the centroid's displacement from t = 0, ``rot``
  (rad, counter-clockwise), ``vx vy`` (m/s), ``ax ay`` (m/s²). Relative to the ground (`` rel`` in the
  name: the block's minus the ground's) unless ``--absolute``. A course's value is the arithmetic mean of
  its blocks';
* ``drift ratio (-)``: the top's mean horizontal displacement relative to the ground over the structure's
  height (the blocks' vertical extent as built) — the run summary's drift;
* ``base shear (N)`` and ``base vertical (N)``: the horizontal and vertical force of all the supports on
  the blocks, −Σ ``support_force`` (the history holds the blocks' force on each support), for the blocks'
  thickness; at rest the vertical is the weight; the shear is positive when the base pushes the structure
  towards +x (= Σ m a_x of the blocks); empty at t = 0 (step 0: no contact force solved yet);
* ``overturning moment (N m)``: moment of the supports' forces on the blocks about the base point O (the
  blocks' lowest point as built, midway between their leftmost and rightmost, moving with the ground),
  counter-clockwise positive, from the blocks' inertia (Newton–Euler: Σ (r − O) × m (a − g) + I α, the
  accelerations by the rule below) — the history keeps the support's resultant, not where it acts; empty at
  t = 0 as the shear is (the same reaction, not yet solved: the inertia's one-sided difference there is the
  first interval's mean, and a moment-against-shear plot would take the row as a point without its shear);
* ``hinges (-)``, ``energy kinetic / potential / dissipated (J)``, ``support work (J)``.

**Accelerations** are finite differences of the recorded velocities: at frame k, (v[k+1] − v[k−1]) /
(t[k+1] − t[k−1]), the mean acceleration over the two recorded intervals around the frame (one-sided at
the first and last frame). They are means over 2 × ``--record-every`` steps: a low-pass filter whose width
is set by the run's ``--record-every`` (record every step to see impacts; ``--every`` here thins the rows
after the differences are taken on every frame).

Courses: the median block height h of the blocks as built; course 1 is the blocks whose centroid lies
within h/2 of the lowest centroid, course 2 the same among the rest, and so on; the top is the blocks
within h/2 of the highest centroid (collapse.py's top). A history written before ``block_extent``
(masonry before 2026-11-29) has no block heights: h is then the median spacing of the distinct centroid
heights (a wall's course height), the height the centroids' extent plus h, and the overturning moment is
left out (no masses); :func:`export_table` says so in its notes.

At a lab's sample times: :mod:`masonrycli.outputs.resample` (``--times``); several histories as one long table:
:func:`long_table` (``--combined``).
"""

from __future__ import annotations

import csv
import difflib
import os
from dataclasses import dataclass, field

import numpy as np

from masonrycli.errors import InputError
from masonrycli.outputs.inspect_history import inspect_history

NEEDED = ("time", "block_q", "block_v", "block_name", "support_q", "support_v", "support_force", "support_name")
SCALARS = (
    ("hinge_count", "hinges (-)"),
    ("energy_kinetic", "energy kinetic (J)"),
    ("energy_potential", "energy potential (J)"),
    ("energy_dissipated", "energy dissipated (J)"),
    ("support_work", "support work (J)"),
)


@dataclass
class Table:
    """The exported columns: ``names`` (with units) and ``values`` (T', one array per column); ``notes``:
    what the user should know (an interrupted run, an estimate)."""

    names: list[str] = field(default_factory=list)
    values: list[np.ndarray] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    main: str = ""
    """The first target's horizontal displacement column (``top ux rel (m)``): what ``--compare`` compares with."""
    point: dict = field(default_factory=dict)
    """The run's study point (``masonry sweep --histories``: its swept values, ``record``), else empty."""

    def add(self, name: str, value) -> None:
        value = np.asarray(value)
        self.names.append(name)
        # + 0.0: no "-0.0" cells (a negated zero force)
        self.values.append(value.astype(np.int64) if value.dtype.kind in "biu" else value.astype(float) + 0.0)


def frame_rate(values: np.ndarray, time: np.ndarray) -> np.ndarray:
    """d values / dt along axis 0 on the recorded frames: (v[k+1] − v[k−1]) / (t[k+1] − t[k−1]) inside,
    one-sided at the ends; NaN with a single frame."""
    values = np.asarray(values, dtype=float)
    out = np.full(values.shape, np.nan)
    if len(time) < 2:
        return out
    shape = (-1,) + (1,) * (values.ndim - 1)
    out[1:-1] = (values[2:] - values[:-2]) / (time[2:] - time[:-2]).reshape(shape)
    out[0] = (values[1] - values[0]) / (time[1] - time[0])
    out[-1] = (values[-1] - values[-2]) / (time[-1] - time[-2])
    return out


def read_history(path) -> dict[str, np.ndarray]:
    """The arrays of the history at ``path`` (checked as ``masonry inspect`` checks it); :class:`InputError`
    for a file that is no history or lacks what the export needs."""
    inspect_history(path)  # one line for a missing, damaged or foreign file
    with np.load(path, allow_pickle=False) as npz:
        missing = [name for name in NEEDED if name not in npz.files]
        if missing:
            raise InputError(f"{os.fspath(path)}: a history without {', '.join(missing)}: nothing to export from it")
        return {name: npz[name] for name in npz.files}


def _heights(h: dict, y0: np.ndarray, notes: list[str], shown: str) -> tuple[float, float, float, float]:
    """(median block height, structure height, lowest y, middle x) of the blocks as built."""
    extent = h.get("block_extent")
    if extent is not None and extent.shape == (len(y0), 4):
        height = float(np.median(extent[:, 3] - extent[:, 1])) if len(y0) else 0.0
        return (
            height,
            float(extent[:, 3].max() - extent[:, 1].min()),
            float(extent[:, 1].min()),
            float(0.5 * (extent[:, 0].min() + extent[:, 2].max())),
        )
    levels = np.unique(y0)
    gaps = np.diff(levels)
    gaps = gaps[gaps > 1e-9]
    height = float(np.median(gaps)) if gaps.size else 0.0
    notes.append(
        f"{shown}: no block_extent (a history of an older masonry): course height estimated from the centroids, "
        f"{height:.4g} m; drift ratio over {np.ptp(y0) + height:.4g} m; no overturning moment (no block masses)"
    )
    return height, float(np.ptp(y0) + height), float(y0.min() - height / 2), float("nan")


def courses(y0: np.ndarray, height: float) -> list[np.ndarray]:
    """Block indices of each course from the bottom (module docstring)."""
    left = np.argsort(y0, kind="stable")
    out = []
    while left.size:
        inside = y0[left] <= y0[left[0]] + height / 2
        out.append(np.sort(left[inside]))
        left = left[~inside]
    return out


def _targets(h: dict, blocks: list[str], course_numbers: list[int], top: bool, height: float, shown: str):
    """(label, block indices) of each target, in the order given: blocks, courses, the top."""
    names = [str(n) for n in h["block_name"]]
    index = {name: i for i, name in enumerate(names)}
    y0 = h["block_q"][0, :, 1]
    out = []
    for name in blocks:
        if name not in index:
            close = difflib.get_close_matches(name, names, n=1)
            hint = f"; did you mean {close[0]}?" if close else ""
            span = f"{names[0]} … {names[-1]}" if names else "none"
            raise InputError(f"--blocks {name}: no such block in {shown} ({len(names)} blocks: {span}){hint}")
        out.append((name, np.array([index[name]])))
    if course_numbers:
        layers = courses(y0, height)
        for k in course_numbers:
            if not 1 <= k <= len(layers):
                raise InputError(f"--course {k}: {shown} has {len(layers)} courses (1 = the lowest)")
            out.append((f"course {k}", layers[k - 1]))
    if top:
        out.append(("top", np.flatnonzero(y0 >= y0.max() - height / 2)))
    return out


def ground_support(h: dict, name: str | None, shown: str) -> int:
    """Index of the reference support: ``name``, or the only support, or the first moving sideways."""
    names = [str(n) for n in h["support_name"]]
    if name is not None:
        if name not in names:
            raise InputError(f"--ground {name}: no such support in {shown} (supports: {', '.join(names) or 'none'})")
        return names.index(name)
    if not names:
        raise InputError(f"{shown}: a history without supports: nothing to measure relative to")
    moving = [s for s in range(len(names)) if np.any(h["support_v"][:, s, 0] != 0)]
    return moving[0] if moving else 0


def export_table(
    path,
    *,
    blocks: list[str] = (),
    course_numbers: list[int] = (),
    top: bool = False,
    ground: str | None = None,
    relative: bool = True,
    every: int = 1,
) -> Table:
    """The table of the history at ``path`` (module docstring); without targets, the top. ``path`` may also
    be the history's arrays (a dict: the Python API's run in memory), named "the run" in the messages."""
    shown = "the run" if isinstance(path, dict) else os.fspath(path)
    h = path if isinstance(path, dict) else read_history(path)
    table = Table(point=_run(h).get("study_point") or {})
    time = np.asarray(h["time"], dtype=float)
    q, v = h["block_q"], h["block_v"]
    if len(time) == 0:
        raise InputError(f"{shown}: a history of no frame: nothing to export")
    status = str(h["status"]) if "status" in h else None
    if status not in (None, "completed"):
        note = str(h.get("note", "")) or status
        table.notes.append(f"{shown}: {note}: exported its {len(time)} frames, up to t = {time[-1]:g} s")
    y0 = q[0, :, 1]
    height, structure_height, base_y, middle_x = _heights(h, y0, table.notes, shown)
    if not (blocks or course_numbers or top):
        top = True
    targets = _targets(h, list(blocks), list(course_numbers), top, height, shown)
    s = ground_support(h, ground, shown)
    if len(h["support_name"]) > 1 and ground is None:
        table.notes.append(f"{shown}: relative to the support {h['support_name'][s]} (--ground names another)")
    sq, sv = h["support_q"][:, s], h["support_v"][:, s]
    ground_u = sq - sq[0]  # (T,3): dx, dy, rotation
    ground_a = frame_rate(sv, time)

    table.add("time (s)", time)
    _add_motion(table, str(h["support_name"][s]), "", ground_u, sv, ground_a, rotation=False)
    rel = " rel" if relative else ""
    for label, members in targets:
        table.main = table.main or f"{label} ux{rel} (m)"
        u = (q[:, members] - q[0, members]).mean(axis=1)  # (T,3) mean displacement and rotation
        vel = v[:, members].mean(axis=1)
        acc = frame_rate(vel, time)
        if relative:
            u = u - ground_u
            vel = vel[:, :2] - sv
            acc = acc[:, :2] - ground_a
        _add_motion(table, label, rel, u, vel, acc, rotation=True)
    top_blocks = np.flatnonzero(y0 >= y0.max() - height / 2)
    top_dx = (q[:, top_blocks, 0] - q[0, top_blocks, 0]).mean(axis=1) - ground_u[:, 0]
    table.add("drift ratio (-)", top_dx / structure_height if structure_height > 0 else np.full(len(time), np.nan))
    force = -h["support_force"].sum(axis=1)  # (T,2): all the supports' force on the blocks
    # the frame of step 0 is before any contact force was solved: its 0 is no force, an empty cell says so
    # (a 0 there drew a spike at the first row of every base-shear plot, the moment beside it non-zero)
    force[h["step"] == 0] = np.nan
    table.add("base shear (N)", force[:, 0])
    table.add("base vertical (N)", force[:, 1])
    moment = overturning_moment(h, time, base_y, middle_x, ground_u)
    if moment is not None:
        # the moment of the same base reaction, empty where the shear is: the blocks' inertia gives a number at
        # step 0 (a one-sided difference, the first interval's mean put at t = 0), but no support force acts
        # yet, and a moment-against-shear (M-V) plot took that row as a half point (a blank x is 0 in Excel)
        moment[h["step"] == 0] = np.nan
        table.add("overturning moment (N m)", moment)
    for name, column in SCALARS:
        if name in h:
            table.add(column, h[name])
    if every > 1:
        table.values = [value[::every] for value in table.values]
    return table


def _add_motion(table: Table, label: str, rel: str, u, vel, acc, rotation: bool) -> None:
    """The columns of one target's (or the ground's) motion: ux, uy, [rot], vx, vy, ax, ay; ``rel`` (" rel" or
    "") marks the relative ones (a rotation is the same either way)."""
    columns = [("ux", "m", u[:, 0]), ("uy", "m", u[:, 1])]
    if rotation:
        columns.append(("rot", "rad", u[:, 2]))
    columns += [
        ("vx", "m/s", vel[:, 0]),
        ("vy", "m/s", vel[:, 1]),
        ("ax", "m/s2", acc[:, 0]),
        ("ay", "m/s2", acc[:, 1]),
    ]
    for col, unit, value in columns:
        table.add(f"{label} {col}{'' if col == 'rot' else rel} ({unit})", value)


def overturning_moment(h: dict, time: np.ndarray, base_y: float, middle_x: float, ground_u: np.ndarray):
    """(T,) N m, or None without the blocks' masses (module docstring): Σ_i (r_i − O) × m_i (a_i − g) + I_i α_i,
    O = (middle_x, base_y) + the ground's displacement."""
    if "block_mass" not in h or "block_inertia" not in h or not np.isfinite(middle_x):
        return None
    mass, inertia = h["block_mass"], h["block_inertia"]
    gravity = _gravity(h)
    q, v = h["block_q"], h["block_v"]
    acc = frame_rate(v, time)  # (T,N,3)
    rx = q[:, :, 0] - (middle_x + ground_u[:, :1])
    ry = q[:, :, 1] - (base_y + ground_u[:, 1:2])
    fx = mass * (acc[:, :, 0] - gravity[0])
    fy = mass * (acc[:, :, 1] - gravity[1])
    return (rx * fy - ry * fx + inertia * acc[:, :, 2]).sum(axis=1)


def _run(h: dict) -> dict:
    """The run's parameters (the history's ``run`` JSON), empty when it has none or they do not read."""
    import json

    try:
        run = json.loads(str(h["run"])) if "run" in h else {}
    except ValueError:
        return {}
    return run if isinstance(run, dict) else {}


def _gravity(h: dict) -> np.ndarray:
    """The run's gravity (m/s²) from its parameters, else (0, −9.81)."""
    try:
        return np.asarray(_run(h).get("gravity_m_s2", (0.0, -9.81)), dtype=float)
    except (ValueError, TypeError):
        return np.array([0.0, -9.81])


def long_table(tables: list[Table], names: list[str], shown: list[str]) -> Table:
    """One table of several runs' (a study's ``--histories``), one row per run × row: ``history`` (``names``,
    the file's stem), the swept values of each run's study point (an empty cell where a run has none), then
    the runs' columns, which must be the same. :class:`InputError` naming the first run whose columns differ."""
    first = tables[0]
    for table, where in zip(tables[1:], shown[1:]):
        if table.names != first.names:
            other = next((n for n in table.names if n not in first.names), None) or next(
                n for n in first.names if n not in table.names
            )
            raise InputError(
                f"--combined: {where} has other columns than {shown[0]} ({other}): one table needs the same "
                "columns (the same structure, targets and --times), export them apart"
            )
    out = Table(notes=[note for table in tables for note in table.notes], main=first.main)
    sizes = [len(table.values[0]) for table in tables]
    out.names.append("history")
    out.values.append(np.repeat(np.array(names, dtype=object), sizes))
    keys = list(dict.fromkeys(key for table in tables for key in table.point))
    for key in keys:
        values = [table.point.get(key) for table in tables]
        if all(v is None or (isinstance(v, int | float) and not isinstance(v, bool)) for v in values):
            whole = all(isinstance(v, int) for v in values)  # None (a run without the key) is an empty cell
            column = np.array([np.nan if v is None else v for v in values], dtype=np.int64 if whole else float)
            column = np.repeat(column, sizes)
        else:
            column = np.repeat(np.array(["" if v is None else str(v) for v in values], dtype=object), sizes)
        out.names.append(f"study {key}" if key in first.names or key == "history" else key)  # a lab's column "amp"
        out.values.append(column)
    for i, name in enumerate(first.names):
        out.names.append(name)
        out.values.append(np.concatenate([table.values[i] for table in tables]))
    return out


def number(x) -> str:
    """A cell: an integer as it is, a float as the shortest text that reads back as the same float
    (``repr``); NaN an empty cell (Excel and pandas read it as missing); text (a lab file's cell) as it is."""
    if isinstance(x, int | str):
        return str(x)
    return repr(x) if np.isfinite(x) else ""


def write_csv(table: Table, part) -> None:
    """Write ``table`` as CSV (UTF-8, comma, one header row) at ``part``."""
    with open(part, "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        writer.writerow(table.names)
        columns = [[number(x) for x in value.tolist()] for value in table.values]
        writer.writerows(zip(*columns))
