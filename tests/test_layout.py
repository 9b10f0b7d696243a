"""The layering the project keeps: each heavy library is imported by one package only.

numba by the engine (masonrycli/engine; the solver lab compiles its research copies of engine kernels
through the engine's ``_jit.njit``, so the flags stay the engine's), rerun by the recording package,
shapely by geometry_library. Tests and documentation scripts may read recordings and build polygons
as references; the product and the benchmarks may not reach around the layer.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CHECKED = ("masonrycli", "geometry_library", "benchmarks")
OWNER = {"numba": "masonrycli/engine", "rerun": "masonrycli/recording", "shapely": "geometry_library"}


def _importers(library: str) -> set[str]:
    pattern = re.compile(rf"^\s*(import {library}\b|from {library}[ .])", re.M)
    found = set()
    for top in CHECKED:
        for path in (ROOT / top).rglob("*.py"):
            if "solver_lab/data" in path.as_posix():
                continue
            if pattern.search(path.read_text(encoding="utf-8")):
                found.add(path.relative_to(ROOT).as_posix())
    return found


@pytest.mark.parametrize("library", sorted(OWNER))
def test_library_is_imported_by_its_package_only(library):
    owner = OWNER[library]
    importers = _importers(library)
    assert importers, f"no module imports {library}: the test would pass vacuously"
    outside = sorted(p for p in importers if not p.startswith(owner + "/"))
    assert not outside, f"{library} imported outside {owner}: {outside}"
