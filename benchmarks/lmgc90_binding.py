"""The ctypes side of benchmarks/lmgc90_reference.py: compas_lmgc90 0.1.11's C structures, its private
NLGS settings (read, checked against the shipped values, patched) and the per-step counters.

Imported by lmgc90_reference.py as a sibling module (the script runs with the reference venv's
interpreter as ``python benchmarks/lmgc90_reference.py``); never imported by masonry or its tests.
"""

from __future__ import annotations

import ctypes
import hashlib
from pathlib import Path

# ---- the private NLGS settings of compas_lmgc90 0.1.11's Fortran wrapper (wrap_lmgc90_compas.f90) ----
# The .so is stripped of local symbols; the module variables sit in .data at these virtual addresses
# (found by their shipped values, which are checked before any write). The load base comes from an
# exported symbol of the same library.
LMGC_SO_SHA256 = "ebdc74121046b9c7ec887b24261a85356f8a6351063081f2fca399a166e6f5c5"
ANCHOR = ("__nlgs_3d_MOD_get_nlgs3d_loop", 0x1649A0)
VAR = {"tol": 0x53B850, "relax": 0x53B860, "norm": 0x53B885, "gs_it2": 0x53B8A0, "gs_it1": 0x53B8A4}
F32 = lambda x: float(ctypes.c_float(x).value)  # noqa: E731  (the wrapper's literals are single precision)
SHIPPED = {"norm": "QM/16", "tol": F32(1.666e-4), "relax": F32(0.1), "gs_it1": 50, "gs_it2": 500}
CONFIGS = {
    "shipped": dict(SHIPPED),
    "matched": {"norm": "Quad ", "tol": 1.666e-4, "relax": 1.0, "gs_it1": 50, "gs_it2": 20},
    # same, convergence checked every 10 sweeps / after every sweep (each check is one more sweep)
    "matched-check10": {"norm": "Quad ", "tol": 1.666e-4, "relax": 1.0, "gs_it1": 10, "gs_it2": 100},
    "matched-check1": {"norm": "Quad ", "tol": 1.666e-4, "relax": 1.0, "gs_it1": 1, "gs_it2": 1000},
}


# --------------------------------------------------------------------------------------------------
# LMGC90 through compas_lmgc90


class Body3D(ctypes.Structure):
    _fields_ = [("coor", ctypes.c_double * 3), ("frame", ctypes.c_double * 9)]


class Inter3D(ctypes.Structure):  # lmgc90_inter_meca_3D of the binding (bind(c) Fortran type)
    _fields_ = [
        ("cdan", ctypes.c_char * 5),
        ("icdan", ctypes.c_int),
        ("cdbdy", ctypes.c_char * 5),
        ("icdbdy", ctypes.c_int),
        ("anbdy", ctypes.c_char * 5),
        ("ianbdy", ctypes.c_int),
        ("cdtac", ctypes.c_char * 5),
        ("icdtac", ctypes.c_int),
        ("antac", ctypes.c_char * 5),
        ("iantac", ctypes.c_int),
        ("icdsci", ctypes.c_int),
        ("iansci", ctypes.c_int),
        ("behav", ctypes.c_char * 5),
        ("status", ctypes.c_char * 5),
        ("coor", ctypes.c_double * 3),
        ("uc", ctypes.c_double * 9),
        ("rloc", ctypes.c_double * 3),
        ("vloc", ctypes.c_double * 3),
        ("gap", ctypes.c_double),
        ("nb_int", ctypes.c_int),
        ("internals", ctypes.c_double * 19),
    ]


class Lmgc:
    def __init__(self):
        from compas_lmgc90 import _lmgc90

        self.path = _lmgc90.__file__
        self.sha256 = hashlib.sha256(Path(self.path).read_bytes()).hexdigest()
        self.lib = ctypes.CDLL(self.path)  # the already loaded library (same handle)
        self.lib.lmgc90_get_nb_inters.restype = ctypes.c_int
        self.lib.lmgc90_get_nb_bodies.restype = ctypes.c_int
        anchor = ctypes.cast(getattr(self.lib, ANCHOR[0]), ctypes.c_void_p).value
        self.base = anchor - ANCHOR[1]
        self.patchable, self.why_not = self._check_patchable()

    # -- the wrapper's private NLGS settings
    def _addr(self, name):
        return self.base + VAR[name]

    def read_settings(self) -> dict:
        return {
            "norm": ctypes.string_at(self._addr("norm"), 5).decode("ascii"),
            "tol": ctypes.c_double.from_address(self._addr("tol")).value,
            "relax": ctypes.c_double.from_address(self._addr("relax")).value,
            "gs_it1": ctypes.c_int32.from_address(self._addr("gs_it1")).value,
            "gs_it2": ctypes.c_int32.from_address(self._addr("gs_it2")).value,
        }

    def _check_patchable(self):
        if self.sha256 != LMGC_SO_SHA256:
            return False, f"_lmgc90 .so SHA-256 {self.sha256} is not the 0.1.11 cp311 manylinux wheel's"
        if self.read_settings() != SHIPPED:
            return False, f"wrapper settings read {self.read_settings()}, expected the shipped {SHIPPED}"
        return True, ""

    def write_settings(self, s: dict) -> None:
        if not self.patchable:
            raise RuntimeError(self.why_not)
        norm = s["norm"].ljust(5)[:5].encode("ascii")
        ctypes.memmove(self._addr("norm"), norm, 5)
        ctypes.c_double.from_address(self._addr("tol")).value = s["tol"]
        ctypes.c_double.from_address(self._addr("relax")).value = s["relax"]
        ctypes.c_int32.from_address(self._addr("gs_it1")).value = s["gs_it1"]
        ctypes.c_int32.from_address(self._addr("gs_it2")).value = s["gs_it2"]
        assert self.read_settings() == {**s, "norm": norm.decode("ascii")}

    # -- state
    def bodies(self):
        n = self.lib.lmgc90_get_nb_bodies()
        arr = (Body3D * n)()
        self.lib.lmgc90_get_all_bodies(arr, n)
        return [tuple(b.coor) for b in arr]

    def poses(self):
        """(centre of mass (B, 3), frame (B, 3, 3)) of every body. A material point moves as
        X(t) = c(t) + F(t)ᵀ F(0) (X(0) − c(0)) (compas_lmgc90's ``Solver._update_meshes``)."""
        import numpy as np

        n = self.lib.lmgc90_get_nb_bodies()
        arr = (Body3D * n)()
        self.lib.lmgc90_get_all_bodies(arr, n)
        return np.array([tuple(b.coor) for b in arr]), np.array([tuple(b.frame) for b in arr]).reshape(n, 3, 3)

    def inters(self):
        n = self.lib.lmgc90_get_nb_inters()
        arr = (Inter3D * max(n, 1))()
        if n:
            self.lib.lmgc90_get_all_inters(arr, n)
        return list(arr)[:n]

    def nlgs_loop(self):
        it, nc = ctypes.c_int(), ctypes.c_int()
        e1, e2, e3 = ctypes.c_double(), ctypes.c_double(), ctypes.c_double()
        getattr(self.lib, ANCHOR[0])(
            ctypes.byref(it), ctypes.byref(e1), ctypes.byref(e2), ctypes.byref(e3), ctypes.byref(nc)
        )
        return it.value, nc.value
