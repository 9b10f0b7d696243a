"""The layering the project keeps: each heavy library is imported by one package only; and every
non-trivial engine kernel opens with its pseudo-code; and no module holds more than 500 lines.

numba by the engine (masonrycli/engine; the solver lab compiles its research copies of engine kernels
through the engine's ``_jit.njit``, so the flags stay the engine's), rerun by the recording package,
shapely by geometry_library. Tests and documentation scripts may read recordings and build polygons
as references; the product and the benchmarks may not reach around the layer.
"""

from __future__ import annotations

import ast
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


KERNEL_LINES = 10
"""A kernel longer than this (decorator and signature excluded) is non-trivial."""


def _kernels_without_pseudo_code() -> list[str]:
    # A kernel's pseudo-code is a comment block right above its decorator or right below its signature.
    missing = []
    for path in sorted((ROOT / "masonrycli" / "engine").glob("*.py")):
        lines = path.read_text(encoding="utf-8").splitlines()
        for node in ast.walk(ast.parse("\n".join(lines))):
            if not isinstance(node, ast.FunctionDef):
                continue
            if not any(k in ast.unparse(d) for d in node.decorator_list for k in ("njit", "kernel_only")):
                continue
            first_statement = node.body[0].lineno  # 1-based
            if first_statement + KERNEL_LINES > node.end_lineno:
                continue
            above = lines[min(d.lineno for d in node.decorator_list) - 2].lstrip()
            inside = lines[first_statement - 2].lstrip()  # the line before the first statement
            if not (above.startswith("#") or inside.startswith("#")):
                missing.append(f"{path.relative_to(ROOT).as_posix()}:{node.lineno} {node.name}")
    return missing


def test_every_non_trivial_kernel_opens_with_its_pseudo_code():
    assert not _kernels_without_pseudo_code(), "kernels without a pseudo-code comment"


MODULE_LINES = 500
"""One concept per module: a module longer than this holds more than one (the house rule)."""


def _long_modules() -> list[str]:
    long = []
    for top in CHECKED:
        for path in sorted((ROOT / top).rglob("*.py")):
            if "solver_lab/data" in path.as_posix():
                continue
            count = len(path.read_text(encoding="utf-8").splitlines())
            if count > MODULE_LINES:
                long.append(f"{path.relative_to(ROOT).as_posix()} ({count} lines)")
    return long


def test_modules_hold_at_most_500_lines():
    checked = sum(1 for top in CHECKED for _ in (ROOT / top).rglob("*.py"))
    assert checked > 100, "too few modules found: the test would pass vacuously"
    assert not _long_modules(), f"modules over {MODULE_LINES} lines: {_long_modules()}"
