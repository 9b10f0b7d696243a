"""A run's history from Python (:mod:`masonrycli.api`): :class:`Run`, its arrays by name with their units, and the
command line's views of them (``masonry export``'s table, ``masonry report``'s page)."""

from __future__ import annotations

import difflib
import json
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from masonrycli.api_keywords import path_value, python_spelled
from masonrycli.errors import InputError


@dataclass(frozen=True, eq=False)
class Run:
    """A run's history: ``run["block_q"]`` is the array of that name in the ``.npz`` (T frames, N blocks, S
    supports, J joints; ``run.unit(name)`` its unit), and a few views of them."""

    arrays: dict
    """Every array of the history, by name, as the ``.npz`` holds them (``units`` and ``run`` too)."""
    outcome: dict | None = None
    """The structure's state (``state``: intact, damaged or collapsed; ``collapse_time`` s, NaN if none;
    ``peak_drift``, ``residual_drift`` × height; ``hinges``; ``max_opening`` m; …: docs/collapse.md); of a
    history read from a file, the keys it keeps (:func:`read_history`), or None for an older file."""
    recording: Path | None = None
    """The recording written, or None."""
    history: Path | None = None
    """The history file written (or read), or None."""
    summary: str = field(default="", repr=False)
    """The command line's end-of-run table, as text ("" for a history read from a file)."""

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self.arrays:
            close = difflib.get_close_matches(name, list(self.arrays), n=3)
            raise KeyError(f"{name!r}: no such array" + (f" (did you mean {', '.join(close)}?)" if close else ""))
        return self.arrays[name]

    def __repr__(self) -> str:
        state = f", {self.outcome['state']}" if self.outcome else ""
        return (
            f"<masonry Run: {self.status}{state}, {len(self.block_names)} blocks, {len(self.time)} frames to "
            f"t = {self.time[-1] if len(self.time) else 0:g} s>"
        )

    def unit(self, name: str) -> str:
        """The unit / meaning of array ``name`` (the history's ``units`` table)."""
        self[name]  # noqa: B018 (an unknown name is a KeyError that says so)
        return self.units.get(name, "")

    @property
    def units(self) -> dict[str, str]:
        return {str(k): str(v) for k, v in self.arrays.get("units", np.zeros((0, 2), dtype=str))}

    @property
    def parameters(self) -> dict:
        """The run's parameters, as its history keeps them (the ``run`` array, JSON): ``scenario``, ``dt_s``,
        ``solver``, ``friction``, …, the ``command`` that ran it, and for a run of a study its ``study_point``
        (``{"freq": 2.0}``) and ``study_table``; {} for a history that keeps none. A teacher reading a study's
        histories had to ``json.loads(str(run["run"]))`` to learn which point each was."""
        text = str(self.arrays.get("run", ""))
        return json.loads(text) if text else {}

    @property
    def time(self) -> np.ndarray:
        """(T,) s, the recorded frames' times."""
        return self.arrays["time"]

    @property
    def status(self) -> str:
        """completed, interrupted, diverged or failed."""
        return str(self.arrays.get("status", ""))

    @property
    def note(self) -> str:
        """Where and why the run stopped ("" when it ran all its steps)."""
        return str(self.arrays.get("note", ""))

    @property
    def block_names(self) -> list[str]:
        return [str(n) for n in self.arrays["block_name"]]

    @property
    def support_names(self) -> list[str]:
        return [str(n) for n in self.arrays["support_name"]]

    @property
    def displacement(self) -> np.ndarray:
        """(T, N, 3) each block's centroid displacement from t = 0, x and y (m), and rotation (rad, CCW)."""
        q = self.arrays["block_q"]
        return q - q[:1]

    def block(self, name: str) -> int:
        """The index of block ``name`` on every block axis."""
        names = self.block_names
        if name not in names:
            close = difflib.get_close_matches(name, names, n=3)
            raise InputError(f"no block {name!r}" + (f" (did you mean {', '.join(close)}?)" if close else ""))
        return names.index(name)

    def hinged_joints(self, frame: int = -1) -> list[str]:
        """The joints hinged at ``frame`` (default the last), named ``"a|b"`` as the run's summary names them."""
        from masonrycli.model import JOINT_SEPARATOR

        names = self.block_names + self.support_names
        body = self.arrays["joint_body"][self.arrays["joint_hinged"][frame]]
        return [f"{names[a]}{JOINT_SEPARATOR}{names[b]}" for a, b in body]

    @python_spelled(
        keywords={"blocks", "courses", "top", "ground", "relative"},
        renamed={"course": "courses", "absolute": "relative"},
    )
    def table(self, *, blocks=(), courses=(), top: bool = False, ground: str | None = None, relative: bool = True):
        """``masonry export``'s columns, name (with its unit) → (T,) array: the ground's motion, each target's
        (a block by name, a course by number from the bottom, the top course) displacement, velocity and
        acceleration relative to the ground (``relative=False``: absolute), ``drift ratio (-)``, base shear,
        overturning moment, hinges, energies (``masonry docs readme``, "Export a history as CSV"). Without
        targets, the top course. ``pandas.DataFrame(run.table())`` makes it a frame."""
        from masonrycli.outputs.export import export_table

        table = export_table(
            self.arrays, blocks=list(blocks), course_numbers=list(courses), top=top, ground=ground, relative=relative
        )
        for note in table.notes:
            warnings.warn(note, UserWarning, stacklevel=2)
        return dict(zip(table.names, table.values))

    @python_spelled(keywords={"out", "force"}, renamed={})
    def report(self, out=None, *, force: bool = False) -> str:
        """``masonry report``'s one-page Markdown of the run (what was run, the ground motion as applied, the
        state, peak and residual drift, hinged joints, unconverged steps: the summary's numbers). ``out``: a
        ``.md`` path to write it to, with its figure beside it (``.png``), refused if it exists unless
        ``force=True``, as ``masonry report H.npz --out R.md``."""
        from masonrycli.outputs.run_report import check_outputs, report_markdown, write_report

        shown = str(self.history) if self.history is not None else "the run"
        if out is None:
            return report_markdown(self.arrays, shown)
        page, picture = check_outputs(path_value(out, "--out", output=True), force)
        write_report(self.arrays, shown, page, picture)
        return page.path.read_text(encoding="utf-8")
