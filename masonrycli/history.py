"""The history file: one row per recorded frame, written as an uncompressed ``.npz``.

Arrays (T frames, N blocks, S supports), block order = scenario order:

    time (T,) s · step (T,) · block_q (T,N,3) [x, y m, rotation from the initial orientation rad CCW]
    block_v (T,N,3) [m/s, m/s, rad/s] · support_q (T,S,3) · support_v (T,S,2) · support_force (T,S,2) N
    contact_count (T,) · nlgs_iterations (T,) · nlgs_residual (T,)
    energy_kinetic (T,) J · energy_potential (T,) J · energy_dissipated (T,) J (cumulated)
    support_work (T,) J (cumulated) · every per-block tensor field of masonrycli.tensors.TENSOR_FIELDS
    joint_body (J,2) · joint_hinged (T,J) bool · hinge_count (T,)  (see masonrycli.mechanism)
    block_name (N,) · support_name (S,) · status () str
    intensity_pga, intensity_pgv, intensity_arias, intensity_d5_95, intensity_sa () — the ground motion as
    applied (masonrycli.intensity), when a support shakes
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from masonrycli.frame import Frame

_SCALARS = (
    "time",
    "step",
    "contact_count",
    "nlgs_iterations",
    "nlgs_residual",
    "energy_kinetic",
    "energy_potential",
    "energy_dissipated",
    "support_work",
)
_ARRAYS = ("block_q", "block_v", "support_q", "support_v", "support_force")


class History:
    """Collects frames in memory and writes them as one ``.npz``."""

    def __init__(self, block_name, support_name):
        self.block_name = np.asarray(block_name, dtype=str)
        self.support_name = np.asarray(support_name, dtype=str)
        self._rows: dict[str, list] = {}
        self.run_values: dict[str, float] = {}
        """One value per run (e.g. ``intensity_pga``), written as 0-d arrays."""

    def __len__(self) -> int:
        return len(self._rows.get("time", ()))

    def append(self, frame: Frame) -> None:
        rows = self._rows
        for name in _SCALARS:
            rows.setdefault(name, []).append(getattr(frame, name))
        for name in _ARRAYS:
            rows.setdefault(name, []).append(np.array(getattr(frame, name), copy=True))
        for name, value in frame.tensors.items():
            rows.setdefault(name, []).append(np.array(value, copy=True))
        rows.setdefault("joint_hinged", []).append(np.array(frame.joint_hinged, copy=True))
        rows.setdefault("hinge_count", []).append(int(frame.joint_hinged.sum()))
        self.joint_body = frame.joint_body

    def arrays(self) -> dict[str, np.ndarray]:
        out = {name: np.asarray(values) for name, values in self._rows.items()}
        out["block_name"] = self.block_name
        out["support_name"] = self.support_name
        out |= {name: np.asarray(value) for name, value in self.run_values.items()}
        if self._rows:
            out["joint_body"] = np.asarray(self.joint_body)
        return out

    def write(self, path: str | os.PathLike, status: str = "completed") -> Path:
        """Write atomically (temporary file then rename) so an interrupted write never leaves half a file."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".tmp.npz")
        np.savez(tmp, status=np.asarray(status), **self.arrays())
        os.replace(tmp, path)
        return path
